"""CMG steering at the elliptic singularity of the four-CMG pyramid: the SR inverse is stuck, the generalised
SR inverse (Wie's deterministic dither) escapes and delivers the commanded torque.

The pyramid (skew 54.74°, 1 N·m·s per gyro, gimbal rates up to 2 rad/s) starts at δ = (−90°, 0, 90°, 0), where
every torque column is normal to x, and is asked for 0.5 N·m along −x, the singular direction. Writes the
figure of ``docs/spacecraft.md`` (``docs/img/spacecraft_cmg_escape.png``, or the path given as the first
argument) and prints the numbers quoted there. Run from the repository root::

    python src/tumble/examples/spacecraft/cmg_singularity_escape.py
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import tumble
from tumble.spacecraft import CMGCluster, ConstantTorque, SingularityWarning, Spacecraft
from tumble._files import write_atomic

DELTA0 = np.radians([-90.0, 0.0, 90.0, 0.0])
TORQUE = np.array([-0.5, 0.0, 0.0])            # N m, body axes
T = np.linspace(0.0, 5.0, 501)                 # s: the cluster reaches its momentum envelope at 6.4 s
CLUSTER = CMGCluster.pyramid(1.0, max_gimbal_rate=2.0)
DEFAULT = Path(__file__).resolve().parents[2] / "docs" / "img" / "spacecraft_cmg_escape.png"


def spacecraft(cluster: CMGCluster) -> Spacecraft:
    return Spacecraft(inertia=np.diag([20.0, 25.0, 15.0]), cmgs=cluster, controller=ConstantTorque(TORQUE))


def run(cluster: CMGCluster) -> tumble.Trajectory:
    craft = spacecraft(cluster)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularityWarning)   # it starts singular: that is the point
        return tumble.simulate(craft, [0.0, 0.0, 0.0], t=T, gimbal_angles0=DELTA0, method="rk4", dt=0.01)


def torque_error(traj: tumble.Trajectory) -> np.ndarray:
    """``|τ − u|/|u|``: the delivered torque against the command."""
    return np.linalg.norm(traj.actuator_torque - TORQUE, axis=-1) / np.linalg.norm(TORQUE)


def figure(sr: tumble.Trajectory, gsr: tumble.Trajectory) -> Figure:
    fig = Figure(figsize=(7.5, 8.0), layout="constrained")
    ax = fig.subplots(3, 1, sharex=True)
    for traj, label, style in ((sr, "SR inverse (ε₀ = 0)", "--"), (gsr, "generalised SR (ε₀ = 0.01)", "-")):
        ax[0].semilogy(T, np.maximum(torque_error(traj), 1e-12), style, label=label)
        ax[2].semilogy(T, np.maximum(traj.singularity, 1e-17), style, label=label)
    ax[0].set_ylabel("torque error |τ − u|/|u|")
    ax[0].legend(loc="lower left", fontsize=8)
    for i in range(4):
        ax[1].plot(T, np.degrees(gsr.gimbal_angle[:, i]), label=f"gimbal {i}")
    ax[1].set_ylabel("gimbal angle, GSR (deg)")
    ax[1].legend(loc="lower left", ncol=4, fontsize=8)
    ax[2].set_ylabel("singularity measure √det(ĀĀᵀ)")
    ax[2].set_xlabel("t (s)")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("Four-CMG pyramid at δ = (−90°, 0, 90°, 0), 0.5 N·m commanded along −x", fontsize=11)
    return fig


def main(path: str | os.PathLike[str] = DEFAULT) -> dict:
    sr, gsr = run(CLUSTER), run(CLUSTER.generalised())
    error = torque_error(gsr)
    cluster = gsr.momentum_body - gsr.omega @ spacecraft(CLUSTER).rate_inertia.T   # the gyros' momentum
    summary = {
        "sr_max_gimbal_motion_rad": float(np.abs(sr.gimbal_angle - DELTA0).max()),
        "sr_max_torque_Nm": float(np.abs(sr.actuator_torque).max()),
        "gsr_first_within_1pct_s": float(T[np.argmax(error < 0.01)]),
        "gsr_max_error_after_3s": float(error[T >= 3.0].max()),
        "gsr_transverse_momentum_Nms": float(np.linalg.norm(cluster[-1, 1:])),
    }
    fig = figure(sr, gsr)
    write_atomic(path, lambda tmp: fig.savefig(tmp, format="png", dpi=110))
    return summary


if __name__ == "__main__":
    for key, value in main(*sys.argv[1:2]).items():
        print(f"{key}: {value:.3g}")
