"""Strapdown attitude and velocity integration (tumble.ins.strapdown, .coning, .increments)."""

import math
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.ins import (ALGORITHMS, Coning, Increments, drift_law, from_trajectory, measure_drift, read_csv,
                        strapdown, write_csv)
from tumble.ins.coning import CONING_RANGES
from tumble._validate import ValidationError

EXAMPLE_CSV = tumble.examples.directory() / "ins" / "coning_gyro.csv"

# The coning laws are leading-order (small α, small ΩT); the spec is 5 %.
# Measured at α = 0.01 rad inside CONING_RANGES: none 3.3e-5, one-sample 2.9 %,
# two-sample 3.0 %, three-sample 1.7 % (at ΩT = 0.3, from an α⁴ term; see docs/ins.md).
CONING_RTOL = 0.05
# Recovery of a simulated attitude from error-free increments (issue: 1e-9). Measured at
# 1 kHz over 6 s: 4.0e-13 (three-sample), 8.5e-14 (two-sample).
RECOVERY_TOL = 1e-9
# Convergence orders from errors at dt and dt/2: measured 2.00, 3.00, 4.00, 4.00 (attitude)
# and 2.00 / 3.00 (velocity without / with sculling); 0.1 allows for the next-order terms.
ORDER_TOL = 0.1

ALPHA, OMEGA = 0.01, 2.0 * math.pi


@pytest.fixture(scope="module")
def tumbling():
    """Exact torque-free motion (no integration error) of diag(1, 2, 3) on grids for 1 and 2 kHz sampling."""
    body = np.diag([1.0, 2.0, 3.0])

    def make(dt, duration):
        steps = 6 * round(duration / (3 * dt))  # whole three-sample updates on a grid of dt/2
        return tumble.simulate(body, [0.4, 1.0, 0.3], t=0.5 * dt * np.arange(steps + 1), method="exact")

    return make


def _max_error(truth, increments, algorithm):
    nav = strapdown(increments, q0=truth.q[0], algorithm=algorithm)
    stride = 2 * ALGORITHMS[algorithm]
    np.testing.assert_array_equal(nav.attitude.t, truth.t[::stride])
    return attitude.relative_angle(nav.attitude.q, truth.q[::stride]).max()


def test_coning_closed_forms_are_consistent():
    coning = Coning(0.3, 2.0)
    t = np.linspace(0.0, 1.0, 2001)
    # ω = 2 q* ⊗ q̇ by a central difference (error h² |q⃛| ~ 1e-11 at h = 1e-6)
    h = 1e-6
    qdot = (coning.attitude(t + h) - coning.attitude(t - h)) / (2 * h)
    omega = 2.0 * attitude.multiply(attitude.conjugate(coning.attitude(t)), qdot)
    np.testing.assert_allclose(omega[:, 1:], coning.rate(t), atol=1e-8)
    # Exact increments vs Simpson's rule on the exact rate (error (t₁ − t₀) h⁴ |ω⁗| / 180 ~ 1e-16 here)
    simpson = from_trajectory(coning.trajectory(t), oversample=4)
    exact = coning.increments(simpson.dt, len(simpson))
    np.testing.assert_allclose(simpson.delta_theta, exact.delta_theta, rtol=0, atol=1e-14)


@pytest.mark.parametrize("algorithm", list(ALGORITHMS))
def test_coning_drift_follows_its_law(algorithm):
    coning = Coning(ALPHA, OMEGA)
    lo, hi = CONING_RANGES[algorithm]
    for x in np.geomspace(lo, hi, 4):
        T = x / OMEGA
        measured = measure_drift(coning, algorithm, T, updates=400)
        predicted = drift_law(algorithm, ALPHA, OMEGA, T)
        assert measured < 0.0  # the computed attitude turns about −z
        assert abs(-measured / predicted - 1.0) < CONING_RTOL, (x, measured, predicted)


@pytest.mark.parametrize("alpha, rtol", [(0.01, 1e-5), (0.3, 1e-2)])
def test_uncompensated_drift_with_sin2_alpha(alpha, rtol):
    # The uncompensated law ½ α² Ω (1 − sin x/x) is exact in x = ΩT; its α² is the leading term of
    # sin²α (derivation in docs/ins.md). With sin²α the law holds to O(α² x²): measured 3.0e-6
    # (α = 0.01, x ≤ 1) and 7.5e-3 (α = 0.3, x = 2), while α² or 1 − cos α would be off by α²/3
    # or α²/4 (3.3e-5, 2.5e-5 at α = 0.01; 3 %, 2.2 % at α = 0.3). At α = 0.3, x = 2 the error
    # reaches 20 rad over the 400 updates: measure_drift must not wrap it at π.
    coning = Coning(alpha, OMEGA)
    for x in (0.05, 0.3, 1.0, 2.0 if alpha > 0.1 else 1.0):
        T = x / OMEGA
        law = drift_law("none", alpha, OMEGA, T) * (math.sin(alpha) / alpha) ** 2
        assert -measure_drift(coning, "none", T, updates=400) == pytest.approx(law, rel=rtol), x


