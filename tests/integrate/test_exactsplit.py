"""Tests of the exact-flow splitting (exact_split2, exact_split4): exact free flow composed with torque kicks.

Checked: torque-free it is the closed-form motion; its order under a
potential torque (heavy top), an ω-dependent and a constant inertial torque;
over long heavy-top runs the energy error stays bounded and the vertical
momentum L_z is kept to rounding; batches; landing on output times.
"""

import numpy as np
import pytest

import tumble
from tumble import attitude, integrate, torques
from tumble.integrate import _exactsplit, _fixed

EPS = np.finfo(np.float64).eps
METHODS = ["exact_split2", "exact_split4"]
FLOWS_PER_STEP = {"exact_split2": _exactsplit.STRANG.flows.size, "exact_split4": _exactsplit.BLANES_MOAN.flows.size}

# Torque-free the kicks vanish and each output interval is one exact free flow
# from the previous output, where method="exact" evaluates once from t[0]: the
# two differ by the rounding of 40 re-starts (measured ≤ 3.4e-15).
TOL_FREE = 1e-13
# Measured order within ± 0.15 of the claim (log-log fit over 4-5 steps, errors
# 8e-3 … 1.7e-12, all above the 1e-13 reference). Observed: exact_split2 1.998
# (Gravity), 2.000 (ConstantInertial); exact_split4 3.995 (Gravity), 4.08
# (ω-dependent damping, RK4 kicks).
ORDER_TOL = 0.15
# L_z (inertial, along g) over a long heavy-top run: every kick adds a torque
# R τ = (R r) × m g ⊥ g and every free flow keeps L_N, so only rounding moves
# it, a few ulp per free flow: bound 10 ε √(free flows) × |L| (measured 1.6e-13
# (asymmetric) and 1.7e-13 (symmetric top) against 7.0e-13 for exact_split2,
# 1e5 flows; 1.0e-13 and 1.8e-13 against 7.7e-13 for exact_split4, 1.2e5 flows).
ROUNDS_PER_FLOW = 10.0
# A batch runs the same compiled path per body as a single run: bitwise today.
TOL_BATCH = 1e-14
# Spin-up about a principal axis: the kicks and the free flows are exact and
# the compositions integrate the angle 0.7 t + 0.05 t² exactly (a quadrature of
# order ≥ 2 of a linear rate); what is left is rounding.
TOL_SPIN = 1e-13

FULL = np.array([[2.0, -0.5, 0.3], [-0.5, 3.0, 0.25], [0.3, 0.25, 4.0]])  # moments ≈ 1.6, 2.9, 4.5 kg·m²
DIAG = np.diag([1.0, 2.0, 3.0])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
OMEGA0 = np.array([0.3, 1.0, -0.2])
G = 9.80665
COM = np.array([0.05, 0.0, 0.2])  # centre of mass from the pivot, body axes (m); FULL is about the pivot


def damping(t, q, omega):
    """An ω-dependent torque (N·m): no potential, so the kick is an RK4 step."""
    return -0.1 * np.asarray(omega)


TORQUES = {
    "Gravity": torques.Gravity(1.0, COM),  # heavy top, ~2 N·m
    "ConstantInertial": torques.ConstantInertial([0.1, -0.2, 0.05]),
    "damping": damping,
}


def state(traj):
    """[R(q) flattened, ω] along the last axis (free of the sign of q)."""
    matrices = attitude.to_matrix(traj.q)
    return np.concatenate([matrices.reshape(matrices.shape[:-2] + (9,)), traj.omega], axis=-1)


@pytest.mark.parametrize("name", METHODS)
def test_methods_are_registered_with_their_torque_support(name):
    m = integrate.METHODS[name]
    assert (m.name, m.adaptive, "torque_free" not in m.needs, m.stepper) == (name, False, True, True)
    assert m.description and m.conserves


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.slow  # compiles exact_split for a torque-free body, which no other fast test runs (~2.5 CPU s cold)
def test_torque_free_is_the_exact_motion(method):
    t = np.linspace(0.0, 20.0, 41)
    exact = tumble.simulate(FULL, OMEGA0, q0=Q0, t=t, method="exact")
    traj = tumble.simulate(FULL, OMEGA0, q0=Q0, t=t, method=method, dt=0.3)
    np.testing.assert_allclose(traj.q, exact.q, rtol=0, atol=TOL_FREE)
    np.testing.assert_allclose(traj.omega, exact.omega, rtol=0, atol=TOL_FREE)


@pytest.mark.parametrize("method, torque, dts", [
    ("exact_split2", "Gravity", [0.2, 0.1, 0.05, 0.025, 0.0125]),
    ("exact_split4", "Gravity", [0.4, 0.2, 0.1, 0.05, 0.025]),
    ("exact_split2", "ConstantInertial", [0.2, 0.1, 0.05, 0.025, 0.0125]),
    ("exact_split4", "damping", [0.4, 0.2, 0.1, 0.05]),
])
def test_measured_order_under_each_torque(method, torque, dts):
    # the declared order (tests/integrate/test_methods.py measures every method's on an exact motion)
    order = integrate.METHODS[method].order
    t = np.array([0.0, 4.0])
    torque = TORQUES[torque]
    ref = state(tumble.simulate(FULL, OMEGA0, q0=Q0, t=t, rtol=1e-13, atol=1e-13, torque=torque))[-1]
    errors = [np.abs(state(tumble.simulate(FULL, OMEGA0, q0=Q0, t=t, method=method, dt=dt, torque=torque))[-1]
                     - ref).max() for dt in dts]
    measured = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert abs(measured - order) <= ORDER_TOL


