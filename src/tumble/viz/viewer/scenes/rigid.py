"""The scene of a body with an attitude and nothing more to draw: a rigid body, a gyroscope, a variable body.

The body is the user's shape (``shape=``), else the equivalent box of the
model's inertia (with its mass when the model is a :class:`tumble.RigidBody`
that has one), else the equivalent box of the trajectory's ``inertia``
(:func:`tumble.viz.viewer._shapes.body_mesh`); the rest is
:func:`~tumble.viz.viewer.scenes._attitude.attitude_scene`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from tumble.rigid_body import RigidBody
from tumble.viz.viewer._scene import check_model
from tumble.viz.viewer._shapes import body_mesh
from tumble.viz.viewer.scenes._attitude import attitude_scene

if TYPE_CHECKING:
    import numpy as np

    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene
    from tumble.viz.viewer._shapes import Mesh
    from tumble.viz.viewer.scenes import Options

__all__ = ["hub_mesh", "scene"]


def hub_mesh(traj: Trajectory, body: RigidBody | None, shape: object) -> tuple[Mesh, str]:
    """The mesh and its note of the body: ``shape``, else ``body`` (a RigidBody or None), else ``traj.inertia``."""
    if isinstance(body, RigidBody):
        return body_mesh(body.inertia, mass=body.mass, com=body.com, shape=shape)
    return body_mesh(traj.inertia, shape=shape)


def scene(traj: Trajectory, idx: np.ndarray, model: RigidBody | None, options: Options) -> Scene:
    check_model(model, (RigidBody,), traj)
    mesh, note = hub_mesh(traj, model, options.shape)
    return attitude_scene(traj, idx, mesh=mesh, mesh_note=note, axis=options.axis, title=options.title)
