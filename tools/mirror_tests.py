"""Move the test modules into folders that mirror the package they test, and fix what the move breaks.

Run from the repository root: ``python tools/mirror_tests.py`` (``--dry-run``: print the plan, change nothing).
It is idempotent: a second run finds nothing to move and nothing to rewrite.

1. Each ``tests/test_*.py`` goes with ``git mv`` (a plain rename for an untracked file) to the folder that
   :data:`FOLDERS` gives for its name, or else the first rule of :data:`RULES` its name starts with, or else
   the root for the test of a top-level module (:func:`folder_of`); the tests of the root package and the
   cross-cutting ones (docs, package, import layers, reliability) stay in
   ``tests/``, and so does a name nothing matches (printed). The name stays: pytest imports the modules in
   its default ``prepend`` mode, as top-level modules named after their file, which must therefore be unique
   across the folders (checked here, before anything moves).
2. In a moved module, ``Path(__file__)``'s repository-root lookups go one level further up
   (``parents[1]`` → ``parents[2]``, ``.parent.parent`` → ``parents[2]``); :data:`PATCHES` fixes the few
   places that need more (a module's own folder and ``tests/`` both on a subprocess's path, the benchmarks
   that import a test module).
3. Every ``tests/test_NAME.py`` named in a tracked text file (docs, sources, benchmarks, tests, .ci,
   pyproject.toml; not CHANGELOG.md, which is history) and every glob ``tests/test_PREFIX*.py`` whose files
   share one folder is rewritten to the file's folder; tests/conftest.py groups the model kinds of
   ``--dist loadfile`` by folder; pyproject.toml puts ``tests/`` on pytest's ``pythonpath`` for the
   top-level helper modules (helpers.py, compile_profile.py, robot_oracle.py, ahrs_peer.py).
4. It prints what it cannot fix: an import of a test module from another folder.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests"

#: Test module → its folder under tests/ ("" the root: the root package and the cross-cutting checks).
FOLDERS = {
    # analytic: the closed forms (tumble.analytic)
    "test_analytic_free.py": "analytic", "test_geometry.py": "analytic", "test_heavy_top.py": "analytic",
    "test_integrable.py": "analytic", "test_stability.py": "analytic",
    # measure: flips, Lyapunov exponents, Poincaré sections (tumble.measure)
    "test_analysis.py": "measure", "test_lyapunov.py": "measure", "test_poincare.py": "measure",
    # integrate: the engine and its methods, the GPU included (tumble.integrate)
    "test_cuda.py": "integrate", "test_cuda_models.py": "integrate", "test_exactsplit.py": "integrate",
    "test_geometric.py": "integrate", "test_methods.py": "integrate",
    "test_featherstone_layout.py": "kernels",
    "test_cli.py": "cli", "test_cli_demo.py": "cli",
    "test_diver.py": "variable", "test_variable.py": "variable",
    "test_chaos_demo.py": "viz", "test_trajectory_views.py": "viz", "test_viewer.py": "viz",
    "test_viewer_browser.py": "viz",
    "test_scenario.py": "scenario", "test_scenario_kinds.py": "scenario",
    # the root package, where no module is named after the test (a test_NAME.py of a module tumble/NAME.py
    # stays in the root without an entry: folder_of)
    "test_body.py": "", "test_cache.py": "", "test_compiling.py": "", "test_frames.py": "", "test_front_door.py": "",
    "test_kinds.py": "",
    # cross-cutting: every model, the package, the docs, the import graph, the renamed modules
    "test_models.py": "", "test_package.py": "", "test_docs.py": "", "test_import_layers.py": "",
    "test_module_size.py": "", "test_moved.py": "", "test_moved_modules.py": "", "test_layout.py": "",
}

#: For a module :data:`FOLDERS` does not name: the first prefix its name starts with gives its folder.
RULES = (
    ("test_reliability", ""), ("test_spacecraft", "spacecraft"), ("test_robot", "robot"),
    ("test_estimation", "estimation"), ("test_ins_", "ins"), ("test_sweep", "sweeps"),
    ("test_scenario", "scenario"), ("test_cuda", "integrate"), ("test_viewer", "viz"), ("test_cli", "cli"),
    ("test_analytic", "analytic"), ("test_kernel", "kernels"), ("test_variable", "variable"),
)

#: Model kinds whose modules one xdist worker runs (tests/conftest.py), by folder.
KIND_FOLDERS = ("spacecraft", "robot")

#: (file after the move, text before, text after): the fixes the general rules do not make.
PATCHES = (
    # the Dask workers and the killed client import this module and helpers.py: both folders on their path
    ("tests/sweeps/test_sweep_dask.py", "TIMEOUT = 60  # s:",
     "TESTS = [str(Path(__file__).parent), str(Path(__file__).parents[1])]  # this module's folder; helpers.py's\n"
     "TIMEOUT = 60  # s:"),
    ("tests/sweeps/test_sweep_dask.py", 'str(root / "src"), str(Path(__file__).parent)])',
     'str(root / "src"), *TESTS])'),
    ("tests/sweeps/test_sweep_dask.py", "sys.path.insert(0, {tests!r})", "sys.path[:0] = {tests!r}"),
    ("tests/sweeps/test_sweep_dask.py", "tests=str(Path(__file__).parent),", "tests=TESTS,"),
    # the benchmarks that reuse a test module's data
    ("benchmarks/bench_estimation.py",
     'sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))\n',
     'sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))\n'
     'sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "estimation"))\n'),
    ("benchmarks/bench_exact.py", '/ "tests"))\nfrom test_analytic_free',
     '/ "tests" / "analytic"))\nfrom test_analytic_free'),
    ("benchmarks/robot_pinocchio_reference.py", 'sys.path.insert(0, "tests")\nfrom test_robot_urdf',
     'sys.path.insert(0, "tests/robot")\nfrom test_robot_urdf'),
    # pytest: the helper modules of tests/ importable from every folder
    ("pyproject.toml", 'testpaths = ["tests"]\n',
     'testpaths = ["tests"]\n# the tests mirror the package (tests/spacecraft/, ...); the helper modules of tests/ '
     '(helpers.py, ...) are\n# imported from every folder\npythonpath = ["tests"]\n'),
    # --dist loadfile: a model kind's modules on one worker, by folder
    ("tests/conftest.py",
     '#: Test modules whose tests compile the same model kind, by the start of their path:',
     '#: Test folders whose modules compile the same model kind:'),
    ("tests/conftest.py", 'KINDS = {"spacecraft": "tests/test_spacecraft_", "robot": "tests/test_robot"}',
     "KINDS = " + repr(tuple(f"tests/{folder}/" for folder in KIND_FOLDERS)).replace("'", '"')),
    ("tests/conftest.py",
     "return next((kind for kind, start in KINDS.items() if module.startswith(start)), module)",
     "return next((kind for kind in KINDS if module.startswith(kind)), module)"),
)

#: Tracked text files that keep the paths they name.
KEEP = {"CHANGELOG.md", "tools/mirror_tests.py"}

NAMED = re.compile(r"\btests/(test_\w+)\.py")
GLOB = re.compile(r"\btests/(test_\w*)\*\.py")
ROOT_LOOKUP = re.compile(r"(Path\(__file__\)(?:\.resolve\(\))?)(?:\.parents\[(\d+)\]|\.parent\.parent\b)")
IMPORT = re.compile(r"^\s*(?:from (test_\w+) import|import (test_\w+))", re.MULTILINE)


def folder_of(name: str) -> str | None:
    """The folder under tests/ of the test module ``name`` ("" the root), or None: nothing matches it.

    :data:`FOLDERS`, then the first rule of :data:`RULES` whose prefix the name starts with; else the root for
    the test of a top-level module (``test_NAME.py`` of ``src/tumble/NAME.py``: a new model module needs no
    entry)."""
    if name in FOLDERS:
        return FOLDERS[name]
    ruled = next((folder for prefix, folder in RULES if name.startswith(prefix)), None)
    if ruled is None and (ROOT / "src" / "tumble" / name.removeprefix("test_")).is_file():
        return ""
    return ruled


def locations() -> dict[str, list[str]]:
    """Test module name → the folders under tests/ that hold one of that name ("" the root)."""
    where: dict[str, list[str]] = {}
    for path in sorted(TESTS.rglob("test_*.py")):
        if "__pycache__" not in path.parts:
            where.setdefault(path.name, []).append(path.parent.relative_to(TESTS).as_posix().strip("."))
    return where


def clashes() -> dict[str, list[str]]:
    """The test module names found in several folders (pytest's prepend import mode needs each once)."""
    return {name: folders for name, folders in locations().items() if len(folders) > 1}


def current() -> dict[str, str]:
    """Test module name → its folder now ("" the root), every ``tests/**/test_*.py``."""
    return {name: folders[0] for name, folders in locations().items()}


def plan() -> tuple[list[tuple[str, str]], list[str]]:
    """The moves (name, folder) to make, and the modules of tests/ that no entry or rule places."""
    moves, unmatched = [], []
    for name, folder in current().items():
        if folder:
            continue
        target = folder_of(name)
        if target is None:
            unmatched.append(name)
        elif target:
            moves.append((name, target))
    return moves, unmatched


def tracked(path: Path) -> bool:
    return subprocess.run(["git", "ls-files", "--error-unmatch", str(path)], cwd=ROOT,
                          capture_output=True).returncode == 0


def move(name: str, folder: str) -> None:
    """``git mv tests/NAME tests/FOLDER/NAME`` and the repository-root lookups of the module one level up."""
    source, target = TESTS / name, TESTS / folder / name
    target.parent.mkdir(exist_ok=True)
    if tracked(source):
        subprocess.run(["git", "mv", str(source), str(target)], cwd=ROOT, check=True)
    else:
        source.rename(target)
        print(f"moved (untracked, not git mv): tests/{name} -> tests/{folder}/{name}")

    def up(match: re.Match) -> str:
        levels = int(match[2]) if match[2] else 1
        return f"{match[1]}.parents[{levels + 1}]"

    text = target.read_text(encoding="utf-8")
    target.write_text(ROOT_LOOKUP.sub(up, text), encoding="utf-8")
    own = [i + 1 for i, line in enumerate(text.splitlines())
           if re.search(r"Path\(__file__\)(\.resolve\(\))?\.parent\b(?!\.parent)", line)]
    if own and not any(file == f"tests/{folder}/{name}" for file, _, _ in PATCHES):
        print(f"check: tests/{folder}/{name} lines {own} use the module's own folder (now tests/{folder})")


def text_files() -> list[Path]:
    """The tracked and untracked-not-ignored text files of the repository, except :data:`KEEP`."""
    names = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                           capture_output=True, check=True).stdout.decode().split("\0")
    files = []
    for name in names:
        path = ROOT / name
        if name and name not in KEEP and path.is_file() and not path.is_symlink():
            try:
                path.read_text(encoding="utf-8")
            except UnicodeDecodeError:
                continue
            files.append(path)
    return files