SYMMETRIC_TOP = dict(  # tests/test_torques.py's fast top: 60 rad/s spin, tilted 0.3 rad
    inertia=np.diag([0.01, 0.01, 0.004]) + 1.0 * 0.1**2 * np.diag([1.0, 1.0, 0.0]),  # about the pivot
    omega0=[0.0, 0.0, 60.0], q0=attitude.from_rotvec([0.3, 0.0, 0.0]), mass=1.0, com=[0.0, 0.0, 0.1])
ASYMMETRIC_TOP = dict(inertia=FULL, omega0=OMEGA0, q0=Q0, mass=1.0, com=COM)


@pytest.mark.parametrize("top", [ASYMMETRIC_TOP, SYMMETRIC_TOP], ids=["asymmetric top", "symmetric top"])
@pytest.mark.parametrize("method, steps, dt", [("exact_split2", 10**5, 0.01), ("exact_split4", 2 * 10**4, 0.05)])
def test_heavy_top_energy_error_bounded_and_vertical_momentum_kept(method, steps, dt, top):
    # E = T + m g·(R r) (g = −9.80665 e_z); measured relative error, first and last
    # tenth: asymmetric top exact_split2 3.59e-5 and 3.63e-5, exact_split4 2.40e-9
    # and 2.39e-9 (rk4 at dt = 0.01 over the same 1e3 s: 1.4e-9 and 1.1e-8,
    # drifting); symmetric top 4.49e-5 and 4.49e-5, 2.73e-7 and 2.72e-7.
    t = np.linspace(0.0, steps * dt, 1001)
    traj = tumble.simulate(top["inertia"], top["omega0"], q0=top["q0"], t=t, method=method, dt=dt,
                           torque=torques.Gravity(top["mass"], top["com"]))
    energy = traj.energy + top["mass"] * G * attitude.rotate(traj.q, top["com"])[:, 2]
    error = np.abs(energy / energy[0] - 1.0)
    assert error[-100:].max() <= 2.0 * error[1:101].max()
    lz = traj.momentum_inertial[:, 2]
    bound = ROUNDS_PER_FLOW * EPS * np.sqrt(steps * FLOWS_PER_STEP[method]) * np.linalg.norm(traj.momentum_inertial[0])
    assert np.abs(lz - lz[0]).max() <= bound


@pytest.mark.parametrize("shared", [True, False], ids=["one body", "a body per member"])
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.slow  # compiles the parallel batch driver of exact_split under gravity (~6 CPU s on a cold cache)
def test_batch_across_blocks_equals_single_runs(method, shared):
    # LANES + 3 bodies: a full block and a short one, in parallel.
    n = _fixed.LANES + 3
    rng = np.random.default_rng(5)
    omega0 = rng.normal(size=(n, 3))
    q0 = rng.normal(size=(n, 4))
    q0 /= np.linalg.norm(q0, axis=-1, keepdims=True)
    inertia = FULL if shared else FULL * rng.uniform(0.5, 2.0, size=(n, 1, 1))
    kwargs = dict(t=np.linspace(0.0, 1.0, 4), method=method, dt=0.05, torque=TORQUES["Gravity"])
    batch = tumble.simulate(inertia, omega0, q0=q0, **kwargs)
    for k in range(n):
        single = tumble.simulate(inertia if shared else inertia[k], omega0[k], q0=q0[k], **kwargs)
        assert np.abs(state(batch)[:, k] - state(single)).max() <= TOL_BATCH


NON_UNIFORM = np.array([0.0, 0.013, 0.1, 0.37, 1.0, 1.05, 2.2, 2.25])


@pytest.mark.parametrize("dt", [0.1, 10.0], ids=["dt inside", "dt beyond every interval"])
@pytest.mark.parametrize("method", METHODS)
def test_lands_on_every_output_time(method, dt):
    # Spin about principal axis 3 of diag(1, 2, 3), spun up by τ₃ = 0.3 N·m:
    # ω₃ = 0.7 + 0.1 t, angle 0.7 t + 0.05 t², both integrated exactly, so a
    # sample taken off its time would be off by ≥ 0.7 × the time error.
    traj = tumble.simulate(tumble.RigidBody(DIAG), [0.0, 0.0, 0.7], t=NON_UNIFORM, method=method, dt=dt,
                           torque=torques.ConstantBody([0.0, 0.0, 0.3]))
    np.testing.assert_array_equal(traj.t, NON_UNIFORM)
    angle = 0.7 * NON_UNIFORM + 0.05 * NON_UNIFORM**2
    np.testing.assert_allclose(traj.omega[:, 2], 0.7 + 0.1 * NON_UNIFORM, rtol=0, atol=TOL_SPIN)
    expected = np.stack([np.cos(angle / 2), 0 * angle, 0 * angle, np.sin(angle / 2)], axis=-1)
    np.testing.assert_allclose(traj.q, expected, rtol=0, atol=TOL_SPIN)
    assert traj.info["n_steps"] == int(np.ceil(np.diff(NON_UNIFORM) / dt).sum())
