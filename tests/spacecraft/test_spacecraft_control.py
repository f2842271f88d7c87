"""Open control of a spacecraft through tumble.simulate: MRP feedback (against an independent integration of the
gyrostat equations), Python laws, external torques, wheel motor torques, the deprecated alias."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tumble
from tumble import attitude, torques
from tumble.spacecraft import (ConstantTorque, MRPFeedback, Orbit, PythonLaw, QuaternionPD, ReactionWheel,
                               Spacecraft, WheelTorques, pyramid_wheels)

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

# Every test that simulates compiles a spacecraft model type on first use (30–60 s with a cold Numba cache on
# the 2 shared cores of the development machine, under 1 s warm).
SLOW = pytest.mark.slow

# ---------------------------------------------------------------------------------------------------------
# MRP feedback: the acceptance test of the issue
# ---------------------------------------------------------------------------------------------------------

J_TOTAL = np.diag([900.0, 800.0, 600.0])   # kg m², wheels included
WHEEL = 0.1                                # kg m², spin inertia of each of the three orthogonal wheels
K_GAIN, P_GAIN = 10.0, 150.0               # N m, N m s
SIGMA0 = np.array([0.1, 0.2, -0.3])
OMEGA0 = np.array([0.01, -0.01, 0.005])    # rad/s
T_MRP = np.linspace(0.0, 600.0, 61)
# The issue asks 1e-9 in ω (rad/s), attitude (rad) and wheel speeds (rad/s) with both integrators at
# rtol = atol = 1e-13. The wheels end near 120 rad/s, so 1e-9 rad/s is 1e-11 relative: tumble's dop853 (148
# steps) agrees with the reference to 2.5e-14 rad/s in ω, 1.1e-13 rad in attitude and 1.5e-10 rad/s in the
# wheel speeds (measured).
MRP_TOL = 1e-9
# The same law written in Python: the same motion up to the rounding of the law's arithmetic (~1e-16 relative),
# which the closed loop does not amplify (it contracts); the issue asks 1e-12.
PYTHON_TOL = 1e-12


def _mrp_craft(controller):
    return Spacecraft(inertia=J_TOTAL, wheels=[ReactionWheel(axis=a, inertia=WHEEL) for a in np.eye(3)],
                      controller=controller)


def _quaternion_of_mrp(sigma):
    """``q = [(1 − σ²), 2σ]/(1 + σ²)`` (Schaub & Junkins, §3.7): the attitude whose MRP is σ."""
    s2 = sigma @ sigma
    return np.concatenate([[(1.0 - s2) / (1.0 + s2)], 2.0 * sigma / (1.0 + s2)])


def _quaternion_of_mrp_batch(sigma):
    """(n, 4) quaternions of the MRPs σ (n, 3)."""
    return np.array([_quaternion_of_mrp(s) for s in sigma])


def _gyrostat(t, y):
    """The gyrostat under MRP feedback, written here from the equations (not by calling tumble):
    state σ (MRP), ω (rad/s, body axes), h (wheel momenta about the body axes, N m s)::

        J_ω ω̇ = −ω × H − ḣ,   H = J_ω ω + h,   J_ω = J − I_s E,   ḣ = −u
        u = −K σ − P ω + ω × H
        σ̇ = ¼ [(1 − σ²) E + 2[σ×] + 2σσᵀ] ω
    """
    sigma, omega, h = y[:3], y[3:6], y[6:]
    j_rate = J_TOTAL - WHEEL * np.eye(3)
    big_h = j_rate @ omega + h
    u = -K_GAIN * sigma - P_GAIN * omega + np.cross(omega, big_h)
    hdot = -u                      # three orthogonal wheels, no limits or friction: the motors deliver u
    omegadot = np.linalg.solve(j_rate, -np.cross(omega, big_h) - hdot)
    s2 = sigma @ sigma
    cross = np.array([[0.0, -sigma[2], sigma[1]], [sigma[2], 0.0, -sigma[0]], [-sigma[1], sigma[0], 0.0]])
    sigmadot = 0.25 * ((1.0 - s2) * np.eye(3) + 2.0 * cross + 2.0 * np.outer(sigma, sigma)) @ omega
    return np.concatenate([sigmadot, omegadot, hdot])


@pytest.fixture(scope="module")
def mrp_reference():
    """scipy's DOP853 from one output time to the next, so that each output is the end of a step: its dense
    output (t_eval) interpolates with an error of ~3e-9 rad/s in the wheel speeds (measured against rtol 3e-14),
    the step ends are consistent to 4e-11 rad/s."""
    states = [np.concatenate([SIGMA0, OMEGA0, WHEEL * OMEGA0])]   # zero wheel speeds: h = I_s (a·ω + 0)
    for start, stop in zip(T_MRP[:-1], T_MRP[1:]):
        sol = solve_ivp(_gyrostat, (start, stop), states[-1], method="DOP853", rtol=1e-13, atol=1e-13)
        assert sol.success
        states.append(sol.y[:, -1])
    y = np.array(states)
    sigma, omega, h = y[:, :3], y[:, 3:6], y[:, 6:]
    assert np.linalg.norm(sigma, axis=-1).max() < 1.0   # no switch to the shadow set is needed
    return sigma, omega, h / WHEEL - omega


@SLOW
def test_mrp_feedback_matches_an_independent_gyrostat_integration(mrp_reference):
    sigma, omega, speeds = mrp_reference
    traj = tumble.simulate(_mrp_craft(MRPFeedback(K=K_GAIN, P=P_GAIN)), OMEGA0, q0=_quaternion_of_mrp(SIGMA0),
                           t=T_MRP, method="dop853", rtol=1e-13, atol=1e-13)
    omega_error = np.abs(traj.omega - omega).max()
    attitude_error = attitude.relative_angle(traj.q, _quaternion_of_mrp_batch(sigma)).max()
    speed_error = np.abs(traj.wheel_speed - speeds).max()
    assert omega_error <= MRP_TOL, omega_error
    assert attitude_error <= MRP_TOL, attitude_error
    assert speed_error <= MRP_TOL, speed_error
    # the regulation happened (|σ| from 0.37 to 7e-6: the slow pole, 1/53 s, decays by e^-11 in 600 s) and the
    # wheels took the momentum (up to 110 rad/s)
    assert np.linalg.norm(sigma[-1]) < 1e-5 and np.abs(speeds[-1]).max() > 50.0


def _python_mrp(t, q, omega, wheel_speeds):
    """MRP feedback in Python from the quaternion, the rate and the wheel speeds (three wheels along x, y, z)."""
    if q[0] < 0.0:
        q = -q
    sigma = q[1:] / (1.0 + q[0])
    big_h = (J_TOTAL - WHEEL * np.eye(3)) @ omega + WHEEL * (omega + wheel_speeds)
    return -K_GAIN * sigma - P_GAIN * omega + np.cross(omega, big_h)


@SLOW
def test_python_law_gives_the_motion_of_the_compiled_law():
    """Both with RK4 at 0.1 s, so that only the law differs (an adaptive method's step sequence reacts to the
    rounding differences of the two laws: with dop853 at rtol 1e-13 the wheel speeds differ by 4.4e-12 rad/s).
    Measured: 7e-18 rad/s in ω, 5e-16 rad in attitude, 5e-14 rad/s in the wheel speeds."""
    q0 = _quaternion_of_mrp(SIGMA0)
    compiled = tumble.simulate(_mrp_craft(MRPFeedback(K=K_GAIN, P=P_GAIN)), OMEGA0, q0=q0, t=T_MRP, method="rk4",
                               dt=0.1)
    python = tumble.simulate(_mrp_craft(_python_mrp), OMEGA0, q0=q0, t=T_MRP, method="rk4", dt=0.1)
    assert np.abs(python.omega - compiled.omega).max() <= PYTHON_TOL
    assert attitude.relative_angle(python.q, compiled.q).max() <= PYTHON_TOL
    assert np.abs(python.wheel_speed - compiled.wheel_speed).max() <= PYTHON_TOL
    np.testing.assert_allclose(python.torque_command, compiled.torque_command, rtol=0, atol=1e-12)
    assert python.info["n_steps"] == compiled.info["n_steps"] == 6000


# The integral term: a constant disturbance torque L fixed in the body. Without it the loop settles where
# K σ = L (ω = 0); with it σ → 0 while P K_I z = L, z = K ∫σ dt. Linearised per axis (σ̇ ≈ ω/4):
# J s³ + P(1 + K_I J) s² + (K/4) s + P K_I K/4 = 0, slowest time constant 114 s for K_I = 3e-5 (53 s without);
# after 3600 s the transients are e^-31 of the initial error: what remains is dop853's (rtol 1e-12) error.
DISTURBANCE = np.array([0.05, -0.03, 0.02])   # N m, body axes
KI = 3e-5                                      # 1/(N m s)
T_INTEGRAL = np.linspace(0.0, 3600.0, 37)


@SLOW
@pytest.mark.parametrize("ki", [None, KI])
def test_integral_term_removes_the_steady_error_of_a_constant_disturbance(ki):
    craft = _mrp_craft(MRPFeedback(K=K_GAIN, P=P_GAIN, Ki=ki))
    traj = tumble.simulate(craft, OMEGA0, q0=_quaternion_of_mrp(SIGMA0), t=T_INTEGRAL, method="dop853",
                           rtol=1e-12, atol=1e-12, torque=torques.ConstantBody(DISTURBANCE))
    q = traj.q[-1] * np.sign(traj.q[-1, 0])
    sigma = q[1:] / (1.0 + q[0])
    # measured: σ within 5e-14 of its steady state, ω 5e-14 rad/s, the integral 1.1e-11 relative of its own
    if ki is None:
        # the exact steady state of the nonlinear loop: K σ = L
        np.testing.assert_allclose(sigma, DISTURBANCE / K_GAIN, rtol=0, atol=1e-11)
        assert "attitude_error_integral" not in traj.extras
    else:
        assert np.abs(sigma).max() < 1e-11
        # ... and the integral holds the disturbance: P K_I K ∫σ dt = L
        np.testing.assert_allclose(traj.attitude_error_integral[-1], DISTURBANCE / (P_GAIN * ki * K_GAIN),
                                   rtol=1e-9)
    assert np.abs(traj.omega[-1]).max() < 1e-11
    # the disturbance is the only external torque: the wheels absorb its impulse, L t, in inertial axes
    np.testing.assert_allclose(traj.external_torque[-1], DISTURBANCE, rtol=1e-15)


def test_mrp_feedback_refuses_bad_gains():
    with pytest.raises(tumble.ValidationError, match="K: must be"):
        MRPFeedback(K=0.0, P=1.0)
    with pytest.raises(tumble.ValidationError, match="P: must be a number > 0 or a symmetric positive-definite"):
        MRPFeedback(K=1.0, P=[[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(tumble.ValidationError, match="Ki: must be"):
        MRPFeedback(K=1.0, P=1.0, Ki=-1.0)
    with pytest.raises(tumble.ValidationError, match="target: must be a non-zero quaternion"):
        MRPFeedback(K=1.0, P=1.0, target=[0.0, 0.0, 0.0, 0.0])
    assert np.array_equal(MRPFeedback(K=1.0, P=2.0).P, 2.0 * np.eye(3))


# ---------------------------------------------------------------------------------------------------------
# Python laws, sampled; external torques; refusals
# ---------------------------------------------------------------------------------------------------------

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])


@SLOW
def test_sampled_python_law_is_called_at_the_sample_times_only():
    calls = []

    def law(t, q, omega, wheel_speeds):
        calls.append(t)
        assert q.shape == (4,) and omega.shape == (3,) and wheel_speeds.shape == (4,)
        return -2.0 * omega

    craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=law, control_period=0.5)
    traj = tumble.simulate(craft, [0.05, -0.02, 0.03], t=np.linspace(0.0, 5.0, 11), method="rk4", dt=0.05)
    # the start and every sample time t = 0.5 k: 11 calls, not 4 per RK4 step (400)
    np.testing.assert_allclose(calls, np.arange(0.0, 5.01, 0.5), rtol=0, atol=1e-12)
    np.testing.assert_allclose(traj.torque_command[::1], -2.0 * traj.omega, rtol=0, atol=1e-15)
    assert isinstance(craft.controller[0], PythonLaw) and traj.info["control_period"] == 0.5


def test_python_law_must_return_a_torque():
    craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=lambda t, q, w, s: [1.0, 2.0])
    with pytest.raises(tumble.ValidationError, match=r"controller: the function <lambda>\(t, q, omega, "
                                                     r"wheel_speeds\) must return 3 finite numbers"):
        tumble.simulate(craft, [0.0, 0.0, 0.0], t=[0.0, 0.1], method="rk4", dt=0.1)


@SLOW
def test_external_torques_compose_with_the_spacecraft_environment():
    """torque= adds to the spacecraft's own gravity gradient: GravityGradient + a Python torque on top of the
    environment equals the environment's torque doubled plus that torque (its extras say so)."""
    orbit = Orbit.circular(700e3, inclination=math.radians(60.0))
    craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), orbit=orbit, gravity_gradient=True,
                       controller=QuaternionPD(0.1, 0.9))
    extra = np.array([1e-4, 0.0, -2e-4])
    torque = torques.GravityGradient(orbit, INERTIA) + (lambda t, q, w: extra)
    t = np.linspace(0.0, 600.0, 13)
    traj = tumble.simulate(craft, [0.001, 0.0, 0.0], t=t, method="rk4", dt=0.5, torque=torque)
    gg = traj.gravity_gradient_torque
    # the same gravity-gradient kernel evaluated twice (the torque program normalises q first): to rounding
    # (measured: equal)
    np.testing.assert_allclose(traj.external_torque, gg + extra, rtol=0, atol=1e-15 * np.abs(gg).max() + 1e-20)
    # the momentum changes by the impulse of both (trapezoidal rule over 50 s intervals of a torque that turns with
    # the orbit, 5.9e3 s: measured 1.6e-4 of the change)
    total_i = attitude.rotate(traj.q, traj.external_torque + gg)
    impulse = np.concatenate([np.zeros((1, 3)), np.cumsum(0.5 * (total_i[1:] + total_i[:-1]) * 50.0, axis=0)])
    h = traj.momentum_inertial
    np.testing.assert_allclose(h - h[0], impulse, rtol=0, atol=2e-3 * np.abs(h - h[0]).max())
    assert craft.invariants(traj) == {}   # external torques act: nothing is conserved


