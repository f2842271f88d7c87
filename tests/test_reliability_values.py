"""Reliability, round 3 (issue 34): no silent value, and a clean error naming the field instead of a bare one.

Each test holds one point of the issue: it failed on the code before the fix (a silent wrong value, a bare
``ZeroDivisionError``, a message naming the wrong thing) and passes after. Every run is a torque-free
``RigidBody`` with ``dop853``, ``rk4`` or ``exact``: the compiled specializations the rest of the suite builds.
"""

import math
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import tumble
from tumble import SolverError, ValidationError, attitude
from tumble._vec import norm
from tumble.analytic import goryachev_chaplygin_invariant, vertical_momentum
from tumble.cli import app
from tumble.scenario import Time
from tumble.torques import Gravity

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
OMEGA0 = np.array([0.1, 1.0, 0.1])
HUGE_Q = [1e308, 1e308, 1e308, 1e308]  # |q| = 2e308: past the float64 maximum, q/|q| = [1/2, 1/2, 1/2, 1/2]


# -- 1. norms that overflow ---------------------------------------------------------------------------


def test_a_quaternion_whose_norm_overflows_normalises_to_its_rotation():
    # before: |q| = inf, q/|q| = 0, to_matrix the identity (a silent wrong rotation)
    assert attitude.normalize(HUGE_Q).tolist() == [0.5, 0.5, 0.5, 0.5]
    # R of [1, 1, 1, 1]/2: the turn of 2π/3 about (1, 1, 1) that takes x → y → z → x
    assert attitude.to_matrix(HUGE_Q).tolist() == [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    assert attitude.rotate(HUGE_Q, [1.0, 0.0, 0.0]).tolist() == [0.0, 1.0, 0.0]
    assert attitude.to_euler(HUGE_Q, "xyz").tolist() == attitude.to_euler([0.5] * 4, "xyz").tolist()
    # and squares that underflow: 1e-320 is subnormal, its square 0
    assert attitude.normalize([1e-320, 0.0, 0.0, 1e-320]) == pytest.approx([2**-0.5, 0.0, 0.0, 2**-0.5], rel=1e-15)


def test_an_initial_quaternion_whose_norm_overflows_is_the_rotation_it_means():
    # before: normalised to zeros, then "simulation diverged ... reduce dt" (the wrong field)
    with pytest.warns(attitude.NonUnitQuaternionWarning):
        traj = tumble.simulate(BODY, OMEGA0, q0=HUGE_Q, t=[0.0, 0.5], method="rk4", dt=0.5)
    assert traj.q[0].tolist() == [0.5, 0.5, 0.5, 0.5]


def test_the_scaled_norm_is_exact_where_the_squares_overflow_or_underflow():
    assert norm([3e300, 4e300]) == 5e300  # np.linalg.norm: inf
    assert norm([3e-200, 4e-200]) == pytest.approx(5e-200, rel=1e-15)  # np.linalg.norm: 0
    assert norm([[1.5e308, 1.5e308], [0.0, 0.0]]).tolist() == [math.inf, 0.0]  # |v| = 2.1e308 > max: inf
    assert norm([3.0, 4.0]) == 5.0


# -- 2. Euler angles past 1e16 rad --------------------------------------------------------------------


@pytest.mark.parametrize("angles, degrees, found", [
    ([1e300, 0.0, 0.0], True, "1.75e+298"),  # before: [nan nan nan nan]
    ([0.0, 1e17, 0.0], False, "1e+17"),      # before: a rotation, where float64 angles are 16 rad apart
])
def test_from_euler_refuses_angles_past_1e16_rad_as_from_rotvec_does(angles, degrees, found):
    with pytest.raises(ValidationError, match=rf"^angles: Euler angle = {re.escape(found)} rad at index \d is past 1e\+16 "):
        attitude.from_euler("xyz", angles, degrees=degrees)
    with pytest.raises(ValidationError, match=r"^r: rotation angle \|r\| = .* is past 1e\+16 rad"):
        attitude.from_rotvec(np.deg2rad(angles) if degrees else angles)
    # below the bound the two agree: the same half-angle formula
    assert attitude.from_euler("xyz", [1e15, 0.0, 0.0]).tolist() == attitude.from_rotvec([1e15, 0.0, 0.0]).tolist()


# -- 3. arithmetic that overflowed into a bare ZeroDivisionError --------------------------------------


@pytest.mark.parametrize("atol", [1e-170, 1e-300])
def test_dop853_with_an_atol_far_below_1e_160_gives_the_motion(atol):
    # before: ZeroDivisionError (the start step's ‖f/atol‖² overflowed, so h0 = 0, then 1/h0)
    traj = tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0], atol=atol)
    exact = tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0], method="exact")
    assert np.abs(traj.omega - exact.omega).max() < 1e-9  # rtol = 1e-10 (default) on |ω| ≈ 1
    assert np.abs(traj.q - exact.q).max() < 1e-9


