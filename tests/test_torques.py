"""Tests of tumble.torques: model values, sums, Python callables, tabulated profiles, constant torques."""

import numpy as np
import pytest

import tumble
from tumble import attitude, torques
from tumble._validate import ValidationError
from helpers import read_by

EPS = np.finfo(np.float64).eps
# Hand values: exact binary fractions and cos/sin 45°, through one quaternion
# rotation (a few roundings each).
ROUNDING = 8 * EPS
# Two runs that evaluate the same torque by different code (compiled model vs
# Python callable; body/inertial conversions done in different orders) see
# values that differ by rounding (~1e-16); with the same steps (rk4, or dop853
# whose controller then takes the same steps) the paths differ by ~1e-15
# (measured ≤ 3e-15). 1e-12 is the agreement promised for equivalent models.
TOL_SAME_TORQUE = 1e-12
# Near a jump of a zero-order hold, dop853 rejects and shrinks steps until the
# jump's share of the error estimate fits the tolerance; there the accept/reject
# decisions of two runs whose torques differ by rounding can differ, and the two
# (equally valid) runs then differ by up to their own global errors, ~10 rtol
# (measured 4e-12; an exact piecewise-linear solution is met to 8e-12).
TOL_ADAPTIVE_AT_JUMPS = 1e-10
# ConstantInertial: L_N(t) = L_N(0) + τ_N t holds exactly; dop853 at
# rtol = atol = 1e-12 over 20 s leaves a global error ~1e-12 |L| in L_N
# (measured 7e-13); 1e-9 relative to the largest |L| is the project's bound.
TOL_LINEAR_MOMENTUM = 1e-9
# ConstantBody about a principal axis of a body spinning about it: ω_k(t) =
# ω₀ + (τ/I_k) t is linear in t, so every Runge–Kutta step is exact and only
# rounding accumulates (~steps × eps × |ω| ≈ 1e-13 for 2000 steps).
TOL_LINEAR_RATE = 1e-12
# The attitude of that spin, θ(t) = ω₀ t + ½ (τ/I_k) t², is not polynomial in
# q: dop853 at 1e-12 over 10 s keeps q to ~1e-12.
TOL_SPIN_ATTITUDE = 1e-10

DIAG = np.diag([1.0, 2.0, 3.0])
# A full tensor (moments ≈ 1.6, 2.9, 4.5): the integrators then work in axes
# rotated from the body axes, so every body <-> principal conversion is exercised.
FULL = np.array([[2.0, -0.5, 0.3], [-0.5, 3.0, 0.25], [0.3, 0.25, 4.0]])
QUARTER_TURN_Z = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])  # body (x, y, z) -> inertial (-y, x, z)
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
OMEGA0 = np.array([0.3, 1.0, -0.2])
TAU = np.array([0.1, -0.2, 0.05])


def state(traj):
    """(n, 7) array [q, ω] of a trajectory."""
    return np.concatenate([traj.q, traj.omega], axis=-1)


def max_diff(a, b):
    return np.abs(state(a) - state(b)).max()


# -- values of the models ------------------------------------------------------------------


def test_constant_models_hand_values():
    omega = [0.5, -1.0, 2.0]
    np.testing.assert_array_equal(torques.ConstantBody([1.0, 2.0, 3.0])(0.0, QUARTER_TURN_Z, omega), [1.0, 2.0, 3.0])
    # Inertial x seen from the body turned a quarter about z is body −y.
    got = torques.ConstantInertial([1.0, 0.0, 0.0])(7.0, QUARTER_TURN_Z, omega)
    np.testing.assert_allclose(got, [0.0, -1.0, 0.0], rtol=0, atol=ROUNDING)


TABLE_T = [0.0, 1.0, 3.0]
TABLE_TAU = [[0.0, 0.0, 0.0], [2.0, 4.0, 6.0], [2.0, 0.0, -2.0]]


@pytest.mark.parametrize(
    ("interpolation", "t", "expected"),
    [
        ("linear", -1.0, [0.0, 0.0, 0.0]),  # before the table: first value held
        ("linear", 0.5, [1.0, 2.0, 3.0]),
        ("linear", 1.0, [2.0, 4.0, 6.0]),
        ("linear", 2.0, [2.0, 2.0, 2.0]),
        ("linear", 5.0, [2.0, 0.0, -2.0]),  # after the table: last value held
        ("previous", -1.0, [0.0, 0.0, 0.0]),
        ("previous", 0.5, [0.0, 0.0, 0.0]),
        ("previous", 1.0, [2.0, 4.0, 6.0]),  # at a sample: that sample
        ("previous", 2.9, [2.0, 4.0, 6.0]),
        ("previous", 3.0, [2.0, 0.0, -2.0]),
        ("previous", 5.0, [2.0, 0.0, -2.0]),
    ],
)
def test_tabulated_hand_values(interpolation, t, expected):
    model = torques.Tabulated(TABLE_T, TABLE_TAU, interpolation=interpolation)
    np.testing.assert_allclose(model(t, QUARTER_TURN_Z, OMEGA0), expected, rtol=0, atol=ROUNDING)


