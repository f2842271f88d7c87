"""The imports of ``src/tumble`` go one way: a module imports only modules of its own layer or of the layers
below it (:data:`LAYERS`), and no modules import one another in a circle.

The graph is read from the source with :mod:`ast`, without importing anything: every ``import a.b`` and
``from a import b`` (absolute or relative), at module level and inside functions, is an edge to the module it
names (``from a import b`` names the module ``a.b`` when there is one, else ``a``), and to the package
``__init__`` modules on the way that Python runs with it (those of the importer's own packages aside: they
are already running). Imports under ``if TYPE_CHECKING:`` are left out: they are never executed.
``importlib.import_module(name)`` with a name computed at run time (the lazy attributes of ``tumble``, the
tables of the CLI and the scenario kinds) cannot be read from the source and is not in the graph.

An import that goes up a layer is reported as such, with its file and line; the cycles are then looked for
among the imports that remain (within one layer, since every other edge goes down), and each is listed.
"""

from __future__ import annotations

import ast
import functools
import shutil
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"

#: The layers, bottom first (docs/architecture.md, "The tree"): each entry places a module, or a package with
#: all the modules under it; the longest entry that names a module places it. Every module of src/tumble must
#: be placed, and every entry must name a module that exists.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("ground floor", ("tumble._quat", "tumble._vec", "tumble._validate", "tumble._inertia", "tumble._elliptic",
                      "tumble._free_flow", "tumble._gravity", "tumble._files", "tumble._cache", "tumble._compiling",
                      "tumble._callback", "tumble._protocol", "tumble._block", "tumble._version", "tumble._moved",
                      "tumble.limits", "tumble._kinds")),
    ("values", ("tumble.attitude", "tumble.dynamics", "tumble.rigid_body", "tumble.torques")),
    ("result", ("tumble._netcdf", "tumble.trajectory")),
    ("estimators", ("tumble.estimation",)),
    ("kernels", ("tumble.kernels",)),
    ("integrate", ("tumble.integrate",)),
    ("front door", ("tumble", "tumble.model", "tumble.rigid_model", "tumble._rigid_cuda", "tumble.simulate")),
    ("domain", ("tumble.analytic", "tumble.axisymmetric", "tumble.flexible", "tumble.fluid", "tumble.ins",
                "tumble.lorentz", "tumble.measure", "tumble.robot", "tumble.slosh", "tumble.spacecraft",
                "tumble.variable")),
    ("sweeps", ("tumble.ensemble", "tumble.sweep", "tumble.sweeps")),
    ("scenario, viz", ("tumble.scenario", "tumble.viz", "tumble.examples")),
    ("cli", ("tumble.cli", "tumble.__main__", "tumble._cli_errors", "tumble._warmup", "tumble.robot.cli")),
)

#: Upward imports kept for one release by a deprecated name, each with its replacement: (importer, imported) ->
#: why it is still here. An entry whose import is gone fails the test, so that it is deleted with the import.
PENDING: dict[tuple[str, str], str] = {
    ("tumble.simulate", "tumble.sweeps"): "the deprecated simulate(store=...) streams through "
                                          "tumble.sweeps.simulate_to_store; removed in 0.5",
    ("tumble.simulate", "tumble.sweeps.stream"): "the same import as ('tumble.simulate', 'tumble.sweeps')",
    ("tumble.sweeps", "tumble.scenario"): "the deprecated tumble.sweeps.sweep_scenario, now "
                                          "tumble.scenario.sweep_scenario; removed in 0.5",
}


#: Upward imports by design, each with its reason: the public namespace registers what the layers above it
#: provide to the ones below (a registry filled from above, not an import from below).
REGISTRATIONS: dict[tuple[str, str], str] = {
    ("tumble", "tumble.viz"): "`import tumble` registers the Trajectory's views (figure, viewer page, tables), "
                              "which tumble.viz.trajectory draws, in tumble.trajectory.VIEWS",
    ("tumble", "tumble.viz.trajectory"): "the same as ('tumble', 'tumble.viz')",
}


