"""Tests of the geometric integrators: splitting2, splitting4 (free body) and cf4 (any torque).

Each is checked for its order (log-log fit against a tight dop853 reference),
what it conserves over long runs, its phase error at a moderate time, batches,
output times, and the refusal of torques by the free-body-only methods.
"""

import numba
import numpy as np
import pytest

import tumble
from tumble import attitude, dynamics, integrate, torques
from tumble.kernels import rigid as _rigid
from tumble._validate import ValidationError
from tumble.integrate import _fixed, _liegroup, _splitting

EPS = np.finfo(np.float64).eps

# Measured order within ± 0.15 of the claim (log-log fit over 4-5 steps, errors
# 1e-4 … 1e-12, all well above the 1e-13 reference). Observed: splitting2
# 2.000, splitting4 3.999, cf4 3.99 (torque-free), 4.02 (ConstantInertial),
# 4.07 (Gravity).
ORDER_TOL = 0.15
# Symmetric tops (I₁ = I₂ or I₂ = I₃): one of the two split flows has zero
# rate and the other commutes with the Casimir flow, so the splitting is the
# exact motion for any dt; 100 steps of dt = 0.5 s leave rounding (measured
# ≤ 3.1e-15 in ω, ≤ 1e-14 in R(q): |L| is held to its initial length, so the
# phase |L| t/I₁ of the 50-rad turn does not drift).
TOL_SYMMETRIC_TOP = 1e-13
# Phase error at t = 20 s against dop853 at 1e-13 (a method that keeps the
# invariants can still be late): bounds are 4 × the measured errors.
PHASE = {  # method, dt (s), torque: max |ΔR(q)| bound
    ("splitting2", 0.01, "none"): 8e-6,   # measured 2.0e-6
    ("splitting4", 0.05, "none"): 3e-10,  # measured 7.5e-11
    ("cf4", 0.05, "none"): 3e-7,          # measured 7.8e-8
    ("cf4", 0.05, "Gravity"): 4e-5,       # measured 9.5e-6
}
# |L| over 1e6 steps (the issue asks for 1e-13 relative). The turns' rounding
# would random-walk |L| by ~EPS·√(turns) (measured 2.6e-13 for splitting4);
# the splitting rescales L to its initial length after each output interval,
# so |L| stays within a few roundings: measured 4.4e-16 (splitting2) and
# 2.2e-16 (splitting4); bound 16 EPS = 3.6e-15.
TOL_MOMENTUM_NORM = 16 * EPS
# With a progress callback the run goes in 100 segments, each rescaling to its own
# start: the segments' few roundings add up (measured 7.1e-15 and 7.0e-15); the
# issue's bound, 1e-13, still holds.
TOL_MOMENTUM_NORM_SEGMENTS = 1e-13
# L_N and |q| − 1 (no projection): each exact turn rounds the quaternion and
# two components of L once, a random walk of ~EPS·√(turns) (2 turns per step
# for splitting2, 12 for splitting4): measured 7.9e-14 and 2.0e-13 (L_N),
# 3.9e-14 and 1.4e-13 (|q| − 1) against EPS·√(turns) = 3.1e-13 and 7.7e-13.
TURNS_PER_STEP = {"splitting2": 2, "splitting4": 12}
# |q| − 1 without projection: the final quaternion of a step is q ⊗ e₁ (⊗ e₂),
# each product rounding once; over 1e5 cf4 steps measured ≤ 1.3e-14 against
# EPS·√(2 × steps) = 9.9e-14.
# The splitting's branch-free sin/cos against the C library's: measured ≤ 2.3e-16
# (2 ulp of 1) for |x| ≤ 1e3.
TOL_SINCOS = 2.3e-16
# A batch runs the same compiled path per body as a single run: bitwise today.
TOL_BATCH = 1e-14
# Uniform spin about a principal axis is integrated exactly by every method
# here; what is left is rounding of the accumulated angle (≤ 100 steps).
TOL_SPIN = 1e-13

