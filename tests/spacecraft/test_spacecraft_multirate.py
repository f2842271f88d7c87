"""Control laws sampled at their own periods: B-dot at 1 s and MRP feedback at 0.1 s held apart (against an
independent NumPy RK4 of the gyrostat that holds each command at its own sample times), every period equal to
control_period (bit for bit the single-period spacecraft), the checks of a law's period, and a new period or law
compiling nothing; the scenario files' ``period``."""

import numpy as np
import pytest
from numba.core import event

import tumble
from tumble.kernels import spacecraft as kernel
from tumble.scenario import ScenarioError, parse
from tumble.spacecraft import (BDot, FlightSoftware, Magnetorquers, MomentumDumping, MRPFeedback, QuaternionPD,
                               ReactionWheel, Spacecraft, WheelTorques, pyramid_wheels)

from helpers import assert_same_run

# Every test that simulates compiles the spacecraft's kernels on first use with a cold Numba cache (its assembled
# right-hand side alone ~35 CPU s); the spacecraft's modules run on one xdist worker (tests/conftest.py, KINDS).
pytestmark = pytest.mark.slow

J_TOTAL = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])  # kg m², wheels included
SPIN = 0.02                               # kg m², spin inertia of each of the three orthogonal wheels
B_INERTIAL = np.array([2e-5, -1e-5, 3e-5])  # T, uniform, inertial axes
K_GAIN, P_GAIN = 0.5, 2.0                  # N m, N m s
BDOT_GAIN = 2e7                            # A m² s/T: a dipole torque of order 1e-3 N m, as the MRP law's
TARGET = np.array([np.cos(0.2), 0.0, np.sin(0.2), 0.0])
Q0 = np.array([np.cos(0.1), np.sin(0.1), 0.0, 0.0])
OMEGA0 = np.array([0.05, -0.04, 0.03])    # rad/s
DT, T_END = 0.01, 3.0
TORQUE_PERIOD, DIPOLE_PERIOD = 0.1, 1.0   # s
T = np.linspace(0.0, T_END, 301)          # every step an output time
# The reference does the same arithmetic in another order: the two agree to round-off, which the closed loop does
# not amplify over 300 steps (measured: 2.2e-16 in q, 2.1e-17 rad/s in ω, 1.6e-15 N m s in the wheel momenta;
# 5.6e-17 N m and 7.1e-15 A m² in the commands, whose scales are 0.13 N m and 23 A m²).
TOL_STATE, TOL_TORQUE, TOL_DIPOLE = 1e-14, 1e-14, 1e-12
# The flight software fed perfect sensors gives the truth to round-off (tests/spacecraft/
# test_spacecraft_flight_software.py's ROUND_OFF; measured here: 4.2e-17 in q, 5.6e-17 rad/s in ω and 8.6e-16 N m
# in the torque command, of scale 1.5 N m).
ROUND_OFF = 1e-13


def _multirate(mrp_period=TORQUE_PERIOD, bdot_period=DIPOLE_PERIOD, **changes):
    """Three orthogonal wheels deliver the MRP law's torque, magnetorquers the B-dot dipole; ``changes``: other
    arguments of the Spacecraft."""
    arguments = dict(inertia=J_TOTAL, wheels=[ReactionWheel(axis=a, inertia=SPIN) for a in np.eye(3)],
                     magnetorquers=Magnetorquers(1e6), magnetic_field=B_INERTIAL,
                     controller=[MRPFeedback(K=K_GAIN, P=P_GAIN, target=TARGET, period=mrp_period),
                                 BDot(BDOT_GAIN, period=bdot_period)])
    return Spacecraft(**{**arguments, **changes})


# -- an independent reference: the gyrostat of three orthogonal wheels, in NumPy ------------------------------

def _qmul(a, b):
    w1, v1, w2, v2 = a[0], a[1:], b[0], b[1:]
    return np.concatenate([[w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)])


def _body(q, v):
    """``v`` (inertial axes) in body axes: ``q* ⊗ v ⊗ q``."""
    conj = q * [1.0, -1.0, -1.0, -1.0]
    return _qmul(_qmul(conj, np.concatenate([[0.0], v])), q)[1:]


def _mrp_command(q, omega, h_wheels, j_rate):
    """``u = −K σ − P ω + ω × H`` (Schaub & Junkins, §8), σ the MRP of ``q_c* ⊗ q`` (shortest rotation)."""
    e = _qmul(TARGET * [1.0, -1.0, -1.0, -1.0], q / np.linalg.norm(q))
    e = e if e[0] >= 0.0 else -e
    sigma = e[1:] / (1.0 + e[0])
    return -K_GAIN * sigma - P_GAIN * omega + np.cross(omega, j_rate @ omega + h_wheels)


