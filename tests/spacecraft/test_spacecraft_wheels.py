"""Reaction wheels and the quaternion PD law: conservation, motor work, saturation, closed-loop response.

Every spacecraft here has wheels and a torque law in the ``pd`` slot (QuaternionPD or
RateDamping), so all the tests share one compiled model type.
"""

import math

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble._validate import ValidationError
from tumble.rigid_body import RigidBody
from tumble.spacecraft import (QuaternionPD, RateDamping, ReactionWheel, SaturationWarning, Spacecraft,
                               pyramid_wheels)

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
WHEEL_INERTIA = 0.02

# RK4 at dt = 0.01 s over 20 s of a tumbling slew with friction: the drift of H_I is the
# integrator's error (measured 2.5e-13 relative); the issue asks 1e-12.
MOMENTUM_RTOL = 1e-12
# Energy minus the work of motors and bearings, relative to the energy swing of 15.7 J
# (measured 2.0e-11; the two are integrated by the same RK4 steps).
WORK_RTOL = 1e-10


# Tests that simulate compile the spacecraft model on first use: 30–40 s with a cold Numba
# cache on the 2 shared cores of the development machine (the rigid body's rk4 takes as long),
# under 1 s warm.
SLOW = pytest.mark.slow


def _craft(**options):
    wheels = options.pop("wheels", None) or pyramid_wheels(WHEEL_INERTIA, viscous=2e-4, coulomb=1e-3,
                                                           coulomb_speed=1.0)
    controller = options.pop("controller", QuaternionPD(0.3, 0.8, target=attitude.from_rotvec([0.4, -0.3, 0.8])))
    return Spacecraft(inertia=INERTIA, wheels=wheels, controller=controller, **options)


@pytest.fixture(scope="module")
def slew():
    craft = _craft()
    t = np.linspace(0.0, 20.0, 201)
    return craft, tumble.simulate(craft, [0.05, -0.02, 0.03], t=t, wheel_speeds0=[10.0, -5.0, 3.0, 0.0],
                                  method="rk4", dt=0.01)


@SLOW
def test_total_angular_momentum_is_conserved(slew):
    _, traj = slew
    h = traj.extras["total_momentum_inertial"].data
    drift = np.abs(np.linalg.norm(h - h[0], axis=-1)).max() / np.linalg.norm(h[0])
    assert drift < MOMENTUM_RTOL


@SLOW
def test_energy_change_equals_wheel_work(slew):
    _, traj = slew
    energy = traj.extras["total_energy"].data
    work = traj.extras["wheel_work"].data
    swing = np.ptp(energy)
    assert swing > 1e-3  # the motors do work
    assert np.abs(energy - energy[0] - work).max() < WORK_RTOL * swing


@SLOW
def test_wheel_speed_is_momentum_over_inertia_less_axis_rate(slew):
    craft, traj = slew
    axes = np.array([w.axis for w in craft.wheels])
    speed = traj.extras["wheel_momentum"].data / WHEEL_INERTIA - traj.omega @ axes.T
    np.testing.assert_allclose(traj.extras["wheel_speed"].data, speed, rtol=0, atol=1e-12)
    np.testing.assert_allclose(traj.extras["wheel_speed"].data[0], [10.0, -5.0, 3.0, 0.0], atol=1e-12)


# Small-angle slew about the z principal axis: the closed loop is θ̈ + 2ζω_n θ̇ + ω_n² θ = 0 up to
# the sin(θ/2) ≈ θ/2 of the quaternion error, a relative error ~θ₀²/24 = 1.7e-5 at θ₀ = 0.02 rad
# (measured max |θ − θ_lin| = 6.2e-6 θ₀).
SLEW_ANGLE = 0.02
LINEAR_ATOL = 1e-4 * SLEW_ANGLE


def _linear_response(t, wn, zeta, theta0):
    wd = wn * math.sqrt(1.0 - zeta * zeta)
    return theta0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))


