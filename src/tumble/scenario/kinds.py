"""The kind table: which model a scenario file describes, and the module that reads it.

A file says its kind with a top-level ``kind = "..."``. A file without one
keeps working: its kind is the one whose marker table it has (``[spacecraft]``
→ ``"spacecraft"``, ``[robot]`` → ``"robot"``, ...), else ``"rigid"``.

Adding a scenario kind is one module (a :class:`tumble.scenario.Scenario`
subclass with the kind's tables, ``build()`` returning a problem with
``.model`` and ``.simulate(progress=...)``, and ``figure(traj)``) and one row
of :data:`tumble._kinds.SCENARIOS`, the registry of model kinds (``docs/architecture.md``, "Adding a model
kind").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from tumble._kinds import SCENARIOS, ScenarioKind, resolve
from tumble.scenario._errors import ScenarioError, short

if TYPE_CHECKING:
    from tumble.scenario._base import Scenario

__all__ = ["DEFAULT_KIND", "KINDS", "Kind", "kind_of", "scenario_class"]


#: Scenario kind -> its row (the model kinds' registry, :data:`tumble._kinds.SCENARIOS`).
KINDS = SCENARIOS
Kind = ScenarioKind

#: The kind of a file that neither says ``kind`` nor has a marker table.
DEFAULT_KIND = "rigid"


def kind_of(data: dict) -> str:
    """The kind of the parsed TOML ``data``: its ``kind`` key, else the kind of its marker table, else
    :data:`DEFAULT_KIND`. Raises :class:`~tumble.scenario.ScenarioError` (no file named yet) for an
    unknown kind, naming the kinds, or for a file with the marker tables of two kinds."""
    names = ", ".join(map(repr, KINDS))
    if "kind" in data:
        kind = data["kind"]
        if not isinstance(kind, str) or kind not in KINDS:
            raise ScenarioError("", [("kind", f"must be one of {names}, got {short(kind)}")])
        return kind
    marked = [name for name, row in KINDS.items() if row.table is not None and isinstance(data.get(row.table), dict)]
    if len(marked) > 1:
        tables = " and ".join(f"[{KINDS[name].table}]" for name in marked)
        raise ScenarioError("", [("kind", f"missing required key: a file with {tables} must say which kind it is "
                                          f"(one of {names})")])
    return marked[0] if marked else DEFAULT_KIND


def scenario_class(kind: str) -> type[Scenario]:
    """The :class:`~tumble.scenario.Scenario` subclass of ``kind`` (a key of :data:`KINDS`)."""
    return resolve(KINDS[kind].scenario)
