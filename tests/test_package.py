"""The package is complete: example files installed with it, one version, the public error name, the notebook
table and the DataFrame of a Trajectory, and a wheel and sdist that carry all of it.

Nothing here compiles a kernel: the trajectories are made by hand from closed forms.
"""

import os
import re
import subprocess
import sys
import tomllib
import traceback
import zipfile
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tumble
from tumble.cli import app
from tumble.trajectory import Extra, Trajectory
from api_annotations import public_functions, unannotated

ROOT = Path(__file__).resolve().parents[1]


# -- example files ------------------------------------------------------------------------------------


def test_example_files_are_found_by_bare_name_and_by_path():
    assert tumble.examples.path("puma560.toml") == tumble.examples.directory() / "robots" / "puma560.toml"
    assert tumble.examples.path("robots/panda.urdf").read_text(encoding="utf-8").startswith("<?xml")
    arm = tumble.robot.load(tumble.examples.path("planar_2link.toml"))
    assert arm.dof == 2
    # a bare name finds its file only because no two example files share a name
    assert [n for n, c in Counter(p.rsplit("/", 1)[-1] for p in tumble.examples.names()).items() if c > 1] == []


def test_every_file_of_the_examples_directory_is_listed():
    on_disk = {p.relative_to(tumble.examples.directory()).as_posix()
               for p in tumble.examples.directory().rglob("*")
               if p.is_file() and "__pycache__" not in p.parts and p.name != "__init__.py"}
    assert set(tumble.examples.names()) == on_disk
    assert {"robots/puma560.toml", "robots/panda.urdf", "ins/coning_gyro.csv", "sweep/spinner.toml",
            "intermediate_axis.toml"} <= on_disk


@pytest.mark.parametrize("name", ["nowhere.toml", "", "robots", 3])
def test_an_unknown_example_is_refused_naming_the_field(name):
    with pytest.raises(tumble.ValidationError) as info:
        tumble.examples.path(name)
    assert info.value.field == "name"


def test_copy_keeps_the_tree_and_never_overwrites(tmp_path):
    written = tumble.examples.copy(tmp_path / "ex")
    assert len(written) == len(tumble.examples.names())
    for name in tumble.examples.names():
        assert (tmp_path / "ex" / name).read_bytes() == tumble.examples.path(name).read_bytes()
    (tmp_path / "ex" / "heavy_top.toml").write_text("edited", encoding="utf-8")
    with pytest.raises(tumble.ValidationError) as info:
        tumble.examples.copy(tmp_path / "ex")
    assert info.value.field == "destination"
    assert (tmp_path / "ex" / "heavy_top.toml").read_text(encoding="utf-8") == "edited"
    (tmp_path / "file").write_text("", encoding="utf-8")
    with pytest.raises(tumble.ValidationError, match="^destination: .* is not a directory"):
        tumble.examples.copy(tmp_path / "file")


def test_examples_commands(tmp_path):
    runner = CliRunner()
    listed = runner.invoke(app, ["examples", "list"])
    assert listed.exit_code == 0
    assert listed.stdout.splitlines()[1:] == tumble.examples.names()
    copied = runner.invoke(app, ["examples", "copy", str(tmp_path / "ex")])
    assert copied.exit_code == 0 and (tmp_path / "ex" / "robots" / "puma560.toml").is_file()
    again = runner.invoke(app, ["examples", "copy", str(tmp_path / "ex")])
    assert again.exit_code == 2 and again.stderr.startswith("error: destination: ")


# -- annotations ------------------------------------------------------------------------------------------


def test_every_public_function_is_annotated():
    """Every public function and method of src/tumble (tests/api_annotations.py says which count) annotates
    each parameter and its return, so that mypy (.ci/run) checks its body and its callers."""
    assert len(public_functions()) > 500  # the walk found the package
    lacking = unannotated()
    assert lacking == {}, "public functions lacking annotations:\n" + "\n".join(
        f"  {name}: {', '.join(lacks)}" for name, lacks in lacking.items())


