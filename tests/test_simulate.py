"""Tests of tumble.simulate and its integrators against exact motion, invariants and each other."""

import numpy as np
import pytest

import tumble
from tumble import attitude, dynamics, integrate, torques
from tumble._validate import ValidationError
from tumble.integrate import SolverError, _fixed
from helpers import read_by

EPS = np.finfo(np.float64).eps

# Torque-free invariants over 1000 s with dop853 at rtol = atol = 1e-12 (the
# project's bound; measured ~3e-11: the local errors, ~1e-12 per accepted
# step, add up like a random walk over ~4000 steps).
TOL_CONSERVATION = 1e-10
# A sphere has ω̇ = 0 exactly: every stage sees the same ω and the steps add
# exact zeros. The bound leaves room for the body <-> principal-axes round trip.
TOL_SPHERE_RATE = 1e-12
# Closed-form symmetric top / sphere over 50 s, dop853 at 1e-12: the phase
# error of the rate and attitude grows to ~2e-12 (measured); bound 1e-10.
TOL_CLOSED_FORM = 1e-10
# Measured RK4 order from a log-log fit over dt = 0.2 … 0.0125 (errors 1e-5 …
# 1e-10, well above the 1e-13 reference): 4.00 ± 0.03 observed, bound ± 0.15.
ORDER_TOL = 0.15
# dop853 at rtol = atol = 1e-12 over 4 s lands within ~1e-12 of the reference
# at 1e-13; "within ~100 × rtol" of it is the bound promised.
TOL_DOP853_AT_1E12 = 100 * 1e-12
# The same body in rotated axes, dop853 at 1e-12 over 10 s: the two runs work
# in principal axes that may differ by signs, so their step sequences (and
# errors, ~1e-12) need not match (measured ≤ 1e-13); 1e-10 is the project's bound.
TOL_FRAME = 1e-10
# rk4 with a fixed step is covariant under the linear change of state of a
# change of body axes; only rounding separates the runs (measured ~1e-14).
TOL_FRAME_RK4 = 1e-12
# A batch runs the same compiled path per body as a single run: the results are
# bitwise equal today; 1e-14 is the bound promised.
TOL_BATCH = 1e-14
# ω linear (or quadratic) in t is integrated exactly by rk4 and dop853; what is
# left is rounding, ~(number of steps) × eps × |ω| ≲ 1e-13.
TOL_POLYNOMIAL_RATE = 1e-12
# A run reported in chunks (progress) resumes each chunk with the step size it
# had; rk4 is bitwise the same, dop853 re-evaluates its first stage at each
# chunk's start on the normalised q instead of reusing the last stage of the
# previous step: a rounding-level change (measured: none at all).
TOL_CHUNKED = 1e-14
# The initial state through the body -> principal -> body axes round trip:
# one rotation each way, a few roundings.
TOL_ROUNDTRIP = 8 * EPS
# |q| after a step is normalised, then turned back into body axes by a unit
# quaternion product: a few roundings of 1.
TOL_UNIT = 1e-14

DIAG = np.diag([1.0, 2.0, 3.0])
# A full tensor (moments ≈ 1.6, 2.9, 4.5), so the integrators work in rotated principal axes.
FULL = np.array([[2.0, -0.5, 0.3], [-0.5, 3.0, 0.25], [0.3, 0.25, 4.0]])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
OMEGA0 = np.array([0.3, 1.0, -0.2])
TAU = np.array([0.1, -0.2, 0.05])


def state(traj):
    """[q, ω] along the last axis."""
    return np.concatenate([traj.q, traj.omega], axis=-1)


