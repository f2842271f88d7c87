"""One scene builder per kind of model, chosen by the trajectory's ``model`` name.

A builder is ``scene(traj, idx, model, options) -> Scene``: the trajectory,
the indices of its samples shown as frames, the model that made it (or
None: what a trajectory alone cannot tell — a robot's links, a spacecraft's
wheels, a diver's segments — needs it) and the :class:`Options`. The registry of
model kinds names each kind's glyph (:data:`tumble._kinds.MODEL_KINDS`): a
module here, read into :data:`BUILDERS`. A model without one is drawn by
:mod:`.rigid` from its attitude, when it has one.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NamedTuple

from tumble._kinds import ATTITUDE, MODEL_KINDS

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


#: Trajectory.model → the builder of its scene: the ``scene`` of the module here that the kind's glyph names.
BUILDERS: dict[str, Callable[[Trajectory, np.ndarray, Any, Options], Scene]] = {
    name: importlib.import_module(f"{__name__}.{kind.glyph}").scene
    for name, kind in MODEL_KINDS.items() if kind.glyph not in (None, ATTITUDE)}
