"""A free-floating space manipulator: a spacecraft hub carrying an arm, the hub as the floating base.

``space_manipulator(hub, arm, mount_position=(0, 0, 0), mount_rotation=None)``
builds a :class:`~tumble.robot.RobotTree` whose floating base (``links[0]``)
is the rigid hub (:class:`tumble.RigidBody` with a mass: its inertia about
its centre of mass, body axes; its centre of mass ``hub.com`` in the hub
frame, 0 if unknown) and whose other links are those of the serial ``arm``,
its base frame placed at ``mount_position`` (m) and ``mount_rotation`` (arm
base axes → hub axes) in the hub frame. No gravity.

Without external forces the total linear and angular momentum stay constant:
joint motion turns and moves the hub (Dubowsky & Papadopoulos, "The
kinematics, dynamics, and control of free-flying and free-floating space
robotic systems", IEEE Trans. Robot. Autom. 9(5), 1993: the generalised
Jacobian). ``tumble.simulate(tree, q0=..., torque=..., t=...)`` integrates
it (:mod:`tumble.robot.motion`), the extras ``angular_momentum`` and
``linear_momentum`` show the conservation.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import ArrayLike

from tumble._inertia import as_rotation, as_shape
from tumble._validate import ValidationError
from tumble.rigid_body import RigidBody
from tumble.robot.chain import SerialChain
from tumble.robot.link import Link
from tumble.robot.tree import RobotTree

__all__ = ["space_manipulator"]


def space_manipulator(hub: RigidBody, arm: SerialChain, *, mount_position: ArrayLike = (0.0, 0.0, 0.0),
                      mount_rotation: ArrayLike | None = None, name: str | None = None) -> RobotTree:
    """The hub and the arm as one floating-base tree (see the module docstring), gravity zero."""
    if not isinstance(hub, RigidBody) or hub.mass is None:
        raise ValidationError("hub: must be a tumble.RigidBody with a mass (kg)")
    if not isinstance(arm, SerialChain):
        raise ValidationError(f"arm: must be a tumble.robot.SerialChain, got {type(arm).__name__}")
    R_m = as_rotation(mount_rotation, "mount_rotation")
    p_m = as_shape(mount_position, "mount_position", (3,))
    com = np.zeros(3) if hub.com is None else hub.com
    base = Link(joint="floating", mass=hub.mass, com=com, inertia=hub.inertia, name="hub")
    first = arm.links[0]
    mounted = dataclasses.replace(first, origin_rotation=R_m @ first.origin_rotation,
                                  origin_position=p_m + R_m @ first.origin_position)
    links = (base, mounted, *arm.links[1:])
    return RobotTree(links, range(-1, len(links) - 1), gravity=(0.0, 0.0, 0.0),
                     name=name or f"{arm.name or 'arm'} on a free hub")
