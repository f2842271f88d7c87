"""The models of tumble.flexible, .slosh, .variable and .ins through the one front door, tumble.simulate:
what each says its exact motion keeps (Model.invariants) is kept by dop853 and rk4, and a method it does not
provide for is refused with the one message of tumble.integrate.check_method."""

import numpy as np
import pytest

import tumble
from tumble import integrate
from tumble.flexible import FlexibleBody, Mode
from tumble.ins import GimbaledGyro, Gyroscope
from tumble.slosh import Pendulum, SloshBody
from tumble.variable import Human, Motion, VariableBody

from helpers import read_by

INERTIA = np.array([[2.0, 0.1, -0.05], [0.1, 3.0, 0.2], [-0.05, 0.2, 4.0]])  # kg m², body axes
OMEGA0 = np.array([0.3, 1.0, -0.4])  # rad/s: a generic tumble


def _swimmer(t):
    """Two 1 kg masses at ±r(t) going once round a circle in the x–y plane of a base body (tests/test_variable.py)."""
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
    "VariableBody": {"momentum_inertial"},
    "MovingHuman": {"momentum_inertial"},
    "Gyroscope": {"energy", "momentum_vertical", "momentum_axial"},
    "GimbaledGyro": {"energy", "momentum_vertical"},
}


def _run(name, method):
    make, state, span, dt, _ = CASES[name]
    model = make()
    t = np.linspace(0.0, span, 21)
    return model, tumble.simulate(model, t=t, **state, **read_by(method, dt=dt, rtol=1e-12, atol=1e-12))


@pytest.mark.slow  # compiles dop853 and rk4 for every model (minutes on a cold cache)
@pytest.mark.parametrize("method", ["dop853", "rk4"])
@pytest.mark.parametrize("name", list(CASES))
def test_invariants_hold(name, method):
    model, traj = _run(name, method)
    assert traj.model == name
    kept = model.invariants(traj)
    assert kept.keys() == KEPT[name]
    for what, value in kept.items():
        start = np.linalg.norm(np.atleast_1d(value[0]))
        assert start > 0.0, what   # a relative change needs a non-zero start
        change = np.linalg.norm((value - value[0]).reshape(len(traj), -1), axis=-1).max() / start
        assert change < CASES[name][4][method], (what, change)


@pytest.mark.parametrize("method", ["splitting2", "exact"])
@pytest.mark.parametrize("name", list(CASES))
def test_methods_the_model_does_not_provide_for_are_refused(name, method):
    make, state, span, dt, _ = CASES[name]
    model = make()
    provides = model.compile(None, 0.0).provides
    with pytest.raises(tumble.ValidationError) as expected:
        integrate.check_method(method, provides, f"a {name}")
    with pytest.raises(tumble.ValidationError) as refused:
        tumble.simulate(model, t=[0.0, span], **state, **read_by(method, dt=0.1))
    assert str(refused.value) == str(expected.value)
    assert str(refused.value).startswith(f"method: {method!r} needs ")


def test_the_gimbal_has_no_body_rate_for_the_lie_group_method():
    # cf4 moves the attitude by exact rotations at the body rate, which the gimbal kernel does not give
    gyro = CASES["GimbaledGyro"][0]()
    with pytest.raises(tumble.ValidationError, match="method: 'cf4' needs the body rate of its attitude quaternion, "
                                                     "which a GimbaledGyro is not; methods for it: 'rk4', 'dop853'"):
        tumble.simulate(gyro, t=[0.0, 0.1], spin=100.0, method="cf4", dt=1e-3)