def _rates(y, u, m, j_rate):
    """``q̇ = ½ q ⊗ [0, ω]``, ``J_ω ω̇ = u + m × B − ω × H`` and ``ḣ = −u`` (the wheels deliver ``u``)."""
    q, omega, h = y[:4], y[4:7], y[7:]
    hub = u + np.cross(m, _body(q, B_INERTIAL)) - np.cross(omega, j_rate @ omega + h)
    return np.concatenate([0.5 * _qmul(q, np.concatenate([[0.0], omega])), np.linalg.solve(j_rate, hub), -u])


def _reference():
    """RK4 of step DT, the quaternion normalised after each step; the MRP command computed at the steps
    k·TORQUE_PERIOD and the B-dot dipole ``m = k ω × B`` at k·DIPOLE_PERIOD, each held until its next."""
    j_rate = J_TOTAL - SPIN * np.eye(3)
    y = np.concatenate([Q0, OMEGA0, SPIN * OMEGA0])  # wheels at rest relative to the hub
    every_torque, every_dipole = round(TORQUE_PERIOD / DT), round(DIPOLE_PERIOD / DT)
    states, torque, dipole = [y], [], []
    for k in range(len(T)):
        if k % every_torque == 0:
            u = _mrp_command(y[:4], y[4:7], y[7:], j_rate)
        if k % every_dipole == 0:
            m = BDOT_GAIN * np.cross(y[4:7], _body(y[:4], B_INERTIAL))
        torque.append(u)
        dipole.append(m)
        if k == len(T) - 1:
            break
        k1 = _rates(y, u, m, j_rate)
        k2 = _rates(y + 0.5 * DT * k1, u, m, j_rate)
        k3 = _rates(y + 0.5 * DT * k2, u, m, j_rate)
        k4 = _rates(y + DT * k3, u, m, j_rate)
        y = y + DT / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        y[:4] /= np.linalg.norm(y[:4])
        states.append(y)
    return np.array(states), np.array(torque), np.array(dipole)


def _steps_of(command, every):
    """Whether ``command`` (one row per step) is constant on each run of ``every`` steps and changes between."""
    held = all(np.array_equal(command[i], command[i - i % every]) for i in range(len(command)))
    changes = all(not np.array_equal(command[i], command[i - 1]) for i in range(every, len(command), every))
    return held and changes