def rodrigues(axis, angle):
    """Rotation matrices about the unit ``axis`` by the angles ``angle`` (n,): (n, 3, 3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


# -- torque-free invariants -----------------------------------------------------------------


@pytest.mark.parametrize("inertia", [DIAG, FULL], ids=["diagonal", "full"])
def test_torque_free_motion_conserves_energy_and_momentum(inertia):
    t = np.linspace(0.0, 1000.0, 101)
    traj = tumble.simulate(tumble.RigidBody(inertia), OMEGA0, q0=Q0, t=t, method="dop853", rtol=1e-12, atol=1e-12)
    energy = dynamics.kinetic_energy(inertia, traj.omega)
    momentum = dynamics.angular_momentum_inertial(inertia, traj.omega, traj.q)
    norm = np.linalg.norm(dynamics.angular_momentum(inertia, traj.omega), axis=-1)
    assert np.abs(energy / energy[0] - 1.0).max() <= TOL_CONSERVATION
    assert np.abs(norm / norm[0] - 1.0).max() <= TOL_CONSERVATION
    assert np.linalg.norm(momentum - momentum[0], axis=-1).max() / norm[0] <= TOL_CONSERVATION


# -- sphere and symmetric top against closed forms --------------------------------------------


@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_sphere_keeps_its_rate_and_turns_uniformly(method):
    # I = k E: ω̇ = 0, so ω is constant and R(t) = R₀ Rot(ω̂, |ω| t).
    t = np.linspace(0.0, 50.0, 51)
    traj = tumble.simulate(tumble.RigidBody(2.0 * np.eye(3)), OMEGA0, q0=Q0, t=t,
                           **read_by(method, dt=1e-2, rtol=1e-12, atol=1e-12))
    assert np.abs(traj.omega - OMEGA0).max() <= TOL_SPHERE_RATE
    if method == "dop853":
        rate = np.linalg.norm(OMEGA0)
        expected = attitude.to_matrix(Q0) @ rodrigues(OMEGA0 / rate, rate * t)
        assert np.abs(attitude.to_matrix(traj.q) - expected).max() <= TOL_CLOSED_FORM


@pytest.mark.parametrize("i3", [1.8, 0.6], ids=["oblate", "prolate"])
def test_symmetric_top_matches_the_closed_form(i3):
    # I = diag(I₁, I₁, I₃): ω₃ is constant and (ω₁, ω₂) turns at Ω = (I₃ − I₁)/I₁ ω₃:
    # ω₁ = w⊥ cos(Ωt + φ), ω₂ = w⊥ sin(Ωt + φ). Since ω = L/I₁ − Ω e₃, the attitude is
    # R(t) = Rot(L̂_N, |L| t/I₁) R₀ Rot(e₃, −Ω t) (precession about L, spin about e₃).
    # (The prolate top's symmetry axis is principal axis 1 after sorting: the
    # integrator then works in permuted axes.)
    i1 = 1.0
    inertia = np.diag([i1, i1, i3])
    t = np.linspace(0.0, 50.0, 101)
    traj = tumble.simulate(tumble.RigidBody(inertia), OMEGA0, q0=Q0, t=t, rtol=1e-12, atol=1e-12)
    big_omega = (i3 - i1) / i1 * OMEGA0[2]
    w_perp, phi = np.hypot(OMEGA0[0], OMEGA0[1]), np.arctan2(OMEGA0[1], OMEGA0[0])
    np.testing.assert_allclose(traj.omega[:, 0], w_perp * np.cos(big_omega * t + phi), rtol=0, atol=TOL_CLOSED_FORM)
    np.testing.assert_allclose(traj.omega[:, 1], w_perp * np.sin(big_omega * t + phi), rtol=0, atol=TOL_CLOSED_FORM)
    np.testing.assert_allclose(traj.omega[:, 2], OMEGA0[2], rtol=0, atol=TOL_CLOSED_FORM)
    r0 = attitude.to_matrix(Q0)
    momentum = r0 @ inertia @ OMEGA0
    size = np.linalg.norm(momentum)
    expected = rodrigues(momentum / size, size * t / i1) @ r0 @ rodrigues(np.array([0.0, 0.0, 1.0]), -big_omega * t)
    assert np.abs(attitude.to_matrix(traj.q) - expected).max() <= TOL_CLOSED_FORM


# -- convergence ---------------------------------------------------------------------------


def sine_torque(t, q, omega):
    """A time-dependent body torque: a wrong stage time would lower RK4's order."""
    return np.array([0.1 * np.sin(t), 0.05 * np.cos(2.0 * t), -0.02])


# The fast lane keeps the torque-free row: the Python torque compiles a reference dop853 path and an rk4 path
# of its own (~8 CPU s on a cold cache).
@pytest.mark.parametrize("torque", [None, pytest.param(sine_torque, marks=pytest.mark.slow)],
                         ids=["torque-free", "time-dependent torque"])
