"""Measurement models of tumble.estimation.sensors against the exact truth they read."""

import math

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.estimation.sensors import CoarseSunSensor, FineSunSensor, Magnetometer, StarTracker


@pytest.fixture(scope="module")
def traj():
    body = tumble.RigidBody(inertia=np.diag([2.0, 3.0, 4.0]))
    return tumble.simulate(body, omega0=[0.3, 0.1, -0.2], t=np.linspace(0.0, 200.0, 4001), rtol=1e-12, atol=1e-12)


MOUNT = attitude.from_rotvec([0.3, -1.2, 0.5])


def _sensor_error(meas, q_true, mounting):
    """Rotation vector v in sensor axes with q̃ = q ⊗ q_BS ⊗ exp(v/2) ⊗ q_BS*."""
    q_is_true = attitude.multiply(q_true, mounting)
    q_is_meas = attitude.multiply(meas, mounting)
    return attitude.to_rotvec(attitude.multiply(attitude.conjugate(q_is_true), q_is_meas))


def test_star_tracker_noise_cross_and_about_boresight(traj):
    st = StarTracker(rate=20.0, sigma_cross=1e-4, sigma_about=8e-4, mounting=MOUNT)
    m = st.sample(traj, seed=3)
    assert m.value.shape == (4001, 4)
    v = _sensor_error(m.value, traj.q, MOUNT)
    np.testing.assert_allclose(v.std(axis=0), [1e-4, 1e-4, 8e-4], rtol=0.05)  # 4001 draws: s.e. 1.1 %
    assert np.all(np.abs(v.mean(axis=0)) < 0.1 * np.array([1e-4, 1e-4, 8e-4]))
    np.testing.assert_allclose(st.covariance, attitude.to_matrix(MOUNT) @ np.diag([1e-8, 1e-8, 6.4e-7])
                               @ attitude.to_matrix(MOUNT).T, rtol=1e-12, atol=1e-20)


def test_star_tracker_misalignment_and_latency_read_the_exact_truth(traj):
    mu = np.array([2e-4, -1e-4, 5e-4])
    st = StarTracker(rate=10.0, sigma_cross=0.0, sigma_about=0.0, latency=0.25, mounting=MOUNT, misalignment=mu)
    m = st.sample(traj.t, traj.q, seed=1)
    np.testing.assert_allclose(m.t, 0.25 + np.arange(m.t.size) * 0.1, atol=1e-12)
    lagged = traj.q[::2][: m.t.size]  # truth at t_k − 0.25 s: grid step 0.05 s
    np.testing.assert_allclose(_sensor_error(m.value, lagged, MOUNT), np.broadcast_to(mu, (m.t.size, 3)), atol=1e-12)


def test_attitude_between_truth_samples_is_interpolated_to_second_order(traj):
    """At 7 Hz on a 20 Hz truth the samples fall between grid points; compare to a 4× finer exact truth."""
    fine = tumble.simulate(tumble.RigidBody(inertia=np.diag([2.0, 3.0, 4.0])), omega0=[0.3, 0.1, -0.2],
                           t=np.linspace(0.0, 200.0, 56001), rtol=1e-12, atol=1e-12)
    m = StarTracker(rate=7.0, sigma_cross=0.0, sigma_about=0.0).sample(traj, seed=0)
    truth = fine.q[np.rint(m.t * 280.0).astype(int)]  # 7 Hz lands on the 280 Hz grid
    # the geodesic (constant-rate) interpolation errs by at most |ω̇| h²/8 to leading order, h = 0.05 s
    inertia = np.array([2.0, 3.0, 4.0])
    w = traj.omega
    omega_dot = (np.roll(inertia, -1) - np.roll(inertia, 1)) * np.roll(w, -1) * np.roll(w, 1) / inertia  # Euler
    bound = np.linalg.norm(omega_dot, axis=-1).max() * 0.05**2 / 8.0
    err = attitude.relative_angle(m.value, truth)
    assert err.max() < 1.05 * bound
    assert err.max() > 0.5 * bound  # the bound is the actual order of the error, not a loose ceiling


