"""The `tumble` command: run, demos, info, --help, --version; exit codes; nothing written on bad input."""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tumble
from tumble._kinds import MODEL_KINDS
from tumble.cli import app
from tumble.scenario import load_scenario, run_scenario

EXAMPLES = tumble.examples.directory()
SRC = Path(__file__).resolve().parents[2] / "src"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.mark.parametrize(
    "command",
    [[], ["run"], ["demo"], ["demo", "racket"], ["demo", "polhode"], ["demo", "top"], ["info"],
     *[["demo", name] for name in ("diver", "flexible", "slosh", "explorer1", "gravity-gradient", "gyro", "coning",
                                   "ins", "budget")],
     ["robot"], ["robot", "torques"]],
    ids=" ".join,
)
def test_help_of_every_command(command):
    result = invoke(*command, "--help")
    assert result.exit_code == 0, result.output
    assert "Usage: tumble" in result.stdout


def test_version():
    result = invoke("--version")
    assert result.exit_code == 0
    assert result.stdout.strip() == f"tumble {tumble.__version__}"


def test_python_dash_m_tumble():
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    done = subprocess.run([sys.executable, "-m", "tumble", "--version"], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"tumble {tumble.__version__}"


def test_run_writes_a_loadable_trajectory_and_a_png(tmp_path):
    scenario = EXAMPLES / "symmetric_top.toml"
    out, png = tmp_path / "top.nc", tmp_path / "top.png"
    result = invoke("run", scenario, "-o", out, "--plot", png)
    assert result.exit_code == 0, result.output
    saved = tumble.load(out)
    direct = run_scenario(load_scenario(scenario))  # the same computation through the library
    np.testing.assert_array_equal(saved.t, direct.t)
    np.testing.assert_array_equal(saved.omega, direct.omega)
    np.testing.assert_array_equal(saved.q, direct.q)
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert "0 to 10 s, 1001 samples" in result.stdout
    assert f"wrote     {out}, {png}" in result.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["top.nc", "top.png"]  # no temporary files left


BAD_FILES = {
    "schema": ("[body]\nmoments = [1.0, 2.0, 3.0]\n[initial]\nomega = [0, 0, 1]\n[time]\nstop = -1.0\nsamples = 5\n",
               "bad.toml: time.stop: must be greater than start"),
    "syntax": ("[body\n", "bad.toml: line 1, column 6: invalid TOML"),
    "physics": ("[body]\ninertia = [[1, 0, 0], [0, 1, 0], [0, 0, 0]]\n[initial]\nomega = [0, 0, 1]\n"
                "[time]\nstop = 1.0\nsamples = 5\n", "bad.toml: body.inertia: must be positive definite"),
}


@pytest.mark.parametrize("case", BAD_FILES)
def test_run_bad_file_exits_2_and_writes_nothing(tmp_path, case):
    text, message = BAD_FILES[case]
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    result = invoke("run", bad, "-o", tmp_path / "out.nc", "--plot", tmp_path / "out.png")
    assert result.exit_code == 2
    assert message in result.stderr
    assert result.stdout == ""
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


def test_run_missing_file_exits_2(tmp_path):
    result = invoke("run", tmp_path / "nope.toml", "-o", tmp_path / "out.nc")
    assert result.exit_code == 2
    assert "nope.toml: cannot read the file" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_run_output_in_missing_directory_exits_2(tmp_path):
    result = invoke("run", EXAMPLES / "symmetric_top.toml", "-o", tmp_path / "no" / "out.nc")
    assert result.exit_code == 2
    assert "--output: directory" in result.stderr and "does not exist" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_solver_failure_exits_2_and_writes_nothing(tmp_path):
    # DOP853 at rtol = atol = 1e-14 on the symmetric top's 10 s: a real SolverError (its step falls below
    # what float64 resolves, or it runs out of steps), reported in one line
    scenario = tmp_path / "tight.toml"
    scenario.write_text((EXAMPLES / "symmetric_top.toml").read_text()
                        + '\n[solver]\nmethod = "dop853"\nrtol = 1e-300\natol = 1e-300\n')
    result = invoke("run", scenario, "-o", tmp_path / "out.nc")
    assert result.exit_code == 2
    assert result.stderr.startswith("error: ") and len(result.stderr.strip().splitlines()) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["tight.toml"]


def test_demo_racket_counts_the_flips_in_the_file(tmp_path):
    out, png = tmp_path / "racket.nc", tmp_path / "racket.png"
    result = invoke("demo", "racket", "-o", tmp_path, "--duration", 20)
    assert result.exit_code == 0, result.output
    match = re.search(r"flips\s+(\d+) in 20 s, mean time between flips ([0-9.]+) s", result.stdout)
    assert match, result.stdout
    printed_count, printed_mean = int(match.group(1)), float(match.group(2))

    # Independent count from the saved file: the intermediate principal axis of
    # the saved inertia, and the samples where the rate about it changes sign.
    saved = tumble.load(out)
    _, vectors = np.linalg.eigh(saved.inertia)
    rate = saved.omega @ vectors[:, 1]
    changes = np.flatnonzero(np.diff(np.sign(rate)) != 0)
    assert printed_count == changes.size
    assert printed_count >= 5  # the T-handle turns over every ~3 s
    # The mean interval between sign-change samples is within one sample spacing of the printed one.
    spacing = saved.t[1] - saved.t[0]
    assert abs(np.diff(saved.t[changes]).mean() - printed_mean) <= spacing
    assert png.read_bytes()[:8] == PNG_MAGIC


def test_demo_racket_prints_the_predicted_flip_interval(tmp_path):
    result = invoke("demo", "racket", "-o", tmp_path, "--duration", 10)
    assert result.exit_code == 0, result.output
    simulated = float(re.search(r"mean time between flips ([0-9.]+) s", result.stdout).group(1))
    predicted = float(re.search(r"predicted time between flips 2K/lambda = ([0-9.]+) s", result.stdout).group(1))
    # Measured 6e-8 apart (printed to 6 digits); 1e-3 is the agreement the demo promises.
    assert predicted == pytest.approx(simulated, rel=1e-3)
    assert predicted == pytest.approx(2.98632, rel=1e-5)  # 2K/λ of the default T-handle motion


def test_demo_polhode_writes_the_figure(tmp_path):
    from tumble.analytic._stability import stability

    png, page = tmp_path / "polhode.png", tmp_path / "polhode.html"
    result = invoke("demo", "polhode", "-o", tmp_path)
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert page.read_text()[:15] == "<!DOCTYPE html>"  # the viewer's page (tests/viz/test_viewer*.py check its content)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["polhode.html", "polhode.png"]  # no temporary files left
    handle = tumble.RigidBody.t_handle()
    report = stability(handle, handle.axes @ np.array([1.0, 10.0, 1.0]))
    assert "axes      1: stable, 2: unstable, 3: stable" in result.stdout
    assert f"flips every 2K/lambda = {report.flip_interval:.6g} s" in result.stdout
    assert f"wrote     {png}, {page}" in result.stdout


def test_demo_polhode_output_in_missing_directory_exits_2(tmp_path):
    result = invoke("demo", "polhode", "-o", tmp_path / "no")
    assert result.exit_code == 2
    assert f"--output: {str(tmp_path / 'no')!r} is not an existing directory" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # the heavy-top demo compiles its integrators (~6 CPU s on a cold cache)
def test_demo_top_writes_the_trajectory_and_the_figure(tmp_path):
    pytest.importorskip("tumble.viz.top")  # written alongside; skipped only while the module is missing
    result = invoke("demo", "top", "-o", tmp_path, "--duration", 0.5)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["top.html", "top.nc", "top.png"]
    assert (tmp_path / "top.png").read_bytes()[:8] == PNG_MAGIC
    assert (tmp_path / "top.html").read_text()[:15] == "<!DOCTYPE html>"
    assert len(tumble.load(tmp_path / "top.nc")) > 1
    exact, simulated = map(float, re.search(r"period\s+([0-9.]+) s \(exact\), ([0-9.]+) s \(simulated\)",
                                            result.stdout).groups())
    assert simulated == pytest.approx(exact, rel=1e-5)  # printed to 6 digits


def test_demo_top_missing_directory_exits_2(tmp_path):
    result = invoke("demo", "top", "-o", tmp_path / "nope")
    assert result.exit_code == 2
    assert "--output:" in result.stderr and "is not an existing directory" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_demo_racket_bad_duration_exits_2(tmp_path):
    result = invoke("demo", "racket", "-o", tmp_path, "--duration", -1)
    assert result.exit_code == 2
    assert "--duration: must be a finite number > 0" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_info_prints_the_file_contents(tmp_path):
    out = tmp_path / "box.nc"
    assert invoke("run", EXAMPLES / "box_inertial_torque.toml", "-o", out).exit_code == 0
    result = invoke("info", out)
    assert result.exit_code == 0, result.output
    moments = np.linalg.eigvalsh(tumble.load(out).inertia)
    assert f"{moments[0]:.6g}, {moments[1]:.6g}, {moments[2]:.6g} kg m^2" in result.stdout
    assert "0 to 20 s, 2001 samples" in result.stdout
    assert "dop853 (rtol 1e-10, atol 1e-12)" in result.stdout
    assert "torque = ConstantInertial([0.0, 0.002, 0.0])" in result.stdout


def test_info_on_a_file_that_is_not_a_trajectory_exits_2(tmp_path):
    junk = tmp_path / "junk.nc"
    junk.write_text("not netcdf")
    result = invoke("info", junk)
    assert result.exit_code == 2
    assert "junk.nc: not a readable tumble trajectory" in result.stderr


# -- extension packages ---------------------------------------------------------------


def test_demo_of_an_extension_writes_its_figure_and_prints_its_numbers(tmp_path):
    from tumble.viz.ins import demo_coning

    result = invoke("demo", "coning", "-o", tmp_path)
    assert result.exit_code == 0, result.output
    expected = demo_coning(tmp_path)  # the same computation, called directly
    for algorithm in ("none", "one-sample", "two-sample", "three-sample"):
        line = next(row for row in result.stdout.splitlines() if row.split()[0] == algorithm)
        assert f"measured drift within {expected[algorithm]['max_relative_deviation']:.1%} of its law" in line
    assert f"wrote     {tmp_path / 'ins_coning.png'}" in result.stdout
    assert (tmp_path / "ins_coning.png").read_bytes()[:8] == PNG_MAGIC


def test_extension_demo_refuses_a_missing_directory(tmp_path):
    result = invoke("demo", "coning", "-o", tmp_path / "missing")
    assert result.exit_code == 2
    assert "is not an existing directory" in result.output


@pytest.mark.slow  # compiles the robot's kernels (~6 CPU s on a cold cache)
def test_robot_torques_prints_the_published_puma_gravity_load():
    # Corke's Robotics Toolbox: gravload(qn) = [0, 31.6399, 6.0351, 0, 0.0283, 0] N m for the PUMA 560
    # at qn = [0, pi/4, pi, 0, pi/4, 0] (4 significant digits, hence 5e-5 relative)
    q = "0 0.7853981633974483 3.141592653589793 0 0.7853981633974483 0"
    result = invoke("robot", "torques", EXAMPLES / "robots" / "puma560.toml", "--q", q)
    assert result.exit_code == 0, result.output
    printed = [float(x) for x in re.findall(r"tau =\s+(\S+) N m", result.stdout)]
    np.testing.assert_allclose(printed, [0.0, 31.6399, 6.0351, 0.0, 0.0283, 0.0], rtol=5e-5, atol=5e-5)


@pytest.mark.slow  # compiles the spacecraft (~35 CPU s on a cold cache)
def test_run_dispatches_a_spacecraft_scenario(tmp_path):
    out = tmp_path / "slew.nc"
    result = invoke("run", EXAMPLES / "spacecraft" / "slew_wheels.toml", "-o", out, "--quiet")
    assert result.exit_code == 0, result.output
    traj = tumble.load(out)
    assert "wheel_speed" in traj.extras and traj.extras["wheel_speed"].data.shape == (len(traj), 4)
    peak = np.abs(traj.extras["wheel_speed"].data).max()
    assert f"peak speed {peak:.4g} rad/s" in result.stdout


@pytest.mark.slow  # compiles the spacecraft (~35 CPU s on a cold cache)
def test_run_writes_the_mrp_disturbance_example_and_its_figure(tmp_path):
    # The command line of the example's header: exit 0, the trajectory (with the MRP integral term and the
    # disturbance torque of its [[torque]] table) and the spacecraft figure written, nothing else left.
    scenario = EXAMPLES / "spacecraft" / "mrp_disturbance.toml"
    out, png = tmp_path / "out.nc", tmp_path / "out.png"
    result = invoke("run", scenario, "-o", out, "--plot", png)
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.nc", "out.png"]
    saved, traj = tumble.load(out), run_scenario(scenario)
    np.testing.assert_array_equal(saved.q, traj.q)
    np.testing.assert_array_equal(saved.extras["attitude_error_integral"].data, traj.attitude_error_integral)
    np.testing.assert_array_equal(saved.extras["external_torque"].data[-1], [0.005, -0.003, 0.002])
    for label, value in load_scenario(scenario).rows(traj):
        assert f"{label} {value}" in " ".join(result.stdout.split())


@pytest.mark.slow  # compiles the spacecraft (~35 CPU s on a cold cache)
@pytest.mark.parametrize("scenario", [EXAMPLES / "symmetric_top.toml", EXAMPLES / "spacecraft" / "slew_wheels.toml"],
                         ids=lambda p: p.stem)
def test_run_parses_the_file_once(tmp_path, monkeypatch, scenario):
    # Count the TOML parses of one `tumble run` (the parser still runs: the call is passed on).
    import tomllib

    calls = []
    parse = tomllib.loads

    def counted(text, **kwargs):
        calls.append(text)
        return parse(text, **kwargs)

    monkeypatch.setattr(tomllib, "loads", counted)
    result = invoke("run", scenario, "-o", tmp_path / "out.nc", "--quiet")
    assert result.exit_code == 0, result.output
    assert calls == [scenario.read_text(encoding="utf-8")]


def test_run_refuses_an_unknown_kind_naming_the_kinds(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('kind = "submarine"\n' + (EXAMPLES / "symmetric_top.toml").read_text(encoding="utf-8"))
    result = invoke("run", bad, "-o", tmp_path / "out.nc")
    assert result.exit_code == 2
    kinds = ", ".join(map(repr, tumble.scenario.KINDS))  # the registry's, in its order: 'rigid', 'spacecraft', ...
    assert result.stderr == f"error: {bad}: kind: must be one of {kinds}, got 'submarine'\n"
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


def test_cli_does_not_import_back():
    # The demo table and the scenario package are read by the CLI; neither imports it (no cycle).
    kinds = ", ".join(f"tumble.scenario.{kind}" for kind in tumble.scenario.KINDS)  # every kind of the registry
    code = f"import sys, tumble.viz.demos, tumble.scenario, {kinds}; print('tumble.cli' in sys.modules)"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


# -- tumble warmup ------------------------------------------------------------------------------------


@pytest.mark.slow  # its subprocess compiles the rigid body's rk4 (~6 CPU s on a cold cache)
def test_warmup_compiles_what_a_new_process_then_loads_from_the_cache():
    env = {**os.environ, "PYTHONPATH": str(Path(tumble.__file__).parents[1])}
    env.pop("TUMBLE_QUIET", None)
    done = subprocess.run([sys.executable, "-m", "tumble", "warmup", "RigidBody, rk4"], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert re.match(r"compiled\s+1 paths in [\d.]+ s\ncache\s+", done.stdout), done.stdout
    # not on a terminal, the display is one line per path, naming it; no compile notice besides
    assert done.stderr == "compiling RigidBody, rk4 (1/1)\n"
    # a new process making the same call compiles nothing: Numba's cache log shows loads and no save
    child = "from tumble._warmup import paths; paths()['RigidBody, rk4']()"
    log = subprocess.run([sys.executable, "-c", child], env={**env, "NUMBA_DEBUG_CACHE": "1"},
                         capture_output=True, text=True, timeout=600, check=True).stdout
    assert "[cache] data loaded" in log and "[cache] data saved" not in log, log


def test_warmup_lists_every_built_in_kind_under_the_methods_it_provides_and_refuses_an_unknown_path():
    result = invoke("warmup", "RigidBody, rk5")
    assert result.exit_code == 2
    assert result.stderr.startswith("error: PATH: unknown 'RigidBody, rk5'; the paths are 'RigidBody, rk4', ")
    listed = invoke("warmup", "--list").stdout.splitlines()
    kinds = list(MODEL_KINDS)  # every built-in kind: the registry's
    assert {"RigidBody", "Spacecraft", "GimbaledGyro"} <= set(kinds)
    by_kind = {kind: [name.split(", ")[1] for name in listed if name.split(", ")[0] == kind] for kind in kinds}
    assert by_kind["RigidBody"] == list(tumble.integrate.METHODS)  # every method applies to a rigid body
    assert by_kind["GimbaledGyro"] == ["rk4", "dop853"]  # no body rate: cf4 refused (tests/test_models.py)
    assert all("rk4" in methods and "dop853" in methods for methods in by_kind.values()), by_kind
    assert listed[-5:] == ["demo racket", "a batch, rk4", "a batch, dop853", "heavy top, rk4", "heavy top, dop853"]
    assert len(listed) == sum(map(len, by_kind.values())) + 5