# ---------------------------------------------------------------------------------------------------------
# Wheel motor torques commanded directly
# ---------------------------------------------------------------------------------------------------------

MOTOR = np.array([0.01, -0.02, 0.005, 0.0])   # N m, one per pyramid wheel


@SLOW
def test_constant_wheel_torques_spin_the_wheels_linearly_and_conserve_momentum():
    craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=WheelTorques(MOTOR))
    t = np.linspace(0.0, 20.0, 21)
    traj = tumble.simulate(craft, [0.01, 0.02, -0.01], t=t, method="rk4", dt=0.05)
    # ḣ_i = u_i (no friction, no limits): h linear in t, which RK4 integrates exactly (measured 2.8e-16)
    np.testing.assert_allclose(traj.wheel_momentum - traj.wheel_momentum[0], t[:, None] * MOTOR, rtol=0,
                               atol=1e-15)
    np.testing.assert_allclose(traj.wheel_torque, np.broadcast_to(MOTOR, (21, 4)), rtol=0, atol=0)
    invariants = craft.invariants(traj)
    h = invariants["momentum_inertial"]
    assert np.abs(h - h[0]).max() < 1e-12 * np.linalg.norm(h[0])   # measured 2.3e-14
    # the motors' work is all the energy change (RK4 at dt = 0.05 s: measured 8e-16 of the 5.3 J change)
    change = invariants["energy_minus_wheel_work"]
    assert np.abs(change - change[0]).max() < 1e-10 * np.ptp(traj.energy)


