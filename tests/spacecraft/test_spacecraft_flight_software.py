"""The flight-software loop: gyro and star tracker through the MEKF, the control law fed the estimate.

Checks, each against theory: a loop fed perfect sensors is the truth-fed controller to round-off; the
knowledge error stays inside the filter's 3σ (a consistent filter: 99.73 % of Gaussian errors); the control
error is the sampled closed loop's linear response to the estimator's errors (so its spectrum is the
estimator's through the loop's transfer functions); a run is reproducible per seed, alone or in a batch;
the part compiles nothing.
"""

import dataclasses

import numpy as np
import pytest
from numba.core import event
from scipy import stats

import tumble
from tumble import ValidationError
from tumble.spacecraft import (ConstantTorque, FlightSoftware, QuaternionPD, ReactionWheel, Sampling, Spacecraft,
                              pyramid_wheels)
from tumble.viz import estimation as demo

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

PERFECT = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=5e-5, delay=0, sensor_noise=False)
#: Measured: 2.2e-16 in q, 4.4e-17 rad/s in ω over 40 s (the estimate equals the truth to round-off).
ROUND_OFF = 1e-13


def _times(duration):
    return np.arange(0.0, duration + 0.5 * demo.PERIOD, demo.PERIOD)


def test_perfect_sensors_give_the_truth_fed_controller():
    t = _times(40.0)
    truth_fed = tumble.simulate(demo.spacecraft(None), [0.01, -0.02, 0.0], t=t, method="rk4", dt=demo.DT)
    loop = tumble.simulate(demo.spacecraft(PERFECT), [0.01, -0.02, 0.0], t=t, method="rk4", dt=demo.DT)
    assert np.abs(loop.q - truth_fed.q).max() <= ROUND_OFF
    assert np.abs(loop.omega - truth_fed.omega).max() <= ROUND_OFF
    np.testing.assert_allclose(loop.wheel_speed, truth_fed.wheel_speed, rtol=0, atol=1e-11)
    assert np.abs(loop.knowledge_error).max() <= ROUND_OFF
    assert np.degrees(np.linalg.norm(loop.control_error[0])) == pytest.approx(30.0, abs=1e-9)  # the slew's angle


@pytest.fixture(scope="module")
def monte_carlo():
    """30 runs of the demo's slew and fine pointing, 300 s: own seeds, gyro biases, initial estimate errors."""
    return demo.monte_carlo(30, duration=300.0, seed=1)


def test_knowledge_error_stays_inside_three_sigma(monte_carlo):
    """A consistent filter's error is N(0, P): 99.73 % of it lies within ±3σ per axis; measured 99.71 % of
    30 runs × 601 samples × 3 axes. The bias estimate converges inside its own 3σ too."""
    inside = np.abs(monte_carlo.knowledge_error) <= monte_carlo.knowledge_error_3sigma
    assert inside.mean() >= 0.99
    bias_error = monte_carlo.bias_estimate[-1] - monte_carlo.gyro_bias[-1]
    assert (np.abs(bias_error) <= monte_carlo.bias_error_3sigma[-1]).mean() >= 0.95


def test_control_error_is_the_loops_response_to_the_estimators_errors(monte_carlo):
    """In fine pointing the closed loop is linear (:func:`~tumble.viz.estimation.loop_response`):
    driven from t = 100 s by the recorded knowledge error and rate error ω̂ − ω, its response reproduces the
    simulated control error: measured relative RMS difference 3.2e-5 (the neglected terms are second order).
    The control error is thus the estimator's errors through the loop, and its spectrum theirs shaped by the
    loop's transfer functions. With the delay or the gains wrong the recursion would miss by order one."""
    traj = monte_carlo
    assert np.all(traj.torque_command[0] == 0.0)  # a one-period delay: nothing acts before the first command
    start = int(round(100.0 / demo.PERIOD))
    predicted = demo.loop_response(traj, start, traj.knowledge_error, traj.omega_estimate - traj.omega)
    simulated = traj.control_error[start:]
    rms = np.sqrt(np.mean(simulated**2))
    assert np.sqrt(np.mean((predicted - simulated) ** 2)) <= 1e-3 * rms
    assert rms > 0.5 * np.sqrt(np.mean(traj.knowledge_error[start:] ** 2))  # the estimator's error reaches the truth