def rewrite_references(where: dict[str, str]) -> list[str]:
    """``tests/test_NAME.py`` → ``tests/FOLDER/test_NAME.py`` and ``tests/test_P*.py`` → ``tests/FOLDER/test_P*.py``
    (when every module it matches is in FOLDER) in every text file; returns the files changed."""

    def named(match: re.Match) -> str:
        folder = where.get(match[1] + ".py", "")
        return f"tests/{folder}/{match[1]}.py" if folder else match[0]

    def glob(match: re.Match) -> str:
        folders = {folder for name, folder in where.items() if name.startswith(match[1])}
        return f"tests/{folders.pop()}/{match[1]}*.py" if len(folders) == 1 and "" not in folders else match[0]

    changed = []
    for path in text_files():
        text = path.read_text(encoding="utf-8")
        new = GLOB.sub(glob, NAMED.sub(named, text))
        if new != text:
            path.write_text(new, encoding="utf-8")
            changed.append(path.relative_to(ROOT).as_posix())
    return changed


def apply_patches() -> list[str]:
    """Each of :data:`PATCHES` whose text before is there; returns those found in neither form."""
    missing = []
    for name, before, after in PATCHES:
        path = ROOT / name
        text = path.read_text(encoding="utf-8") if path.is_file() else ""
        if before in text and after not in text:
            path.write_text(text.replace(before, after), encoding="utf-8")
        elif after not in text:
            missing.append(f"{name}: {before!r}")
    return missing


