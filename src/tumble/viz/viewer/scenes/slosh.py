"""The scene of a sloshing spacecraft: the hub and the pendulum that stands for the fuel.

The rod runs from the hinge ``b`` to ``b + l s`` (``s`` the trajectory's
``pendulum_direction``, body axes), turned by ``R(q)``; drawn at true scale
(exaggeration 1: the pendulum's swing is a large motion) with ``b`` and ``l``
of the model; without the model, from the centre with a rod of the body's
half-diagonal.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from tumble.slosh import SloshBody
from tumble.viz.viewer._scene import Lines, check_model
from tumble.viz.viewer.scenes._attitude import attitude_scene, rotations
from tumble.viz.viewer.scenes.rigid import hub_mesh

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene
    from tumble.viz.viewer.scenes import Options

__all__ = ["scene"]


def scene(traj: Trajectory, idx: np.ndarray, model: SloshBody | None, options: Options) -> Scene:
    check_model(model, (SloshBody,), traj)
    body = model.body if isinstance(model, SloshBody) else None
    mesh, note = hub_mesh(traj, body, options.shape)
    scene = attitude_scene(traj, idx, mesh=mesh, mesh_note=note, axis=options.axis, title=options.title, body="hub")
    if isinstance(model, SloshBody):
        hinge, length, where = model.pendulum.hinge, model.pendulum.length, "the model's hinge and length"
    else:
        hinge, length = np.zeros(3), float(np.linalg.norm(mesh.vertices, axis=-1).max())
        where = "from the centre, a rod of the hub's half-diagonal (no model given)"
    ends = np.stack([np.broadcast_to(hinge, (len(idx), 3)), hinge + length * traj.pendulum_direction[idx]], axis=1)
    R = rotations(cast(np.ndarray, traj.q)[idx])
    scene.lines.append(Lines("slosh pendulum", np.einsum("fij,fpj->fpi", R, ends), "#17becf", width=7.0,
                             markers=True))
    scene.notes.append(f"slosh pendulum: rod and mass at true scale (exaggeration 1), {where}")
    scene.extent = max(scene.extent, 1.1 * float(np.linalg.norm(ends, axis=-1).max()))
    return scene
