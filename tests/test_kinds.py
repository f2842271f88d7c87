"""The registry of model kinds (`tumble._kinds`): every kind has each of its pieces, and the tables that name
kinds read it.

Each row is checked for its model class, its kernel, its scenario table, its viewer glyph and its warm-up
example without compiling (the fast tests: building a model and its kernel's `provides` compiles nothing).
Running the examples is `tumble warmup`'s and `benchmarks/bench_startup.py`'s (it compiles every kind: minutes on a
cold cache); each kind's own test module runs it under its methods.
"""

import inspect

import numpy as np
import pytest

import tumble
from tumble import _kinds, _warmup
from tumble._kinds import ATTITUDE, MODEL_KINDS, SCENARIOS, resolve
from tumble._validate import ValidationError
from tumble.scenario import Scenario
from tumble.scenario.kinds import scenario_class
from tumble.viz.viewer import html_page
from tumble.viz.viewer.scenes import BUILDERS


@pytest.fixture(scope="module")
def examples():
    """Kind -> (model, initial state) of its warm-up example."""
    return {name: _warmup.example(name) for name in MODEL_KINDS}


@pytest.mark.parametrize("name", MODEL_KINDS)
def test_the_example_is_a_model_of_the_class_the_row_names_and_of_its_kind(name, examples):
    cls = resolve(MODEL_KINDS[name].model)
    model, _ = examples[name]
    assert inspect.isclass(cls) and isinstance(model, cls)
    assert model.kind == name


@pytest.mark.parametrize("name", MODEL_KINDS)
def test_the_kernel_is_the_module_of_the_compiled_model(name, examples):
    model, _ = examples[name]
    kernel = model.compile(None, 0.0)
    assert type(kernel).__module__ == MODEL_KINDS[name].kernel
    assert "rhs" in kernel.provides  # every kind runs under a fixed-step scheme (tests/test_models.py)


@pytest.mark.parametrize("name", MODEL_KINDS)
def test_the_scenario_table_loads(name):
    kind = MODEL_KINDS[name].scenario
    assert kind in SCENARIOS
    assert issubclass(scenario_class(kind), Scenario)


def test_every_scenario_kind_builds_some_model_kind():
    assert {kind.scenario for kind in MODEL_KINDS.values()} == set(SCENARIOS)
    assert tumble.scenario.KINDS is SCENARIOS  # the scenario package reads the registry


def _two_samples(name, attitude):
    """A trajectory of the kind ``name``: two samples at rest, with or without an attitude."""
    return tumble.Trajectory(t=np.array([0.0, 1.0]), q=np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)) if attitude else None,
                             omega=np.zeros((2, 3)) if attitude else None,
                             inertia=np.diag([1.0, 2.0, 3.0]) if attitude else None,
                             totals={} if attitude else {"energy": np.zeros(2)}, model=name)


@pytest.mark.parametrize("name", MODEL_KINDS)
def test_the_glyph_is_the_viewer_scene_of_the_kind(name):
    glyph = MODEL_KINDS[name].glyph
    if glyph not in (None, ATTITUDE):
        assert BUILDERS[name] is resolve(f"tumble.viz.viewer.scenes.{glyph}:scene")
        return
    # without a scene module: drawn from its attitude by the rigid body's scene, else refused by name (whether
    # the kind has an attitude is checked on a run by test_the_example_runs_for_the_default_method)
    assert name not in BUILDERS
    if glyph == ATTITUDE:
        assert html_page(_two_samples(name, attitude=True)).startswith("<!DOCTYPE html>")
    with pytest.raises(ValidationError, match=f"traj: a {name} trajectory without an attitude has no scene"):
        html_page(_two_samples(name, attitude=False))


@pytest.mark.parametrize("name", MODEL_KINDS)
def test_the_example_provides_the_default_method(name, examples):
    # checked without compiling: the methods whose needs the kernel's declared capabilities meet
    assert "dop853" in _warmup.methods(name)
    assert inspect.signature(tumble.simulate).parameters["method"].default == "dop853"


def test_the_warmup_paths_are_every_kind_of_the_registry_under_its_methods():
    kinds = [path.split(", ")[0] for path in _warmup.paths() if path.split(", ")[0] in MODEL_KINDS]
    assert list(dict.fromkeys(kinds)) == list(MODEL_KINDS)


def test_the_registry_imports_none_of_its_pieces():
    source = inspect.getsource(_kinds)
    assert [line for line in source.splitlines() if line.startswith(("import ", "from "))] == [
        "from __future__ import annotations", "import importlib", "from dataclasses import dataclass",
        "from typing import Any"]
