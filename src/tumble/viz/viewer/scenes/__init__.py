"""One scene builder per kind of model, chosen by the trajectory's ``model`` name.

A builder is ``scene(traj, idx, model, options) -> Scene``: the trajectory,
the indices of its samples shown as frames, the model that made it (or
None: what a trajectory alone cannot tell — a robot's links, a spacecraft's
wheels, a diver's segments — needs it) and the :class:`Options`. A model
without a row is drawn by :mod:`.rigid` from its attitude, when it has one.
Adding a model to the viewer is one module here and one row of
:data:`BUILDERS`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NamedTuple

from tumble.viz.viewer.scenes import flexible, human, rigid, robot, slosh, spacecraft

if TYPE_CHECKING:
    import numpy as np

    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene

__all__ = ["BUILDERS", "Options"]


class Options(NamedTuple):
    """axis: the body axis (0, 1, 2) whose trace is drawn; shape: the user's shape of the body, or None;
    title: the page's title."""

    axis: int
    shape: object
    title: str


#: Trajectory.model → the builder of its scene.
BUILDERS: dict[str, Callable[[Trajectory, np.ndarray, Any, Options], Scene]] = {
    "RigidBody": rigid.scene,
    "Spacecraft": spacecraft.scene,
    "SerialChain": robot.scene,
    "MovingHuman": human.scene,
    "FlexibleBody": flexible.scene,
    "SloshBody": slosh.scene,
}