def test_the_annotation_check_sees_a_missing_annotation(tmp_path):
    package = tmp_path / "tumble"
    (package / "_private").mkdir(parents=True)
    (package / "kernels").mkdir()
    (package / "mod.py").write_text(
        "def f(x: int, *args, **kwargs: int) -> int: ...\n"
        "def g(x: int) -> None:\n    def nested(y): ...\n"
        "def _private(y): ...\n"
        "class C:\n    def m(self, y) -> None: ...\n    def __repr__(self): ...\n"
        "    def __init__(self, z): ...\n    @staticmethod\n    def s(w: int): ...\n", encoding="utf-8")
    (package / "_private" / "mod.py").write_text("def h(y): ...\n", encoding="utf-8")
    (package / "kernels" / "k.py").write_text("def kernel(y): ...\n", encoding="utf-8")
    assert unannotated(tmp_path) == {"tumble.mod.f": ["*args"], "tumble.mod.C.m": ["y"],
                                     "tumble.mod.C.__init__": ["z", "return"], "tumble.mod.C.s": ["return"]}


# -- names and version ------------------------------------------------------------------------------------


def test_validation_error_prints_its_public_name():
    with pytest.raises(tumble.ValidationError) as info:
        tumble.RigidBody(np.diag([1.0, 2.0, -3.0]))
    line = traceback.format_exception_only(info.value)[-1]
    assert line.startswith("tumble.ValidationError: inertia: ")
    assert repr(tumble.ValidationError).endswith("'tumble.ValidationError'>")


def test_one_version_source():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert "version" not in project["project"] and project["project"]["dynamic"] == ["version"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "tumble._version.__version__"}
    # the changelog's newest entry is this version
    newest = re.search(r"^## (\S+)", (ROOT / "CHANGELOG.md").read_text(encoding="utf-8"), flags=re.M)
    assert newest.group(1) == tumble.__version__


# -- the notebook table and the DataFrame ----------------------------------------------------------------

# A body spun up about its major axis z: ω = (0, 0, 2 + 0.1 t) rad/s, I = diag(1, 2, 3) kg m², so that
# q = [cos(φ/2), 0, 0, sin(φ/2)] with φ = 2t + 0.05 t², T = 3/2 ω_z² and |L| = 3 ω_z, exactly.
T = np.linspace(0.0, 1.0, 11)
RATE = 2.0 + 0.1 * T
PHI = 2.0 * T + 0.05 * T**2


def spun_up(batch=False):
    q = np.stack([np.cos(PHI / 2), 0 * T, 0 * T, np.sin(PHI / 2)], axis=-1)
    omega = np.stack([0 * T, 0 * T, RATE], axis=-1)
    wheel = Extra(np.stack([RATE, -RATE], axis=-1), ("wheel",), "rad/s", "two wheels")
    if batch:   # the same body twice, the second spinning the other way
        q, omega = np.stack([q, q * [1, 1, 1, -1]], axis=1), np.stack([omega, -omega], axis=1)
        wheel = Extra(np.stack([wheel.data, -wheel.data], axis=1), ("wheel",), "rad/s", "two wheels")
    return Trajectory(T, q, omega, np.diag([1.0, 2.0, 3.0]), "rk4", {"n_steps": 10, "dt": 0.1},
                      {"wheel_speed": wheel}, {}, "RigidBody")


def test_notebook_table_gives_shape_method_span_and_drifts():
    html = spun_up()._repr_html_()
    table = html[: html.index("</table>") + len("</table>")]
    cells = dict(re.findall(r"<th[^>]*>(.*?)</th><td[^>]*>(.*?)</td>", table))
    assert cells["model"] == "RigidBody" and cells["method"] == "rk4"
    assert cells["samples"] == "11 times" and cells["time span"] == "0 … 1 s"
    assert cells["n_steps"] == "10" and cells["dt"] == "0.1"
    # exact: ΔE/E₀ = (2.1² − 2²)/2² = 0.1025; Δ|L|/|L₀| = 0.1/2 = 0.05; L_I stays along z: the same 0.05
    assert cells["max |E − E₀| / E₀"] == "1.025e-01"
    assert cells["max ||L| − |L₀|| / |L₀|"] == "5.000e-02"
    assert cells["max |L_I − L_I₀| / |L_I₀|"] == "5.000e-02"
    assert "wheel_speed (rad/s)" in cells["extras"]
    assert spun_up(batch=True)._repr_html_().count("11 times × 2 bodies") == 1