def test_rk4_converges_at_fourth_order(torque):
    t = np.array([0.0, 4.0])
    body = tumble.RigidBody(FULL)
    ref = tumble.simulate(body, OMEGA0, q0=Q0, t=t, rtol=1e-13, atol=1e-13, torque=torque)
    dts = np.array([0.2, 0.1, 0.05, 0.025, 0.0125])
    errors = [
        np.abs(state(tumble.simulate(body, OMEGA0, q0=Q0, t=t, method="rk4", dt=dt, torque=torque))[-1]
               - state(ref)[-1]).max()
        for dt in dts
    ]
    order = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert abs(order - integrate.METHODS["rk4"].order) <= ORDER_TOL


@pytest.mark.parametrize("torque", [None, sine_torque], ids=["torque-free", "time-dependent torque"])
def test_dop853_error_follows_the_tolerance(torque):
    t = np.array([0.0, 4.0])
    body = tumble.RigidBody(FULL)
    ref = state(tumble.simulate(body, OMEGA0, q0=Q0, t=t, rtol=1e-13, atol=1e-13, torque=torque))[-1]

    def error(tol):
        return np.abs(state(tumble.simulate(body, OMEGA0, q0=Q0, t=t, rtol=tol, atol=tol, torque=torque))[-1]
                      - ref).max()

    loose, tight = error(1e-8), error(1e-12)
    assert loose > tight
    assert tight <= TOL_DOP853_AT_1E12


# -- frame invariance ----------------------------------------------------------------------


def rotated_runs(inertia, rotation, torque, torque_rotated, **kwargs):
    """The same body and motion described in body axes B and in B' (v_B = R v_B')."""
    first = tumble.simulate(tumble.RigidBody(inertia), OMEGA0, q0=Q0, torque=torque, **kwargs)
    second = tumble.simulate(tumble.RigidBody(rotation.T @ inertia @ rotation), rotation.T @ OMEGA0,
                             q0=attitude.multiply(Q0, attitude.from_matrix(rotation)), torque=torque_rotated, **kwargs)
    return first, second


def frame_difference(inertia, rotation, first, second):
    """max relative difference of L_N, and of R(q(t)) with the second run's mapped back to axes B."""
    momentum = dynamics.angular_momentum_inertial(inertia, first.omega, first.q)
    momentum2 = dynamics.angular_momentum_inertial(rotation.T @ inertia @ rotation, second.omega, second.q)
    d_momentum = np.abs(momentum - momentum2).max() / np.abs(momentum).max()
    d_attitude = np.abs(attitude.to_matrix(first.q) - attitude.to_matrix(second.q) @ rotation.T).max()
    return max(d_momentum, d_attitude)


def damping(t, q, omega):
    """τ = −0.1 ω: a body-axes torque that a Python callable gets in whatever axes the body uses."""
    return -0.1 * omega


RAMP_T, RAMP_TAU = [0.0, 4.0, 10.0], np.array([TAU, -TAU, [0.0, 0.1, 0.2]])
# (torque in axes B, the same torque for the body described in B' = B rotated by R;
# a body-axes table rotates row by row: (Rᵀ τ)ᵀ = τᵀ R)
FRAME_TORQUES = {
    "torque-free": lambda r: (None, None),
    "ConstantInertial": lambda r: (torques.ConstantInertial(TAU),) * 2,
    "ConstantBody": lambda r: (torques.ConstantBody(TAU), torques.ConstantBody(r.T @ TAU)),
    "Tabulated inertial": lambda r: (torques.Tabulated(RAMP_T, RAMP_TAU, frame="inertial"),) * 2,
    "Tabulated body": lambda r: (torques.Tabulated(RAMP_T, RAMP_TAU), torques.Tabulated(RAMP_T, RAMP_TAU @ r)),
    "Python damping": lambda r: (damping, damping),
}


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("kind", FRAME_TORQUES)
@pytest.mark.parametrize("inertia", [DIAG, FULL], ids=["diagonal", "full"])
def test_motion_does_not_depend_on_the_body_axes(inertia, kind, seed, random_rotation):
    rotation = random_rotation(seed)
    first, second = rotated_runs(inertia, rotation, *FRAME_TORQUES[kind](rotation), t=np.linspace(0.0, 10.0, 11),
                                 rtol=1e-12, atol=1e-12)
    assert frame_difference(inertia, rotation, first, second) <= TOL_FRAME