def _inside(craft):
    traj = demo.monte_carlo(30, duration=300.0, seed=1, craft=craft)
    return traj, (np.abs(traj.knowledge_error) <= traj.knowledge_error_3sigma).mean()


def test_a_sun_sensor_and_a_magnetometer_replace_the_star_tracker():
    """Two direction sensors (a 1e-3 rad fine Sun sensor, a 3e-3 rad magnetometer in a uniform field) make the
    attitude observable: the filter stays consistent, ≥ 99 % inside 3σ (measured 99.58 %), at the accuracy
    of the directions (fine-pointing RMS error between σ_sun/10 and σ_mag; measured 2.2e-4 rad)."""
    fsw = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, sun_sensor_sigma=1e-3, sun_direction=[1.0, 0.5, 0.2],
                         magnetometer_sigma=3e-3, attitude_sigma0=1e-2, bias_sigma0=1e-5)
    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02, max_torque=0.2),
                       controller=QuaternionPD(0.2, target=demo.TARGET, max_rate=np.radians(1.0)),
                       control_period=demo.PERIOD, flight_software=fsw, magnetic_field=[2e-5, -1e-5, 3e-5])
    traj, inside = _inside(craft)
    assert inside >= 0.99
    rms = np.sqrt(np.mean(traj.knowledge_error[200:] ** 2))
    assert 1e-4 <= rms <= 3e-3


def test_a_slower_star_tracker_widens_the_bounds_between_its_samples():
    """A star tracker at 0.2 Hz (every 10th sample): the 3σ bound grows while the gyro alone propagates and
    drops at each star-tracker sample; the filter stays consistent (≥ 99 % inside; measured 99.89 %)."""
    fsw = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=np.radians(10.0 / 3600.0),
                         star_tracker_sampling=Sampling(period=10 * demo.PERIOD), attitude_sigma0=1e-3,
                         bias_sigma0=1e-5)
    traj, inside = _inside(demo.spacecraft(fsw))
    assert inside >= 0.99
    bound = traj.knowledge_error_3sigma[:, 0]
    updates = np.arange(10, traj.t.size - 1, 10)
    assert np.all(bound[updates] < bound[updates - 1])
    assert np.all(bound[updates + 1] > bound[updates])


def test_a_run_is_reproducible_per_seed(monte_carlo):
    """Run 7 alone (its seed, bias and initial estimate) equals run 7 of the batch, bit for bit; another seed
    gives other noise."""
    i = 7
    initial = {name: value[i] for name, value in demo.dispersions(demo.FSW, 30, seed=1).items()}
    alone = tumble.simulate(demo.spacecraft(), np.zeros(3), t=monte_carlo.t, method="rk4", dt=demo.DT, **initial)
    np.testing.assert_array_equal(alone.q, monte_carlo.q[:, i])
    np.testing.assert_array_equal(alone.knowledge_error, monte_carlo.knowledge_error[:, i])
    other = tumble.simulate(demo.spacecraft(), np.zeros(3), t=monte_carlo.t[:50], method="rk4", dt=demo.DT,
                            **(initial | {"sensor_seed0": initial["sensor_seed0"] + 1000.0}))
    assert np.all(other.knowledge_error[:, 0] != alone.knowledge_error[:50, 0])


def test_the_part_compiles_nothing():
    t = _times(2.0)
    tumble.simulate(demo.spacecraft(None), [0.01, -0.02, 0.03], t=t, method="rk4", dt=demo.DT)
    with event.install_recorder("numba:compile") as compiles:
        traj = tumble.simulate(demo.spacecraft(), [0.01, -0.02, 0.03], t=t, method="rk4", dt=demo.DT)
    assert [e.data["dispatcher"].py_func.__qualname__ for e in compiles.buffer if e.is_start] == []
    assert np.abs(traj.knowledge_error).max() > 0.0  # the flight software ran


