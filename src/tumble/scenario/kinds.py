"""The kind table: which model a scenario file describes, and the module that reads it.

A file says its kind with a top-level ``kind = "..."``. A file without one
keeps working: its kind is the one whose marker table it has (``[spacecraft]``
→ ``"spacecraft"``, ``[robot]`` → ``"robot"``, ...), else ``"rigid"``.

Adding a model kind is one module (a :class:`tumble.scenario.Scenario`
subclass with the kind's tables, ``build()`` returning a problem with
``.model`` and ``.simulate(progress=...)``, and ``figure(traj)``) and one row
here.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

from tumble.scenario._errors import ScenarioError, short

if TYPE_CHECKING:
    from tumble.scenario._base import Scenario

__all__ = ["DEFAULT_KIND", "KINDS", "Kind", "kind_of", "scenario_class"]


@dataclass(frozen=True)
class Kind:
    """One row of the kind table.

    scenario    : ``"module:Class"``, the kind's top-level table (a :class:`~tumble.scenario.Scenario` subclass),
                  imported only when a file of this kind is read
    table       : a top-level table whose presence means this kind in a file without ``kind`` (None: none)
    description : what the kind simulates, in words
    """

    scenario: str
    table: str | None
    description: str


KINDS = {
    "rigid": Kind("tumble.scenario.rigid:RigidScenario", None,
                  "a rigid body under external torques, optionally with a nutation [damper] (tumble.RigidBody)"),
    "spacecraft": Kind("tumble.scenario.spacecraft:SpacecraftScenario", "spacecraft",
                       "a spacecraft with wheels, CMGs, thrusters, magnetorquers and controllers "
                       "(tumble.spacecraft.Spacecraft)"),
    "flexible": Kind("tumble.scenario.flexible:FlexibleScenario", "flexible",
                     "a hub with flexible appendages: cantilever modes of the hybrid-coordinate model "
                     "(tumble.flexible.FlexibleBody)"),
    "slosh": Kind("tumble.scenario.slosh:SloshScenario", "slosh",
                  "a free-floating hub with a fuel-slosh pendulum (tumble.slosh.SloshBody)"),
    "variable": Kind("tumble.scenario.variable:VariableScenario", "variable",
                     "a body whose inertia and shape momentum are tabulated in time (tumble.variable.VariableBody)"),
    "human": Kind("tumble.scenario.human:HumanScenario", "human",
                  "a human body in flight moving its joints: de Leva's segments (tumble.variable.MovingHuman)"),
    "gyroscope": Kind("tumble.scenario.gyroscope:GyroscopeScenario", "gyroscope",
                      "a spinning rotor on a pivot or in a two-axis gimbal (tumble.ins.Gyroscope, "
                      "tumble.ins.GimbaledGyro)"),
    "robot": Kind("tumble.scenario.robot:RobotScenario", "robot",
                  "a robot arm on a fixed base from a DH table or URDF file (tumble.robot.SerialChain)"),
}

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
    module, name = KINDS[kind].scenario.split(":")
    return getattr(importlib.import_module(module), name)
