"""The scene of a human body in flight (a diver, a gymnast): its segments at their poses.

For a :class:`tumble.variable.MovingHuman` (the model, or its
:class:`~tumble.variable.Human`), the segment poses relative to the trunk
frame B come from :meth:`tumble.variable.Human.kinematics` at the frame
times with the joint angles the trajectory recorded (``joint_angles``): segment ``i`` has axes
``R_i`` and joint ``o_i`` (B axes, from the hip centre) and the whole-body
centre of mass is ``C``; drawn about ``C``, a point ``v`` of the segment (own
axes) is at ``R(q) (R_i v + o_i − C)``. Each segment is drawn as the uniform
box with its own principal moments and mass (de Leva's segment inertias),
centred on its centre of mass. Without the model, the body is the box of
the trajectory's inertia.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from tumble._inertia import principal_axes
from tumble._validate import ValidationError
from tumble.variable.human import Human, MovingHuman
from tumble.viz.viewer._scene import Solid, check_model
from tumble.viz.viewer._shapes import Mesh, box_mesh, equivalent_box
from tumble.viz.viewer.scenes import rigid
from tumble.viz.viewer.scenes._attitude import attitude_scene, rotations

if TYPE_CHECKING:
    from tumble.rigid_body import Part
    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene
    from tumble.viz.viewer.scenes import Options

__all__ = ["scene", "segment_mesh"]

_TRUNK, _LEFT, _RIGHT = "#f2a541", "#d62728", "#1f77b4"
_NOTE = ("its segments, each the uniform box of its own mass and principal moments (de Leva 1996) at its pose "
         "from Human.kinematics, about the whole-body centre of mass (red: left limbs, blue: right limbs)")


def segment_mesh(part: Part) -> Mesh:
    """The equivalent box of a segment's ``part`` (mass, inertia about its centre of mass), in the segment's axes,
    centred on its centre of mass."""
    _, moments, axes = principal_axes(part.inertia, "inertia", check_triangle=False)
    return box_mesh(equivalent_box(moments, part.mass)).moved(axes, part.com)


class _AtFrames:
    """Joint angles known at the frames only (the trajectory's ``joint_angles``): a pose needs no rates."""

    def __init__(self, values):
        self._values = values

    def angle(self, t):
        return self._values

    def rate(self, t):
        return np.zeros_like(self._values)


def scene(traj: Trajectory, idx: np.ndarray, model: MovingHuman | Human | None, options: Options) -> Scene:
    check_model(model, (MovingHuman, Human), traj)
    if model is None:
        return rigid.scene(traj, idx, None, options)
    human = model.human if isinstance(model, MovingHuman) else model
    if traj.joint_angles.shape[-1] != len(human.dofs):
        raise ValidationError(f"model: has {len(human.dofs)} joint angles, the trajectory's joint_angles "
                              f"{traj.joint_angles.shape[-1]}")
    angles = traj.joint_angles[idx]
    kin = human.kinematics(traj.t[idx], {name: _AtFrames(angles[:, k]) for k, name in enumerate(human.dofs)})
    R = rotations(cast(np.ndarray, traj.q)[idx])
    meshes = [segment_mesh(s.part) for s in human.segments]
    points = [np.einsum("fij,vj->fvi", kin.rotation[:, i], m.vertices) + (kin.joint[:, i] - kin.com)[:, None]
              for i, m in enumerate(meshes)]
    half = float(max(np.linalg.norm(p, axis=-1).max() for p in points))
    scene = attitude_scene(traj, idx, mesh=None, mesh_note=_NOTE, axis=options.axis, title=options.title,
                           body="trunk frame B", half=half)
    for i, (segment, mesh) in enumerate(zip(human.segments, meshes)):
        color = _LEFT if "left" in segment.name else _RIGHT if "right" in segment.name else _TRUNK
        scene.solids.append(Solid(segment.name, mesh, R @ kin.rotation[:, i],
                                  np.einsum("fij,fj->fi", R, kin.joint[:, i] - kin.com), color))
    return scene