@pytest.mark.parametrize("kind", FRAME_TORQUES)
def test_rk4_motion_does_not_depend_on_the_body_axes_to_rounding(kind, random_rotation):
    rotation = random_rotation(0)
    first, second = rotated_runs(FULL, rotation, *FRAME_TORQUES[kind](rotation), t=np.linspace(0.0, 10.0, 11),
                                 method="rk4", dt=0.05)
    assert frame_difference(FULL, rotation, first, second) <= TOL_FRAME_RK4


@pytest.mark.parametrize("bodies", [1, 6], ids=["one body", "one per member"])
def test_states_reach_body_axes_by_the_quaternion_product_and_the_rotation(bodies, random_batch):
    # the compiled change of axes of the outputs against the batched API: q_NB = q_NP ⊗ q_BP* bit for bit
    # (the same product), ω_B = R_BP ω_P to the rounding of its three terms (einsum pairs them otherwise)
    from tumble.rigid_model import RigidBodies, _to_body_axes

    model = RigidBodies.of(random_batch(bodies)[0])
    axes, q_bp = model.axes, model.q_bp
    states = np.random.default_rng(8).normal(size=(4, 6, 7)) * [1.0, 1.0, 1.0, 1.0, 1e-3, 1.0, 1e3]
    q, omega = np.empty((4, 6, 4)), np.empty((4, 6, 3))
    _to_body_axes(states, q_bp, axes, q, omega)
    np.testing.assert_array_equal(q, attitude.multiply(states[..., :4], attitude.conjugate(q_bp)))
    np.testing.assert_allclose(omega, np.einsum("bij,tbj->tbi", axes, states[..., 4:]), rtol=0,
                               atol=2 * EPS * np.abs(states[..., 4:]).sum(axis=-1).max())


# -- batches -------------------------------------------------------------------------------


BATCH_TORQUES = {
    "torque-free": None,
    "ConstantBody": torques.ConstantBody(TAU),
    "ConstantInertial + Tabulated": torques.ConstantInertial(TAU)
    + torques.Tabulated([0.0, 1.0, 2.0], [[0.0, 0.1, 0.0], [0.2, 0.0, -0.1], [0.0, 0.0, 0.3]]),
    "Python": damping,
}


# The fast lane keeps the torque-free batches: each torque type compiles a block driver and a batch driver
# of its own (~7 CPU s on a cold cache).
@pytest.mark.parametrize("torque", [name if name == "torque-free" else pytest.param(name, marks=pytest.mark.slow)
                                    for name in BATCH_TORQUES])
@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_batch_equals_single_runs(method, torque, random_batch):
    n = 5
    inertia, omega0, q0 = random_batch(n)
    torque = BATCH_TORQUES[torque]
    kwargs = dict(t=np.linspace(0.0, 3.0, 7), **read_by(method, dt=1e-2, rtol=1e-10, atol=1e-12), torque=torque)
    batch = tumble.simulate(inertia, omega0, q0=q0, **kwargs)
    assert batch.q.shape == (7, n, 4) and batch.omega.shape == (7, n, 3) and batch.inertia.shape == (n, 3, 3)
    for k in range(n):
        single = tumble.simulate(tumble.RigidBody(inertia[k]), omega0[k], q0=q0[k], **kwargs)
        assert np.abs(state(batch)[:, k] - state(single)).max() <= TOL_BATCH


def test_a_lone_body_and_a_batch_share_one_compiled_dop853_path():
    # the path of one body gets the same argument types from a lone run as from the parallel batch
    # (docs/architecture.md, "One signature per path"): one compiled copy per model type, not two
    from numba import typeof

    from tumble.integrate import _dop853

    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    t = np.linspace(0.0, 1.0, 3)
    lone = tumble.simulate(body, [0.1, 1.0, 0.0], t=t)
    batch = tumble.simulate(body, [[0.3, 1.0, 0.0], [0.1, 1.0, 0.0]], t=t)
    assert np.array_equal(batch.q[:, 1], lone.q) and np.array_equal(batch.omega[:, 1], lone.omega)
    model = typeof(tumble.as_model(body).compile(None, 0.0))
    assert [signature[0] for signature in _dop853.dop853_path.signatures].count(model) == 1


