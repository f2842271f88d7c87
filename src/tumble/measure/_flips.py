"""Measurements on trajectories: the flips of the intermediate-axis (tennis-racket) motion.

A body spun about its intermediate principal axis ``e₂`` (the middle moment
``I₁ < I₂ < I₃``) is unstable: a small perturbation grows and the body turns
over, again and again, with the rate component ``ω₂ = ω·e₂`` changing sign at
each turn (Landau & Lifshitz, *Mechanics*, §37; Ashbaugh, Chicone & Cushman,
J. Dyn. Diff. Eq. 3, 67 (1991)). A *flip* is here a sign change of ``ω₂``.
"""

from __future__ import annotations

import numpy as np

from tumble._validate import ValidationError
from tumble.rigid_body import RigidBody
from tumble.trajectory import Trajectory

__all__ = ["intermediate_rate", "flip_times"]


def intermediate_rate(trajectory: Trajectory, body: RigidBody) -> np.ndarray:
    """``ω₂(t) = ω(t)·e₂``: the rate about the intermediate principal axis, rad/s, shape (n,).

    ``e₂ = body.axes[:, 1]`` is the intermediate principal axis in body axes
    (``body.moments`` ascending). One body only: ``trajectory.omega`` (n, 3).
    """
    if trajectory.batch_size is not None:
        raise ValidationError(
            f"trajectory: must hold a single body (omega of shape (n, 3)), got a batch of {trajectory.batch_size}; "
            "pass trajectory.member(i)"
        )
    return trajectory.omega @ body.axes[:, 1]


def flip_times(trajectory: Trajectory, body: RigidBody) -> np.ndarray:
    """Times (s) at which the intermediate-axis rate ``ω₂ = ω·e₂`` changes sign, ascending.

    Between samples ``k`` and ``k + 1`` with ``ω₂`` of opposite signs (a zero
    sample counts as positive), the crossing is placed by linear
    interpolation::

        t* = t_k + (t_{k+1} − t_k) ω₂,k / (ω₂,k − ω₂,k+1)

    The samples must be dense enough that ``ω₂`` changes sign at most once
    between two of them: a flip lasts about ``1/λ`` with
    ``λ = |ω| √((I₂ − I₁)(I₃ − I₂)/(I₁ I₃))``, so sample several times per ``1/λ``.
    """
    rate = intermediate_rate(trajectory, body)
    t = trajectory.t
    k = np.flatnonzero((rate[:-1] >= 0.0) != (rate[1:] >= 0.0))
    return t[k] + (t[k + 1] - t[k]) * rate[k] / (rate[k] - rate[k + 1])