def test_dop853_at_rates_of_1e75_gives_the_motion_or_the_steps_it_would_need():
    omega0 = [1e75, 1e74, 0.0]
    # before: ZeroDivisionError for both (‖f/scale‖² of the zero component overflowed)
    t = [0.0, 1e-73, 2e-73]  # about 20 rad of turn
    traj = tumble.simulate(BODY, omega0, t=t)
    exact = tumble.simulate(BODY, omega0, t=t, method="exact")
    assert np.abs(traj.omega - exact.omega).max() / 1e75 < 1e-9  # measured 3e-11
    assert np.abs(traj.q - exact.q).max() < 1e-8  # measured 2e-10
    with pytest.raises(SolverError, match=r"^max_steps: the run would need 2.3e\+75 steps or more to t=1 \(projected "
                                          r"from its first 1000"):
        tumble.simulate(BODY, omega0, t=[0.0, 1.0])


@pytest.mark.parametrize("scale", [1e-200, 1e-300, 1e140])
def test_the_exact_motion_does_not_depend_on_the_size_of_the_inertia(scale):
    # Euler's equations are homogeneous in I: the motion of c·I is that of I. Before: "diverged at t = 0 s:
    # reduce dt" (L² = Σ Iᵢ²ωᵢ² underflowed to 0 or overflowed to inf)
    t = np.linspace(0.0, 10.0, 5)
    unit = tumble.simulate(BODY, OMEGA0, t=t, method="exact")
    scaled = tumble.simulate(tumble.RigidBody(BODY.inertia * scale), OMEGA0, t=t, method="exact")
    assert np.abs(scaled.omega - unit.omega).max() < 1e-14  # measured 9e-16 (the moments round differently)
    assert np.abs(scaled.q - unit.q).max() < 1e-14


def test_the_exact_motion_is_the_same_bit_for_bit_when_the_inertia_is_scaled_by_a_power_of_two():
    # the moments are brought to [0.5, 1) by a power of two, an exact scaling: the motion of 2^k I is that of I
    t = np.linspace(0.0, 10.0, 5)
    unit = tumble.simulate(BODY, OMEGA0, t=t, method="exact")
    for k in (-600, -3, 5, 400):
        scaled = tumble.simulate(tumble.RigidBody(BODY.inertia * 2.0**k), OMEGA0, t=t, method="exact")
        assert scaled.omega.tolist() == unit.omega.tolist() and scaled.q.tolist() == unit.q.tolist(), k


@pytest.mark.parametrize("scale", [2.0**-530, 1e-160, 1e100])
def test_the_exact_motion_at_any_rate_is_the_same_motion_in_its_own_time(scale):
    # Euler's equations are quadratic in ω: ω(t; c ω0) = c ω(c t; ω0), q(t; c ω0) = q(c t; ω0). Before, at
    # |ω| ~ 1e-160 rad/s (ω² underflows) the exact motion moved ω₃ by 42 % in 1 s (it moves by 1e-320)
    t = np.linspace(0.0, 10.0, 5)
    unit = tumble.simulate(BODY, OMEGA0, t=t, method="exact")
    scaled = tumble.simulate(BODY, scale * OMEGA0, t=t / scale, method="exact")
    if math.frexp(scale)[0] == 0.5:  # a power of two: the same numbers, bit for bit
        assert (scaled.omega / scale).tolist() == unit.omega.tolist() and scaled.q.tolist() == unit.q.tolist()
    assert np.abs(scaled.omega / scale - unit.omega).max() < 1e-14  # measured ≤ 9.5e-16 (1e100 passed before too)
    assert np.abs(scaled.q - unit.q).max() < 1e-13