def test_star_tracker_sun_exclusion(traj):
    sun = np.array([1.0, 0.0, 0.0])
    st = StarTracker(rate=20.0, sigma_cross=0.0, sigma_about=0.0, exclusion={"sun": math.radians(30.0)})
    m = st.sample(traj, directions={"sun": sun}, seed=0)
    angle_to_sun = np.arccos(attitude.rotate(traj.q, [0.0, 0.0, 1.0]) @ sun)
    blinded = angle_to_sun < math.radians(30.0)
    assert 0 < blinded.sum() < blinded.size
    np.testing.assert_array_equal(np.isnan(m.value[:, 0]), blinded)
    assert attitude.relative_angle(m.value[~blinded], traj.q[~blinded]).max() < 1e-12


def test_each_sensor_is_reproducible_per_seed_with_its_own_stream(traj):
    mag = Magnetometer(rate=5.0, sigma=1e-7)
    a = mag.sample(traj, field_inertial=[2e-5, 0.0, -4e-5], seed=12)
    b = mag.sample(traj, field_inertial=[2e-5, 0.0, -4e-5], seed=12)
    c = mag.sample(traj, field_inertial=[2e-5, 0.0, -4e-5], seed=13)
    np.testing.assert_array_equal(a.value, b.value)
    assert not np.array_equal(a.value, c.value)


def test_magnetometer_and_sun_sensors_against_the_formulas(traj):
    field = np.array([2e-5, 1e-6, -4e-5])
    errors = np.array([[1e-3, 2e-4, 0.0], [0.0, -5e-4, 1e-4], [3e-4, 0.0, 2e-3]])
    bias = np.array([1e-7, -2e-7, 3e-8])
    m = Magnetometer(rate=20.0, errors=errors, bias=bias).sample(traj, field_inertial=field, seed=0)
    exact = attitude.rotate_inverse(traj.q, field)
    np.testing.assert_allclose(m.value, exact @ (np.eye(3) + errors).T + bias, rtol=0, atol=1e-18)
    noisy = Magnetometer(rate=20.0, sigma=1e-7).sample(traj, field_inertial=field, seed=4)
    np.testing.assert_allclose((noisy.value - exact).std(axis=0), 1e-7, rtol=0.05)

    sun = np.array([0.0, 0.6, 0.8])
    normals = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -1.0, 0], [0, 0, 1.0], [0, 0, -1.0]])
    css = CoarseSunSensor(rate=20.0, normals=normals).sample(traj, sun=sun, seed=0)
    s_b = attitude.rotate_inverse(traj.q, sun)
    np.testing.assert_allclose(css.value, np.maximum(s_b @ normals.T, 0.0), atol=1e-15)

    fss = FineSunSensor(rate=20.0, sigma=1e-3, field_of_view=math.radians(45.0)).sample(traj, sun=sun, seed=2)
    inside = s_b[:, 2] >= math.cos(math.radians(45.0))
    np.testing.assert_array_equal(~np.isnan(fss.value[:, 0]), inside)
    err = np.arccos(np.clip(np.sum(fss.value[inside] * s_b[inside], axis=-1), -1, 1))
    np.testing.assert_allclose(np.sqrt(np.mean(err**2)), math.sqrt(2) * 1e-3, rtol=0.1)  # 2 axes across ŝ


def test_measurements_on_filter_times():
    t = np.linspace(0.0, 10.0, 11)
    q = attitude.identity(11)
    m = StarTracker(rate=0.5, sigma_cross=0.0, sigma_about=0.0).sample(t, q, seed=0)
    placed = m.on(t)
    np.testing.assert_array_equal(~np.isnan(placed[:, 0]), np.arange(11) % 2 == 0)
    with pytest.raises(tumble.ValidationError, match=r"times: must contain every measurement time"):
        m.on(t[1:])


@pytest.mark.parametrize(("call", "message"), [
    (lambda tr: StarTracker(rate=40.0, sigma_cross=1e-4, sigma_about=1e-4).sample(tr),
     "rate: must not exceed the truth's output rate 1/Δt = 20 Hz"),
    (lambda tr: StarTracker(rate=1.0, sigma_cross=1e-4, sigma_about=1e-4).sample(tr.t, np.zeros((4001, 4))),
     "q: must be non-zero"),
    (lambda tr: StarTracker(rate=1.0, sigma_cross=1e-4, sigma_about=1e-4, exclusion={"sun": 0.3}).sample(tr),
     "directions: must give the 'sun' direction"),
    (lambda tr: Magnetometer(rate=1.0, sigma=-1.0), "sigma: must be a finite number >= 0"),
])
def test_sensor_bad_input(traj, call, message):
    with pytest.raises(tumble.ValidationError, match=message):
        call(traj)
