"""Sensor error models and the Allan deviation (tumble.ins.sensors, tumble.ins.allan)."""

import math

import numpy as np
import pytest

import tumble
from tumble.ins import (FLICKER_FACTOR, Coning, Imu, Increments, SensorErrors, allan_deviation,
                        from_trajectory, gauss_markov_adev)
from tumble.viz.ins import allan_figure
from tumble._validate import ValidationError

# Recovery of N and B from the Allan deviation of a simulated gyro (issue: 10 %).
# Measured with seed 0: N/N_true = 1.006, 1.006, 1.006; B/B_true = 0.988, 1.024, 1.011
# (and 0.997–1.037 for seeds 1–3).
RECOVERY_RTOL = 0.10
# Overlapping ADEV of white noise vs N/√τ: for m ≤ 100 of 4e5 samples the relative
# standard error is below 1.5 % (≈ 1/√(K/m) × 0.75); 5 % is more than 3 σ.
WHITE_RTOL = 0.05
# Synthesised flicker: the analytic ADEV of the Gauss–Markov bank stays within 2.5 % of
# 0.664 B over [20 T_min, T_max/10] (computed: 0.977 … 0.996).
FLICKER_FLAT_RTOL = 0.025


def _increments(count=1000, dt=0.01, seed=3):
    rng = np.random.default_rng(seed)
    return Increments(t0=0.0, dt=dt, delta_theta=1e-3 * rng.standard_normal((count, 3)),
                      delta_v=1e-2 * rng.standard_normal((count, 3)))


def test_deterministic_terms_are_exact():
    truth = _increments()
    errors = SensorErrors(bias=[1e-3, -2e-3, 5e-4], scale_factor=[1e-4, -2e-4, 3e-4],
                          misalignment=[[0, 1e-4, -2e-4], [3e-4, 0, 1e-4], [-1e-4, 2e-4, 0]])
    measured = errors.apply(truth.delta_theta, truth.dt, np.random.default_rng(0))
    matrix = np.eye(3) + np.diag(errors.scale_factor) + errors.misalignment
    expected = truth.delta_theta @ matrix.T + errors.bias * truth.dt
    np.testing.assert_allclose(measured, expected, rtol=0, atol=1e-18)


def test_same_seed_same_numbers():
    truth = _increments()
    imu = Imu(gyro=SensorErrors(white_noise=1e-3, bias_instability=1e-4, random_walk=1e-5, quantization=1e-6),
              accel=SensorErrors(white_noise=1e-2, quantization=1e-5))
    a, b, c = imu.measure(truth, seed=42), imu.measure(truth, seed=42), imu.measure(truth, seed=43)
    np.testing.assert_array_equal(a.delta_theta, b.delta_theta)
    np.testing.assert_array_equal(a.delta_v, b.delta_v)
    # another seed, other numbers (a few quantized outputs, of 1e-4 noise in 1e-6 quanta, may coincide)
    assert np.mean(a.delta_theta != c.delta_theta) > 0.99
    # the gyro draws first: its output does not depend on whether accelerometer data are present
    gyro_only = imu.measure(Increments(truth.t0, truth.dt, truth.delta_theta), seed=42)
    np.testing.assert_array_equal(gyro_only.delta_theta, a.delta_theta)


def test_quantization_carries_the_residual():
    truth = _increments()
    q = 1e-4
    measured = SensorErrors(quantization=q).apply(truth.delta_theta, truth.dt, np.random.default_rng(0))
    counts = measured / q
    np.testing.assert_allclose(counts, np.round(counts), rtol=0, atol=1e-6)  # whole quanta (to rounding)
    residual = np.cumsum(truth.delta_theta, axis=0) - np.cumsum(measured, axis=0)
    assert np.abs(residual).max() <= 0.5 * q * (1 + 1e-9)  # the error never accumulates


def test_angle_random_walk_variance():
    # Var(Δθ) = N² dt; 3e5 draws: relative standard error of the variance √(2/3e5) = 0.26 %
    N, dt = 2e-3, 0.01
    measured = SensorErrors(white_noise=N).apply(np.zeros((100_000, 3)), dt, np.random.default_rng(1))
    assert measured.var() / (N * N * dt) == pytest.approx(1.0, abs=0.013)  # 5 standard errors


def test_allan_deviation_of_white_noise_is_n_over_root_tau():
    N, dt = 1e-3, 0.01
    rate = N / math.sqrt(dt) * np.random.default_rng(7).standard_normal(400_000)
    adev = allan_deviation(rate, dt, m=[1, 2, 5, 10, 20, 50, 100])
    np.testing.assert_allclose(adev.sigma, N / np.sqrt(adev.tau), rtol=WHITE_RTOL)
    # increments and rates give the same curve
    same = allan_deviation(rate * dt, dt, kind="increment", m=[1, 2, 5, 10, 20, 50, 100])
    np.testing.assert_allclose(same.sigma, adev.sigma, rtol=1e-12)