def test_tabulated_inertial_frame_is_rotated_into_the_body():
    # τ_N(0.5) = (1, 2, 3); body = Rᵀ τ_N = (τ_y, −τ_x, τ_z) for a quarter turn about z.
    model = torques.Tabulated(TABLE_T, TABLE_TAU, frame="inertial")
    np.testing.assert_allclose(model(0.5, QUARTER_TURN_Z, OMEGA0), [2.0, -1.0, 3.0], rtol=0, atol=ROUNDING)


def test_python_torque_receives_the_state_and_returns_its_value():
    model = torques.PythonTorque(lambda t, q, omega: t * omega + q[1:])
    np.testing.assert_allclose(model(2.0, QUARTER_TURN_Z, [1.0, 2.0, 3.0]),
                               [2.0, 4.0, 6.0 + np.sin(np.pi / 4)], rtol=0, atol=ROUNDING)


def test_sum_adds_the_terms():
    a, b = torques.ConstantBody([1.0, 2.0, 3.0]), torques.ConstantInertial([1.0, 0.0, 0.0])
    total = a + b + (lambda t, q, omega: np.array([0.0, 0.0, t]))
    assert len(total.terms()) == 3
    assert total.needs_python
    np.testing.assert_allclose(total(4.0, QUARTER_TURN_Z, OMEGA0), [1.0, 1.0, 7.0], rtol=0, atol=ROUNDING)
    # No torque is the neutral element, on either side.
    assert (a + None) is a
    assert (None + a) is a


# -- bad models ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: torques.ConstantBody([1.0, 2.0]), "torque"),
        (lambda: torques.ConstantBody([[1.0, 2.0, 3.0]]), "torque"),
        (lambda: torques.ConstantInertial([1.0, np.nan, 3.0]), "torque"),
        (lambda: torques.Tabulated([0.0, 1.0, 1.0], np.zeros((3, 3))), "t"),
        (lambda: torques.Tabulated([0.0, 1.0], np.zeros((3, 3))), "torque"),
        (lambda: torques.Tabulated([0.0, 1.0], np.zeros((2, 3)), frame="world"), "frame"),
        (lambda: torques.Tabulated([0.0, 1.0], np.zeros((2, 3)), interpolation="cubic"), "interpolation"),
        (lambda: torques.PythonTorque(3.0), "torque"),
        (lambda: torques.ConstantBody(TAU) + 3.0, "torque"),
    ],
)
def test_bad_models_are_refused_naming_the_field(make, field):
    with pytest.raises(ValidationError, match=rf"^{field}: "):
        make()


def test_calling_a_model_on_a_batch_is_refused():
    with pytest.raises(ValidationError, match=r"^q, omega: "):
        torques.ConstantBody(TAU)(0.0, np.tile(Q0, (2, 1)), np.tile(OMEGA0, (2, 1)))


# -- constant torques against exact motion ---------------------------------------------------


@pytest.mark.parametrize("inertia", [DIAG, FULL], ids=["diagonal", "full"])
def test_constant_inertial_torque_grows_inertial_momentum_linearly(inertia):
    # dL_N/dt = τ_N exactly, whatever the body does: L_N(t) = L_N(0) + τ_N t.
    t = np.linspace(0.0, 20.0, 21)
    traj = tumble.simulate(tumble.RigidBody(inertia), OMEGA0, q0=Q0, t=t, rtol=1e-12, atol=1e-12,
                           torque=torques.ConstantInertial(TAU))
    momentum = traj.momentum_inertial
    expected = momentum[0] + t[:, None] * TAU
    scale = np.linalg.norm(momentum, axis=-1).max()
    assert np.abs(momentum - expected).max() / scale <= TOL_LINEAR_MOMENTUM