@pytest.mark.parametrize("omega0, t, turned", [
    (OMEGA0, [0.0, 1e17], "1.01e+17 rad"),
    ([1e150, 1e149, 1e148], [0.0, 1.0], "1.01e+150 rad"),
    (OMEGA0, [-1e308, 1e308], "more than 1.8e308 rad"),
])
def test_the_exact_motion_refuses_a_turn_past_1e16_rad(omega0, t, turned):
    # before: an attitude and a rate that looked like any other (float64 phases there are 2 rad apart or more)
    with pytest.raises(ValidationError, match=rf"^t: the exact motion from t = .* would turn {re.escape(turned)}, "
                                              r"past 1e\+16 rad"):
        tumble.simulate(BODY, omega0, t=t, method="exact")
    traj = tumble.simulate(BODY, OMEGA0, t=[0.0, 9.9e15], method="exact")  # within the bound: a finite state
    assert np.isfinite(traj.q).all() and abs(np.linalg.norm(traj.q[-1]) - 1.0) < 1e-15


@pytest.mark.parametrize("method, options, message", [
    ("rk4", {"dt": 1.0}, "max_steps: the run needs more than 1.8e308 steps of dt = 1 s from t = -1e+308 to 1e+308 s"),
    ("dop853", {}, "the step size fell below the float64 resolution of t"),
])
def test_output_times_from_minus_to_plus_1e308_are_one_clean_error(method, options, message):
    # before: t[1] − t[0] overflowed in the check of increasing times and in the step count (a RuntimeWarning,
    # an error under this suite's filters)
    with pytest.raises((ValidationError, SolverError), match=f"^{re.escape(message)}"):
        tumble.simulate(BODY, OMEGA0, t=[-1e308, 1e308], method=method, **options)


def test_scenario_times_from_minus_to_plus_1e308_are_finite_and_even():
    # before: linspace gave NaN (stop - start = inf), reported as "time: must be finite (found nan …)", and
    # step = 1e307 raised OverflowError (int of inf)
    assert Time(start=-1e308, stop=1e308, samples=3).times().tolist() == [-1e308, 0.0, 1e308]
    times = Time(start=-1e308, stop=1e308, step=1e307).times()
    assert times.size == 21 and times[0] == -1e308 and times[-1] == 1e308 and times[10] == 0.0
    assert np.all(np.diff(times) > 0.0)
    with pytest.raises(ValueError, match="more than the limit"):  # 2e308 / 1e-300 steps: inf, refused
        Time(start=-1e308, stop=1e308, step=1e-300)


def test_a_scenario_from_minus_to_plus_1e308_is_one_clean_error(tmp_path):
    path = tmp_path / "far.toml"
    path.write_text("[body]\nmoments = [1.0, 2.0, 3.0]\n[initial]\nomega = [0.1, 1.0, 0.1]\n"
                    "[time]\nstart = -1e308\nstop = 1e308\nsamples = 3\n")
    result = CliRunner().invoke(app, ["run", str(path), "-o", str(tmp_path / "out.nc")])
    assert result.exit_code == 2, result.stderr
    assert result.stderr.startswith("error: the step size fell below the float64 resolution of t")
    assert len(result.stderr.splitlines()) == 1 and not (tmp_path / "out.nc").exists()


# -- 4. messages that named the wrong thing -----------------------------------------------------------


@pytest.mark.parametrize("given, message", [
    (dict(omega0=np.ones((5, 3)), q0=np.tile([1.0, 0.0, 0.0, 0.0], (4, 1))),
     "q0: a batch of 4 does not match the 5 of omega0"),
    (dict(model=np.tile(np.eye(3), (3, 1, 1)), omega0=np.ones((2, 3))),
     "model: a batch of 3 does not match the 2 of omega0"),
])
def test_disagreeing_batch_sizes_name_the_field(given, message):
    # before: "batch sizes disagree: {...}", no field (ValidationError.field was "")
    model = given.pop("model", BODY)
    with pytest.raises(ValidationError, match=f"^{message}") as error:
        tumble.simulate(model, t=[0.0, 1.0], **given)
    assert error.value.field == message.split(":")[0]


