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

import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

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

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike

    from tumble.trajectory import Trajectory

__all__ = [
    "Link", "Frame", "RobotTree", "SerialChain", "load", "space_manipulator", "UrdfRepairWarning",
    "frame_poses", "frame_pose", "frame_jacobian", "center_of_mass", "centroidal_momentum_matrix",
    "centroidal_momentum",
    "rnea", "gravity_torques", "coriolis", "mass_matrix", "forward_dynamics",
    "link_poses", "kinetic_energy", "potential_energy",
    "simulate",
]


def simulate(chain: RobotTree, q0: ArrayLike, qd0: ArrayLike, *, t: ArrayLike,
             torque: ArrayLike | Callable[[float, np.ndarray, np.ndarray], ArrayLike] | None = None,
             method: str = "rk4", dt: float | None = None, rtol: float = 1e-10, atol: float = 1e-12,
             gravity: ArrayLike | None = None, max_steps: int | None = None) -> Trajectory:
    """Deprecated: use ``tumble.simulate(chain, q0=q0, qd0=qd0, t=t, ...)``, which this forwards to.

    ``gravity`` (m/s², base frame) runs ``chain.with_gravity(gravity)``; of
    ``dt``, ``rtol``, ``atol`` and ``max_steps`` only those ``method`` reads
    are passed on. Returns a :class:`tumble.Trajectory`.
    """
    import tumble
    from tumble.integrate import METHODS

    warnings.warn("tumble.robot.simulate is deprecated: use tumble.simulate(chain, q0=..., qd0=..., t=...)",
                  DeprecationWarning, stacklevel=2)
    if gravity is not None:
        chain = chain.with_gravity(gravity)
    given: dict[str, Any] = {"dt": dt, "rtol": rtol, "atol": atol, "max_steps": max_steps}
    reads = METHODS[method].options if method in METHODS else ()
    return tumble.simulate(chain, q0=q0, qd0=qd0, t=t, torque=torque, method=method,
                           **{name: given[name] for name in reads})