@pytest.mark.parametrize(("change", "message"), [
    (dict(control_period=None), r"^flight_software: needs a control_period"),
    (dict(controller=None), r"^flight_software: needs a torque law"),
    (dict(flight_software=FlightSoftware(1e-5, 1e-8, magnetometer_sigma=1e-3)),
     r"^flight_software: a magnetometer needs a magnetic_field"),
    (dict(flight_software=FlightSoftware(1e-5, 1e-8, coarse_sun_sensor_sigma=1e-2)),
     r"^flight_software: a Sun sensor needs the Sun: a sun_direction or an environment"),
])
def test_a_loop_without_its_period_or_law_is_refused(change, message):
    arguments = dict(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02),
                     controller=QuaternionPD(0.2), control_period=0.5, flight_software=PERFECT) | change
    with pytest.raises(ValidationError, match=message):
        Spacecraft(**arguments)


@pytest.mark.parametrize(("change", "message"), [
    (dict(delay=2), r"^delay: must be a number in \[0, 1\] \(control periods\)"),
    (dict(delay=True), r"^delay: must be a number in \[0, 1\]"),
    (dict(star_tracker_sigma=[1e-5, 0.0, 1e-5]), r"^star_tracker_sigma: must be a number or 3 numbers > 0"),
    (dict(gyro_arw=-1.0), r"^gyro_arw: "),
    (dict(seed=0.5), r"^seed: must be whole numbers in \[0, 2\*\*53\)"),
    (dict(star_tracker_sampling=Sampling(0.5, stream=0)), r"^stream: each sensor needs its own noise stream"),
    (dict(gyro_sampling=0.1), r"^gyro_sampling: must be a Sampling"),
    (dict(sun_direction=[1.0, 0.0, 0.0]), r"^sun_direction: give it with a Sun sensor"),
    (dict(coarse_sun_sensor_sigma=0.0), r"^coarse_sun_sensor_sigma: "),
    (dict(sun_sensor_sigma=1e-3, sun_direction=[0.0, 0.0, 0.0]), r"^sun_direction: must be 3 numbers, not all"),
    (dict(star_tracker_sigma=None), r"^star_tracker_sigma: the filter needs an attitude sensor"),
])
def test_bad_flight_software_is_refused(change, message):
    arguments = dict(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=5e-5) | change
    with pytest.raises(ValidationError, match=message):
        FlightSoftware(**arguments)


def test_a_bad_seed_is_refused():
    with pytest.raises(ValidationError, match=r"^sensor_seed0: must be whole numbers"):
        tumble.simulate(demo.spacecraft(), np.zeros(3), t=_times(1.0), method="rk4", dt=demo.DT, sensor_seed0=-1.0)


def test_scenario_table_runs_the_loop():
    """``[spacecraft.flight_software]`` and the ``[initial]`` keys of its state give the run of the library."""
    from tumble.scenario import parse_scenario

    scenario = parse_scenario("""
[spacecraft]
moments = [10.0, 12.0, 8.0]
wheel_pyramid = {inertia = 0.02}
control_period = 0.5
flight_software = {gyro_arw = 1e-5, gyro_rrw = 1e-8, star_tracker_sigma = [5e-5, 5e-5, 1e-4], seed = 3}
[[spacecraft.controller]]
kind = "quaternion_pd"
natural_frequency = 0.2
[initial]
omega = [0.0, 0.0, 0.0]
gyro_bias = [1e-5, 0.0, -1e-5]
[time]
stop = 5.0
step = 0.5
[solver]
dt = 0.1
""")
    traj = scenario.run()
    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02), controller=QuaternionPD(0.2),
                       control_period=0.5, flight_software=FlightSoftware(1e-5, 1e-8, [5e-5, 5e-5, 1e-4], seed=3))
    expected = tumble.simulate(craft, np.zeros(3), t=traj.t, method="rk4", dt=0.1, gyro_bias0=[1e-5, 0.0, -1e-5])
    np.testing.assert_array_equal(traj.knowledge_error, expected.knowledge_error)
    np.testing.assert_array_equal(traj.gyro_bias[0], [1e-5, 0.0, -1e-5])


