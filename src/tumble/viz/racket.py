"""The tennis-racket (Dzhanibekov) figure: a T-handle's body rates in principal axes, its flips marked
(``tumble demo racket``, ``docs/stability.md``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tumble.measure import intermediate_rate
from tumble.rigid_body import RigidBody
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["racket_figure"]


def racket_figure(traj: Trajectory, body: RigidBody, flips: np.ndarray) -> Figure:
    """Figure of the body rate in principal axes (rad/s) against time (s), the flips marked."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 4.5), layout="constrained")
    ax = fig.subplots()
    principal = traj.omega @ body.axes  # ω_P = R_BPᵀ ω_B, row by row
    ax.plot(traj.t, intermediate_rate(traj, body), lw=2.0, label=r"$\omega_2$ (intermediate axis)")
    for k, style in ((0, "--"), (2, ":")):
        ax.plot(traj.t, principal[:, k], style, label=rf"$\omega_{k + 1}$")
    for i, t_flip in enumerate(flips):
        ax.axvline(t_flip, color="0.6", lw=0.8, label="flip" if i == 0 else None)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("body rate, principal axes (rad/s)")
    ax.set_title(f"T-handle spun about its intermediate axis: {flips.size} flips", loc="left")
    ax.grid(True, alpha=0.3)
    fig.legend(loc="outside right upper", fontsize="small")
    return fig