def stray_imports(where: dict[str, str]) -> list[str]:
    """Imports of a test module from another folder (prepend mode puts a module's own folder on sys.path)."""
    found = []
    for path in TESTS.rglob("*.py"):
        folder = path.parent.relative_to(TESTS).as_posix().strip(".")
        for match in IMPORT.finditer(path.read_text(encoding="utf-8")):
            module = (match[1] or match[2]) + ".py"
            if module in where and where[module] != folder:
                found.append(f"{path.relative_to(ROOT)} imports {module[:-3]} from tests/{where[module]}")
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dry-run", action="store_true", help="print the moves, change nothing")
    args = parser.parse_args()
    if clashes():
        sys.exit(f"test modules of one name in several folders (pytest's prepend mode needs one): {clashes()}")
    moves, unmatched = plan()
    for name, folder in moves:
        print(f"{'would move' if args.dry_run else 'move'} tests/{name} -> tests/{folder}/{name}")
    for name in unmatched:
        print(f"unmatched, stays in tests/: {name} (add it to FOLDERS or RULES in tools/mirror_tests.py)")
    if args.dry_run:
        return
    for name, folder in moves:
        move(name, folder)
    where = current()
    for name in rewrite_references(where):
        print(f"paths rewritten: {name}")
    for patch in apply_patches():
        print(f"not found, fix by hand: {patch}")
    for problem in stray_imports(where):
        print(f"fix by hand: {problem}")


if __name__ == "__main__":
    main()