@pytest.mark.slow  # compiles the parallel rk4 batch driver (~7 CPU s on a cold cache)
@pytest.mark.parametrize("extra", [1, 3], ids=["lone body in the last block", "partial last block"])
@pytest.mark.parametrize("torque", ["torque-free", "ConstantInertial + Tabulated"])
def test_rk4_batch_across_blocks_equals_single_runs(torque, extra, random_batch):
    # rk4 advances up to LANES bodies together (structure of arrays); a batch of
    # LANES + extra bodies has a full block and a short one (a lone body takes
    # the one-body path).
    n = _fixed.LANES + extra
    inertia, omega0, q0 = random_batch(n)
    kwargs = dict(t=np.linspace(0.0, 1.0, 3), method="rk4", dt=1e-2, torque=BATCH_TORQUES[torque])
    batch = tumble.simulate(inertia, omega0, q0=q0, **kwargs)
    for k in range(n):
        single = tumble.simulate(tumble.RigidBody(inertia[k]), omega0[k], q0=q0[k], **kwargs)
        assert np.abs(state(batch)[:, k] - state(single)).max() <= TOL_BATCH


# The fast lane keeps the torque-free rows: a torque compiles a block driver and a batch driver of its own.
@pytest.mark.parametrize("torque", [None, pytest.param(torques.ConstantInertial(TAU), marks=pytest.mark.slow)],
                         ids=["torque-free", "ConstantInertial"])
@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_batch_of_one_body_broadcasts_omega0_or_q0(method, torque, random_batch):
    n = 5
    _, omega0, q0 = random_batch(n)
    kwargs = dict(t=np.linspace(0.0, 3.0, 4), **read_by(method, dt=1e-2), torque=torque)
    body = tumble.RigidBody(FULL)
    by_rate = tumble.simulate(body, omega0, q0=Q0, **kwargs)
    by_attitude = tumble.simulate([body] * n, OMEGA0, q0=q0, **kwargs)
    for k in range(n):
        single = tumble.simulate(body, omega0[k], q0=Q0, **kwargs)
        assert np.abs(state(by_rate)[:, k] - state(single)).max() <= TOL_BATCH
        single = tumble.simulate(body, OMEGA0, q0=q0[k], **kwargs)
        assert np.abs(state(by_attitude)[:, k] - state(single)).max() <= TOL_BATCH


# -- output times --------------------------------------------------------------------------


def spin_up(**kwargs):
    """Spin about principal axis 3 of diag(1, 2, 3) at 0.7 rad/s under τ₃ = 0.3 N·m: ω₃ = 0.7 + 0.1 t."""
    return tumble.simulate(tumble.RigidBody(DIAG), [0.0, 0.0, 0.7], torque=torques.ConstantBody([0.0, 0.0, 0.3]),
                           **kwargs)


NON_UNIFORM = np.array([0.0, 0.013, 0.1, 0.37, 1.0, 1.05, 2.2, 2.25])


@pytest.mark.parametrize("dt", [0.1, 10.0], ids=["dt inside", "dt beyond every interval"])
def test_rk4_lands_on_every_output_time(dt):
    # ω₃ is linear in t, which rk4 integrates exactly: a sample taken off its
    # requested time would be off by 0.1 × the time error.
    traj = spin_up(t=NON_UNIFORM, method="rk4", dt=dt)
    np.testing.assert_array_equal(traj.t, NON_UNIFORM)
    np.testing.assert_allclose(traj.omega[:, 2], 0.7 + 0.1 * NON_UNIFORM, rtol=0, atol=TOL_POLYNOMIAL_RATE)
    # Each interval is cut into ⌈span/dt⌉ equal steps, none longer than dt.
    assert traj.info["n_steps"] == int(np.ceil(np.diff(NON_UNIFORM) / dt).sum())