@SLOW
def test_pd_slew_follows_the_second_order_response():
    wn, zeta = 0.25, 0.6
    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(WHEEL_INERTIA),
                       controller=QuaternionPD(wn, zeta))
    t = np.linspace(0.0, 40.0, 81)
    q0 = attitude.from_rotvec([0.0, 0.0, SLEW_ANGLE])
    traj = tumble.simulate(craft, [0.0, 0.0, 0.0], t=t, q0=q0, method="rk4", dt=0.05)
    theta = attitude.to_rotvec(traj.q)[:, 2]
    np.testing.assert_allclose(theta, _linear_response(t, wn, zeta, SLEW_ANGLE), rtol=0, atol=LINEAR_ATOL)


@SLOW
def test_rate_damping_decays_with_its_time_constant():
    # u = −J_ω ω/τ + ω × H cancels the gyroscopic torque, so ω(t) = ω₀ exp(−t/τ) exactly;
    # RK4 at dt = 0.05 s (h/τ = 0.025): relative error (h/τ)⁵/120 = 8e-11 per step, 1.6e-8 after
    # the 200 steps to t = 10 s (measured 1.66e-8).
    tau = 2.0
    craft = _craft(controller=RateDamping(tau), wheels=pyramid_wheels(WHEEL_INERTIA))  # no friction
    t = np.linspace(0.0, 10.0, 11)
    w0 = np.array([0.1, -0.2, 0.05])
    traj = tumble.simulate(craft, w0, t=t, method="rk4", dt=0.05)
    np.testing.assert_allclose(traj.omega, np.exp(-t / tau)[:, None] * w0, rtol=2e-8, atol=0)


@SLOW
def test_hub_plus_wheels_equals_total_inertia():
    hub = RigidBody(np.diag([9.0, 11.0, 7.5]), mass=100.0, com=[0.01, 0.0, -0.02])
    wheels = [ReactionWheel(axis=a, inertia=WHEEL_INERTIA, mass=2.0, position=p, transverse_inertia=0.011)
              for a, p in zip(np.eye(3), [[0.3, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.3]])]
    described = Spacecraft(
        hub=hub, wheels=wheels, controller=QuaternionPD(0.3, 0.8, target=attitude.from_rotvec([0.4, -0.3, 0.8])))
    # The total, summed independently: rotor inertias I_s a aᵀ + I_t (E − a aᵀ) and the parallel axis theorem.
    masses = np.array([100.0, 2.0, 2.0, 2.0])
    coms = np.array([[0.01, 0.0, -0.02], [0.3, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.3]])
    com = masses @ coms / masses.sum()
    total = np.diag([9.0, 11.0, 7.5]) + sum(
        WHEEL_INERTIA * np.outer(a, a) + 0.011 * (np.eye(3) - np.outer(a, a)) for a in np.eye(3))
    for m, c in zip(masses, coms - com):
        total = total + m * (c @ c * np.eye(3) - np.outer(c, c))
    np.testing.assert_allclose(described.total_inertia, total, rtol=1e-14)
    given = Spacecraft(inertia=total, wheels=wheels,
                       controller=QuaternionPD(0.3, 0.8, target=attitude.from_rotvec([0.4, -0.3, 0.8])))
    t = np.linspace(0.0, 5.0, 6)
    a = tumble.simulate(described, [0.05, -0.02, 0.03], t=t, method="rk4", dt=0.05)
    b = tumble.simulate(given, [0.05, -0.02, 0.03], t=t, method="rk4", dt=0.05)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-13)
    np.testing.assert_allclose(a.omega, b.omega, rtol=0, atol=1e-13)


