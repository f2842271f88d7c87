"""``spacecraft_figure``: the attitude, rates, actuator states and torques of a spacecraft run.

Matplotlib's object-oriented API (no pyplot state). Panels, top to bottom:

1. attitude error: rotation angle from ``target`` (deg, log scale) when a target is given,
   else the magnitude of the body rate |ω| (deg/s, log scale), as a detumble is judged;
2. body rates ω (deg/s);
3. the actuators' states, as the trajectory holds them: wheel speeds (rpm), CMG gimbal
   angles (deg) with the singularity measure, thruster firings, or the magnetic dipole (A·m²);
4. torques (N·m): the controller's command (dashed) and what the actuators deliver.
"""

from __future__ import annotations

import os

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._files import write_atomic
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["spacecraft_figure", "save_spacecraft_figure"]

_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")


def spacecraft_figure(traj: Trajectory, *, target: ArrayLike | None = None, title: str | None = None) -> Figure:
    """The four panels described in the module docstring, for one spacecraft (no batch axis).

    ``target`` : unit quaternion ``[w, x, y, z]`` (body → inertial) of the commanded attitude.
    """
    from matplotlib.figure import Figure

    assert traj.q is not None and traj.omega is not None  # a spacecraft has an attitude
    if traj.q.ndim != 2:
        raise ValueError("traj: spacecraft_figure draws one spacecraft, not a batch")
    extras, t = traj.extras, traj.t
    fig = Figure(figsize=(8.0, 10.0), layout="constrained")
    ax_att, ax_rate, ax_act, ax_torque = fig.subplots(4, 1, sharex=True)
    if target is None:
        ax_att.semilogy(t, np.degrees(np.linalg.norm(traj.omega, axis=-1)), color="k")
        ax_att.set_ylabel("|ω| (deg/s)")
    else:
        target = np.broadcast_to(attitude.normalize(target), traj.q.shape)
        ax_att.semilogy(t, np.maximum(np.degrees(attitude.relative_angle(traj.q, target)), 1e-12), color="k")
        ax_att.set_ylabel("angle to target (deg)")
    for k, name in enumerate("xyz"):
        ax_rate.plot(t, np.degrees(traj.omega[:, k]), color=_COLORS[k], label=f"ω_{name}")
    ax_rate.set_ylabel("body rate (deg/s)")
    ax_rate.legend(loc="upper right", ncol=3)
    _actuators(ax_act, t, extras)
    if "torque_command" in extras:
        for k, name in enumerate("xyz"):
            ax_torque.plot(t, extras["torque_command"].data[:, k], color=_COLORS[k], ls="--", lw=1.0)
    for k, name in enumerate("xyz"):
        ax_torque.plot(t, extras["actuator_torque"].data[:, k], color=_COLORS[k], label=f"τ_{name}")
    ax_torque.set_ylabel("torque (N m)")
    title_ = "actuators (solid), command (dashed)" if "torque_command" in extras else "actuators"
    ax_torque.legend(loc="upper right", ncol=3, title=title_, fontsize="small")
    ax_torque.set_xlabel("t (s)")
    if title:
        fig.suptitle(title)
    return fig


def _actuators(ax, t, extras):
    if "wheel_speed" in extras:
        speed = extras["wheel_speed"].data * 30.0 / np.pi
        for i in range(speed.shape[1]):
            ax.plot(t, speed[:, i], color=_COLORS[i % len(_COLORS)], label=f"wheel {i}")
        ax.set_ylabel("wheel speed (rpm)")
    elif "gimbal_angle" in extras:
        angles = np.degrees(extras["gimbal_angle"].data)
        for i in range(angles.shape[1]):
            ax.plot(t, angles[:, i], color=_COLORS[i % len(_COLORS)], label=f"gimbal {i}")
        ax.set_ylabel("gimbal angle (deg)")
        twin = ax.twinx()
        twin.plot(t, extras["singularity"].data, color="k", ls=":", label="singularity measure")
        twin.set_ylabel("sqrt(det(A Aᵀ))/h³")
    elif "thruster_firing" in extras:
        firing = extras["thruster_firing"].data
        for i in range(firing.shape[1]):
            ax.fill_between(t, i, i + 0.8 * firing[:, i], step="post", color=_COLORS[(i // 2) % 3])
        ax.set_ylabel("thruster firing")
        ax.set_yticks(np.arange(firing.shape[1]) + 0.4, [str(i) for i in range(firing.shape[1])])
        return
    elif "dipole" in extras:
        for k, name in enumerate("xyz"):
            ax.plot(t, extras["dipole"].data[:, k], color=_COLORS[k], label=f"m_{name}")
        ax.set_ylabel("dipole (A m²)")
    else:
        ax.set_axis_off()
        return
    ax.legend(loc="upper right", ncol=4, fontsize="small")


def save_spacecraft_figure(traj: Trajectory, path: str | os.PathLike[str], **options: Any) -> Path:
    """Draw :func:`spacecraft_figure` and write it to ``path`` (PNG) atomically; returns the path."""
    fig = spacecraft_figure(traj, **options)
    write_atomic(path, lambda tmp: fig.savefig(tmp, format="png", dpi=110))
    return Path(path)