def test_uncompensated_law_keeps_its_digits_at_high_update_rates():
    # ½ α² Ω (1 − sin x/x) = α² Ω x²/12 (1 − x²/20 + x⁴/840 − …): at x = 1e-6 the closed form would
    # lose 12 digits to cancellation (and return 0 below x ≈ 1e-8)
    for x in (1e-9, 1e-6, 1e-3, 0.5):
        series = ALPHA**2 * OMEGA * x**2 / 12 * (1 - x**2 / 20 + x**4 / 840 - x**6 / 60480)
        assert drift_law("none", ALPHA, OMEGA, x / OMEGA) == pytest.approx(series, rel=2e-9 if x == 0.5 else 1e-15)
    # above the series' range the closed form is used: x = 2 by hand
    assert drift_law("none", ALPHA, OMEGA, 2 / OMEGA) == pytest.approx(
        0.5 * ALPHA**2 * OMEGA * (1 - math.sin(2.0) / 2.0), rel=1e-15)


def test_coning_laws_numbers():
    # α²Ω (ΩT)⁴/960 and α²Ω (ΩT)⁶/204120 at α = 0.01, Ω = 2π, ΩT = 0.5 (by hand)
    assert drift_law("two-sample", ALPHA, OMEGA, 0.5 / OMEGA) == pytest.approx(1e-4 * OMEGA * 0.0625 / 960, rel=1e-14)
    assert drift_law("three-sample", ALPHA, OMEGA, 0.5 / OMEGA) == pytest.approx(
        1e-4 * OMEGA * 0.015625 / 204120, rel=1e-14)
    with pytest.raises(ValidationError, match="algorithm"):
        drift_law("four-sample", ALPHA, OMEGA, 0.1)


@pytest.mark.slow  # the first exact torque-free run compiles the closed-form flow (~10 s of CPU cold)
@pytest.mark.parametrize("algorithm", ["two-sample", "three-sample"])
def test_error_free_increments_recover_a_simulated_attitude(tumbling, algorithm):
    truth = tumbling(1e-3, 6.0)
    assert _max_error(truth, from_trajectory(truth, oversample=2), algorithm) < RECOVERY_TOL


def test_convergence_orders_of_the_attitude_algorithms(tumbling):
    expected = {"none": 2, "one-sample": 3, "two-sample": 4, "three-sample": 4}
    coarse, fine = tumbling(4e-3, 3.0), tumbling(2e-3, 3.0)
    for algorithm, order in expected.items():
        ratio = (_max_error(coarse, from_trajectory(coarse), algorithm)
                 / _max_error(fine, from_trajectory(fine), algorithm))
        assert abs(math.log2(ratio) - order) < ORDER_TOL, (algorithm, math.log2(ratio))


def test_sculling_raises_the_order_of_the_velocity(tumbling):
    # Specific force fixed in inertial space, balancing gravity: the true velocity stays zero.
    g = np.array([0.0, 0.0, -9.80665])
    errors = {}
    for dt in (2e-3, 1e-3):
        truth = tumbling(dt, 3.0)
        increments = from_trajectory(truth, specific_force=-g)
        for sculling in (False, True):
            nav = strapdown(increments, q0=truth.q[0], algorithm="two-sample", g=g, sculling=sculling)
            errors[dt, sculling] = np.abs(nav.velocity).max()
    assert abs(math.log2(errors[2e-3, False] / errors[1e-3, False]) - 2) < ORDER_TOL
    assert abs(math.log2(errors[2e-3, True] / errors[1e-3, True]) - 3) < ORDER_TOL
    assert errors[1e-3, True] < 1e-3 * errors[1e-3, False]  # measured 8.4e-10 vs 1.0e-5


def test_accelerometer_at_a_lever_arm_measures_the_point_velocity(tumbling):
    # No specific force at the centre of mass, no gravity: the sensor point moves with
    # v_p = R(q) (ω × r), which the strapdown velocity must follow (to 2.2e-10 m/s, measured).
    truth = tumbling(1e-3, 3.0)
    r = np.array([0.1, -0.05, 0.2])
    v_point = attitude.rotate(truth.q, np.cross(truth.omega, r))
    increments = from_trajectory(truth, specific_force=[0.0, 0.0, 0.0], lever_arm=r)
    nav = strapdown(increments, q0=truth.q[0], algorithm="two-sample", v0=v_point[0])
    np.testing.assert_allclose(nav.velocity, v_point[::4], rtol=0, atol=1e-9)


def test_navigation_output_is_a_comparable_trajectory():
    coning = Coning(0.05, OMEGA)
    increments = coning.increments(0.01, 30, t0=2.0)
    nav = strapdown(increments, q0=coning.attitude(2.0), algorithm="three-sample")
    traj = nav.attitude
    assert isinstance(traj, tumble.Trajectory) and traj.method == "strapdown"
    np.testing.assert_allclose(traj.t, 2.0 + 0.03 * np.arange(11), rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(traj.q, axis=-1), 1.0, rtol=0, atol=1e-15)
    # omega: the mean rate over the update ending at each time (Δθ / T)
    np.testing.assert_allclose(traj.omega[1], increments.delta_theta[:3].sum(axis=0) / 0.03, rtol=1e-14)
    assert nav.velocity is None