def test_demo_estimation_writes_its_figures_and_prints_its_numbers(tmp_path):
    """``tumble demo estimation``: 40 runs, ≥ 99 % of the knowledge errors inside 3σ (measured 99.71 %), and
    in fine pointing the control error's RMS between 1 and 3 times the knowledge error's (measured 1.8e-5 and
    2.9e-5 rad: the truth follows the estimate, plus the rate noise through the rate feedback)."""
    from typer.testing import CliRunner

    from tumble.cli import app

    result = CliRunner().invoke(app, ["demo", "estimation", "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    summary = demo.demo_estimation(tmp_path)  # the same computation, called directly
    assert f"{summary['inside_3sigma']:.2%} of the knowledge errors of 40 runs" in result.stdout
    assert summary["inside_3sigma"] >= 0.99
    assert 1.0 <= summary["control_rms_rad"] / summary["knowledge_rms_rad"] <= 3.0
    for name in ("estimation_loop.png", "estimation_spectra.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


#: The demo's loop with a 20 Hz gyro and a 2 Hz star tracker whose reading is out 0.15 s after its time;
#: the flight software at 2 Hz, integrated in steps of 0.05 s.
FAST_GYRO = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=np.radians(10.0 / 3600.0),
                           gyro_sampling=Sampling(period=0.05, latency=0.02),
                           star_tracker_sampling=Sampling(period=0.5, latency=0.15),
                           attitude_sigma0=1e-3, bias_sigma0=1e-5)
FAST_DT = 0.05


def _fast_gyro_runs(runs, duration, fsw=FAST_GYRO, seed=1):
    initial = demo.dispersions(fsw, runs, seed=seed)
    return tumble.simulate(demo.spacecraft(fsw), np.zeros((runs, 3)), t=_times(duration), method="rk4",
                           dt=FAST_DT, **initial)


@pytest.fixture(scope="module")
def fast_gyro():
    """40 runs of 200 s of the demo's slew with :data:`FAST_GYRO`."""
    return _fast_gyro_runs(40, 200.0)


def test_each_sensor_reads_on_its_own_clock(fast_gyro):
    """The newest reading the flight software used at ``t_k`` is the sensor's newest out by then: taken at
    ``m·period`` (from t₀ = 0) with ``m·period + latency ≤ t_k``, exactly (the same floating-point value)."""
    t = fast_gyro.t
    for sensor, sampling in ((0, FAST_GYRO.gyro_sampling), (1, FAST_GYRO.star_tracker_sampling)):
        m = np.floor((t - sampling.latency) / sampling.period + 1e-9)
        expected = np.where(m >= 0, 0.0 + m * sampling.period, np.nan)
        np.testing.assert_array_equal(fast_gyro.sensor_time[:, 3, sensor], expected)
    assert np.isnan(fast_gyro.sensor_time[:, :, 2:]).all()  # no Sun sensor, no magnetometer


def test_a_2_hz_star_tracker_and_a_20_hz_gyro_keep_the_filter_consistent(fast_gyro):
    """NEES of the attitude, ε_k = δθᵀ P_θθ⁻¹ δθ, averaged over the 40 runs: a consistent filter's lies in the
    two-sided 95 % interval of χ²(3·40)/40 at 95 % of the samples (Bar-Shalom, Li & Kirubarajan 2001, §5.4);
    asked ≥ 90 % (measured 94.3 %) and its mean over the run within 10 % of 3 (measured 3.02)."""
    error = fast_gyro.knowledge_error[1:]
    P = fast_gyro.covariance[1:, :, :3, :3]
    nees = np.einsum("kri,kri->kr", error, np.linalg.solve(P, error[..., None])[..., 0]).mean(axis=1)
    low, high = stats.chi2.ppf([0.025, 0.975], 3 * 40) / 40
    inside = np.mean((nees >= low) & (nees <= high))
    assert inside >= 0.90, inside
    assert abs(nees.mean() - 3.0) <= 0.3, nees.mean()


def test_a_sensors_noise_is_its_own():
    """Changing the star tracker's rate or stream leaves the gyro's noise (its true bias walk, drawn from
    the gyro's stream) unchanged bit for bit; changing the gyro's stream changes it."""
    base = _fast_gyro_runs(2, 10.0)
    slower = _fast_gyro_runs(2, 10.0, fsw=dataclasses.replace(
        FAST_GYRO, star_tracker_sampling=Sampling(period=1.0, latency=0.15, stream=7)))
    np.testing.assert_array_equal(slower.gyro_bias, base.gyro_bias)
    assert np.any(slower.knowledge_error != base.knowledge_error)
    other = _fast_gyro_runs(2, 10.0, fsw=dataclasses.replace(
        FAST_GYRO, gyro_sampling=Sampling(period=0.05, latency=0.02, stream=9)))
    assert np.all(other.gyro_bias[-1] != base.gyro_bias[-1])


def test_a_direction_sensor_off_the_gyros_clock_is_refused():
    """The star tracker at the control period 0.5 s, the gyro at 0.2 s: its readings would fall between the
    gyro's."""
    with pytest.raises(ValidationError, match=r"^star_tracker_sampling: the period 0.5 s must be a whole number "
                                              r"of the gyro's period 0.2 s"):
        demo.spacecraft(dataclasses.replace(PERFECT, gyro_sampling=Sampling(period=0.2)))


@pytest.mark.parametrize(("sampling", "message"), [
    (dict(period=0.5, latency=0.5), r"^latency: must be shorter than the period 0.5 s"),
    (dict(period=0.0), r"^period: "),
    (dict(latency=-1.0), r"^latency: "),
    (dict(stream=-1), r"^stream: must be whole numbers"),
])
def test_bad_sampling_is_refused(sampling, message):
    with pytest.raises(ValidationError, match=message):
        Sampling(**sampling)


def test_a_step_that_misses_a_sensors_clock_is_refused():
    craft = demo.spacecraft(dataclasses.replace(PERFECT, gyro_sampling=Sampling(period=0.25)))
    with pytest.raises(ValidationError, match=r"^dt: must divide the gyro's period 0.25 s into whole steps"):
        tumble.simulate(craft, np.zeros(3), t=_times(1.0), method="rk4", dt=0.1)


def test_a_sweep_over_noise_seeds_and_gyro_biases_is_the_runs_it_stands_for():
    """``tumble.sweep`` with an integer seed dispersion (:class:`~tumble.sweeps.NoiseSeed`) and a vector bias
    dispersion (:class:`~tumble.sweeps.Normal` of shape (3,)): each of its 8 samples equals the direct
    :func:`tumble.simulate` of the seed and bias it drew, bit for bit."""
    from tumble.sweeps import NoiseSeed, Normal

    t = _times(20.0)
    ds = tumble.sweep(demo.spacecraft(), {"sensor_seed0": NoiseSeed(), "gyro_bias0": Normal(np.zeros(3), 1e-5)},
                      samples=8, seed=5, t=t, method="rk4", dt=demo.DT, workers=0, trajectories=True,
                      chunk=3, omega0=np.zeros(3))
    seeds, biases = ds["sensor_seed0"].values, ds["gyro_bias0"].values
    assert len(set(seeds.tolist())) == 8 and seeds.dtype.kind in "iu"
    for i in range(8):
        alone = tumble.simulate(demo.spacecraft(), np.zeros(3), t=t, method="rk4", dt=demo.DT,
                                sensor_seed0=float(seeds[i]), gyro_bias0=biases[i])
        np.testing.assert_array_equal(ds["q"].values[i], alone.q)
        np.testing.assert_array_equal(ds["knowledge_error"].values[i], alone.knowledge_error)
        np.testing.assert_array_equal(ds["gyro_bias"].values[i], alone.gyro_bias)


@pytest.mark.parametrize("delay", [0.37, 0.5, 1.0])
def test_a_fractional_computation_delay_switches_the_torque_exactly_then(delay):
    """A constant torque command ``u`` about the principal axis z, computed at t = 0 and acting from the
    computation delay ``δ = delay·T`` on (T = 0.5 s; δ = 0.185 s is no whole number of the 0.1 s steps, so
    the steps end at ``k T + δ``): ω_z(t) = u (t − δ)₊ / J_ω,zz exactly (RK4 integrates a linear rate without
    error; a step straddling δ would miss by up to u·dt/J), ω_x = ω_y = 0, and the command acts from δ."""
    u, period = 0.01, 0.5
    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=[ReactionWheel(axis=[0.0, 0.0, 1.0], inertia=0.02)],
                       controller=ConstantTorque([0.0, 0.0, u]), control_period=period,
                       flight_software=dataclasses.replace(PERFECT, delay=delay))
    t = np.arange(0.0, 5.05, 0.1)
    traj = tumble.simulate(craft, np.zeros(3), t=t, method="rk4", dt=0.1)
    lag = delay * period
    expected = u * np.maximum(t - lag, 0.0) / craft.rate_inertia[2, 2]
    np.testing.assert_allclose(traj.omega[:, 2], expected, rtol=0, atol=1e-15)
    assert np.all(traj.omega[:, :2] == 0.0)
    np.testing.assert_array_equal(traj.torque_command[:, 2], np.where(t >= lag - 1e-12, u, 0.0))


def test_coarse_sun_sensors_and_a_magnetometer_keep_the_filter_consistent():
    """Six cosine heads of σ = 0.01 (full scale 1) on the body's faces give the Sun vector ``I₊ − I₋`` of noise
    √2 σ per axis, the MEKF's direction model of σ = √2 σ / |v|; with a 3e-3 rad magnetometer the filter stays
    consistent (≥ 99 % inside 3σ; measured 99.89 %, fine-pointing RMS error 6.3e-4 rad)."""
    fsw = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, coarse_sun_sensor_sigma=0.01, sun_direction=[1.0, 0.5, 0.2],
                         magnetometer_sigma=3e-3, attitude_sigma0=1e-2, bias_sigma0=1e-5)
    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02, max_torque=0.2),
                       controller=QuaternionPD(0.2, target=demo.TARGET, max_rate=np.radians(1.0)),
                       control_period=demo.PERIOD, flight_software=fsw, magnetic_field=[2e-5, -1e-5, 3e-5])
    _, inside = _inside(craft)
    assert inside >= 0.99, inside


