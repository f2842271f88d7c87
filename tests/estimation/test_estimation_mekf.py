"""The MEKF's consistency over a Monte-Carlo of 200 runs: NEES and NIS inside their 95 % χ² bounds, bias
convergence within 3σ."""

import numpy as np
import pytest
from scipy.stats import chi2

import tumble
from tumble import attitude
from tumble.estimation import mekf
from tumble.ins import from_trajectory

# The estimation kernels (parallel over the Monte-Carlo runs) take tens of CPU s to compile on a cold Numba cache.
pytestmark = pytest.mark.slow

RUNS = 200
DT = 0.5            # gyro interval, s
ARW = 3e-5          # rad/√s
RRW = 1e-7          # rad/s^1.5
BIAS_SIGMA = 2e-4   # rad/s, initial bias uncertainty
ANGLE_SIGMA = 2e-3  # rad, initial attitude uncertainty
ST_COV = np.diag([5e-5, 5e-5, 4e-4]) ** 2  # star tracker: cross- and about-boresight, rad²


@pytest.fixture(scope="module")
def truth():
    """A tumbling body's exact attitude every DT for 300 s and its exact mean rates over each interval."""
    body = tumble.RigidBody(inertia=np.diag([10.0, 14.0, 8.0]))
    grid = np.linspace(0.0, 300.0, 1201)
    traj = tumble.simulate(body, omega0=[0.02, -0.05, 0.03], q0=attitude.normalize([1.0, 0.2, -0.1, 0.3]), t=grid,
                           rtol=1e-12, atol=1e-12)
    inc = from_trajectory(traj, oversample=2)
    return grid[::2], traj.q[::2], inc.rate


def _draws(truth, star_every: int, seed: int):
    """RUNS runs' true biases (R, K, 3) and the filter's inputs: gyro rates, initial attitudes, star tracker
    quaternions every star_every steps (NaN between), P0."""
    t, q_true, rate_true = truth
    K = t.size
    rng = np.random.default_rng(seed)
    bias = BIAS_SIGMA * rng.standard_normal((RUNS, 1, 3)) + np.concatenate(
        [np.zeros((RUNS, 1, 3)), np.cumsum(RRW * np.sqrt(DT) * rng.standard_normal((RUNS, K - 1, 3)), axis=1)], axis=1)
    rate = rate_true + bias[:, :-1] + ARW / np.sqrt(DT) * rng.standard_normal((RUNS, K - 1, 3))
    q0 = attitude.multiply(q_true[0], attitude.from_rotvec(ANGLE_SIGMA * rng.standard_normal((RUNS, 3))))
    noise = rng.standard_normal((RUNS, K, 3)) @ np.linalg.cholesky(ST_COV).T
    star = attitude.multiply(q_true, attitude.from_rotvec(noise))
    star[:, np.arange(K) % star_every != 0] = np.nan
    P0 = np.diag([ANGLE_SIGMA**2] * 3 + [BIAS_SIGMA**2] * 3)
    return bias, rate, q0, star, P0


def _monte_carlo(truth, star_every: int, seed: int = 5):
    """RUNS runs: their true biases (R, K, 3), and the MEKF's estimates with a star tracker every star_every steps."""
    bias, rate, q0, star, P0 = _draws(truth, star_every, seed)
    est = mekf(truth[0], rate, q0=q0, P0=P0, arw=ARW, rrw=RRW, star_tracker=star, star_tracker_covariance=ST_COV)
    return bias, est


def _fraction_inside(values, dof, runs):
    """Fraction of times whose run-averaged statistic lies inside the two-sided 95 % bounds of χ²(dof·runs)/runs."""
    lo, hi = chi2.ppf([0.025, 0.975], dof * runs) / runs
    return np.mean((values >= lo) & (values <= hi))


def test_mekf_nees_and_nis_inside_95_percent_chi2_bounds(truth):
    bias, est = _monte_carlo(truth, star_every=4)
    nees = est.nees(truth[1], bias).mean(axis=0)              # (K,): average over runs
    assert _fraction_inside(nees, 6, RUNS) >= 0.90            # 95 % expected for a consistent filter
    assert abs(nees.mean() / 6.0 - 1.0) < 0.05                # and no bias on average
    measured = est.nis_dof[0] > 0
    assert np.all(est.nis_dof[:, measured] == 3)
    nis = est.nis[:, measured].mean(axis=0)
    assert _fraction_inside(nis, 3, RUNS) >= 0.90
    assert abs(nis.mean() / 3.0 - 1.0) < 0.05


def test_mekf_bias_converges_to_the_simulated_one_within_3_sigma(truth):
    bias, est = _monte_carlo(truth, star_every=2, seed=9)
    err = bias[:, -1] - est.bias[:, -1]
    sigma = np.sqrt(np.diagonal(est.covariance[:, -1], axis1=-2, axis2=-1)[:, 3:])
    assert np.mean(np.abs(err) <= 3.0 * sigma) >= 0.99       # 99.73 % expected
    assert sigma.max() < 0.1 * BIAS_SIGMA                     # converged: the uncertainty fell tenfold