@pytest.mark.parametrize("method", ["rk4", "dop853"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_constant_body_torque_about_a_principal_spin_axis_is_exact(axis, method):
    # Spin about principal axis k with τ along it: the cross terms vanish identically,
    # ω_k(t) = ω₀ + (τ/I_k) t, the other rates stay 0, and the attitude is a turn
    # about e_k by θ(t) = ω₀ t + ½ (τ/I_k) t². (k = 1 is the intermediate axis:
    # exactly on it the motion is still this one.)
    moments = np.diag(DIAG)
    w0, tau = 0.7, 0.3
    omega0, torque = np.zeros(3), np.zeros(3)
    omega0[axis], torque[axis] = w0, tau
    t = np.linspace(0.0, 10.0, 11)
    traj = tumble.simulate(tumble.RigidBody(DIAG), omega0, t=t, **read_by(method, dt=5e-3, rtol=1e-12,
                           atol=1e-12), torque=torques.ConstantBody(torque))
    expected = np.zeros((t.size, 3))
    expected[:, axis] = w0 + tau / moments[axis] * t
    assert np.abs(traj.omega - expected).max() / np.abs(expected).max() <= TOL_LINEAR_RATE
    if method == "dop853":
        theta = w0 * t + 0.5 * tau / moments[axis] * t**2
        q = np.zeros((t.size, 4))
        q[:, 0], q[:, 1 + axis] = np.cos(theta / 2), np.sin(theta / 2)
        assert np.abs(traj.q - q).max() <= TOL_SPIN_ATTITUDE


# -- Python callables in simulate -----------------------------------------------------------


@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_python_callable_equals_the_compiled_model(method):
    # The callable computes τ_B = R(q)ᵀ τ_N with R the rotation of q/|q| (attitude.rotate_inverse),
    # as the compiled model does also at Runge–Kutta stages, where |q| = 1 + O(h²).
    t = np.linspace(0.0, 5.0, 6)
    kwargs = dict(q0=Q0, t=t, **read_by(method, dt=1e-2, rtol=1e-12, atol=1e-12))
    body = tumble.RigidBody(FULL)
    compiled = tumble.simulate(body, OMEGA0, torque=torques.ConstantInertial(TAU), **kwargs)
    python = tumble.simulate(body, OMEGA0, torque=lambda t, q, omega: attitude.rotate_inverse(q, TAU), **kwargs)
    assert max_diff(compiled, python) <= TOL_SAME_TORQUE


def test_python_callable_sees_body_axes_state():
    # At the start the callable is given t[0], q0 (normalised) and ω0, all in body axes,
    # although the integrator works in the principal axes of this full tensor.
    calls = []

    def spy(t, q, omega):
        calls.append((t, q, omega))
        return np.zeros(3)

    with pytest.warns(attitude.NonUnitQuaternionWarning):  # |q0| = 2: normalised, with a warning
        tumble.simulate(tumble.RigidBody(FULL), OMEGA0, q0=2.0 * Q0, t=[1.5, 1.6], method="rk4", dt=0.1, torque=spy)
    t, q, omega = calls[0]
    assert type(t) is float and t == 1.5
    np.testing.assert_allclose(q, Q0, rtol=0, atol=ROUNDING)
    np.testing.assert_allclose(omega, OMEGA0, rtol=0, atol=ROUNDING)
    assert len(calls) == 4  # one rk4 step, four stages


@pytest.mark.parametrize(
    "returns",
    [lambda t, q, w: np.zeros(2), lambda t, q, w: np.array([0.0, np.nan, 0.0]), lambda t, q, w: None],
    ids=["wrong shape", "nan", "None"],
)
def test_python_callable_bad_return_is_a_validation_error(returns):
    with pytest.raises(ValidationError, match=r"^torque: .*must return 3 finite numbers"):
        tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 1.0], torque=returns)


def test_python_callable_exception_propagates_and_the_model_stays_usable():
    failing = {"now": True}

    def torque(t, q, omega):
        if failing["now"]:
            raise ZeroDivisionError("boom")
        return TAU

    model = torques.PythonTorque(torque)
    with pytest.raises(ZeroDivisionError, match="boom"):
        tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 1.0], torque=model)
    failing["now"] = False
    again = tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 1.0], method="rk4", dt=0.1, torque=model)
    same = tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 1.0], method="rk4", dt=0.1,
                           torque=torques.ConstantBody(TAU))
    assert max_diff(again, same) <= TOL_SAME_TORQUE


# -- tabulated profiles in simulate -----------------------------------------------------------


def tabulated_as_python(t_table, tau_table, frame, interpolation):
    """A Python callable doing what Tabulated(t_table, tau_table, ...) promises."""
    t_table, tau_table = np.asarray(t_table), np.asarray(tau_table)

    def torque(t, q, omega):
        if interpolation == "linear":
            value = np.array([np.interp(t, t_table, tau_table[:, i]) for i in range(3)])
        else:  # last sample at or before t, first sample before the table
            value = tau_table[max(np.searchsorted(t_table, t, side="right") - 1, 0)]
        return value if frame == "body" else attitude.rotate_inverse(q, value)

    return torque