@SLOW
def test_speed_limit_is_reported_and_held():
    limit = 20.0
    wheels = pyramid_wheels(WHEEL_INERTIA, max_torque=0.05, max_speed=limit)
    craft = _craft(wheels=wheels)
    t = np.linspace(0.0, 20.0, 41)
    with pytest.warns(SaturationWarning, match="speed limit"):
        traj = tumble.simulate(craft, [0.0, 0.0, 0.0], t=t, method="rk4", dt=0.01)
    speed, flag = traj.extras["wheel_speed"].data, traj.extras["wheel_saturated"].data
    assert flag.any()
    # the motor stops at the limit: the speed overshoots it by at most one step of max torque
    assert np.abs(speed).max() <= limit + 0.05 / WHEEL_INERTIA * 0.01 * 1.0001
    assert np.all(np.isfinite(traj.q))


@SLOW
def test_torque_limit_is_respected(slew):
    wheels = pyramid_wheels(WHEEL_INERTIA, max_torque=0.01)
    traj = tumble.simulate(_craft(wheels=wheels), [0.0, 0.0, 0.0], t=np.linspace(0.0, 2.0, 21), method="rk4",
                           dt=0.01)
    assert np.abs(traj.extras["wheel_torque"].data).max() == pytest.approx(0.01, rel=1e-15)


@SLOW
def test_pd_torque_limit_scales_the_command_keeping_its_direction():
    # at rest (ω = 0) the unlimited law is u = C ω_c = −K q_e,v = −2ω_n² J_ω q_e,v (Wie, Weiss &
    # Arapostathis 1989), computed here independently; max_torque scales it so that max |u_k| = limit
    wn, limit = 0.3, 0.01
    target = attitude.from_rotvec([0.4, -0.3, 0.8])
    craft = _craft(controller=QuaternionPD(wn, 0.8, target=target, max_torque=limit))
    traj = tumble.simulate(craft, [0.0, 0.0, 0.0], t=np.linspace(0.0, 5.0, 11), method="rk4", dt=0.01)
    u = traj.extras["torque_command"].data
    error = attitude.multiply(attitude.conjugate(target), attitude.identity())
    unlimited = -2.0 * wn**2 * craft.rate_inertia @ (np.sign(error[0]) * error[1:])
    np.testing.assert_allclose(u[0], limit * unlimited / np.abs(unlimited).max(), rtol=1e-14, atol=0)
    assert np.abs(u).max() <= limit * (1.0 + 1e-15)


@SLOW
def test_zero_order_hold_holds_the_command_between_samples():
    period = 0.5
    craft = _craft(control_period=period)
    t = np.linspace(0.0, 2.0, 41)  # every 0.05 s: 10 outputs per sample
    traj = tumble.simulate(craft, [0.05, -0.02, 0.03], t=t, method="rk4", dt=0.05)
    u = traj.extras["torque_command"].data
    for k in range(4):
        block = u[10 * k:10 * k + 10]
        np.testing.assert_array_equal(block, np.broadcast_to(block[0], block.shape))
    assert not np.array_equal(u[0], u[10])


def test_zero_order_hold_refuses_steps_that_miss_the_samples():
    craft = _craft(control_period=0.25)
    with pytest.raises(ValidationError, match="dt: must divide control_period"):
        tumble.simulate(craft, [0.0, 0.0, 0.0], t=[0.0, 1.0], method="rk4", dt=0.1)
    with pytest.raises(ValidationError, match="method: a sampled controller"):
        tumble.simulate(craft, [0.0, 0.0, 0.0], t=[0.0, 1.0], method="dop853")
    with pytest.raises(ValidationError, match="output interval"):
        tumble.simulate(craft, [0.0, 0.0, 0.0], t=[0.0, 0.33], method="rk4", dt=0.05)


def test_zero_order_hold_refuses_the_closed_form():
    # method="exact" has no step (dt is None): once a TypeError dividing the control period by None
    craft = _craft(control_period=0.25)
    with pytest.raises(ValidationError, match="method: a sampled controller"):
        tumble.simulate(craft, [0.0, 0.0, 0.0], t=[0.0, 1.0], method="exact")


