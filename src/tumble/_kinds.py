"""The registry of model kinds: one row per kind, read by the scenario files, the viewer and ``tumble warmup``.

A model *kind* is what a :class:`~tumble.Trajectory` names in ``traj.model`` (``Model.kind``: ``"RigidBody"``,
``"Spacecraft"``, ...). Its pieces live in the layers they belong to — the compiled kernel in
``tumble/kernels/``, the model class in its domain, the scenario table in ``tumble/scenario/``, the viewer glyph
in the viewer's scenes, a tiny example in :mod:`tumble._warmup` — and this table names each of them once. It sits
on the ground floor and imports none of them: every piece is a dotted name, imported only where it is used
(:func:`resolve`). Whether a kind runs on a GPU is not a column: its kernel declares the ``"cuda"`` capability
(``provides``, :mod:`tumble._protocol`).

:data:`SCENARIOS` is the table of scenario kinds (a file's ``kind = "..."``): one scenario kind may build
several model kinds (``"gyroscope"``: a :class:`~tumble.ins.Gyroscope` on a pivot or a
:class:`~tumble.ins.GimbaledGyro`; ``"robot"``: a chain or a tree). ``tests/test_kinds.py`` checks that every
piece named here exists and works together; ``docs/architecture.md`` ("Adding a model kind") lists the files.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

__all__ = ["ATTITUDE", "MODEL_KINDS", "SCENARIOS", "ModelKind", "ScenarioKind", "resolve"]

#: The glyph of a kind that the rigid body's scene draws from its attitude (``traj.q``) alone.
ATTITUDE = "attitude"


def resolve(target: str) -> Any:
    """The object that ``"module:name"`` names, its module imported now."""
    module, name = target.split(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class ModelKind:
    """One model kind.

    model    : ``"module:Class"``, the model class (:class:`tumble.model.Model`) whose ``kind`` is the row's name
    kernel   : the module of its compiled kernel (``tumble.kernels...``: the NamedTuple, ``provides``, the protocol
               overloads)
    scenario : the scenario kind (a key of :data:`SCENARIOS`) whose files build it, or None
    glyph    : how the offline viewer draws it: the name of its scene module among the viewer's scenes (a function
               ``scene(traj, idx, model, options)``), :data:`ATTITUDE` (the rigid body's scene, from ``traj.q``), or
               None (no scene: the viewer refuses it by name)
    example  : ``"module:function"``, a function ``() -> (model, initial state)`` giving a tiny model of the kind and
               the keyword arguments of ``simulate`` that start it (what ``tumble warmup`` compiles)
    """

    model: str
    kernel: str
    scenario: str | None
    glyph: str | None
    example: str


@dataclass(frozen=True)
class ScenarioKind:
    """One scenario kind: what a file with ``kind = "..."`` describes.

    scenario    : ``"module:Class"``, the kind's top-level table (a :class:`~tumble.scenario.Scenario` subclass),
                  imported only when a file of this kind is read
    table       : a top-level table whose presence means this kind in a file without ``kind`` (None: none)
    description : what the kind simulates, in words
    """

    scenario: str
    table: str | None
    description: str


#: Model kind (``traj.model``) -> its pieces.
MODEL_KINDS: dict[str, ModelKind] = {
    "RigidBody": ModelKind("tumble.rigid_model:RigidBodies", "tumble.kernels.rigid", "rigid", "rigid",
                           "tumble._warmup:rigid"),
    "Spacecraft": ModelKind("tumble.spacecraft.model:Spacecraft", "tumble.kernels.spacecraft", "spacecraft",
                            "spacecraft", "tumble._warmup:spacecraft"),
    "FlexibleBody": ModelKind("tumble.flexible:FlexibleBody", "tumble.kernels.flexible", "flexible", "flexible",
                              "tumble._warmup:flexible"),
    "SloshBody": ModelKind("tumble.slosh:SloshBody", "tumble.kernels.slosh", "slosh", "slosh",
                           "tumble._warmup:slosh"),
    "VariableBody": ModelKind("tumble.variable.body:VariableBody", "tumble.kernels.variable", "variable", ATTITUDE,
                              "tumble._warmup:variable"),
    "MovingHuman": ModelKind("tumble.variable.human:MovingHuman", "tumble.kernels.variable", "human", "human",
                             "tumble._warmup:human"),
    "Gyroscope": ModelKind("tumble.ins.gyroscope:Gyroscope", "tumble.kernels.rigid", "gyroscope", ATTITUDE,
                           "tumble._warmup:gyroscope"),
    "GimbaledGyro": ModelKind("tumble.ins.gimbal:GimbaledGyro", "tumble.kernels.gimbal", "gyroscope", ATTITUDE,
                              "tumble._warmup:gimbaled_gyro"),
    "SerialChain": ModelKind("tumble.robot.chain:SerialChain", "tumble.kernels.robot", "robot", "robot",
                             "tumble._warmup:serial_chain"),
    "RobotTree": ModelKind("tumble.robot.tree:RobotTree", "tumble.kernels.robot", "robot", None,
                           "tumble._warmup:robot_tree"),
    "KirchhoffBody": ModelKind("tumble.fluid:KirchhoffBody", "tumble.kernels.fluid", "fluid", "fluid",
                               "tumble._warmup:fluid"),
}

#: Scenario kind (a file's ``kind``) -> its table.
SCENARIOS: dict[str, ScenarioKind] = {
    "rigid": ScenarioKind("tumble.scenario.rigid:RigidScenario", None,
                          "a rigid body under external torques, optionally with a nutation [damper] (tumble.RigidBody)"),
    "spacecraft": ScenarioKind("tumble.scenario.spacecraft:SpacecraftScenario", "spacecraft",
                               "a spacecraft with wheels, CMGs, thrusters, magnetorquers and controllers "
                               "(tumble.spacecraft.Spacecraft)"),
    "flexible": ScenarioKind("tumble.scenario.flexible:FlexibleScenario", "flexible",
                             "a hub with flexible appendages: cantilever modes of the hybrid-coordinate model "
                             "(tumble.flexible.FlexibleBody)"),
    "slosh": ScenarioKind("tumble.scenario.slosh:SloshScenario", "slosh",
                          "a free-floating hub with a fuel-slosh pendulum (tumble.slosh.SloshBody)"),
    "variable": ScenarioKind("tumble.scenario.variable:VariableScenario", "variable",
                             "a body whose inertia and shape momentum are tabulated in time "
                             "(tumble.variable.VariableBody)"),
    "human": ScenarioKind("tumble.scenario.human:HumanScenario", "human",
                          "a human body in flight moving its joints: de Leva's segments (tumble.variable.MovingHuman)"),
    "gyroscope": ScenarioKind("tumble.scenario.gyroscope:GyroscopeScenario", "gyroscope",
                              "a spinning rotor on a pivot or in a two-axis gimbal (tumble.ins.Gyroscope, "
                              "tumble.ins.GimbaledGyro)"),
    "robot": ScenarioKind("tumble.scenario.robot:RobotScenario", "robot",
                          "a robot arm on a fixed base from a DH table or URDF file (tumble.robot.SerialChain)"),
    "fluid": ScenarioKind("tumble.scenario.fluid:FluidScenario", "fluid",
                          "a rigid body in an ideal fluid: Kirchhoff's equations with an added mass "
                          "(tumble.fluid.KirchhoffBody)"),
}
