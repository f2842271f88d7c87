"""tumble's Madgwick, Mahony and EKF side by side with the `ahrs` package's filters of the same name, on IMU and
magnetometer data tumble generated from a tumbling body (accuracy against tumble's exact truth)."""

import numpy as np
import pytest
from ahrs_peer import run_peer

import tumble
from tumble import attitude
from tumble.estimation import ahrs_ekf, madgwick, mahony
from tumble.estimation.sensors import Magnetometer
from tumble.ins import Imu, SensorErrors

# The estimation kernels (parallel over the Monte-Carlo runs) take tens of CPU s to compile on a cold Numba cache.
pytestmark = pytest.mark.slow

pytest.importorskip("ahrs")

DT = 0.01                      # s, 100 Hz
G = 9.80665                    # m/s², the specific force of a body held at rest points up (+z_L)
INCLINATION = np.radians(60.0)
FIELD_L = 5e-5 * np.array([np.cos(INCLINATION), 0.0, -np.sin(INCLINATION)])  # T, north–west–up


def imu_data(duration: float = 30.0, seed: int = 1):
    """A body tumbling at ~1 rad/s, held at its centre of mass: exact truth and noisy gyro, accelerometer and
    magnetometer samples in the filters' convention (sample k: the rate over (t_{k−1}, t_k], readings at t_k)."""
    body = tumble.RigidBody(inertia=np.diag([1.0, 2.0, 3.0]))
    grid = np.linspace(0.0, duration, int(round(duration / DT)) * 2 + 1)
    traj = tumble.simulate(body, omega0=[0.4, 1.0, -0.3], q0=attitude.normalize([1.0, 0.3, 0.2, -0.4]), t=grid,
                           rtol=1e-12, atol=1e-12)
    imu = Imu(gyro=SensorErrors(bias=[0.01, -0.02, 0.015], white_noise=2e-3),
              accel=SensorErrors(white_noise=0.02))
    inc = imu.sample(traj, oversample=2, specific_force=[0.0, 0.0, G], seed=seed)
    mag = Magnetometer(rate=1.0 / DT, sigma=2e-7).sample(traj, field_inertial=FIELD_L, seed=seed + 1).value
    rate = np.concatenate([inc.rate[:1], inc.rate])
    accel = np.concatenate([inc.delta_v[:1], inc.delta_v]) / DT
    return traj.q[::2], rate, accel, mag


FILTERS = {
    "madgwick": (madgwick, {"gain": 0.041}),
    "mahony": (mahony, {"k_p": 1.0, "k_i": 0.3}),
    "ekf": (ahrs_ekf, {"inclination": INCLINATION}),
}
#: Largest angle (rad) between tumble's and the peer's estimates: the same arithmetic for Madgwick and Mahony;
#: tumble's EKF normalises the predicted quaternion before the update, the peer's does not (6e-7 rad here).
AGREEMENT = {"madgwick": 1e-12, "mahony": 1e-12, "ekf": 1e-5}


@pytest.fixture(scope="module")
def data():
    return imu_data()


@pytest.mark.parametrize("name", FILTERS)
def test_ahrs_filter_matches_the_peer_and_is_no_less_accurate(data, name):
    q_true, rate, accel, mag = data
    ours_fn, options = FILTERS[name]
    q0 = q_true[0]
    ours = ours_fn(rate, accel, mag, DT, q0=q0, **options)
    peer = run_peer(name, rate, accel, mag, DT, q0, **options)
    settled = slice(500, None)  # after 5 s
    err_ours = attitude.relative_angle(ours[settled], q_true[settled])
    err_peer = attitude.relative_angle(peer[settled], q_true[settled])
    rms_ours, rms_peer = np.sqrt(np.mean(err_ours**2)), np.sqrt(np.mean(err_peer**2))
    assert rms_ours <= rms_peer * (1.0 + 1e-6)
    assert attitude.relative_angle(ours, peer).max() < AGREEMENT[name]  # the same filter, in tumble's frame
    assert rms_ours < np.radians(3.0)


def test_ahrs_filters_batched_runs_equal_single_runs(data):
    q_true, rate, accel, mag = data
    batch = np.stack([rate, rate + 1e-3])
    for fn, options in FILTERS.values():
        both = fn(batch, np.stack([accel, accel]), np.stack([mag, mag]), DT, q0=q_true[0], **options)
        np.testing.assert_array_equal(both[0], fn(rate, accel, mag, DT, q0=q_true[0], **options))
        assert not np.array_equal(both[0], both[1])


@pytest.mark.parametrize(("call", "message"), [
    (lambda d: madgwick(d[1], d[2][:-1], d[3], DT, q0=d[0][0]), "accel: must have the shape of rate"),
    (lambda d: mahony(d[1], d[2], np.zeros_like(d[3]), DT, q0=d[0][0]), "mag: every sample must be non-zero"),
    (lambda d: ahrs_ekf(d[1], d[2], d[3], DT, q0=[0, 0, 0, 0], inclination=1.0), "q0: must be non-zero"),
    (lambda d: ahrs_ekf(d[1], d[2], d[3], DT, q0=d[0][0], inclination=1.0, P0=-np.eye(4)),
     "P0: must be positive definite"),
    (lambda d: madgwick(d[1], d[2], d[3], 0.0, q0=d[0][0]), "dt: must be a finite number > 0"),
])
def test_ahrs_bad_input(data, call, message):
    with pytest.raises(tumble.ValidationError, match=message):
        call(data)