def test_a_trajectory_file_with_nan_times_is_not_called_empty(tmp_path):
    from tumble.viz import viewer

    ds = tumble.simulate(BODY, OMEGA0, t=[0.0, 0.5, 1.0], method="rk4", dt=0.5).to_xarray()
    path = tmp_path / "nan.nc"
    ds.assign_coords(time=np.array([0.0, np.nan, 1.0])).to_netcdf(path, engine="h5netcdf")
    with pytest.raises(ValidationError, match=r"is not a tumble trajectory \(.*t: must be finite \(found nan at "
                                              r"index 1\)\)$"):
        viewer.write_html(path, tmp_path / "out.html")


@pytest.mark.parametrize("text", ["1,,2", "1, 2,", ",1 2"])
def test_robot_torques_refuses_an_empty_entry_in_q(text):
    # before: "1,,2" was read as the two numbers 1 and 2
    result = CliRunner().invoke(app, ["robot", "torques", str(tumble.examples.path("robots/planar_2link.toml")),
                                      "--q", text])
    assert result.exit_code == 2 and result.stderr.startswith("error: --q: must be numbers separated by commas")


def test_sweep_refuses_a_scheduler_address_that_is_not_one(tmp_path):
    # before: exit 1 ("a bug"), ValueError from distributed's address parser
    result = CliRunner().invoke(app, ["sweep", str(tumble.examples.path("sweep/spinner.toml")), "-o",
                                      str(tmp_path / "out.zarr"), "--scheduler", "garbage", "--quiet"])
    assert result.exit_code == 2, (result.stderr, result.exception)
    assert result.stderr.startswith("error: --scheduler: must be a scheduler address such as tcp://host:8786, "
                                    "got 'garbage'")
    assert not (tmp_path / "out.zarr").exists()


# -- 5. arity, text, non-unit quaternions -------------------------------------------------------------


def test_a_torque_function_of_the_wrong_arity_is_refused_naming_the_signature():
    # before: TypeError: <lambda>() takes 2 positional arguments but 3 were given, from inside the run
    with pytest.raises(ValidationError, match=r"^torque: the function <lambda>\(t, q\) must take the 3 arguments "
                                              r"\(t, q, omega\)$"):
        tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0], method="rk4", dt=0.5, torque=lambda t, q: np.zeros(3))
    # any callable that takes three positional arguments is fine
    traj = tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0], method="rk4", dt=0.5, torque=lambda *args: np.zeros(3))
    assert traj.omega[0].tolist() == OMEGA0.tolist()


@pytest.mark.parametrize("omega0", [["0", "1", "0"], [b"0", 1.0, 0.0], np.array(["0", "1", "0"])])
def test_numbers_given_as_text_are_refused(omega0):
    # before: NumPy converted the strings and the run went ahead
    with pytest.raises(ValidationError, match=r"^omega0: must be an array of real numbers, not text"):
        tumble.simulate(BODY, omega0, t=[0.0, 1.0])


def test_a_complex_array_is_refused_not_cut_to_its_real_part():
    # before: a NumPy complex array was cast to its real part with only a ComplexWarning
    with pytest.raises(ValidationError, match=r"^omega0: must be an array of real numbers, not complex"):
        tumble.simulate(BODY, np.array([0.1, 1.0 + 1.0j, 0.1]), t=[0.0, 1.0])


def test_an_initial_quaternion_off_unit_length_is_normalised_with_a_warning_beyond_1e_6():
    # before: [2, 0, 0, 0] was normalised without a word
    with pytest.warns(attitude.NonUnitQuaternionWarning, match=r"^q0: \|q0\| = 2 is not 1 \(further than 1e-06\)"):
        traj = tumble.simulate(BODY, OMEGA0, q0=[2.0, 0.0, 0.0, 0.0], t=[0.0, 0.5], method="rk4", dt=0.5)
    assert traj.q[0].tolist() == [1.0, 0.0, 0.0, 0.0]
    with pytest.warns(attitude.NonUnitQuaternionWarning, match=r"^q0: \|q0\[1\]\| = 3 "):  # a batch names the member
        tumble.simulate(BODY, OMEGA0, q0=[[1.0, 0.0, 0.0, 0.0], [0.0, 3.0, 0.0, 0.0]], t=[0.0, 0.5], method="rk4",
                        dt=0.5)
    with warnings.catch_warnings():  # within 1e-6: normalised silently (|q| - 1 = 5e-7 here)
        warnings.simplefilter("error")
        tumble.simulate(BODY, OMEGA0, q0=[1.0 + 5e-7, 0.0, 0.0, 0.0], t=[0.0, 0.5], method="rk4", dt=0.5)