def test_mekf_with_vector_observations_tracks_the_attitude(truth):
    """Two known directions (e.g. Sun and magnetic field) instead of a star tracker, 2 degrees of freedom each."""
    t, q_true, rate_true = truth
    rng = np.random.default_rng(2)
    refs = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]])
    sigma = np.array([1e-3, 2e-3])
    b = attitude.rotate_inverse(q_true[:, None, :], refs) + sigma[:, None] * rng.standard_normal((t.size, 2, 3))
    est = mekf(t, rate_true + ARW / np.sqrt(DT) * rng.standard_normal(rate_true.shape), q0=q_true[0],
               P0=np.diag([1e-4] * 3 + [1e-8] * 3), arw=ARW, rrw=RRW, vectors=b, references=refs, vector_sigma=sigma)
    assert np.all(est.nis_dof == 4)
    angle = attitude.relative_angle(est.q, q_true)
    sigma_angle = np.sqrt(np.trace(est.covariance[:, :3, :3], axis1=-2, axis2=-1))
    assert np.mean(angle[100:] <= 3.0 * sigma_angle[100:]) > 0.97
    assert angle[100:].max() < 3e-3


@pytest.mark.parametrize(("change", "message"), [
    ({"P0": np.diag([1.0, 1.0, 1.0, 1.0, 1.0, -1.0])}, "P0: must be positive definite"),
    ({"P0": np.eye(6) + np.triu(np.ones((6, 6)), 1) * 0.1}, "P0: must be symmetric"),
    ({"q0": [0.0, 0.0, 0.0, 0.0]}, "q0: must be non-zero"),
    ({"star_tracker": np.tile([1.0, 0, 0, 0], (3, 1)), "star_tracker_covariance": -np.eye(3)},
     "star_tracker_covariance: must be positive definite"),
    ({"rate": np.zeros((3, 3))}, "rate: must have shape"),
    ({"bias0": [0.0, np.nan, 0.0]}, "bias0: must be finite"),
    ({"star_tracker": np.zeros((3, 4)), "star_tracker_covariance": np.eye(3)},
     "star_tracker: a measurement must be non-zero"),
])
def test_mekf_bad_input_names_the_field_and_rule(change, message):
    args = {"rate": np.zeros((2, 3)), "q0": [1.0, 0, 0, 0], "P0": np.eye(6), "arw": 1e-4, "rrw": 1e-6} | change
    with pytest.raises(tumble.ValidationError, match=message):
        mekf([0.0, 1.0, 2.0], args.pop("rate"), **args)


@pytest.mark.parametrize("omega", [[0.3, -1.2, 0.7], [1e-5, 2e-5, -1e-5], [0.0, 0.0, 0.0]])
def test_mekf_transition_matrix_is_the_exponential_of_the_error_dynamics(omega):
    """Φ's closed form (both branches: |ω̂|Δt above and below 1e-3) against expm(F Δt) of δẋ = F δx,
    F = [[−[ω̂×], −I], [0, 0]]; with σ_u = 0 the process noise is σ_v²Δt I on the attitude."""
    from scipy.linalg import expm

    from tumble.estimation._mekf import _propagate

    dt, arw = 0.2, 1e-3
    w = np.array(omega)
    skew = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    F = np.zeros((6, 6))
    F[:3, :3], F[:3, 3:] = -skew, -np.eye(3)
    q, beta, P = np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3), np.zeros((6, 6))
    Phi, W = np.empty((6, 6)), np.empty((3, 3))
    _propagate(q, beta, P, w, dt, arw**2, 0.0, Phi, W)
    np.testing.assert_allclose(Phi, expm(F * dt), rtol=0, atol=1e-14)
    np.testing.assert_allclose(P, np.diag([arw**2 * dt] * 3 + [0.0] * 3), rtol=0, atol=1e-20)
    np.testing.assert_allclose(q, attitude.from_rotvec(w * dt), rtol=0, atol=1e-15)


def test_every_combination_of_measurements_runs_one_compiled_filter(truth):
    """Neither, a star tracker, vectors, both: the filter's inputs are handed over in one form (contiguous,
    read-only), so the four runs share one compiled copy of it rather than compiling one per combination of
    the measurements given (about 20 CPU s each on a cold cache)."""
    from tumble.estimation import _mekf

    t, q_true, rate_true = truth
    refs = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]])
    star = dict(star_tracker=q_true, star_tracker_covariance=ST_COV)
    vectors = dict(vectors=attitude.rotate_inverse(q_true[:, None, :], refs), references=refs,
                   vector_sigma=[1e-3, 2e-3])
    for given in ({}, star, vectors, {**star, **vectors}):
        est = mekf(t, rate_true, q0=q_true[0], P0=np.diag([1e-4] * 3 + [1e-8] * 3), arw=ARW, rrw=RRW, **given)
        assert np.all(est.nis_dof[1:] == 3 * ("star_tracker" in given) + 4 * ("vectors" in given))
    assert len(_mekf._mekf_batch.signatures) == 1, _mekf._mekf_batch.signatures


def test_mekf_batch_of_runs_equals_each_run_alone(truth):
    """prange over runs: every run of a batch gives bit for bit what it gives alone."""
    bias, est = _monte_carlo(truth, star_every=4, seed=3)
    _, rate, q0, star, P0 = _draws(truth, star_every=4, seed=3)
    for i in (0, 117):
        alone = mekf(truth[0], rate[i], q0=q0[i], P0=P0, arw=ARW, rrw=RRW, star_tracker=star[i],
                     star_tracker_covariance=ST_COV)
        assert alone.q.shape == (truth[0].size, 4)
        np.testing.assert_array_equal(alone.q, est.q[i])
        np.testing.assert_array_equal(alone.covariance, est.covariance[i])