@pytest.mark.parametrize(
    ("method", "interpolation", "frame", "tol"),
    [
        ("rk4", "linear", "body", TOL_SAME_TORQUE),
        ("rk4", "linear", "inertial", TOL_SAME_TORQUE),
        ("rk4", "previous", "body", TOL_SAME_TORQUE),
        ("rk4", "previous", "inertial", TOL_SAME_TORQUE),
        ("dop853", "linear", "body", TOL_SAME_TORQUE),
        ("dop853", "linear", "inertial", TOL_SAME_TORQUE),
        ("dop853", "previous", "body", TOL_ADAPTIVE_AT_JUMPS),
        ("dop853", "previous", "inertial", TOL_ADAPTIVE_AT_JUMPS),
    ],
)
def test_tabulated_equals_the_same_interpolation_in_python(method, interpolation, frame, tol):
    # The table starts after and ends before the run, so both held ends are used.
    # The output times include the samples, so dop853 lands on every kink instead
    # of straddling it with a step whose error estimate, and so the step sequence,
    # hangs on rounding.
    rng = np.random.default_rng(11)
    t_table = np.sort(rng.uniform(0.5, 2.5, 9))
    tau_table = rng.standard_normal((9, 3))
    t = np.union1d(np.linspace(0.0, 3.0, 7), t_table)
    kwargs = dict(q0=Q0, t=t, **read_by(method, dt=1e-2, rtol=1e-12, atol=1e-12))
    body = tumble.RigidBody(FULL)
    table = torques.Tabulated(t_table, tau_table, frame=frame, interpolation=interpolation)
    compiled = tumble.simulate(body, OMEGA0, torque=table, **kwargs)
    python = tumble.simulate(body, OMEGA0, torque=tabulated_as_python(t_table, tau_table, frame, interpolation),
                             **kwargs)
    assert max_diff(compiled, python) <= tol


def _spin_under_table(interpolation, dt):
    """ω₃(t) of a body spinning about principal axis 3 under a tabulated torque about it (rk4)."""
    t_table = np.array([0.0, 1.0, 2.0, 3.0])
    tau_table = np.zeros((4, 3))
    tau_table[:, 2] = [0.5, -0.3, 0.8, 0.2]
    t = np.linspace(0.0, 4.0, 9)  # holds the sample times: rk4 steps land on them
    traj = tumble.simulate(tumble.RigidBody(DIAG), [0.0, 0.0, 1.0], t=t, method="rk4", dt=dt,
                           torque=torques.Tabulated(t_table, tau_table, interpolation=interpolation))
    return t, t_table, tau_table[:, 2], traj.omega[:, 2]


def test_linear_table_with_steps_landing_on_the_samples_is_exact():
    # ω₃' = τ₃(t)/I₃ with τ₃ piecewise linear: ω₃ is piecewise quadratic, which RK4
    # integrates exactly on steps that do not straddle a sample time (torques.md).
    t, t_table, tau3, omega3 = _spin_under_table("linear", 0.05)
    tau_t = np.interp(t, t_table, tau3)
    seg = np.clip(np.searchsorted(t_table, t, side="right") - 1, 0, 2)
    # ∫ of the piecewise-linear τ₃ from 0 to t (trapezoids of whole segments + the part segment)
    whole = np.concatenate([[0.0], np.cumsum(np.diff(t_table) * (tau3[:-1] + tau3[1:]) / 2)])
    inside = np.where(t <= t_table[-1], (t - t_table[seg]) * (np.interp(t_table[seg], t_table, tau3) + tau_t) / 2,
                      0.0)
    held = np.where(t > t_table[-1], (t - t_table[-1]) * tau3[-1], 0.0)
    area = np.where(t > t_table[-1], whole[-1] + held, whole[seg] + inside)
    assert np.abs(omega3 - (1.0 + area / 3.0)).max() <= TOL_LINEAR_RATE


