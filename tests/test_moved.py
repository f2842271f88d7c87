"""Figures and demos moved out of the model modules into tumble.viz: the old public names warn and still work."""

import importlib

import pytest

MOVED = [
    ("tumble.flexible", "demo_flexible", "tumble.viz.flexible"),
    ("tumble.flexible", "slew_figure", "tumble.viz.flexible"),
    ("tumble.slosh", "demo_slosh", "tumble.viz.slosh"),
    ("tumble.slosh", "nutation_figure", "tumble.viz.slosh"),
    ("tumble.spacecraft", "gravity_gradient_stability_figure", "tumble.viz.passive"),
    ("tumble.spacecraft", "spacecraft_figure", "tumble.viz.spacecraft"),
    ("tumble.spacecraft", "save_spacecraft_figure", "tumble.viz.spacecraft"),
    ("tumble.spacecraft.figure", "spacecraft_figure", "tumble.viz.spacecraft"),
    ("tumble.spacecraft.passive", "demo_explorer1", "tumble.viz.passive"),
    ("tumble.spacecraft.passive", "demo_gravity_gradient", "tumble.viz.passive"),
    ("tumble.spacecraft.passive", "explorer1_figure", "tumble.viz.passive"),
    ("tumble.spacecraft.budget", "demo_budget", "tumble.viz.budget"),
    ("tumble.ins", "allan_figure", "tumble.viz.ins"),
    ("tumble.ins", "demo_ins", "tumble.viz.ins"),
    ("tumble.ins.allan", "allan_figure", "tumble.viz.ins"),
    ("tumble.ins.demo", "demo_coning", "tumble.viz.ins"),
    ("tumble.ins.demo", "DEMO_GYRO", "tumble.viz.ins"),
    ("tumble.ins.demo", "CONING_RANGES", "tumble.ins.coning"),
    ("tumble.robot.cli", "app", "tumble.cli.robot"),
    ("tumble.robot.demo", "demo_robot", "tumble.viz.robot"),
    ("tumble.robot.space_demo", "space_arm", "tumble.viz.space_arm"),
    ("tumble.variable.demo", "figure_dive", "tumble.viz.diver"),
    ("tumble._cli_errors", "exit_codes", "tumble.cli.errors"),
]


@pytest.mark.parametrize(("old", "name", "new"), MOVED)
def test_a_moved_name_warns_naming_its_new_place_and_is_the_same_object(old, name, new):
    with pytest.warns(DeprecationWarning, match=rf"^{old}\.{name} moved to {new}\.{name}; "):
        value = getattr(importlib.import_module(old), name)
    assert value is getattr(importlib.import_module(new), name)


def test_an_unknown_name_is_still_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'tumble.flexible' has no attribute 'demo_nothing'"):
        importlib.import_module("tumble.flexible").demo_nothing  # noqa: B018


MODEL_MODULES = ["flexible.py", "slosh.py", "lorentz.py", "spacecraft/passive.py", "spacecraft/budget.py",
                 "spacecraft/__init__.py", "spacecraft/figure.py", "ins/allan.py", "ins/__init__.py"]


@pytest.mark.parametrize("path", MODEL_MODULES)
def test_a_model_module_imports_no_matplotlib(path):
    """Their figures and demos live in tumble.viz: no import of matplotlib, at any level, in the model's source."""
    import ast
    from pathlib import Path

    import tumble

    tree = ast.parse((Path(tumble.__file__).parent / path).read_text(encoding="utf-8"))
    imported = [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]
    imported += [node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module]
    assert [name for name in imported if name.split(".")[0] == "matplotlib"] == []