def test_dop853_lands_on_every_output_time():
    traj = spin_up(t=NON_UNIFORM, method="dop853", rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(traj.t, NON_UNIFORM)
    np.testing.assert_allclose(traj.omega[:, 2], 0.7 + 0.1 * NON_UNIFORM, rtol=0, atol=TOL_POLYNOMIAL_RATE)


@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_run_starts_at_the_first_output_time(method):
    # τ₃ = 0.3 t (a Tabulated ramp) from t₀ = 5: ω₃ = 0.7 + 0.3 (t² − t₀²) / (2 I₃),
    # quadratic in t, which both methods integrate exactly.
    t = np.linspace(5.0, 8.0, 7)
    ramp = torques.Tabulated([0.0, 100.0], [[0.0, 0.0, 0.0], [0.0, 0.0, 30.0]])
    traj = tumble.simulate(tumble.RigidBody(DIAG), [0.0, 0.0, 0.7], t=t, **read_by(method, dt=0.1, rtol=1e-12,
                           atol=1e-12), torque=ramp)
    np.testing.assert_allclose(traj.omega[:, 2], 0.7 + 0.3 * (t**2 - 25.0) / 6.0, rtol=0, atol=TOL_POLYNOMIAL_RATE)


@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_single_output_time_returns_the_initial_state(method):
    with pytest.warns(attitude.NonUnitQuaternionWarning):  # |q0| = 3: normalised, with a warning
        traj = tumble.simulate(tumble.RigidBody(FULL), OMEGA0, q0=3.0 * Q0, t=[2.0], **read_by(method, dt=0.1))
    np.testing.assert_array_equal(traj.t, [2.0])
    np.testing.assert_allclose(traj.q, [Q0], rtol=0, atol=TOL_ROUNDTRIP)
    np.testing.assert_allclose(traj.omega, [OMEGA0], rtol=0, atol=TOL_ROUNDTRIP)


@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_progress_reports_and_does_not_change_the_result(method):
    calls = []
    t = np.linspace(0.0, 10.0, 201)
    kwargs = dict(q0=Q0, t=t, **read_by(method, dt=1e-2, rtol=1e-12, atol=1e-12))
    quiet = tumble.simulate(tumble.RigidBody(FULL), OMEGA0, **kwargs)
    loud = tumble.simulate(tumble.RigidBody(FULL), OMEGA0, progress=lambda done, total: calls.append((done, total)),
                           **kwargs)
    done = [d for d, _ in calls]
    assert all(total == t.size for _, total in calls) and done == sorted(done) and done[-1] == t.size
    assert np.abs(state(loud) - state(quiet)).max() <= TOL_CHUNKED


# -- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        pytest.param(dict(t=[0.0, 1.0, 1.0]), r"^t: output times must be strictly increasing", id="t repeated"),
        pytest.param(dict(t=[0.0, 2.0, 1.0]), r"^t: output times must be strictly increasing", id="t decreasing"),
        pytest.param(dict(t=[0.0, np.nan]), r"^t: must be finite", id="t nan"),
        pytest.param(dict(t=[]), r"^t: ", id="t empty"),
        pytest.param(dict(t=[[0.0, 1.0]]), r"^t: must be a 1-D array", id="t 2-D"),
        pytest.param(dict(omega0=[1.0, 2.0]), r"^omega0: must have shape", id="omega0 shape"),
        pytest.param(dict(omega0=[1.0, np.nan, 0.0]), r"^omega0: must be finite", id="omega0 nan"),
        pytest.param(
            dict(omega0=np.zeros((2, 2, 3))),
            r"^omega0: a batch has one leading axis",
            id="omega0 2 batch axes",
        ),
        pytest.param(dict(q0=[1.0, 0.0, 0.0]), r"^q0: must have shape", id="q0 shape"),
        pytest.param(dict(q0=[1.0, 0.0, np.inf, 0.0]), r"^q0: must be finite", id="q0 inf"),
        pytest.param(dict(q0=[0.0, 0.0, 0.0, 0.0]), r"^q0: must be a non-zero", id="q0 zero"),
        pytest.param(dict(q0=[Q0, np.zeros(4)]), r"^q0: must be a non-zero", id="q0 zero in a batch"),
        pytest.param(dict(method="euler"), r"^method: must be one of", id="unknown method"),
        pytest.param(dict(method="rk4"), r"^dt: ", id="rk4 without dt"),
        pytest.param(dict(method="rk4", dt=0.0), r"^dt: must be a finite number > 0", id="dt zero"),
        pytest.param(dict(method="rk4", dt=-1e-3), r"^dt: must be a finite number > 0", id="dt negative"),
        pytest.param(dict(method="rk4", dt=np.nan), r"^dt: must be a finite number > 0", id="dt nan"),
        pytest.param(dict(rtol=0.0), r"^rtol: must be a finite number > 0", id="rtol zero"),
        pytest.param(dict(rtol=-1e-8), r"^rtol: must be a finite number > 0", id="rtol negative"),
        pytest.param(dict(rtol=1e-17), r"^rtol: must be >= 1e-15", id="rtol below 1e-15"),
        pytest.param(dict(atol=0.0), r"^atol: must be a finite number > 0", id="atol zero"),
        pytest.param(dict(max_steps=0), r"^max_steps: must be >= 1", id="max_steps zero"),
        pytest.param(
            dict(omega0=np.ones((5, 3)), q0=np.tile(Q0, (4, 1))),
            r"^q0: a batch of 4 does not match the 5 of omega0",
            id="omega0 vs q0 batch",
        ),
        pytest.param(
            dict(body=np.tile(FULL, (3, 1, 1)), omega0=np.ones((2, 3))),
            r"^model: a batch of 3 does not match the 2 of omega0",
            id="inertia vs omega0 batch",
        ),
        pytest.param(
            dict(body=np.diag([1.0, 2.0, -3.0])),
            r"^inertia: must be positive definite",
            id="inertia not definite",
        ),
        pytest.param(
            dict(body=np.stack([FULL, np.diag([0.0, 1.0, 1.0])])),
            r"^inertia\[1\]: must be positive definite",  # the member is named
            id="batch inertia not definite",
        ),
        pytest.param(
            dict(body=FULL + np.triu(np.ones((3, 3)), 1)),
            r"^inertia: must be symmetric",
            id="inertia not symmetric",
        ),
        pytest.param(dict(body=np.ones(3)), r"^inertia: must have shape", id="inertia shape"),
        pytest.param(dict(torque=5.0), r"^torque: must be a torque model or a callable", id="torque not callable"),
    ],
)
def test_bad_input_is_refused_naming_the_field_and_rule(changes, message):
    kwargs = dict(body=tumble.RigidBody(DIAG), omega0=OMEGA0, t=[0.0, 1.0]) | changes
    with pytest.raises(ValidationError, match=message):
        tumble.simulate(kwargs.pop("body"), kwargs.pop("omega0"), **kwargs)