def test_each_law_is_held_at_its_own_period_and_the_motion_matches_an_independent_rk4():
    traj = tumble.simulate(_multirate(), omega0=OMEGA0, q0=Q0, t=T, method="rk4", dt=DT)
    states, torque, dipole = _reference()
    every_torque, every_dipole = round(TORQUE_PERIOD / DT), round(DIPOLE_PERIOD / DT)
    assert _steps_of(traj.torque_command, every_torque) and _steps_of(traj.dipole_command, every_dipole)
    assert not _steps_of(traj.torque_command, every_dipole // 2)  # not the dipole's (the test can fail)
    np.testing.assert_allclose(traj.q, states[:, :4], rtol=0, atol=TOL_STATE)
    np.testing.assert_allclose(traj.omega, states[:, 4:7], rtol=0, atol=TOL_STATE)
    np.testing.assert_allclose(traj.wheel_momentum, states[:, 7:], rtol=0, atol=TOL_STATE)
    np.testing.assert_allclose(traj.torque_command, torque, rtol=0, atol=TOL_TORQUE)
    np.testing.assert_allclose(traj.dipole_command, dipole, rtol=0, atol=TOL_DIPOLE)
    # The dipole matters to the motion: held at the MRP law's period instead, the motion differs.
    faster = tumble.simulate(_multirate(bdot_period=TORQUE_PERIOD), omega0=OMEGA0, q0=Q0, t=T, method="rk4", dt=DT)
    assert np.abs(faster.omega - traj.omega).max() > 1e3 * TOL_STATE


def test_a_law_with_a_period_is_held_while_the_others_stay_continuous():
    """No control_period: the B-dot held at 1 s, the MRP law continuous (its command changes at every step)."""
    traj = tumble.simulate(_multirate(mrp_period=None), omega0=OMEGA0, q0=Q0, t=T, method="rk4", dt=DT)
    assert _steps_of(traj.dipole_command, round(DIPOLE_PERIOD / DT)) and _steps_of(traj.torque_command, 1)


def test_a_wheel_torque_law_is_held_at_its_own_period():
    """A ramp of motor torques sampled every 0.05 s: each wheel's motor torque is the ramp's value at the last
    sample, to the rounding of the interpolation (no torque law and no limits: the motor torque is the command)."""
    ramp = WheelTorques([[0.0, 1e-3, -2e-3, 0.0], [4e-3, -1e-3, 0.0, 2e-3]], t=[0.0, 1.0], period=0.05)
    craft = Spacecraft(inertia=J_TOTAL, wheels=pyramid_wheels(SPIN), controller=ramp)
    t = np.linspace(0.0, 1.0, 101)
    traj = tumble.simulate(craft, omega0=OMEGA0, t=t, method="rk4", dt=DT)
    sampled = t[(np.arange(t.size) // 5) * 5]  # the last sample time 0.05 k at or before each output time
    expected = np.array([np.interp(sampled, ramp.t, ramp.torques[:, i]) for i in range(4)]).T
    assert _steps_of(traj.wheel_torque, 5)
    np.testing.assert_allclose(traj.wheel_torque, expected, rtol=0, atol=1e-17)  # 10 ulp of 4e-3 N m


@pytest.mark.parametrize("control_period", [None, 0.5])
def test_every_period_equal_to_control_period_is_the_single_period_spacecraft_bit_for_bit(control_period):
    single = tumble.simulate(_multirate(None, None, control_period=0.5), omega0=OMEGA0, q0=Q0, t=T, method="rk4",
                             dt=DT)
    own = tumble.simulate(_multirate(0.5, 0.5, control_period=control_period), omega0=OMEGA0, q0=Q0, t=T,
                          method="rk4", dt=DT)
    for name in ("q", "omega", "wheel_momentum", "torque_command", "dipole_command"):
        np.testing.assert_array_equal(getattr(own, name), getattr(single, name))


def _fsw():
    return FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=5e-5, delay=0, sensor_noise=False)


@pytest.mark.parametrize("build, run, message", [
    (lambda: BDot(1.0, period=0.0), None, r"^period: must be None \(the spacecraft's control_period\) or a finite "
                                          r"number > 0 \(s\), got 0.0$"),
    (lambda: MRPFeedback(1.0, 1.0, period=-0.1), None, r"^period: must be None"),
    (lambda: WheelTorques([0.0] * 4, period=float("inf")), None, r"^period: must be None"),
    (lambda: _multirate(bdot_period=0.25), dict(method="rk4", dt=0.1),
     r"^controller\[1\]\.period: must be a whole number of steps dt = 0.1 s \(the law's samples fall on the "
     r"steps\), got 0.25 s \(2.5 steps\)$"),
    (lambda: _multirate(), dict(method="dop853"),  # adaptive steps do not land on the samples
     r"^method: a sampled controller \(controller\[0\]\.period = 0.1 s\) needs a fixed-step method"),
    (lambda: Spacecraft(inertia=J_TOTAL, wheels=pyramid_wheels(SPIN), controller=QuaternionPD(0.2, period=0.25),
                        control_period=0.1, flight_software=_fsw()), None,
     r"^controller\[0\]\.period: with flight software a law's period must be a whole multiple of control_period "
     r"= 0.1 s \(the law reads the estimate of its sample time\), got 0.25 s$"),
    (lambda: Spacecraft(inertia=J_TOTAL, wheels=pyramid_wheels(SPIN), controller=QuaternionPD(0.2, period=0.05),
                        control_period=0.1, flight_software=_fsw()), None,
     r"^controller\[0\]\.period: with flight software a law's period must be a whole multiple"),
    (lambda: _multirate(control_period=0.5, wheels=pyramid_wheels(SPIN),
                        controller=[BDot(1.0, period=1.0), MomentumDumping(0.1)]), None,
     r"^controller\[0\]\.period: the dipole laws, and the torque law when the magnetorquers deliver its torque, "
     r"make one dipole command held at one period; got 1.0 s and 0.5 s$"),
    (lambda: Spacecraft(inertia=J_TOTAL, magnetorquers=Magnetorquers(1e6), magnetic_field=B_INERTIAL,
                        controller=[QuaternionPD(0.2), BDot(1.0, period=1.0)]), None,
     r"^controller\[1\]\.period: the dipole laws, and the torque law when the magnetorquers deliver its torque, "
     r"make one dipole command held at one period; got continuous and 1.0 s$"),
])
def test_bad_law_periods_are_refused(build, run, message):
    with pytest.raises(tumble.ValidationError, match=message):
        craft = build()
        if run is not None:
            tumble.simulate(craft, omega0=OMEGA0, t=T, **run)


def test_with_flight_software_a_law_at_a_multiple_of_control_period_reads_the_latest_estimate():
    """With perfect sensors and no delay the loop reads the truth at its samples: the PD law at twice the control
    period is the PD law at that control period without flight software, to the filter's round-off."""
    t = np.linspace(0.0, 4.0, 41)
    craft = Spacecraft(inertia=J_TOTAL, wheels=pyramid_wheels(SPIN), controller=QuaternionPD(0.5, target=TARGET,
                                                                                             period=0.2),
                       control_period=0.1, flight_software=_fsw())
    truth_fed = Spacecraft(inertia=J_TOTAL, wheels=pyramid_wheels(SPIN), controller=QuaternionPD(0.5, target=TARGET),
                           control_period=0.2)
    traj = tumble.simulate(craft, omega0=OMEGA0, t=t, method="rk4", dt=0.05)
    reference = tumble.simulate(truth_fed, omega0=OMEGA0, t=t, method="rk4", dt=0.05)
    assert _steps_of(traj.torque_command, 2)  # the outputs every control period, the law held two
    np.testing.assert_allclose(traj.q, reference.q, rtol=0, atol=ROUND_OFF)
    np.testing.assert_allclose(traj.omega, reference.omega, rtol=0, atol=ROUND_OFF)
    np.testing.assert_allclose(traj.torque_command, reference.torque_command, rtol=0, atol=ROUND_OFF)


def test_a_new_period_or_law_compiles_nothing():
    tumble.simulate(_multirate(), omega0=OMEGA0, t=T[:3], method="rk4", dt=DT)
    signatures = len(kernel.evaluate.signatures)
    with event.install_recorder("numba:compile") as compiles:
        other = _multirate(0.2, 0.5, control_period=0.1, wheels=pyramid_wheels(SPIN),
                           controller=[MRPFeedback(K=K_GAIN, P=P_GAIN, period=0.2),
                                       BDot(BDOT_GAIN, period=0.5), MomentumDumping(0.1, period=0.5),
                                       WheelTorques([1e-3, 0.0, 0.0, -1e-3], period=0.05)])
        traj = tumble.simulate(other, omega0=OMEGA0, t=T[:31], method="rk4", dt=DT)
    assert [e.data["dispatcher"].py_func.__qualname__ for e in compiles.buffer if e.is_start] == []
    assert len(kernel.evaluate.signatures) == signatures
    assert _steps_of(traj.torque_command, 20)  # the new composition ran: the torque law held at 0.2 s


# -- scenario files ------------------------------------------------------------------------------------------

MULTIRATE_SCENARIO = f"""
[spacecraft]
inertia = {J_TOTAL.tolist()}
[[spacecraft.wheels]]
axis = [1, 0, 0]
inertia = {SPIN}
[[spacecraft.wheels]]
axis = [0, 1, 0]
inertia = {SPIN}
[[spacecraft.wheels]]
axis = [0, 0, 1]
inertia = {SPIN}
[spacecraft.magnetorquers]
max_dipole = 1e6
[spacecraft.magnetic_field]
uniform = {B_INERTIAL.tolist()}
[[spacecraft.controller]]
kind = "mrp_feedback"
K = {K_GAIN}
P = {P_GAIN}
target = {TARGET.tolist()}
period = {TORQUE_PERIOD}
[[spacecraft.controller]]
kind = "bdot"
gain = {BDOT_GAIN}
period = {DIPOLE_PERIOD}
[initial]
omega = {OMEGA0.tolist()}
q = {Q0.tolist()}
[time]
stop = {T_END}
samples = {len(T)}
[solver]
method = "rk4"
dt = {DT}
"""


def test_a_scenario_gives_each_law_its_period():
    traj = parse(MULTIRATE_SCENARIO, source="multirate.toml").run()
    assert_same_run(traj, tumble.simulate(_multirate(), omega0=OMEGA0, q0=Q0, t=T, method="rk4", dt=DT))


@pytest.mark.parametrize("old, new, where, rule", [
    (f"period = {DIPOLE_PERIOD}", "period = 0.0", "spacecraft.controller[1].period", "must be > 0"),
    (f"period = {DIPOLE_PERIOD}", "period = 1.005", "spacecraft.controller[1].period",
     "must be a whole number of steps dt = 0.01 s"),
    ("[[spacecraft.controller]]\nkind = \"bdot\"", "[[spacecraft.controller]]\nkind = \"momentum_dumping\"\n"
     "gain = 0.1\n[[spacecraft.controller]]\nkind = \"bdot\"", "spacecraft.controller[2].period",
     "make one dipole command held at one period"),
])
def test_a_bad_period_in_a_scenario_names_its_key(old, new, where, rule):
    text = MULTIRATE_SCENARIO.replace(old, new)
    assert text != MULTIRATE_SCENARIO
    with pytest.raises(ScenarioError) as info:
        parse(text, source="multirate.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems
