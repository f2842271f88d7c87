"""Every model through the one front door, under every method: the model × method matrix.

For each model and each method of tumble.integrate.METHODS: when the model's kernel provides what the
method needs, the run keeps what the model says its exact motion keeps (Model.invariants), to a tolerance
stated per model and method; otherwise the run is refused with the one message of
tumble.integrate.check_method, which names the methods that work."""

import numpy as np
import pytest

import tumble
from tumble import attitude, integrate, robot
from tumble.flexible import FlexibleBody, Mode
from tumble.fluid import KirchhoffBody
from tumble.ins import GimbaledGyro, Gyroscope
from tumble.slosh import Pendulum, SloshBody
from tumble.spacecraft import MRPFeedback, ReactionWheel, Spacecraft
from tumble.variable import Human, Motion, VariableBody

from helpers import read_by

# Every test here compiles the integrators of several model kinds on a cold Numba cache (tens of CPU s).
pytestmark = pytest.mark.slow

INERTIA = np.array([[2.0, 0.1, -0.05], [0.1, 3.0, 0.2], [-0.05, 0.2, 4.0]])  # kg m², body axes
OMEGA0 = np.array([0.3, 1.0, -0.4])  # rad/s: a generic tumble
Q0 = attitude.normalize([0.9, 0.1, -0.3, 0.2])  # a generic attitude, unit (simulate warns on one that is not)
ROBOTS = tumble.examples.directory() / "robots"


def _coupled_added_mass():
    """A full added mass (Fossen's order) whose angular–linear block is not zero (tests/test_fluid.py)."""
    root = np.random.default_rng(7).normal(size=(6, 6))
    return root @ root.T + np.diag([5.0, 8.0, 12.0, 1.0, 1.5, 2.0])


def _swimmer(t):
    """Two 1 kg masses at ±r(t) going once round a circle in the x–y plane of a base body (tests/variable/test_variable.py)."""
    u = np.clip(t / 2.0, 0.0, 1.0)
    s = 2.0 * np.pi * u**3 * (10.0 - 15.0 * u + 6.0 * u * u)
    s_dot = 2.0 * np.pi * 30.0 * u * u * (1.0 - u) ** 2 / 2.0
    r = np.stack([1.0 + 0.8 * np.cos(s), 0.8 * np.sin(s), np.zeros_like(s)], axis=-1)
    v = np.stack([-0.8 * np.sin(s) * s_dot, 0.8 * np.cos(s) * s_dot, np.zeros_like(s)], axis=-1)
    inertia = np.diag([0.3, 0.4, 0.5]) + 2.0 * (np.einsum("ni,ni->n", r, r)[:, None, None] * np.eye(3)
                                                - np.einsum("ni,nj->nij", r, r))
    return inertia, 2.0 * np.cross(r, v)


# Each model with a generic initial state, the span of the run (s), the rk4 step (s), and the largest change
# allowed of each invariant over 20 output times, relative to its start (|v − v₀| / |v₀|), under dop853
# (rtol = atol = 1e-12) and rk4. Measured (the comments: dop853; rk4, the worst invariant): at these steps
# both keep every invariant to 1e-13 or better; the momenta of the variable bodies sit in the state, where
# no torque-free step changes them, and lose only the rounding of R(q)ᵀ and R(q). Each tolerance leaves a
# factor ≥ 10 over the measured change.
CASES = {
    "FlexibleBody": (
        lambda: FlexibleBody(INERTIA, [Mode(3.0, 0.0, [0.3, 0.5, 0.2]), Mode(7.0, 0.0, [0.1, -0.4, 0.6])]),
        dict(omega0=OMEGA0, eta0=[0.05, 0.0], eta_rate0=[0.0, 0.1]), 5.0, 1e-3,
        {"dop853": 1e-12, "rk4": 1e-12}),      # measured 7.6e-14; 3.5e-14 (energy)
    "SloshBody": (
        lambda: SloshBody(tumble.RigidBody(np.array([[3.0, 0.1, 0.0], [0.1, 4.0, -0.2], [0.0, -0.2, 5.0]]),
                                           mass=10.0), Pendulum(mass=2.0, length=0.5, hinge=[0.3, -0.2, 0.4])),
        dict(omega0=OMEGA0, direction0=[1.0, 1.0, 0.0], rate0=[0.0, 0.3, 1.0]), 5.0, 1e-3,
        {"dop853": 1e-11, "rk4": 1e-11}),      # measured 3.0e-13; 2.1e-13 (momentum)
    "KirchhoffBody": (
        lambda: KirchhoffBody(tumble.RigidBody(INERTIA, mass=10.0), _coupled_added_mass()),
        dict(omega0=OMEGA0, velocity0=[1.0, 0.2, -0.3], q0=Q0, position0=[1.0, -2.0, 0.5]), 5.0, 1e-3,
        {"dop853": 1e-11, "rk4": 1e-11}),      # measured 4.0e-13 (|P|²); 2.1e-13 (momentum)
    "VariableBody": (
        lambda: VariableBody.from_functions(lambda t: _swimmer(t)[0], lambda t: _swimmer(t)[1], t_span=(0.0, 2.0),
                                            dt=1e-2),
        dict(omega0=[0.3, -1.0, 2.0]), 2.0, 1e-3,
        {"dop853": 1e-13, "rk4": 1e-13}),      # measured 1.4e-15; 4.7e-16 (the momentum: rounding)
    "MovingHuman": (
        lambda: Human.de_leva().moving({"left_shoulder_abduction": Motion(np.pi, [(0.2, 0.6, 0.0)])},
                                       t_span=(0.0, 1.0)),
        dict(omega0=[5.0, 0.0, 0.3]), 1.0, 1e-3,
        {"dop853": 1e-13, "rk4": 1e-13}),      # measured 8.7e-16; 8.6e-16
    "Gyroscope": (
        lambda: Gyroscope(spin_inertia=2e-3, transverse_inertia=1.5e-3, spin=100.0, mass=0.1, offset=0.02,
                          tilt=1.0),
        dict(precession_rate0=0.5), 0.2, 1e-4,
        {"dop853": 1e-12, "rk4": 1e-11}),      # measured 1.4e-14; 1.1e-13 (vertical momentum)
    "GimbaledGyro": (
        lambda: GimbaledGyro(spin_inertia=2e-3, transverse_inertia=1.5e-3, inner_gimbal=(4e-4, 5e-4, 3e-4),
                             outer_gimbal=1e-3, imbalance=0.01),
        dict(spin=100.0, theta0=1.0, phi_dot0=0.3, theta_dot0=-0.2), 0.2, 1e-4,
        {"dop853": 1e-13, "rk4": 1e-13}),      # measured 7.7e-16; 7.0e-15 (vertical momentum)
}
# What each model keeps (its invariants() on a run without torque, friction or damping)
KEPT = {
    "FlexibleBody": {"energy", "momentum_inertial"},
    "SloshBody": {"energy", "momentum_inertial"},
    "KirchhoffBody": {"energy", "momentum_inertial", "linear_impulse_inertial", "impulse_squared", "impulse_product"},
    "VariableBody": {"momentum_inertial"},
    "MovingHuman": {"momentum_inertial"},
    "Gyroscope": {"energy", "momentum_vertical", "momentum_axial"},
    "GimbaledGyro": {"energy", "momentum_vertical"},
}


# The rigid body, free, in rotated body axes: every method applies. Its invariants (T, L_N): the
# splittings keep |L| and L_N to rounding and T to their bounded error (dt = 1e-3 s, |ω| ~ 1 rad/s);
# torque-free, the exact-flow splittings are the exact motion. Measured: dop853 8.7e-13, rk4 and cf4
# 8.0e-15, splitting2 3.7e-9 (its O(dt²) energy error), splitting4 2.8e-14, exact_split2/4 1.7e-15,
# exact 6.8e-16.
CASES["RigidBody"] = (lambda: tumble.as_model(tumble.RigidBody(INERTIA)), dict(omega0=OMEGA0, q0=Q0), 5.0, 1e-3,
                      {"dop853": 1e-11, "rk4": 1e-12, "cf4": 1e-12, "splitting2": 1e-7, "splitting4": 1e-12,
                       "exact_split2": 1e-13, "exact_split4": 1e-13, "exact": 1e-14})
KEPT["RigidBody"] = {"energy", "momentum_inertial"}
# The gyroscope is a heavy top: the exact-flow splittings are symplectic for its gravity torque, so its
# energy error stays bounded (measured 1.2e-10 for exact_split2 at dt = 1e-4 s, 1.3e-14 for exact_split4)
# and its vertical and axial momenta are kept to rounding.
CASES["Gyroscope"][4].update(exact_split2=1e-9, exact_split4=1e-12)
# A robot arm (the planar two-link arm of examples/robots) falling under gravity: its invariant is the
# power balance E − W, the total energy less the work of the joint torques. Measured: dop853 2.2e-13;
# rk4 1.9e-10, its truncation error at dt = 1 ms (fourth order: tests/robot/test_robot_simulate.py).
CASES["SerialChain"] = (lambda: robot.load(ROBOTS / "planar_2link.toml"), dict(q0=[0.3, -0.5], qd0=[0.1, 0.2]),
                        1.0, 1e-3, {"dop853": 1e-11, "rk4": 1e-9})
