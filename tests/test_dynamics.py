"""Tests of tumble.dynamics: Euler's equations (both forms), kinematics and invariants."""

import numpy as np
import pytest

from tumble import dynamics
from tumble._validate import ValidationError

EPS = np.finfo(np.float64).eps
# Hand values below come out of a few float operations on small integers and
# exact binary fractions (plus cos/sin 45°): allow a few roundings.
ROUNDING = 8 * EPS
# omega_dot solves I x = τ − ω × Iω by LU; the principal form divides by the
# moments after rotating by an eigenvector matrix R (itself accurate to ~eps).
# For |I| ~ 3, |ω| ~ 1 and moments ≥ 1 the two agree to ~1e-15; 1e-13 leaves
# room for the conditioning of the 3×3 solve (moments 1..3).
TOL_FORMS = 1e-13

DIAG = np.diag([1.0, 2.0, 3.0])
FULL = np.array([[2.0, 1.0, 0.0], [1.0, 3.0, 0.0], [0.0, 0.0, 4.0]])
QUARTER_TURN_Z = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])  # body x -> inertial y


def rel_err(actual, expected):
    """max |actual − expected| / max |expected|."""
    expected = np.asarray(expected)
    return np.abs(np.asarray(actual) - expected).max() / np.abs(expected).max()


def random_tensor(rng):
    """A symmetric positive-definite tensor with moments in [1, 3] (kg·m²)."""
    a = rng.standard_normal((3, 3))
    q, _ = np.linalg.qr(a)
    return q @ np.diag(rng.uniform(1.0, 3.0, 3)) @ q.T


# -- Euler's equations: hand values ----------------------------------------------------


def test_omega_dot_diagonal_hand_values():
    # I = diag(1, 2, 3), ω = (1, 1, 1), τ = 0:
    # ω̇₁ = (2 − 3)/1 = −1, ω̇₂ = (3 − 1)/2 = 1, ω̇₃ = (1 − 2)/3 = −1/3.
    expected = [-1.0, 1.0, -1.0 / 3.0]
    np.testing.assert_allclose(dynamics.omega_dot(DIAG, [1.0, 1.0, 1.0]), expected, rtol=0, atol=ROUNDING)
    np.testing.assert_allclose(
        dynamics.omega_dot_principal([1.0, 2.0, 3.0], [1.0, 1.0, 1.0]), expected, rtol=0, atol=ROUNDING
    )


