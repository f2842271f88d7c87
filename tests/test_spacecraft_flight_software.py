"""The flight-software loop: gyro and star tracker through the MEKF, the control law fed the estimate.

Checks, each against theory: a loop fed perfect sensors is the truth-fed controller to round-off; the
knowledge error stays inside the filter's 3σ (a consistent filter: 99.73 % of Gaussian errors); the control
error is the sampled closed loop's linear response to the estimator's errors (so its spectrum is the
estimator's through the loop's transfer functions); a run is reproducible per seed, alone or in a batch;
the part compiles nothing.
"""

import numpy as np
import pytest
from numba.core import event

import tumble
from tumble import ValidationError
from tumble.spacecraft import FlightSoftware, QuaternionPD, Spacecraft, pyramid_wheels
from tumble.spacecraft import estimation_demo as demo

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
    """A consistent filter's error is N(0, P): 99.73 % of it lies within ±3σ per axis; measured 99.76 % of
    30 runs × 601 samples × 3 axes. The bias estimate converges inside its own 3σ too."""
    inside = np.abs(monte_carlo.knowledge_error) <= monte_carlo.knowledge_error_3sigma
    assert inside.mean() >= 0.99
    bias_error = monte_carlo.bias_estimate[-1] - monte_carlo.gyro_bias[-1]
    assert (np.abs(bias_error) <= monte_carlo.bias_error_3sigma[-1]).mean() >= 0.95


def test_control_error_is_the_loops_response_to_the_estimators_errors(monte_carlo):
    """In fine pointing the closed loop is linear (:func:`~tumble.spacecraft.estimation_demo.loop_response`):
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
    attitude observable: the filter stays consistent, ≥ 99 % inside 3σ (measured 99.83 %), at the accuracy
    of the directions (fine-pointing RMS error between σ_sun/10 and σ_mag; measured 2.3e-4 rad)."""
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
    """A star tracker every 10th sample (0.2 Hz): the 3σ bound grows while the gyro alone propagates and drops
    at each star-tracker sample; the filter stays consistent (≥ 99 % inside; measured 99.76 %)."""
    fsw = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=np.radians(10.0 / 3600.0),
                         star_tracker_every=10, attitude_sigma0=1e-3, bias_sigma0=1e-5)
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
])
def test_a_loop_without_its_period_or_law_is_refused(change, message):
    arguments = dict(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02),
                     controller=QuaternionPD(0.2), control_period=0.5, flight_software=PERFECT) | change
    with pytest.raises(ValidationError, match=message):
        Spacecraft(**arguments)


@pytest.mark.parametrize(("change", "message"), [
    (dict(delay=2), r"^delay: must be 0 or 1 control period"),
    (dict(star_tracker_sigma=[1e-5, 0.0, 1e-5]), r"^star_tracker_sigma: must be a number or 3 numbers > 0"),
    (dict(gyro_arw=-1.0), r"^gyro_arw: "),
    (dict(seed=0.5), r"^seed: must be whole numbers in \[0, 2\*\*53\)"),
    (dict(star_tracker_every=0), r"^star_tracker_every: must be a whole number ≥ 1"),
    (dict(sun_sensor_sigma=1e-3), r"^sun_direction: give it with sun_sensor_sigma"),
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
    """``tumble demo estimation``: 40 runs, ≥ 99 % of the knowledge errors inside 3σ (measured 99.74 %), and
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