KEPT["SerialChain"] = {"energy_minus_work"}
# A spacecraft with three reaction wheels under Schaub's MRP feedback (the craft of tests/spacecraft/test_spacecraft_control.py,
# so the compiled type is shared), started off target and with spinning wheels: the law's torque is internal, so
# the spacecraft keeps its inertial momentum, and its energy changes by the work of the wheel motors only (the
# wheels spin up: E grows from 26 J to 1.4 kJ, so E − W is measured against its 26 J start). Measured: dop853
# 4.3e-12 (E − W), 3.2e-15 (momentum); rk4 at dt = 0.05 s 1.5e-8 (E − W, its O(dt⁴) truncation error: 2.4e-7,
# 1.5e-8, 9.3e-10 at dt = 0.1, 0.05, 0.025 s), 8.8e-13 (momentum); cf4 the same to 2 digits.
CASES["Spacecraft"] = (
    lambda: Spacecraft(inertia=np.diag([900.0, 800.0, 600.0]),
                       wheels=[ReactionWheel(axis=a, inertia=0.1) for a in np.eye(3)],
                       controller=MRPFeedback(K=10.0, P=150.0)),
    dict(omega0=[0.01, -0.01, 0.005], q0=Q0, wheel_speeds0=[20.0, -10.0, 5.0]), 60.0, 0.05,
    {"dop853": 1e-10, "rk4": 2e-7})
KEPT["Spacecraft"] = {"momentum_inertial", "energy_minus_wheel_work"}
# cf4 (Lie group, order 4) on the models that give a body rate, at the rk4 steps: measured at or below
# rk4's change on every model (3.5e-14 flexible, 2.1e-13 slosh, 2.0e-13 fluid, 6.9e-16 variable, 1.1e-15 human,
# 3.5e-15 gyroscope); the tolerance of rk4 applies.
for _case in CASES.values():
    _case[4].setdefault("cf4", _case[4]["rk4"])


def _run(name, method):
    make, state, span, dt, _ = CASES[name]
    model = make()
    t = np.linspace(0.0, span, 21)
    return model, tumble.simulate(model, t=t, **state, **read_by(method, dt=dt, rtol=1e-12, atol=1e-12))


def _provides(name):
    return CASES[name][0]().compile(None, 0.0).provides


MATRIX = [(name, method) for name in CASES for method in integrate.METHODS]


@pytest.mark.slow  # compiles every method for every model (minutes on a cold cache)
@pytest.mark.parametrize("name, method", MATRIX)
def test_every_model_under_every_method(name, method):
    make, state, span, dt, tolerances = CASES[name]
    provides = _provides(name)
    if not integrate.METHODS[method].needs <= provides:
        with pytest.raises(tumble.ValidationError) as expected:
            integrate.check_method(method, provides, f"a {name}")
        with pytest.raises(tumble.ValidationError) as refused:
            tumble.simulate(make(), t=[0.0, span], **state, **read_by(method, dt=0.1))
        assert str(refused.value) == str(expected.value)
        assert str(refused.value).startswith(f"method: {method!r} needs ")
        return
    model, traj = _run(name, method)
    assert traj.model == name and traj.method == method
    kept = model.invariants(traj)
    assert kept.keys() == KEPT[name]
    for what, value in kept.items():
        start = np.linalg.norm(np.atleast_1d(value[0]))
        assert start > 0.0, what   # a relative change needs a non-zero start
        change = np.linalg.norm((value - value[0]).reshape(len(traj), -1), axis=-1).max() / start
        assert change < tolerances[method], (what, change)


def test_every_model_provides_at_least_the_right_hand_side():
    for name in CASES:
        assert "rhs" in _provides(name), name


def test_the_gimbal_has_no_body_rate_for_the_lie_group_method():
    # cf4 moves the attitude by exact rotations at the body rate, which the gimbal kernel does not give
    gyro = CASES["GimbaledGyro"][0]()
    with pytest.raises(tumble.ValidationError, match="method: 'cf4' needs the body rate of its attitude quaternion, "
                                                     "which a GimbaledGyro is not; methods for it: 'rk4', 'dop853'"):
        tumble.simulate(gyro, t=[0.0, 0.1], spin=100.0, method="cf4", dt=1e-3)