@SLOW
def test_tabulated_and_python_wheel_torques_agree_and_add_to_the_torque_law():
    """A zero-order-hold table whose steps land on the output times equals the same profile in Python; with a
    torque law the direct command adds to what the law allocates to each wheel."""
    times = np.array([0.0, 2.0, 4.0])
    values = np.array([MOTOR, -MOTOR, 0.5 * MOTOR])
    table = WheelTorques(values, t=times, interpolation="previous")

    def profile(t, q, omega, wheel_speeds):   # the sample at or before t, as the table's zero-order hold
        return values[np.searchsorted(times, t, side="right") - 1]

    t = np.linspace(0.0, 6.0, 13)
    runs = []
    for law in (table, WheelTorques(profile)):
        craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                           controller=[ConstantTorque([0.002, -0.001, 0.0]), law])
        runs.append(tumble.simulate(craft, [0.01, 0.02, -0.01], t=t, method="rk4", dt=0.05))
    a, b = runs
    # both take the sample at or before each stage time: the same motion to rounding
    np.testing.assert_allclose(a.omega, b.omega, rtol=0, atol=1e-15)
    np.testing.assert_allclose(a.wheel_momentum, b.wheel_momentum, rtol=0, atol=1e-15)
    # motor torque = the allocation of the torque command (−A⁺ u) + the direct command
    axes = np.array([w.axis for w in pyramid_wheels(0.02)])
    allocated = -a.torque_command @ np.linalg.pinv(axes.T).T
    direct = values[np.minimum(np.searchsorted(times, t, side="right") - 1, 2)]
    np.testing.assert_allclose(a.wheel_torque, allocated + direct, rtol=0, atol=1e-16)