def test_bad_input_is_refused():
    increments = Coning(0.05, OMEGA).increments(0.01, 10)
    with pytest.raises(ValidationError, match="takes 3 samples per update; got 10"):
        strapdown(increments, algorithm="three-sample")
    with pytest.raises(ValidationError, match="algorithm: must be one of"):
        strapdown(increments, algorithm="four-sample")
    with pytest.raises(ValidationError, match="q0"):
        strapdown(increments, q0=[0, 0, 0, 0], algorithm="none")
    with pytest.raises(ValidationError, match="delta_theta"):
        Increments(t0=0.0, dt=0.1, delta_theta=np.zeros((4, 2)))
    with pytest.raises(ValidationError, match="dt"):
        Increments(t0=0.0, dt=-0.1, delta_theta=np.zeros((4, 3)))


def test_csv_round_trip_and_example_file(tmp_path):
    coning = Coning(0.05, OMEGA)
    written = coning.increments(1.0 / 60.0, 120)
    # the example file holds exactly these samples (17 significant digits round-trip float64)
    example = read_csv(EXAMPLE_CSV)
    np.testing.assert_array_equal(example.delta_theta, written.delta_theta)
    assert example.dt == pytest.approx(written.dt, rel=1e-14) and abs(example.t0) < 1e-15
    path = tmp_path / "gyro.csv"
    increments = Increments(t0=0.5, dt=0.01, delta_theta=written.delta_theta[:6],
                            delta_v=2.0 * written.delta_theta[:6])
    write_csv(path, increments)
    back = read_csv(path)
    np.testing.assert_array_equal(back.delta_theta, increments.delta_theta)
    np.testing.assert_array_equal(back.delta_v, increments.delta_v)
    assert back.dt == pytest.approx(0.01, rel=1e-12) and back.t0 == pytest.approx(0.5, rel=1e-12)


def test_csv_rate_columns_are_multiplied_by_dt(tmp_path):
    path = tmp_path / "rates.csv"
    path.write_text("# a rate gyro\nt,omega_x,omega_y,omega_z,f_x,f_y,f_z\n"
                    "0.1,1,2,3,0,0,9.8\n0.2,1,2,3,0,0,9.8\n0.3,-1,0,0.5,0,0,9.8\n")
    increments = read_csv(path)
    np.testing.assert_allclose(increments.delta_theta[2], [-0.1, 0.0, 0.05], rtol=1e-14)
    np.testing.assert_allclose(increments.delta_v[:, 2], 0.98, rtol=1e-14)
    assert increments.t0 == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("text, message", [
    ("t,dtheta_x,dtheta_y,dtheta_z\n0.1,0,0,0\n0.2,0,abc,0\n0.3,0,0,0\n",
     r"line 3, column 3 \('dtheta_y'\): 'abc' is not a number"),
    ("t,dtheta_x,dtheta_y,dtheta_z\n0.1,0,0,0\n0.2,0,0\n0.3,0,0,0\n", "line 3: has 3 columns, the header has 4"),
    ("t,dtheta_x,dtheta_y\n0.1,0,0\n0.2,0,0\n", "missing column"),
    ("t,dtheta_x,dtheta_y,dtheta_z,wx\n", r"column 5: unknown column 'wx'"),
    ("t,dtheta_x,dtheta_y,dtheta_z\n0.1,0,0,0\n0.2,0,0,0\n0.35,0,0,0\n", r"line 4, column 1 \('t'\)"),
    ("t,dtheta_x,dtheta_y,dtheta_z\n0.1,0,0,0\n0.2,0,nan,0\n", "must be finite"),
    ("t,dtheta_x,dtheta_y,dtheta_z,omega_x,omega_y,omega_z\n", "not both"),
])
def test_malformed_csv_names_line_and_column(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValidationError, match=message):
        read_csv(path)


def test_docs_example(capsys, monkeypatch):
    """The CSV example of docs/ins.md runs, and its errors are the coning laws times 2 s (within 5 %)."""
    root = Path(__file__).resolve().parents[2]
    text = (root / "docs" / "ins.md").read_text(encoding="utf-8")
    start = text.index("```python", text.index("**Input from a file.**")) + len("```python")
    monkeypatch.chdir(root)
    exec(compile(text[start:text.index("```", start)], "docs/ins.md", "exec"), {})  # the project's own text
    printed = dict(line.split(" ", 1) for line in capsys.readouterr().out.splitlines())
    alpha = 0.05
    for algorithm, T in (("none", 1 / 60), ("two-sample", 2 / 60)):
        error = float(printed[algorithm].split()[0])
        assert error == pytest.approx(2.0 * drift_law(algorithm, alpha, OMEGA, T), rel=CONING_RTOL)