def test_dataframe_columns_and_values():
    frame = spun_up().to_dataframe()
    assert list(frame.columns) == ["q_w", "q_x", "q_y", "q_z", "omega_x", "omega_y", "omega_z", "energy",
                                   "momentum_body_x", "momentum_body_y", "momentum_body_z",
                                   "wheel_speed[0]", "wheel_speed[1]"]
    assert frame.index.name == "t" and np.array_equal(frame.index, T)
    # the arrays themselves, copied: equal to the bit; the energy 3/2 ω_z² to rounding (1 ulp of ~6.6 J)
    assert np.array_equal(frame["q_z"], np.sin(PHI / 2)) and np.array_equal(frame["omega_z"], RATE)
    np.testing.assert_allclose(frame["energy"], 1.5 * RATE**2, rtol=4e-16, atol=0)
    assert np.array_equal(frame["wheel_speed[1]"], -RATE)
    batch = spun_up(batch=True).to_dataframe()
    assert batch.index.names == ["t", "body"] and len(batch) == 22
    assert np.array_equal(batch.xs(1, level="body")["omega_z"], -RATE)


# -- the wheel and the sdist -------------------------------------------------------------------------------


@pytest.mark.slow
def test_wheel_and_sdist_carry_the_package_data(tmp_path):
    """python -m build (no isolation: setuptools and build come with the test extra) from a copy of the files git
    tracks or would track (not the ignored ones: caches, builds)."""
    tracked = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT, capture_output=True, check=True).stdout
    source = tmp_path / "source"
    for name in tracked.decode().split("\0"):
        if name and (ROOT / name).is_file():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            (source / name).write_bytes((ROOT / name).read_bytes())
    subprocess.run([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(tmp_path / "dist"),
                    str(source)], check=True, capture_output=True)
    version = tumble.__version__
    wheel = tmp_path / "dist" / f"tumble-{version}-py3-none-any.whl"
    names = set(zipfile.ZipFile(wheel).namelist())
    examples = {f"tumble/examples/{n}" for n in tumble.examples.names()}
    assert examples <= names
    assert {"tumble/py.typed", "tumble/viz/viewer/viewer.js", "tumble/examples/__init__.py"} <= names
    licenses = f"tumble-{version}.dist-info/licenses/"
    assert {licenses + "LICENSE", licenses + "NOTICE", licenses + "LICENSES/Apache-2.0.txt"} <= names
    assert not [n for n in names if n.startswith(("tests/", "docs/", "benchmarks/")) or "__pycache__" in n]
    metadata = zipfile.ZipFile(wheel).read(f"tumble-{version}.dist-info/METADATA").decode()
    assert f"Version: {version}\n" in metadata and "License-Expression: MIT AND Apache-2.0\n" in metadata
    sdist = subprocess.run(["tar", "tzf", str(tmp_path / "dist" / f"tumble-{version}.tar.gz")],
                           capture_output=True, check=True, text=True).stdout.split()
    assert {f"tumble-{version}/{n}" for n in ("LICENSE", "NOTICE", "CHANGELOG.md", "mkdocs.yml",
                                              "docs/conventions.md", "src/tumble/examples/robots/panda.urdf")} \
        <= set(sdist)
    # the installed wheel runs from anywhere, with its example files beside it
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target",
                    str(tmp_path / "site"), str(wheel)], check=True)
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "site")}
    run = subprocess.run([sys.executable, "-c", "import tumble; print(tumble.__version__); "
                          "print(tumble.examples.path('puma560.toml'))"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, check=True)
    assert run.stdout.split() == [version, str(tmp_path / "site" / "tumble" / "examples" / "robots" / "puma560.toml")]