@SLOW
def test_sampled_wheel_torques_are_held_between_samples():
    """With a control period the motor commands of a ramp are sampled at t = 0, 0.5, 1, ... s and held: each
    wheel's torque is the ramp's value at the last sample, and h grows piecewise linearly by it."""
    ramp = WheelTorques(np.outer([0.0, 2.0], MOTOR), t=[0.0, 2.0])            # 0 → 2 u over 2 s, linear
    craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=ramp, control_period=0.5)
    t = np.linspace(0.0, 2.0, 41)
    traj = tumble.simulate(craft, [0.01, 0.02, -0.01], t=t, method="rk4", dt=0.05)
    held = np.floor(t / 0.5 + 1e-9) * 0.5                                      # the last sample time
    np.testing.assert_allclose(traj.wheel_torque, held[:, None] * MOTOR, rtol=0, atol=1e-17)
    # ∫ of the held staircase: exact for RK4 (constant within each step)
    impulse = np.concatenate([[0.0], np.cumsum(held[:-1] * np.diff(t))])
    np.testing.assert_allclose(traj.wheel_momentum - traj.wheel_momentum[0], impulse[:, None] * MOTOR, rtol=0,
                               atol=1e-16)


def test_wheel_torques_are_checked():
    with pytest.raises(tumble.ValidationError, match="controller: WheelTorques gives 3 motor torques for 4 wheels"):
        Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=WheelTorques([0.0, 0.0, 0.0]))
    with pytest.raises(tumble.ValidationError, match="controller: WheelTorques needs reaction wheels"):
        Spacecraft(inertia=INERTIA, controller=WheelTorques([0.0]))
    with pytest.raises(tumble.ValidationError,
                       match=r"t: sample times must be strictly increasing \(t\[1\] = 0.0 <= t\[0\] = 1.0\)"):
        WheelTorques([[0.0], [1.0]], t=[1.0, 0.0])
    with pytest.raises(tumble.ValidationError, match="interpolation"):
        WheelTorques([0.0], interpolation="cubic")
    with pytest.raises(tumble.ValidationError, match="controller: at most one torque law"):
        Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                   controller=[QuaternionPD(0.1), MRPFeedback(K=1.0, P=1.0)])


# ---------------------------------------------------------------------------------------------------------
# The front door's rules and the deprecated alias
# ---------------------------------------------------------------------------------------------------------


def test_initial_state_names_follow_the_parts():
    craft = Spacecraft(inertia=INERTIA, controller=None)
    with pytest.raises(tumble.ValidationError, match="wheel_speeds0: a Spacecraft has no initial state"):
        tumble.simulate(craft, [0.0, 0.0, 0.0], t=[0.0, 1.0], wheel_speeds0=[1.0])
    names = [f.name for f in _mrp_craft(MRPFeedback(K=1.0, P=1.0, Ki=1e-3)).state_fields()]
    assert names == ["omega0", "q0", "wheel_speeds0", "attitude_error_integral0"]

