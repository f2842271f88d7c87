"""The tests mirror the package (tools/mirror_tests.py places each module), and every test file that the docs,
sources, benchmarks and tests name exists."""

import importlib.util
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("mirror_tests", ROOT / "tools" / "mirror_tests.py")
mirror_tests = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mirror_tests)

#: A test file named by its path from the repository root, a glob (``tests/viz/test_viewer*.py``) included.
NAMED = re.compile(r"\btests/(?:\w+/)*[\w*]+\.py")


def test_every_test_module_is_in_the_folder_of_what_it_tests():
    moves, unmatched = mirror_tests.plan()
    assert moves == [], "run python tools/mirror_tests.py"
    assert unmatched == [], "add the module to FOLDERS or RULES in tools/mirror_tests.py"
    assert mirror_tests.clashes() == {}


def test_the_test_files_that_the_repository_names_exist():
    named = {(path.relative_to(ROOT).as_posix(), match) for path in mirror_tests.text_files()
             for match in NAMED.findall(path.read_text(encoding="utf-8"))}
    assert len(named) > 100  # docs/reliability.md alone names ~30
    assert sorted((where, name) for where, name in named if not list(ROOT.glob(name))) == []
