"""Robot manipulators: serial chains from DH tables and URDF, inverse and forward dynamics.

A :class:`SerialChain` is an immutable, validated model (built with
:meth:`SerialChain.from_dh`, :meth:`SerialChain.from_urdf` or :func:`load`);
joint states are plain arrays of shape (n,) or (B, n). The algorithms are
compiled and batched::

    chain = tumble.robot.load("examples/robots/puma560.toml")
    tau = tumble.robot.rnea(chain, q, qd, qdd)          # inverse dynamics (N·m)
    M = tumble.robot.mass_matrix(chain, q)              # joint-space inertia
    qdd = tumble.robot.forward_dynamics(chain, q, qd, tau)
    run = tumble.robot.simulate(chain, q0, qd0, t=t, method="rk4", dt=1e-3)

See ``docs/robot.md`` for the conventions (frames, DH variants, units).
"""

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
from tumble.robot.link import Link
from tumble.robot.simulate import JointTrajectory, simulate

__all__ = [
    "Link", "SerialChain", "load",
    "rnea", "gravity_torques", "coriolis", "mass_matrix", "forward_dynamics",
    "link_poses", "kinetic_energy", "potential_energy",
    "simulate", "JointTrajectory",
]