def test_omega_dot_principal_with_torque_hand_values():
    # moments (1, 2, 3), ω = (1, 2, 3), τ = (1, 1, 1):
    # ω̇₁ = (1 + (2 − 3)·6)/1 = −5, ω̇₂ = (1 + (3 − 1)·3)/2 = 3.5, ω̇₃ = (1 + (1 − 2)·2)/3 = −1/3.
    got = dynamics.omega_dot_principal([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [1.0, 1.0, 1.0])
    np.testing.assert_allclose(got, [-5.0, 3.5, -1.0 / 3.0], rtol=0, atol=ROUNDING)


def test_omega_dot_full_tensor_hand_values():
    # I = FULL, ω = (1, −1, 2): Iω = (1, −2, 8), ω × Iω = (−8 + 4, 2 − 8, −2 + 1) = (−4, −6, −1).
    # With τ = 0: I ω̇ = (4, 6, 1) → ω̇₃ = 1/4 and [[2, 1], [1, 3]] (a, b) = (4, 6) → a = 6/5, b = 8/5.
    got = dynamics.omega_dot(FULL, [1.0, -1.0, 2.0])
    np.testing.assert_allclose(got, [1.2, 1.6, 0.25], rtol=0, atol=ROUNDING)


def test_omega_dot_at_rest_is_inverse_inertia_times_torque():
    # ω = 0: ω̇ = I⁻¹ τ; choosing τ = I a gives ω̇ = a.
    a = np.array([0.3, -1.2, 0.7])
    got = dynamics.omega_dot(FULL, np.zeros(3), FULL @ a)
    np.testing.assert_allclose(got, a, rtol=0, atol=ROUNDING)


@pytest.mark.parametrize("seed", range(4))
def test_full_tensor_form_equals_principal_form_in_principal_axes(seed):
    # I = R diag(m) Rᵀ: the body-axes ω̇ is R times the principal-axes ω̇ of (Rᵀω, Rᵀτ).
    rng = np.random.default_rng(seed)
    inertia = random_tensor(rng)
    moments, axes = np.linalg.eigh(inertia)
    axes[:, 2] *= np.linalg.det(axes)  # right-handed: ω × Iω is a cross product only in proper axes
    omega, torque = rng.standard_normal(3), rng.standard_normal(3)
    principal = dynamics.omega_dot_principal(moments, axes.T @ omega, axes.T @ torque)
    assert rel_err(dynamics.omega_dot(inertia, omega, torque), axes @ principal) <= TOL_FORMS


# -- kinematics --------------------------------------------------------------------------


def test_quaternion_rate_at_identity_is_half_omega():
    omega = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(dynamics.quaternion_rate([1.0, 0.0, 0.0, 0.0], omega), [0.0, 0.5, 1.0, 1.5],
                               rtol=0, atol=ROUNDING)


@pytest.mark.parametrize("seed", range(3))
def test_quaternion_rate_matches_vector_form(seed):
    # q ⊗ [0, ω] = [−u·ω, w ω + u × ω] with q = [w, u] (Hamilton product, written out here).
    rng = np.random.default_rng(seed)
    q = rng.standard_normal(4)
    q /= np.linalg.norm(q)
    omega = rng.standard_normal(3)
    w, u = q[0], q[1:]
    expected = 0.5 * np.concatenate([[-u @ omega], w * omega + np.cross(u, omega)])
    got = dynamics.quaternion_rate(q, omega)
    np.testing.assert_allclose(got, expected, rtol=0, atol=ROUNDING)
    # q̇ is tangent to the unit sphere: q · q̇ = 0.
    assert abs(q @ got) <= ROUNDING


# -- invariants --------------------------------------------------------------------------


def test_invariants_hand_values():
    omega = [1.0, -1.0, 2.0]
    # Iω = (1, −2, 8); T = ½ (1 + 2 + 16) = 9.5.
    np.testing.assert_array_equal(dynamics.angular_momentum(FULL, omega), [1.0, -2.0, 8.0])
    assert dynamics.kinetic_energy(FULL, omega) == 9.5
    # A quarter turn about z maps body (x, y, z) to inertial (−y, x, z): L_N = (2, 1, 8).
    np.testing.assert_allclose(dynamics.angular_momentum_inertial(FULL, omega, QUARTER_TURN_Z),
                               [2.0, 1.0, 8.0], rtol=0, atol=8 * ROUNDING)


@pytest.mark.parametrize("seed", range(3))
def test_invariants_do_not_depend_on_body_axes(seed, random_rotation):
    # The same body and motion in axes rotated by R: I' = Rᵀ I R, ω' = Rᵀ ω, q' = q ⊗ q(R).
    rng = np.random.default_rng(seed)
    inertia, omega = random_tensor(rng), rng.standard_normal(3)
    r = random_rotation(seed)
    inertia2, omega2 = r.T @ inertia @ r, r.T @ omega
    assert rel_err(dynamics.kinetic_energy(inertia2, omega2), dynamics.kinetic_energy(inertia, omega)) <= TOL_FORMS
    assert rel_err(dynamics.angular_momentum(inertia2, omega2), r.T @ dynamics.angular_momentum(inertia, omega)) \
        <= TOL_FORMS


# -- batches -----------------------------------------------------------------------------


@pytest.mark.parametrize("batched_inertia", [False, True], ids=["inertia (3,3)", "inertia (5,3,3)"])
def test_batches_broadcast_like_loops(batched_inertia):
    # Every function on a batch equals the function applied body by body, to rounding.
    rng = np.random.default_rng(7)
    n = 5
    inertia = np.stack([random_tensor(rng) for _ in range(n)]) if batched_inertia else random_tensor(rng)
    omega, torque = rng.standard_normal((n, 3)), rng.standard_normal((n, 3))
    q = rng.standard_normal((n, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    one = (lambda k: inertia[k]) if batched_inertia else (lambda k: inertia)

    cases = {
        "omega_dot": (dynamics.omega_dot(inertia, omega, torque),
                      [dynamics.omega_dot(one(k), omega[k], torque[k]) for k in range(n)]),
        "kinetic_energy": (dynamics.kinetic_energy(inertia, omega),
                           [dynamics.kinetic_energy(one(k), omega[k]) for k in range(n)]),
        "angular_momentum": (dynamics.angular_momentum(inertia, omega),
                             [dynamics.angular_momentum(one(k), omega[k]) for k in range(n)]),
        "angular_momentum_inertial": (dynamics.angular_momentum_inertial(inertia, omega, q),
                                      [dynamics.angular_momentum_inertial(one(k), omega[k], q[k]) for k in range(n)]),
        "quaternion_rate": (dynamics.quaternion_rate(q, omega),
                            [dynamics.quaternion_rate(q[k], omega[k]) for k in range(n)]),
    }
    for name, (batch, loop) in cases.items():
        loop = np.array(loop)
        assert batch.shape == loop.shape, name
        np.testing.assert_allclose(batch, loop, rtol=ROUNDING, atol=ROUNDING, err_msg=name)


def test_omega_dot_principal_broadcasts_one_set_of_moments():
    rng = np.random.default_rng(3)
    omega = rng.standard_normal((5, 3))
    got = dynamics.omega_dot_principal([1.0, 2.0, 3.0], omega)
    loop = [dynamics.omega_dot(DIAG, w) for w in omega]
    assert got.shape == (5, 3)
    np.testing.assert_allclose(got, loop, rtol=ROUNDING, atol=ROUNDING)


def test_quaternion_rate_broadcasts_one_attitude_over_rates():
    omega = np.arange(15.0).reshape(5, 3)
    got = dynamics.quaternion_rate([1.0, 0.0, 0.0, 0.0], omega)
    assert got.shape == (5, 4)
    np.testing.assert_array_equal(got[:, 0], 0.0)
    np.testing.assert_array_equal(got[:, 1:], 0.5 * omega)


# -- bad input ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: dynamics.omega_dot(np.eye(2), [1.0, 0.0, 0.0]), "inertia"),
        (lambda: dynamics.omega_dot(DIAG, [1.0, np.nan, 0.0]), "omega"),
        (lambda: dynamics.omega_dot(DIAG, [1.0, 0.0, 0.0], [1.0, 2.0]), "torque"),
        (lambda: dynamics.omega_dot_principal([1.0, 2.0], [1.0, 0.0, 0.0]), "moments"),
        (lambda: dynamics.kinetic_energy(DIAG, [1.0, 0.0]), "omega"),
        (lambda: dynamics.quaternion_rate([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]), "q"),
    ],
)
def test_bad_input_names_the_field(call, field):
    with pytest.raises(ValidationError, match=rf"^{field}: "):
        call()