# -- 6. a run past max_steps said early --------------------------------------------------------------


def test_a_run_projected_past_twice_max_steps_stops_after_one_percent_of_them():
    # 2.4 steps per second of this motion: t = 1e6 s needs 2.4e6 steps. Before: 1e6 steps, then "max_steps=1000000
    # reached" (with the default max_steps = 1e8: a minute and a half of computing before the same failure)
    with pytest.raises(SolverError, match=r"^max_steps: the run would need 2.4e\+06 steps or more to t=1e\+06 "
                                          r"\(projected from its first 10000 "):
        tumble.simulate(BODY, [0.001, 1.0, 0.001], t=[0.0, 1e6], max_steps=10**6)


def test_a_run_at_the_rate_bound_stops_at_once_instead_of_after_max_steps():
    # |ω| = 1e150 rad/s (the bound of initial states): before, the start step was 0 (the difference estimate of
    # ‖f'‖ overflowed), t never moved and the run made max_steps steps of nothing: 86 s with the default
    with pytest.raises(SolverError, match=r"^max_steps: the run would need \S+ steps or more to t=1 \(projected "
                                          r"from its first 1000 "):
        tumble.simulate(BODY, [1e150, 1e149, 1e148], t=[0.0, 1.0], max_steps=10**6)
    # and on a span it can cover, it keeps the energy
    traj = tumble.simulate(BODY, [1e150, 1e149, 1e148], t=[0.0, 1e-148])
    assert abs(traj.energy[-1] / traj.energy[0] - 1.0) < 1e-10  # measured 1.1e-12


# -- 7. tumble.viz.viewer, lazily imported ----------------------------------------------------------------


def test_tumble_viewer_is_imported_on_first_use():
    # before: AttributeError: module 'tumble' has no attribute 'viewer' (a fresh process: nothing imported it yet)
    out = subprocess.run([sys.executable, "-c", "import tumble; print(tumble.viz.viewer.write_html.__module__)"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "tumble.viz.viewer"


# -- 8. the Goryachev–Chaplygin invariant, whatever the body axes -------------------------------------


def test_the_goryachev_chaplygin_invariant_does_not_depend_on_the_orientation_of_the_symmetry_axis():
    # A = B = 4C, the centre of mass along e₁ = x: a half-turn about x maps the top onto itself (same inertia,
    # same com), so the same motion in the turned body axes is omega' = Rᵀω, q' = q ⊗ q_R. Before: G' = −G.
    body, gravity = tumble.RigidBody(np.diag([4.0, 4.0, 1.0])), Gravity(mass=1.0, com=[1.0, 0.0, 0.0],
                                                                        g=[0.0, 0.0, -9.81])
    q = attitude.from_euler("ZYX", [0.3, -0.7, 1.1])
    up = attitude.rotate_inverse(q, [0.0, 0.0, 1.0])
    omega = np.array([0.4, -1.3, 2.2])
    i_up = body.inertia @ up
    omega -= (omega @ i_up) / (i_up @ i_up) * i_up  # L_z = (I ω)·γ = 0: the Goryachev–Chaplygin level
    assert abs(vertical_momentum(body, gravity, omega, q)) < 1e-15
    half_turn = np.diag([1.0, -1.0, -1.0])
    turned = goryachev_chaplygin_invariant(body, gravity, half_turn.T @ omega,
                                           attitude.multiply(q, attitude.from_matrix(half_turn)))
    g = goryachev_chaplygin_invariant(body, gravity, omega, q)
    assert g > 0.5  # not a zero that both signs would share (0.796)
    assert turned == pytest.approx(g, rel=1e-14)
