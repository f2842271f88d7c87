"""No module of ``src/tumble`` over :data:`LIMIT` lines unless its docstring says why.

The reason is stated as the long modules state it: "... is one unit (about N lines): <why>" (``attitude.py``:
every representation converts through the same checks; ``spacecraft/model.py``: the checks, compiled parts,
initial state and outputs read one list of parts; ``analytic/_heavy_top.py``: the class whose methods read the
same constants of motion). N counts the unit (the module or its one class), so it is at most the module's lines;
the reason is a clause of at least five words after the parenthesis.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "tumble"
LIMIT = 500
#: "one unit (about N lines)" and the reason that follows it, to the end of its sentence.
REASON = re.compile(r"\bone unit \(about (\d+) lines\)[,:]?\s+(?P<why>[^.]+)")


def unstated(source: str) -> str | None:
    """Why a module over :data:`LIMIT` lines fails the rule (None: it states its reason)."""
    lines = len(source.splitlines())
    if lines <= LIMIT:
        return None
    docstring = " ".join((ast.get_docstring(ast.parse(source)) or "").split())
    match = REASON.search(docstring)
    if match is None:
        return f"{lines} lines and no 'one unit (about N lines): why' in its docstring"
    if int(match[1]) > lines:
        return f"{lines} lines, but its docstring says its unit is about {match[1]} lines"
    if len(match["why"].split()) < 5:
        return f"{lines} lines, and its docstring's reason is {match['why']!r}"
    return None


def test_every_long_module_states_why():
    failures = {path.relative_to(SRC).as_posix(): unstated(path.read_text(encoding="utf-8"))
                for path in sorted(SRC.rglob("*.py"))}
    assert {name: why for name, why in failures.items() if why} == {}


@pytest.mark.parametrize("docstring, why", [
    ("A module.", "501 lines and no 'one unit (about N lines): why' in its docstring"),
    ("It is one unit (about 900 lines): the same checks read each other.",
     "501 lines, but its docstring says its unit is about 900 lines"),
    ("It is one unit (about 450 lines): long.", "501 lines, and its docstring's reason is 'long'"),
    ("It is one unit (about 450 lines): every function reads the same table of parts.", None),
])
def test_the_rule_on_planted_modules(docstring, why):
    source = f'"""{docstring}"""\n' + "x = 1\n" * 500
    assert unstated(source) == why


def test_a_short_module_needs_no_reason():
    assert unstated('"""A module."""\n' + "x = 1\n" * 499) is None
