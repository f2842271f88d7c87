"""Scenario kind ``"robot"``: a robot arm on a fixed base (:class:`tumble.robot.SerialChain`).

``[robot]`` names a robot file — a DH table (``.toml``) or a URDF (``.urdf``,
``.xml``), read by :func:`tumble.robot.load` (``docs/robot.md``) — by a path
relative to the scenario file, and may replace its gravity and apply constant
joint torques::

    kind = "robot"

    [robot]
    file = "../robots/planar_2link.toml"   # relative to this file
    gravity = [0.0, -9.81, 0.0]           # m/s², base frame (default: the robot file's)
    torque = [2.0, 0.0]                    # N m (revolute) or N (prismatic), one per joint (default: none)

    [initial]
    q = [-1.5707963267948966, 0.0]         # joint coordinates, rad or m, base to tip (not a quaternion)
    qd = [0.0, 0.0]                        # joint rates, rad/s or m/s (default 0)

The run integrates ``M(q) q̈ + C(q, q̇) q̇ + g(q) = τ`` (:mod:`tumble.robot.motion`);
the joint limits of the robot file are not enforced.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import numpy as np
from pydantic import Field

from tumble import robot
from tumble.scenario._base import Scenario
from tumble.scenario._errors import ScenarioError, in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Number, _Table, _Text, _Vector
from tumble.scenario.tables import ModelState, Solver, Time
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["RobotScenario"]


class RobotTable(_Table):
    """``[robot]``: the robot ``file`` (relative to the scenario file), optional ``gravity`` (m/s², base frame)
    and constant joint ``torque`` (N m or N, one per joint)."""

    file: _Text
    gravity: _Vector | None = None
    torque: list[_Number] | None = None

    def chain(self, directory: Path) -> robot.RobotTree:
        """The chain of the robot file (a relative ``file`` is taken from ``directory``) under ``gravity``; a
        refusal is reported against ``robot.file`` or ``robot.gravity``."""
        path = directory / self.file
        try:
            with keyed({}, "robot.file"):
                chain = robot.load(path)
        except OSError as exc:
            raise ScenarioError("", [("robot.file", f"cannot read {path} ({exc.strerror or exc})")]) from None
        if self.gravity is None:
            return chain
        with keyed({"gravity": "robot.gravity"}, "robot.gravity"):
            return chain.with_gravity(self.gravity)


class RobotInitial(ModelState):
    """``[initial]``: joint coordinates ``q`` (rad or m, base to tip; required) and rates ``qd`` (default 0)."""

    q: Annotated[list[_Number], Field(min_length=1)]
    qd: list[_Number] | None = None


class RobotScenario(Scenario):
    """A validated robot-arm scenario (``kind = "robot"``, or a ``[robot]`` table)."""

    robot: RobotTable
    initial: RobotInitial
    time: Time
    solver: Solver = Solver()

    def build(self) -> Run:
        """The :class:`~tumble.robot.SerialChain`, its initial joint state and torque; a refusal names the key."""
        with in_file(self.source):
            chain = self.robot.chain(Path(self.source).parent)
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS, "torque": "robot.torque"}
            torque = None if self.robot.torque is None else np.array(self.robot.torque)
            return Run(chain, self.initial.state(chain), self.time.times(), self.solver.method,
                       self.solver.options(), torque, keys, self.source)

    def figure(self, traj: Trajectory) -> Figure:
        """:meth:`tumble.Trajectory.plot`: joint coordinates, energy, joint rates; titled with the scenario's name."""
        return traj.plot(title=self.name)

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """The energy balance ``E − W`` (constant along the exact motion) and the first joint to leave its limits."""
        chain = self.model
        balance = traj.energy - traj.work
        rows = [("balance", f"E - W changes by at most {np.abs(balance - balance[0]).max():.3g} J (exact: 0); "
                            f"the joint torques did W = {traj.work[-1]:.6g} J")]
        outside = ~chain.within_limits(traj.joint_position)
        if outside.any():
            k = int(outside.argmax())
            q = traj.joint_position[k]
            names = [str(name) for name, out in zip(chain.joint_names, (q < chain.lower) | (q > chain.upper)) if out]
            rows.append(("limits", f"{', '.join(names)} leaves its range at t = {traj.t[k]:.6g} s (not enforced)"))
        return rows
