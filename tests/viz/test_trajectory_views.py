"""The result type imports nothing above it: its figure, viewer page, notebook view and table are views that
tumble.viz.trajectory registers in tumble.trajectory.VIEWS when `import tumble` loads it."""

import ast
from pathlib import Path

import numpy as np
import pytest

import tumble
import tumble.trajectory
import tumble.viz.trajectory as views

SRC = Path(tumble.__file__).parent
#: What the result type and its file format may not import, at any level (outside `if TYPE_CHECKING:`).
ABOVE = ("tumble.viz", "tumble._tables", "tumble.scenario", "tumble.cli", "tumble.sweep",
         "matplotlib", "pandas")


def _imports(path: Path) -> set[str]:
    """Every module ``path`` imports, module level or inside functions, but not under ``if TYPE_CHECKING:``."""
    found: set[str] = set()
    nodes: list[ast.AST] = [ast.parse(path.read_text(encoding="utf-8"))]
    while nodes:
        node = nodes.pop()
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            continue
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = "tumble" + ("." + node.module if node.module else "") if node.level else node.module
            found |= {base} | {f"{base}.{alias.name}" for alias in node.names}
        nodes.extend(ast.iter_child_nodes(node))
    return found


@pytest.mark.parametrize("name", ["trajectory.py", "_netcdf.py"])
def test_the_result_type_imports_nothing_above_it(name):
    above = sorted(m for m in _imports(SRC / name) if any(m == a or m.startswith(a + ".") for a in ABOVE))
    assert above == []


def test_import_tumble_fills_the_views_with_the_functions_of_viz():
    assert tumble.trajectory.VIEWS == {"plot": views.plot, "to_html": views.to_html,
                                       "notebook_html": views.notebook_html, "to_dataframe": views.to_dataframe}


def test_the_methods_are_the_views():
    traj = tumble.Trajectory(t=[0.0, 1.0], q=[[1.0, 0, 0, 0]] * 2, omega=[[0.0, 0.0, 2.0]] * 2,
                             inertia=np.diag([1.0, 2.0, 3.0]), method="exact")
    assert traj._repr_html_() == views.notebook_html(traj)
    assert traj.to_dataframe().equals(views.to_dataframe(traj))
    figure = traj.plot(title="t")
    assert figure._suptitle.get_text() == "t" and len(figure.axes) == 3