FULL = np.array([[2.0, -0.5, 0.3], [-0.5, 3.0, 0.25], [0.3, 0.25, 4.0]])  # moments ≈ 1.6, 2.9, 4.5
DIAG = np.diag([1.0, 2.0, 3.0])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
OMEGA0 = np.array([0.3, 1.0, -0.2])
TAU = np.array([0.1, -0.2, 0.05])
TORQUES = {
    "none": None,
    "ConstantInertial": torques.ConstantInertial(TAU),
    "Gravity": torques.Gravity(1.0, [0.05, 0.0, 0.2]),  # heavy top on a pivot, ~2 N·m
}
GEOMETRIC = ["splitting2", "splitting4", "cf4"]


def state(traj):
    """[q, ω] along the last axis."""
    return np.concatenate([traj.q, traj.omega], axis=-1)


def reference(body, t, torque=None, omega0=OMEGA0, q0=Q0):
    return tumble.simulate(body, omega0, q0=q0, t=t, rtol=1e-13, atol=1e-13, torque=torque)


# -- registry ------------------------------------------------------------------------------


@pytest.mark.parametrize("name, torque", [("splitting2", False), ("splitting4", False), ("cf4", True)])
def test_methods_are_registered_with_their_torque_support(name, torque):
    m = integrate.METHODS[name]
    assert (m.name, m.adaptive, "torque_free" not in m.needs) == (name, False, torque)
    assert m.description and m.conserves


# -- order ---------------------------------------------------------------------------------


@pytest.mark.slow  # each method's declared order is measured in the fast lane by tests/integrate/test_methods.py
@pytest.mark.parametrize("method, torque, dts", [
    ("splitting2", "none", [0.2, 0.1, 0.05, 0.025, 0.0125]),
    ("splitting4", "none", [0.4, 0.2, 0.1, 0.05, 0.025]),
    ("cf4", "none", [0.2, 0.1, 0.05, 0.025, 0.0125]),
    ("cf4", "ConstantInertial", [0.2, 0.1, 0.05, 0.025, 0.0125]),
    ("cf4", "Gravity", [0.1, 0.05, 0.025, 0.0125]),
])
def test_measured_order_under_each_torque(method, torque, dts):
    # the declared order (tests/integrate/test_methods.py measures every method's on an exact motion)
    order = integrate.METHODS[method].order
    t = np.array([0.0, 4.0])
    body = tumble.RigidBody(FULL)
    torque = TORQUES[torque]
    ref = state(reference(body, t, torque))[-1]
    errors = [np.abs(state(tumble.simulate(body, OMEGA0, q0=Q0, t=t, method=method, dt=dt, torque=torque))[-1]
                     - ref).max() for dt in dts]
    measured = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert abs(measured - order) <= ORDER_TOL


@pytest.mark.parametrize("key", PHASE, ids=lambda k: f"{k[0]}-{k[2]}")
def test_attitude_and_rate_in_phase_with_the_reference(key):
    method, dt, torque = key
    body = tumble.RigidBody(FULL)
    t = np.linspace(0.0, 20.0, 21)
    ref = reference(body, t, TORQUES[torque])
    traj = tumble.simulate(body, OMEGA0, q0=Q0, t=t, method=method, dt=dt, torque=TORQUES[torque])
    assert np.abs(attitude.to_matrix(traj.q) - attitude.to_matrix(ref.q)).max() <= PHASE[key]
    assert np.abs(traj.omega - ref.omega).max() <= PHASE[key]


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e3])
def test_splitting_sincos_matches_the_c_library(scale):
    x = scale * np.random.default_rng(0).uniform(-1.0, 1.0, 100_000)
    x[:9] = [0.0, -0.0, np.pi / 4, np.pi / 2, np.pi, 1.5 * np.pi, 2.0 * np.pi, -np.pi / 2, 1e-300]  # quadrants
    sin, cos = _sincos_of(x)
    assert np.abs(sin - np.sin(x)).max() <= TOL_SINCOS
    assert np.abs(cos - np.cos(x)).max() <= TOL_SINCOS


@numba.njit
def _sincos_loop(x, sin, cos):
    for i in range(x.shape[0]):
        sin[i], cos[i] = _splitting._sincos(x[i])


def _sincos_of(x):
    sin, cos = np.empty_like(x), np.empty_like(x)
    _sincos_loop(x, sin, cos)
    return sin, cos


# -- exact cases and output times -----------------------------------------------------------