def test_exhausted_max_steps_is_a_solver_error():
    with pytest.raises(SolverError, match=r"max_steps=10 reached before t=100"):
        tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=[0.0, 100.0], max_steps=10)


# -- unit quaternion ----------------------------------------------------------------------


@pytest.mark.parametrize("method", ["rk4", "dop853"])
def test_quaternion_stays_unit(method):
    traj = tumble.simulate(tumble.RigidBody(FULL), OMEGA0, q0=Q0, t=np.linspace(0.0, 20.0, 2001),
                           **read_by(method, dt=1e-2, rtol=1e-8, atol=1e-8), torque=torques.ConstantInertial(TAU))
    assert np.abs(np.linalg.norm(traj.q, axis=-1) - 1.0).max() <= TOL_UNIT


def test_an_object_that_is_not_a_model_is_refused_naming_its_type():
    with pytest.raises(ValidationError, match=r"^model: must be a tumble model .* got dict"):
        tumble.simulate({"inertia": DIAG}, [0.0, 0.0, 1.0], t=[0.0, 1.0])


def test_lane_passes_drop_reference_counts_only_without_a_torque_program():
    # the fused lane passes (_fused.advance) compiled without reference counting vectorise in the process that
    # compiles them
    # (docs/architecture.md); a torque program's evaluator may call Python, which allocates, so a model
    # with one keeps the counts (compiled without them, its batch failed to type in a fresh process)
    from numba import typeof

    from tumble.integrate import _fused
    from tumble.kernels import rigid

    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    free = typeof(rigid.build([body], None))
    with_program = typeof(rigid.build([body], torques.ConstantBody([0.1, 0.0, 0.0])))
    with_python = typeof(rigid.build([body], torques.as_torque_model(lambda t, q, w: np.zeros(3))))
    assert not _fused.counts_references(free)
    assert _fused.counts_references(with_program) and _fused.counts_references(with_python)
