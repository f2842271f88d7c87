"""The scene of a rigid body in an ideal fluid: the body turning, and the path of its origin.

The body, its axes, ω and the angular impulse are the attitude scene's, drawn
about the body origin; beside them, the path ``x(t) − x(0)`` of the origin
(the trajectory's ``position``, inertial) as a trail from the centre, scaled
so that its largest excursion is three times the body's half-diagonal (the
scale is stated). The body is the user's shape, else the equivalent box of
the model's inertia and mass, else of the trajectory's inertia
(:func:`tumble.viz.viewer.scenes.rigid.hub_mesh`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tumble.fluid import KirchhoffBody
from tumble.viz.viewer._scene import Lines, check_model
from tumble.viz.viewer.scenes._attitude import attitude_scene
from tumble.viz.viewer.scenes.rigid import hub_mesh

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene
    from tumble.viz.viewer.scenes import Options

__all__ = ["scene"]

_PATH_LENGTH = 3.0  # the largest excursion of the drawn path, × the body's half-diagonal


def scene(traj: Trajectory, idx: np.ndarray, model: KirchhoffBody | None, options: Options) -> Scene:
    check_model(model, (KirchhoffBody,), traj)
    mesh, note = hub_mesh(traj, model.body if isinstance(model, KirchhoffBody) else None, options.shape)
    scene = attitude_scene(traj, idx, mesh=mesh, mesh_note=note, axis=options.axis, title=options.title)
    half = float(np.linalg.norm(mesh.vertices, axis=-1).max())
    path = traj.position[idx] - traj.position[0]
    largest = float(np.linalg.norm(path, axis=-1).max())
    scale = _PATH_LENGTH * half / largest if largest > 0.0 else 0.0
    scene.lines.append(Lines("path of the body origin", scale * path, "#8c564b", width=3.0, trail=True))
    scene.notes.append(f"path of the body origin x(t) − x(0), inertial, drawn at {scale:.4g} m per m"
                       if largest > 0.0 else "path of the body origin: at rest throughout")
    scene.extent = max(scene.extent, 1.1 * _PATH_LENGTH * half)
    return scene