def rodrigues(axis, angle):
    """Rotation matrices about the unit ``axis`` by the angles ``angle`` (n,): (n, 3, 3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


@pytest.mark.parametrize("method", ["splitting2", "splitting4"])
@pytest.mark.parametrize("i3", [1.8, 0.6], ids=["oblate", "prolate"])
def test_splitting_is_exact_for_a_symmetric_top(method, i3):
    # Closed form (see tests/test_simulate.py): ω₃ constant, (ω₁, ω₂) turning at
    # Ω = (I₃ − I₁)/I₁ ω₃; R(t) = Rot(L̂_N, |L| t/I₁) R₀ Rot(e₃, −Ω t).
    inertia = np.diag([1.0, 1.0, i3])
    t = np.linspace(0.0, 50.0, 101)
    traj = tumble.simulate(tumble.RigidBody(inertia), OMEGA0, q0=Q0, t=t, method=method, dt=0.5)
    big_omega = (i3 - 1.0) * OMEGA0[2]
    w_perp, phi = np.hypot(OMEGA0[0], OMEGA0[1]), np.arctan2(OMEGA0[1], OMEGA0[0])
    expected = np.stack([w_perp * np.cos(big_omega * t + phi), w_perp * np.sin(big_omega * t + phi),
                         np.full_like(t, OMEGA0[2])], axis=-1)
    assert np.abs(traj.omega - expected).max() <= TOL_SYMMETRIC_TOP
    r0 = attitude.to_matrix(Q0)
    momentum = r0 @ inertia @ OMEGA0
    size = np.linalg.norm(momentum)
    rotation = rodrigues(momentum / size, size * t) @ r0 @ rodrigues(np.array([0.0, 0.0, 1.0]), -big_omega * t)
    assert np.abs(attitude.to_matrix(traj.q) - rotation).max() <= TOL_SYMMETRIC_TOP


NON_UNIFORM = np.array([0.0, 0.013, 0.1, 0.37, 1.0, 1.05, 2.2, 2.25])


@pytest.mark.parametrize("dt", [0.1, 10.0], ids=["dt inside", "dt beyond every interval"])
@pytest.mark.parametrize("method", GEOMETRIC)
def test_lands_on_every_output_time(method, dt):
    # Spin about principal axis 3 of diag(1, 2, 3): free, ω₃ = 0.7 rad/s; for cf4
    # also spun up by τ₃ = 0.3 N·m, ω₃ = 0.7 + 0.1 t. Both are integrated exactly
    # (cf4's exponents add up the RK4 quadrature of the angle, exact for
    # 0.7 t + 0.05 t²), so a sample taken off its time would be off by ≥ 0.7 × the
    # time error.
    spin_up = method == "cf4"
    torque = torques.ConstantBody([0.0, 0.0, 0.3]) if spin_up else None
    traj = tumble.simulate(tumble.RigidBody(DIAG), [0.0, 0.0, 0.7], t=NON_UNIFORM, method=method, dt=dt,
                           torque=torque)
    np.testing.assert_array_equal(traj.t, NON_UNIFORM)
    rate = 0.7 + (0.1 * NON_UNIFORM if spin_up else 0.0)
    angle = 0.7 * NON_UNIFORM + (0.05 * NON_UNIFORM**2 if spin_up else 0.0)
    np.testing.assert_allclose(traj.omega[:, 2], rate, rtol=0, atol=TOL_SPIN)
    expected = np.stack([np.cos(angle / 2), 0 * angle, 0 * angle, np.sin(angle / 2)], axis=-1)
    np.testing.assert_allclose(traj.q, expected, rtol=0, atol=TOL_SPIN)
    assert traj.info["n_steps"] == int(np.ceil(np.diff(NON_UNIFORM) / dt).sum())


# -- long runs: invariants ---------------------------------------------------------------------


def long_run(method, steps=10**6, dt=0.05, progress=None):
    """diag(1, 2, 3), ω₀ = (0.3, 1, −0.2) rad/s, 1e6 steps of 0.05 s (about 8000 turns), 1001 samples."""
    t = np.linspace(0.0, steps * dt, 1001)
    traj = tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=t, method=method, dt=dt, progress=progress)
    energy = dynamics.kinetic_energy(DIAG, traj.omega)
    error = np.abs(energy / energy[0] - 1.0)
    return traj, error[1:101].max(), error[-100:].max()


@pytest.mark.parametrize("method", ["splitting2", "splitting4"])
def test_splitting_keeps_momentum_and_bounds_the_energy_error_over_a_million_steps(method):
    traj, first, last = long_run(method)
    turns = TURNS_PER_STEP[method] * traj.info["n_steps"]
    norm = np.linalg.norm(dynamics.angular_momentum(DIAG, traj.omega), axis=-1)
    momentum = dynamics.angular_momentum_inertial(DIAG, traj.omega, traj.q)
    assert np.abs(norm / norm[0] - 1.0).max() <= TOL_MOMENTUM_NORM
    assert np.linalg.norm(momentum - momentum[0], axis=-1).max() / norm[0] <= EPS * np.sqrt(turns)
    # no drift: the energy error oscillates (splitting2 2.9e-5, splitting4 2.1e-11 in both tenths)
    assert last <= 2.0 * first
    assert np.abs(np.linalg.norm(traj.q, axis=-1) - 1.0).max() <= EPS * np.sqrt(turns)


@pytest.mark.parametrize("method", ["splitting2", "splitting4"])
def test_splitting_keeps_momentum_when_run_in_progress_segments(method):
    reported = []
    traj, _, _ = long_run(method, progress=lambda done, total: reported.append(done))
    assert len(reported) == 100 and reported[-1] == traj.t.size
    norm = np.linalg.norm(dynamics.angular_momentum(DIAG, traj.omega), axis=-1)
    assert np.abs(norm / norm[0] - 1.0).max() <= TOL_MOMENTUM_NORM_SEGMENTS


@pytest.mark.parametrize("method", ["rk4", "cf4"])
def test_runge_kutta_energy_error_drifts_over_the_same_run(method):
    # rk4 (and cf4, whose rate part is RK4: without torque ω does not depend on q)
    # lose energy secularly: 4.1e-7 in the first tenth, 4.1e-6 in the last.
    _, first, last = long_run(method)
    assert last > 2.0 * first


@pytest.mark.parametrize("torque", ["none", "ConstantInertial", "Gravity"])
def test_cf4_keeps_the_unit_quaternion_without_projection(torque):
    steps = 10**5
    t = np.linspace(0.0, steps * 0.01, 1001)
    # principal axes = body axes: q is returned as integrated (no change of axes)
    traj = tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=t, method="cf4", dt=0.01, torque=TORQUES[torque])
    assert np.abs(np.linalg.norm(traj.q, axis=-1) - 1.0).max() <= EPS * np.sqrt(2 * steps)


@pytest.mark.slow  # compiles the fused and the staged cf4 block drivers (~9 CPU s on a cold cache)
def test_fused_cf4_equals_its_stages_over_a_block_bit_for_bit():
    # A rigid body runs CF4 fused (_fused.advance: the step of a lane in registers); the block formulation,
    # stage by stage over the lanes (_cf4_step, which the other models run), then q/|q|, must round alike.
    model = _rigid.build([tumble.RigidBody(DIAG)], None)
    rng = np.random.default_rng(3)
    y0 = np.concatenate([attitude.normalize(rng.standard_normal((5, 4))), rng.standard_normal((5, 3))], axis=1)
    h, steps = 0.03, 40
    fused = integrate.solve(model, y0, np.array([0.0, steps * h]), method="cf4", dt=h).states[-1]
    Y = np.ascontiguousarray(y0.T)
    K, S, W, Q2 = np.empty((4, 7, 5)), np.empty((7, 5)), np.empty((4, 3, 5)), np.empty((4, 5))
    for k in range(steps):
        _liegroup._cf4_step(model, 0, k * h, h, Y, K, S, W, Q2)
        Y[:4] *= 1.0 / np.sqrt(Y[0] * Y[0] + Y[1] * Y[1] + Y[2] * Y[2] + Y[3] * Y[3])
    np.testing.assert_array_equal(fused, Y.T)
    assert np.abs(fused - y0).max() > 0.1  # the bodies moved


@pytest.mark.slow  # compiles a flexible body's cf4 paths, alone and in a block (~12 CPU s on a cold cache)
def test_a_lone_body_runs_cf4_on_its_state_vector_as_a_batch_member_runs_it_in_a_block():
    # A model without point_rates runs CF4's stages (_cf4_step) on one body's state vector, as rk4 and dop853
    # run a lone body: its right-hand side on a state vector serves every method, and no block of one lane is
    # compiled for it. Each lane of a block does the same operations in the same order: bit for bit.
    from tumble.flexible import FlexibleBody, Mode
    from tumble.simulate import as_model

    flexible = FlexibleBody(np.diag([10.0, 12.0, 8.0]), [Mode(3.0, 0.02, [0.3, 0.5, 0.2])])
    omega0 = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9]])
    t = np.linspace(0.0, 2.0, 5)
    batch = tumble.simulate(flexible, omega0, t=t, method="cf4", dt=0.05, eta0=[0.1])
    lone = tumble.simulate(flexible, omega0[1], t=t, method="cf4", dt=0.05, eta0=[0.1])
    np.testing.assert_array_equal(lone.q, batch.q[:, 1])
    np.testing.assert_array_equal(lone.omega, batch.omega[:, 1])
    assert np.abs(lone.q - lone.q[0]).max() > 0.1  # it moved
    # the stages' arrays of a lone body are those of a state vector (they were a block of one lane, (n, 1))
    kernel, n = as_model(flexible).compile(None, 0.0), 7 + 2
    stages = numba.njit(lambda model, y: _fixed.workspace(_liegroup.SCHEME, model, 0, y))(kernel, np.zeros(n))
    assert [a.shape for a in stages[:4]] == [(4, n), (n,), (4, 3), (4,)]


# -- batches -------------------------------------------------------------------------------


@pytest.mark.slow  # compiles the parallel batch driver of each method (~25 CPU s on a cold cache)
@pytest.mark.parametrize("method, torque", [("splitting2", "none"), ("splitting4", "none"), ("cf4", "none"),
                                            ("cf4", "ConstantInertial")])
@pytest.mark.parametrize("shared", [False, True], ids=["a body per member", "one body"])
def test_batch_across_blocks_equals_single_runs(method, torque, shared, random_batch):
    # LANES + 3 bodies: a full block and a short one, in parallel.
    n = _fixed.LANES + 3
    inertia, omega0, q0 = random_batch(n)
    if shared:
        inertia = inertia[0]
    kwargs = dict(t=np.linspace(0.0, 1.0, 4), method=method, dt=0.03, torque=TORQUES[torque])
    batch = tumble.simulate(inertia, omega0, q0=q0, **kwargs)
    for k in range(n):
        single = tumble.simulate(inertia if shared else inertia[k], omega0[k], q0=q0[k], **kwargs)
        assert np.abs(state(batch)[:, k] - state(single)).max() <= TOL_BATCH


# -- refusals ------------------------------------------------------------------------------


def damping(t, q, omega):
    return -0.1 * omega


@pytest.mark.parametrize("method", ["splitting2", "splitting4"])
@pytest.mark.parametrize("torque", [torques.ConstantBody(TAU), TORQUES["Gravity"], damping],
                         ids=["ConstantBody", "Gravity", "Python"])
def test_free_body_methods_refuse_a_torque(method, torque):
    with pytest.raises(ValidationError, match=rf"method: '{method}' needs a rigid body without torque"
                                              r".*methods for it: 'rk4', 'dop853', 'cf4'") as info:
        tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 1.0], method=method, dt=0.1, torque=torque)
    assert repr(torque) in str(info.value)


def test_solve_refuses_a_model_with_a_torque_for_the_free_body_methods():
    model = _rigid.build([tumble.RigidBody(DIAG)], torques.ConstantBody(TAU))
    y0 = np.array([[1.0, 0.0, 0.0, 0.0, *OMEGA0]])
    with pytest.raises(ValidationError, match="'splitting4' needs a rigid body without torque, which a RigidModel is"):
        integrate.solve(model, y0, np.array([0.0, 1.0]), method="splitting4", dt=0.1)


@pytest.mark.parametrize("method", GEOMETRIC)
def test_fixed_step_methods_need_dt(method):
    with pytest.raises(ValidationError, match=rf"dt: method '{method}' has a fixed step"):
        tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 1.0], method=method)