@pytest.mark.parametrize("kwargs, message", [
    ({"inertia": None}, "inertia: give exactly one"),
    ({"wheels": [ReactionWheel([0, 0, 1], 0.01)], "hub": RigidBody(np.eye(3), mass=1.0), "inertia": None},
     "wheels: with Spacecraft\\(hub=...\\)"),
    ({"controller": "pd"}, "controller: must be one of"),
    ({"control_period": -1.0}, "control_period: must be None"),
    ({"gravity_gradient": True}, "gravity_gradient: needs an orbit"),
])
def test_bad_spacecraft_is_refused(kwargs, message):
    options = {"inertia": INERTIA, "wheels": pyramid_wheels(WHEEL_INERTIA), **kwargs}
    with pytest.raises(ValidationError, match=message):
        Spacecraft(**options)


@pytest.mark.parametrize("kwargs, message", [
    ({"axis": [0, 0, 0], "inertia": 0.1}, "axis: must be a non-zero vector"),
    ({"axis": [0, 0, 1], "inertia": -0.1}, "inertia: must be a finite number > 0"),
    ({"axis": [0, 0, 1], "inertia": 0.1, "max_speed": 0.0}, "max_speed: must be > 0"),
    ({"axis": [0, 0, 1], "inertia": 0.1, "mass": 1.0}, "mass: give mass, position and transverse_inertia"),
])
def test_bad_wheel_is_refused(kwargs, message):
    with pytest.raises(ValidationError, match=message):
        ReactionWheel(**kwargs)


def test_simulate_refuses_a_method_the_spacecraft_does_not_provide_for():
    with pytest.raises(ValidationError, match="method: 'splitting2' needs .*, which a Spacecraft is not; "
                                              "methods for it: 'rk4', 'dop853', 'cf4'"):
        tumble.simulate(_craft(), [0.0, 0.0, 0.0], t=[0.0, 1.0], method="splitting2", dt=0.1)


@SLOW  # also compiles the parallel batch driver for the spacecraft model
def test_batch_equals_one_by_one():
    craft = _craft()
    t = np.linspace(0.0, 2.0, 5)
    w0 = np.array([[0.05, -0.02, 0.03], [0.0, 0.1, 0.0], [-0.02, 0.0, 0.01]])
    speeds = np.array([[10.0, -5.0, 3.0, 0.0], [0.0, 0.0, 0.0, 0.0], [1.0, 2.0, 3.0, 4.0]])
    batch = tumble.simulate(craft, w0, t=t, wheel_speeds0=speeds, method="rk4", dt=0.01)
    assert batch.q.shape == (5, 3, 4) and batch.extras["wheel_speed"].data.shape == (5, 3, 4)
    for b in range(3):
        one = tumble.simulate(craft, w0[b], t=t, wheel_speeds0=speeds[b], method="rk4", dt=0.01)
        np.testing.assert_array_equal(batch.q[:, b], one.q)
        np.testing.assert_array_equal(batch.extras["wheel_speed"].data[:, b], one.extras["wheel_speed"].data)


@SLOW  # also compiles dop853 for the spacecraft model
def test_adaptive_and_fixed_step_agree():
    # continuous control is smooth (no limits reached), so dop853 at rtol 1e-12 and RK4 at
    # dt = 0.005 s agree to their errors (measured 5.3e-15 rad/s and 9.4e-15 in q)
    craft = _craft(wheels=pyramid_wheels(WHEEL_INERTIA, viscous=2e-4))
    t = np.linspace(0.0, 10.0, 11)
    a = tumble.simulate(craft, [0.05, -0.02, 0.03], t=t, method="rk4", dt=0.005)
    b = tumble.simulate(craft, [0.05, -0.02, 0.03], t=t, method="dop853", rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(a.omega, b.omega, rtol=0, atol=1e-13)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-13)
