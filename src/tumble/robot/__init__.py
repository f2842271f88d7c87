"""Robots: serial chains and kinematic trees from DH tables and URDF, fixed or floating base, dynamics, simulation.

A :class:`RobotTree` (kinematic tree, Featherstone's parent array; optional
floating base, mimic joints and named frames) and its special case
:class:`SerialChain` are immutable, validated models (built with
:meth:`SerialChain.from_dh`, :meth:`RobotTree.from_urdf` or :func:`load`);
joint states are plain arrays of shape (n,) or (B, n). The algorithms are
compiled and batched::

    chain = tumble.robot.load(tumble.examples.path("puma560.toml"))   # a file installed with tumble
    tau = tumble.robot.rnea(chain, q, qd, qdd)          # inverse dynamics (N·m)
    M = tumble.robot.mass_matrix(chain, q)              # joint-space inertia
    qdd = tumble.robot.forward_dynamics(chain, q, qd, tau)
    run = tumble.simulate(chain, q0=q, qd0=qd, t=t)     # the front door: a tumble.Trajectory

See ``docs/robot.md`` for the conventions (frames, DH variants, units).
"""

from __future__ import annotations

from tumble.robot.chain import SerialChain, load
from tumble.robot.dynamics import (
    coriolis,
    forward_dynamics,
    gravity_torques,
    kinetic_energy,
    link_poses,
    mass_matrix,
    potential_energy,
    rnea,
)
from tumble.robot.kinematics import (
    center_of_mass,
    centroidal_momentum,
    centroidal_momentum_matrix,
    frame_jacobian,
    frame_pose,
    frame_poses,
)
from tumble.robot.link import Frame, Link
from tumble.robot.space import space_manipulator
from tumble.robot.tree import RobotTree
from tumble.robot.urdf import UrdfRepairWarning

__all__ = [
    "Link", "Frame", "RobotTree", "SerialChain", "load", "space_manipulator", "UrdfRepairWarning",
    "frame_poses", "frame_pose", "frame_jacobian", "center_of_mass", "centroidal_momentum_matrix",
    "centroidal_momentum",
    "rnea", "gravity_torques", "coriolis", "mass_matrix", "forward_dynamics",
    "link_poses", "kinetic_energy", "potential_energy",
]
