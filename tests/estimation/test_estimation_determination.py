"""TRIAD, Davenport's q-method and QUEST: agreement with each other and with scipy, QUEST's covariance."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import tumble
from tumble import attitude
from tumble.estimation import davenport, quest, triad

# The estimation kernels (parallel over the Monte-Carlo runs) take tens of CPU s to compile on a cold Numba cache.
pytestmark = pytest.mark.slow


def _scene(n_att: int, n_vec: int, seed: int = 7):
    """Random attitudes (n_att, 4), inertial unit vectors (n_vec, 3) and their exact body components."""
    rng = np.random.default_rng(seed)
    q = attitude.normalize(rng.standard_normal((n_att, 4)))
    r = rng.standard_normal((n_vec, 3))
    r /= np.linalg.norm(r, axis=-1, keepdims=True)
    return q, r, attitude.rotate_inverse(q[:, None, :], r)


def test_noise_free_methods_agree_with_each_other_truth_and_scipy_align_vectors():
    q, r, b = _scene(200, 4)
    q_triad = triad(b[:, :2], r[:2])
    q_dav = davenport(b, r, [1e-3, 2e-3, 1e-3, 5e-3])
    q_quest = quest(b, r, [1e-3, 2e-3, 1e-3, 5e-3]).q
    q_scipy = np.stack([attitude.from_scipy(Rotation.align_vectors(r, bi)[0]) for bi in b])
    for est in (q_triad, q_dav, q_quest, q_scipy):
        assert attitude.relative_angle(est, q).max() < 1e-12  # rad
    assert attitude.relative_angle(q_quest, q_dav).max() < 1e-12
    assert attitude.relative_angle(q_triad, q_quest).max() < 1e-12


def test_rotations_by_pi_about_each_axis_use_sequential_rotations():
    """QUEST's γ vanishes for a rotation by π; the sequential-rotation pass still gives the exact attitude."""
    _, r, _ = _scene(1, 3)
    q = attitude.from_rotvec(np.pi * np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0.6, 0.0, 0.8]]))
    b = attitude.rotate_inverse(q[:, None, :], r)
    assert attitude.relative_angle(quest(b, r).q, q).max() < 1e-12
    assert attitude.relative_angle(davenport(b, r), q).max() < 1e-12


def test_noisy_optimum_matches_scipy_align_vectors_with_weights():
    q, r, b = _scene(50, 5, seed=3)
    sigma = np.array([1e-3, 3e-3, 2e-3, 1e-2, 4e-3])
    b = b + np.random.default_rng(4).normal(scale=sigma[:, None], size=b.shape)
    est = quest(b, r, sigma)
    for i in range(len(q)):
        bi = b[i] / np.linalg.norm(b[i], axis=-1, keepdims=True)
        rot, _ = Rotation.align_vectors(r, bi, weights=1.0 / sigma**2)
        assert attitude.relative_angle(est.q[i], attitude.from_scipy(rot)) < 1e-10
    assert attitude.relative_angle(davenport(b, r, sigma), est.q).max() < 1e-10


def test_quest_covariance_matches_monte_carlo_scatter_within_10_percent():
    """1e4 draws of the QUEST measurement model; the sample covariance of δθ vs P_θθ (Shuster 1989)."""
    draws = 10_000
    q_true = attitude.normalize([0.3, -0.5, 0.7, 0.2])
    r = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.2], [0.3, 0.4, 1.0]])
    r /= np.linalg.norm(r, axis=-1, keepdims=True)
    sigma = np.array([1e-3, 2e-3, 5e-4])
    b_true = attitude.rotate_inverse(q_true, r)
    rng = np.random.default_rng(11)
    noise = rng.normal(size=(draws, 3, 3)) * sigma[:, None]
    noise -= np.sum(noise * b_true, axis=-1, keepdims=True) * b_true  # v_i ⊥ b_i, covariance σ²(I − bbᵀ)
    est = quest(b_true + noise, r, sigma)
    dtheta = attitude.to_rotvec(attitude.multiply(attitude.conjugate(est.q), q_true))  # q_true = q̂ ⊗ exp(δθ/2)
    scatter = np.cov(dtheta.T)
    predicted = quest(b_true, r, sigma).covariance  # P_θθ at the true vectors
    # the variances along the principal axes of P_θθ, and the whole matrix, within 10 %
    values, axes = np.linalg.eigh(predicted)
    np.testing.assert_allclose(np.diag(axes.T @ scatter @ axes), values, rtol=0.10)
    np.testing.assert_allclose(scatter, predicted, atol=0.10 * values.min())
    assert np.all(abs(np.mean(dtheta, axis=0) @ axes) < 0.05 * np.sqrt(values))  # unbiased: < 0.05σ (5 s.e.)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: triad([[1, 0, 0], [2, 0, 0]], [[1, 0, 0], [0, 1, 0]]), "b: the two vectors must not be parallel"),
    (lambda: triad([[1, 0, 0], [0, 1, 0]], [[0, 0, 1], [0, 0, -3]]), "r: the two vectors must not be parallel"),
    (lambda: quest([[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [0, 1, 0]]), "b: vectors must be non-zero"),
    (lambda: quest([[1, 0, 0], [0, 1, 0]], [[1, 0, 0], [0, 1, 0]], sigma=[1e-3, 0.0]), "sigma: must be > 0"),
    (lambda: davenport([[1, 0, 0], [0, 1, 0]], [[1, 0, 0]]), "r: must hold as many vectors as b"),
])
def test_bad_input_names_the_field_and_rule(call, message):
    with pytest.raises(tumble.ValidationError, match=message):
        call()