def test_gauss_markov_adev_limits():
    sigma, T = 2.0, 5.0
    # τ ≫ T: white noise of PSD 2σ²T → σ_A² = 2σ²T/τ (relative correction 3T/(2τ) = 1.5e-4 at τ = 1e4 T)
    assert gauss_markov_adev(5e4, sigma, T) == pytest.approx(math.sqrt(2 * sigma**2 * T / 5e4), rel=1e-4)
    # τ ≪ T: rate random walk K² = 2σ²/T → σ_A² = K² τ/3 (relative correction ~ τ/T = 1e-4)
    assert gauss_markov_adev(5e-4, sigma, T) == pytest.approx(math.sqrt(2 * sigma**2 / T * 5e-4 / 3), rel=1e-4)


def test_flicker_bank_is_flat_at_0664_b():
    errors = SensorErrors(bias_instability=1.0, flicker_band=(0.1, 1000.0))
    times = errors.correlation_times()
    np.testing.assert_allclose(times, 0.1 * 10 ** (0.5 * np.arange(9)), rtol=1e-12)
    variance = math.log(math.sqrt(10.0)) / math.pi
    tau = np.geomspace(2.0, 100.0, 30)
    adev = np.sqrt(sum(gauss_markov_adev(tau, math.sqrt(variance), T) ** 2 for T in times))
    np.testing.assert_allclose(adev / FLICKER_FACTOR, 1.0, atol=FLICKER_FLAT_RTOL)


@pytest.mark.slow  # 1e6 samples × 3 axes: about 10 s
def test_allan_deviation_recovers_n_and_b():
    B = 1e-5
    N = FLICKER_FACTOR * B * math.sqrt(0.3)  # N/√τ meets 0.664 B at τ = 0.3 s
    K = 0.063 * B                            # the curve rises again beyond ~100 s
    errors = SensorErrors(white_noise=N, bias_instability=B, flicker_band=(0.1, 1000.0), random_walk=K)
    dt = 0.01
    measured = errors.apply(np.zeros((1_000_000, 3)), dt, np.random.default_rng(0))
    m = np.unique(np.round(np.logspace(0, 5, 41))).astype(int)
    adev = allan_deviation(measured, dt, kind="increment", m=m)
    np.testing.assert_allclose(adev.white_noise(tau_max=0.03), N, rtol=RECOVERY_RTOL)
    np.testing.assert_allclose(adev.bias_instability(), B, rtol=RECOVERY_RTOL)
    figure = allan_figure({"simulated": adev}, white_noise=N, bias_instability=B)
    assert len(figure.axes[0].lines) == 5  # three axes, N/√τ, 0.664 B


def test_imu_samples_a_trajectory():
    t = np.linspace(0.0, 1.0, 401)
    truth = tumble.simulate(np.diag([1.0, 2.0, 3.0]), [0.4, 1.0, 0.3], t=t, method="exact")
    perfect = Imu().sample(truth, oversample=4, seed=0)
    np.testing.assert_array_equal(perfect.delta_theta, from_trajectory(truth, oversample=4).delta_theta)
    assert perfect.dt == pytest.approx(0.01, rel=1e-12) and len(perfect) == 100
    # measured rates are the mean rates over the sample intervals: Δθ/dt
    np.testing.assert_array_equal(perfect.rate, perfect.delta_theta / perfect.dt)
    np.testing.assert_allclose(perfect.t, 0.01 * np.arange(1, 101), rtol=1e-12)


def test_from_trajectory_checks_its_grid():
    coning = Coning(0.1, 1.0)
    with pytest.raises(ValidationError, match="oversample"):
        from_trajectory(coning.trajectory(np.linspace(0, 1, 11)), oversample=3)
    with pytest.raises(ValidationError, match="multiple of oversample"):
        from_trajectory(coning.trajectory(np.linspace(0, 1, 12)), oversample=2)
    with pytest.raises(ValidationError, match="uniformly spaced"):
        from_trajectory(coning.trajectory(np.array([0.0, 0.1, 0.3])), oversample=2)
    with pytest.raises(ValidationError, match="specific_force"):
        from_trajectory(coning.trajectory(np.linspace(0, 1, 11)), specific_force=np.zeros((3, 3)))


def test_sensor_errors_validation():
    with pytest.raises(ValidationError, match="misalignment: the diagonal must be zero"):
        SensorErrors(misalignment=np.eye(3))
    with pytest.raises(ValidationError, match="white_noise"):
        SensorErrors(white_noise=-1.0)
    with pytest.raises(ValidationError, match="flicker_band"):
        SensorErrors(flicker_band=(10.0, 1.0))
    with pytest.raises(ValidationError, match="bias"):
        SensorErrors(bias=[1.0, 2.0])
    with pytest.raises(ValidationError, match="kind"):
        allan_deviation(np.zeros(10), 0.1, kind="angle")