def module_files(root: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file of the package ``root/tumble``."""
    files = {}
    for path in sorted((root / "tumble").rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        files[".".join(parts)] = path
    return files


def _type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _named(node: ast.Import | ast.ImportFrom, package: str, modules: Mapping[str, Path]) -> Iterable[str]:
    """The modules an import statement names (each the longest name of it that is a module of ``modules``)."""
    def known(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    if isinstance(node, ast.Import):
        names = [alias.name for alias in node.names]
    else:
        base = node.module or ""
        if node.level:
            parts = package.split(".")[: len(package.split(".")) - node.level + 1]
            base = ".".join(parts + ([node.module] if node.module else []))
        names = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base for alias in node.names]
    return filter(None, map(known, names))


def imports(module: str, path: Path, modules: Mapping[str, Path]) -> list[tuple[str, int]]:
    """``(imported module, line)`` for each tumble module that ``module`` (its source at ``path``) imports,
    anywhere but under ``if TYPE_CHECKING:``, with the packages Python runs on the way."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    ancestors = {module.rsplit(".", k)[0] for k in range(module.count(".") + 1)}
    found: list[tuple[str, int]] = []

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _type_checking(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            for name in _named(node, package, modules):
                parts = name.split(".")
                for k in range(1, len(parts) + 1):
                    target = ".".join(parts[:k])
                    if target in modules and (k == len(parts) or target not in ancestors):
                        found.append((target, node.lineno))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(_parsed(path.read_text(encoding="utf-8")))
    return found


@functools.cache
def _parsed(source: str) -> ast.Module:
    """The syntax tree of a module's source, parsed once per text: the planted copies of the package share
    every file but one with it."""
    return ast.parse(source)


def layer_of(module: str, layers: Sequence[tuple[str, Sequence[str]]]) -> int | None:
    """The index in ``layers`` of the longest entry that is ``module`` or a package above it, or None."""
    best: tuple[int, int] | None = None
    for index, (_, entries) in enumerate(layers):
        for entry in entries:
            covers = module == entry or (entry != "tumble" and module.startswith(entry + "."))
            if covers and (best is None or len(entry) > best[1]):
                best = (index, len(entry))
    return None if best is None else best[0]


def _shortest_cycle(start: str, graph: Mapping[str, Mapping[str, int]]) -> list[str]:
    """The shortest path start -> ... -> start in ``graph`` (breadth first, neighbours in name order)."""
    came_from: dict[str, str] = {}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for nxt in sorted(graph[node]):
                if nxt == start:
                    path = [node]
                    while path[-1] != start:
                        path.append(came_from[path[-1]])
                    return path[::-1] + [start]
                if nxt not in came_from:
                    came_from[nxt] = node
                    following.append(nxt)
        frontier = following
    return []


def _cycles(graph: Mapping[str, Mapping[str, int]]) -> list[list[str]]:
    """One shortest cycle through the first module (by name) of each strongly connected component."""
    reach: dict[str, set[str]] = {}
    for start in graph:
        seen, stack = set(), [start]
        while stack:
            for nxt in graph[stack.pop()]:
                if nxt not in seen:
                    seen.add(nxt)
                    stack.append(nxt)
        reach[start] = seen
    cycles, done = [], set()
    for module in sorted(graph):
        if module in done or module not in reach[module]:
            continue
        component = {other for other in reach[module] if module in reach[other]}
        done |= component
        cycles.append(_shortest_cycle(module, graph))
    return cycles


def violations(root: Path, layers: Sequence[tuple[str, Sequence[str]]] = LAYERS,
               pending: Mapping[tuple[str, str], str] = {**PENDING, **REGISTRATIONS}) -> list[str]:
    """Every breach of the layers by the package ``root/tumble``, one message each."""
    modules = module_files(root)
    rel = {name: path.relative_to(root).as_posix() for name, path in modules.items()}
    problems = [f"{name}: not placed in a layer (add it to LAYERS in tests/test_import_layers.py)"
                for name in modules if layer_of(name, layers) is None]
    problems += [f"LAYERS: {entry!r} ({layer}) is not a module of src/tumble"
                 for layer, entries in layers for entry in entries if entry not in modules]
    graph: dict[str, dict[str, int]] = {}
    for name, path in modules.items():
        edges = graph.setdefault(name, {})
        for target, line in imports(name, path, modules):
            edges.setdefault(target, line)
    problems += [f"PENDING: {importer} no longer imports {imported}: delete the entry"
                 for importer, imported in pending if imported not in graph.get(importer, {})]
    for importer, edges in graph.items():
        for imported, line in list(edges.items()):
            if (importer, imported) in pending:
                del edges[imported]
                continue
            low, high = layer_of(importer, layers), layer_of(imported, layers)
            if low is not None and high is not None and high > low:
                problems.append(f"{rel[importer]}:{line}: {importer} ({layers[low][0]}) imports {imported} "
                                f"({layers[high][0]}), a layer above it")
                del edges[imported]
    for cycle in _cycles(graph):
        steps = [f"{a} ({rel[a]}:{graph[a][b]})" for a, b in zip(cycle, cycle[1:])]
        problems.append("import cycle: " + " -> ".join(steps + [cycle[-1]]))
    return problems


def test_every_module_is_placed_and_imports_go_down_the_layers_without_cycles():
    assert violations(SRC) == []


def _copy(tmp_path: Path) -> Path:
    shutil.copytree(SRC / "tumble", tmp_path / "tumble", ignore=shutil.ignore_patterns("__pycache__", "*.nbi",
                                                                                         "*.nbc"))
    return tmp_path


def _plant(root: Path, module: str, code: str) -> int:
    """Append ``code`` to ``module``'s file; the line of its last line."""
    path = root / (module.replace(".", "/") + ".py")
    text = path.read_text(encoding="utf-8")
    path.write_text(text + code, encoding="utf-8")
    return len((text + code).splitlines())


def _line(root: Path, module: str, statement: str) -> int:
    lines = (root / (module.replace(".", "/") + ".py")).read_text(encoding="utf-8").splitlines()
    return lines.index(statement) + 1


def test_a_planted_cycle_is_listed_with_each_file_and_line(tmp_path):
    root = _copy(tmp_path)
    line = _plant(root, "tumble._quat", "\n\ndef _planted():\n    from tumble import _inertia\n")
    back = _line(root, "tumble._inertia", "from tumble import _quat")
    assert violations(root) == [f"import cycle: tumble._inertia (tumble/_inertia.py:{back}) -> "
                                f"tumble._quat (tumble/_quat.py:{line}) -> tumble._inertia"]


def test_a_planted_upward_import_in_a_function_names_its_line_and_both_layers(tmp_path):
    root = _copy(tmp_path)
    line = _plant(root, "tumble._vec", "\n\ndef _planted():\n    import tumble.cli\n")
    assert violations(root) == [f"tumble/_vec.py:{line}: tumble._vec (ground floor) imports tumble.cli (cli), "
                                f"a layer above it"]


def test_a_relative_import_of_a_package_counts_its_init(tmp_path):
    root = _copy(tmp_path)
    line = _plant(root, "tumble.kernels.rigid", "\n\ndef _planted():\n    from ..analytic import _free\n")
    assert violations(root) == [
        f"tumble/kernels/rigid.py:{line}: tumble.kernels.rigid (kernels) imports {name} (domain), a layer above it"
        for name in ("tumble.analytic", "tumble.analytic._free")]


def test_an_import_under_type_checking_is_not_an_edge(tmp_path):
    root = _copy(tmp_path)
    _plant(root, "tumble._vec", "\n\nfrom typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n    import tumble.cli\n")
    assert violations(root) == []


def test_a_new_module_must_be_placed_and_a_stale_entry_is_named(tmp_path):
    root = _copy(tmp_path)
    (root / "tumble" / "planted.py").write_text('"""Planted."""\n', encoding="utf-8")
    layers = LAYERS + (("attic", ("tumble.gone",)),)
    assert violations(root, layers) == [
        "tumble.planted: not placed in a layer (add it to LAYERS in tests/test_import_layers.py)",
        "LAYERS: 'tumble.gone' (attic) is not a module of src/tumble"]


def test_a_pending_import_that_is_gone_must_be_deleted(tmp_path):
    root = _copy(tmp_path)
    pending = {**PENDING, **REGISTRATIONS, ("tumble._vec", "tumble.cli"): "planted"}
    assert violations(root, pending=pending) == ["PENDING: tumble._vec no longer imports tumble.cli: delete the entry"]