def test_no_sun_no_coarse_sun_sensor_reading():
    """Along one equatorial orbit at the equinox (cylindrical shadow, the environment table's Sun), the coarse
    Sun sensor (every 5 s) gives a reading only while at least half the Sun is seen: the newest one the flight
    software used at each output time is the last 5 s sample time whose shadow fraction, interpolated in the
    table here with ``numpy.interp``, is ≥ 0.5; the eclipse holds it back for about a third of the orbit."""
    from datetime import datetime, timezone

    from tumble.spacecraft import Environment, Orbit

    orbit = Orbit.circular(500e3, 0.0)
    env = Environment.sample(orbit, datetime(2026, 3, 20, 12, 0, tzinfo=timezone.utc), duration=orbit.period,
                             step=10.0, shadow="cylindrical")
    fsw = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=5e-5, coarse_sun_sensor_sigma=0.01,
                         coarse_sun_sensor_sampling=Sampling(period=5.0), sensor_noise=False, delay=0)
    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02), controller=QuaternionPD(0.2),
                       control_period=1.0, flight_software=fsw, environment=env)
    t = np.arange(0.0, env.t[-1] - 10.0, 10.0)
    traj = tumble.simulate(craft, np.zeros(3), t=t, method="rk4", dt=0.5)
    samples = np.arange(0.0, t[-1] + 2.5, 5.0)
    lit = samples[np.interp(samples, env.t, env.shadow) >= 0.5]
    last = np.searchsorted(lit, t, side="right") - 1
    np.testing.assert_array_equal(traj.sensor_time[:, 4], np.where(last >= 0, lit[np.maximum(last, 0)], np.nan))
    held = traj.sensor_time[:, 4] < t - 5.0
    assert 0.25 <= held.mean() <= 0.45