def test_zero_order_hold_costs_the_documented_first_order_error_per_jump():
    # torques.md: a step that ends on a jump Δτ sees the new value in its last RK4
    # stage, so ω₃ = L₃/I₃ picks up h Δτ / (6 I₃) per jump. Check the law exactly
    # (it is what a user is told to expect) and that it halves with h.
    for dt in (0.05, 0.025):
        t, t_table, tau3, omega3 = _spin_under_table("previous", dt)
        seg = np.clip(np.searchsorted(t_table, t, side="right") - 1, 0, 3)
        area = np.concatenate([[0.0], np.cumsum(np.diff(t_table) * tau3[:-1])])
        exact = 1.0 + (area[seg] + (t - t_table[seg]) * tau3[seg]) / 3.0
        jumps_before = np.array([np.sum(np.diff(tau3)[t_table[1:] <= tk]) for tk in t])
        predicted = dt * jumps_before / (6.0 * 3.0)
        assert np.abs((omega3 - exact) - predicted).max() <= TOL_LINEAR_RATE


def test_sum_in_simulate_equals_the_summed_callable():
    a, b = torques.ConstantBody([0.2, 0.0, -0.1]), torques.ConstantInertial(TAU)
    t = np.linspace(0.0, 5.0, 6)
    kwargs = dict(q0=Q0, t=t, rtol=1e-12, atol=1e-12)
    body = tumble.RigidBody(FULL)
    summed = tumble.simulate(body, OMEGA0, torque=a + b, **kwargs)
    python = tumble.simulate(body, OMEGA0, torque=lambda t, q, w: a.torque + attitude.rotate_inverse(q, TAU),
                             **kwargs)
    assert max_diff(summed, python) <= TOL_SAME_TORQUE


# --- Gravity and FunctionOfTime ----------------------------------------------

TOL_GRAVITY = 1e-13  # a cross product and one rotation of O(10) numbers: rounding only


def test_gravity_torque_is_r_cross_m_g_in_body_axes():
    rng = np.random.default_rng(7)
    mass, com, g = 1.7, np.array([0.02, -0.01, 0.12]), np.array([0.0, 0.0, -9.81])
    model = torques.Gravity(mass, com, g)
    for _ in range(5):
        q = attitude.normalize(rng.standard_normal(4))
        expected = np.cross(com, mass * attitude.rotate_inverse(q, g))
        assert np.abs(model(0.3, q, [0.1, 0.2, 0.3]) - expected).max() <= TOL_GRAVITY


def test_gravity_heavy_top_conserves_energy_and_vertical_momentum():
    # A symmetric top on a pivot: E = T + m g·(R r) and L_z (inertial, along g) are conserved.
    mass, length = 1.0, 0.1
    com = np.array([0.0, 0.0, length])
    inertia = np.diag([0.01, 0.01, 0.004]) + mass * (length**2) * np.diag([1.0, 1.0, 0.0])  # about the pivot
    q0 = attitude.from_rotvec([0.3, 0.0, 0.0])
    t = np.linspace(0.0, 5.0, 51)
    traj = tumble.simulate(inertia, [0.0, 0.0, 60.0], q0=q0, t=t, rtol=1e-12, atol=1e-12,
                           torque=torques.Gravity(mass, com, (0.0, 0.0, -9.81)))
    height = attitude.rotate(traj.q, com)[:, 2]
    energy = traj.energy + mass * 9.81 * height
    lz = traj.momentum_inertial[:, 2]
    assert np.abs(energy - energy[0]).max() <= 1e-10 * abs(energy[0])  # DOP853 at 1e-12 over 5 s
    assert np.abs(lz - lz[0]).max() <= 1e-10 * abs(lz[0])


def test_function_of_time_in_body_and_inertial_axes():
    q = attitude.from_rotvec([0.0, np.pi / 2, 0.0])
    body = torques.FunctionOfTime(lambda t: [t, 0.0, 0.0])
    inertial = torques.FunctionOfTime(lambda t: [0.0, 0.0, 2.0 * t], frame="inertial")
    assert np.abs(body(1.5, q, [0, 0, 0]) - [1.5, 0.0, 0.0]).max() == 0.0
    assert np.abs(inertial(1.5, q, [0, 0, 0]) - attitude.rotate_inverse(q, [0.0, 0.0, 3.0])).max() <= TOL_GRAVITY


@pytest.mark.parametrize("bad, field", [
    (dict(mass=-1.0, com=[0, 0, 1]), "mass"),
    (dict(mass=1.0, com=[0, 1]), "com"),
    (dict(mass=1.0, com=[0, 0, 1], g=[0, np.nan, 0]), "g"),
])
def test_gravity_refuses_bad_input(bad, field):
    with pytest.raises(tumble.ValidationError, match=field):
        torques.Gravity(**bad)


def test_function_of_time_refuses_bad_input():
    with pytest.raises(tumble.ValidationError, match="function"):
        torques.FunctionOfTime(3.0)
    with pytest.raises(tumble.ValidationError, match="frame"):
        torques.FunctionOfTime(np.sin, frame="lvlh")
