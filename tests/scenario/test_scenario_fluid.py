"""Scenario kind "fluid" (tumble.scenario.fluid): its example file runs as tumble.simulate of the same
KirchhoffBody built in Python (bitwise) and shows Munk's moment at Lamb's rate; bad files are refused naming the
key; `tumble run` writes the trajectory, the figure and the summary row."""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tumble
from tumble import attitude
from tumble.cli import app
from tumble.fluid import KirchhoffBody, ellipsoid_added_mass
from tumble.scenario import ScenarioError, load, parse

from helpers import assert_same_run

EXAMPLE = tumble.examples.directory() / "fluid" / "munk_moment.toml"
TEXT = EXAMPLE.read_text(encoding="utf-8")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def example():
    """The example loaded and run once: (scenario, trajectory)."""
    scenario = load(EXAMPLE)
    return scenario, scenario.run()


@pytest.mark.slow  # compiles the KirchhoffBody's dop853 path (about 8 CPU s cold)
def test_the_example_is_simulate_of_the_same_model_built_in_python(example):
    scenario, traj = example
    assert scenario.kind == "fluid"
    body = tumble.RigidBody.ellipsoid(mass=171.74, semi_axes=[1.0, 0.2, 0.2])
    model = KirchhoffBody(body, ellipsoid_added_mass([1.0, 0.2, 0.2], 1025.0))
    reference = tumble.simulate(model, [0.0, 0.01, 0.0], velocity0=[2.0, 0.0, 0.0], t=np.linspace(0.0, 20.0, 401),
                                method="dop853", rtol=1e-10, atol=1e-10)
    assert_same_run(traj, reference)
    for name in ("velocity", "angular_impulse", "linear_impulse", "position"):
        np.testing.assert_array_equal(getattr(traj, name), getattr(reference, name))


@pytest.mark.slow  # runs the example (about 8 CPU s cold)
def test_the_example_turns_broadside_at_munks_rate_keeping_its_integrals(example):
    scenario, traj = example
    model = scenario.model
    # Lamb § 126 linearised (tumble.fluid): a small pitch grows as cosh λt, λ² = c₁ (c₃ − c₁) u² / (a₂ c₃)
    c1, c3 = (model.mass_matrix[k, k] for k in (0, 2))
    a2 = model.mass_matrix[4, 4]
    rate = 2.0 * math.sqrt(c1 * (c3 - c1) / (a2 * c3))  # u = 2 m/s: λ = 2.30 /s
    early = traj.t <= 1.0  # the pitch angle stays below 0.03 rad: the nonlinear terms are below 1e-3
    linear = 0.01 * np.cosh(rate * traj.t[early])
    assert np.abs(traj.omega[early, 1] / linear - 1.0).max() < 1e-3  # measured 1.0e-4
    # then the hull turns past broadside: its x axis is reversed (more than 170°) within 6 s
    axis_x = attitude.rotate(traj.q, np.array([1.0, 0.0, 0.0]))
    assert np.degrees(np.arccos(np.clip(axis_x[traj.t <= 6.0, 0], -1.0, 1.0))).max() > 170.0
    # the integrals, at the file's rtol = atol = 1e-10; the angular impulse about the inertial origin against the
    # size of its terms |x| |P| (it is a small difference of large ones far from the start). Measured: ≤ 5.6e-13
    # (T, R P, |P|²) and 2.5e-13 of |x| |P| = 1.4e4 N m s
    kept = model.invariants(traj)
    for name in ("energy", "linear_impulse_inertial", "impulse_squared"):
        value = kept[name]
        assert np.abs(value - value[0]).max() < 1e-10 * np.abs(value).max(), name
    size = np.linalg.norm(traj.position, axis=-1).max() * np.linalg.norm(traj.linear_impulse, axis=-1).max()
    assert np.abs(kept["momentum_inertial"] - kept["momentum_inertial"][0]).max() < 1e-10 * size


def test_the_kind_follows_from_the_fluid_table():
    without = re.sub(r'(?m)^kind = ".*"\n', "", TEXT, count=1)
    assert without != TEXT
    assert parse(without, source=str(EXAMPLE)).kind == "fluid"


# (text replaced, replacement, key of the problem)
BAD = [
    ("ellipsoid = [1.0, 0.2, 0.2]", "ellipsoid = [1.0, -0.2, 0.2]", "fluid.ellipsoid"),
    ("density = 1025.0", "", "fluid"),
    ("density = 1025.0", "added_mass = [[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]]", "fluid.added_mass"),
    ("ellipsoid = [1.0, 0.2, 0.2]     # m: the hull's semi-axes, body axes\ndensity = 1025.0",
     "added_mass = [[1.0, 0.0, 0.0, 0.0, 0.5, 0.0], [0.0, 1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0], "
     "[0.0, 0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]]",
     "fluid.added_mass"),
    ("velocity = [2.0, 0.0, 0.0]", "velocity = [2.0, 0.0]", "initial.velocity"),
    ("mass = 171.74", "mass = 0.0", "body.mass"),
]


@pytest.mark.parametrize(("old", "new", "key"), BAD, ids=[b[2] + "-" + str(i) for i, b in enumerate(BAD)])
def test_a_bad_file_is_refused_naming_the_key(old, new, key):
    assert old in TEXT
    with pytest.raises(ScenarioError) as info:
        parse(TEXT.replace(old, new), source="case.toml").build()
    assert info.value.field == key, str(info.value)
    assert str(info.value).startswith(f"case.toml: {key}: ")


def test_the_asymmetric_added_mass_of_a_file_is_refused_with_the_librarys_rule():
    old, new, key = BAD[3]
    with pytest.raises(ScenarioError, match=r"^case.toml: fluid.added_mass: must be symmetric \(an ideal fluid's "
                                            r"added mass is\), got max \|M − Mᵀ\| = 0.5$"):
        parse(TEXT.replace(old, new), source="case.toml").build()


@pytest.mark.slow  # runs the example and draws its figure (about 10 CPU s cold)
def test_tumble_run_writes_the_trajectory_the_figure_and_the_summary(tmp_path, example):
    out, png = tmp_path / "out.nc", tmp_path / "out.png"
    result = CliRunner().invoke(app, ["run", str(EXAMPLE), "-o", str(out), "--plot", str(png), "--quiet"])
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == PNG_MAGIC
    saved = tumble.load(out)
    np.testing.assert_array_equal(saved.energy, example[1].energy)
    np.testing.assert_array_equal(saved.position, example[1].position)
    (label, value), = example[0].rows(example[1])
    assert label == "path" and value.startswith("37.68 m from the start; body x turned ")
    assert f"{label} {value}" in " ".join(result.stdout.split())


def test_the_docs_show_the_example_as_it_is():
    docs = (Path(__file__).resolve().parents[2] / "docs" / "scenarios.md").read_text(encoding="utf-8")
    shown = dict(re.findall(r"```toml\n# examples/(\S+)\n(.*?)```", docs, flags=re.S))
    assert shown["fluid/munk_moment.toml"] == TEXT
