"""Demonstration: the Franka Panda released under gravity, its joint angles and its energy balance.

:func:`demo_robot` simulates the arm of ``tumble.examples.path("panda.urdf")`` (from the
source tree, or the URDF given) falling from a bent pose with no joint torque
(``tumble.simulate(chain, q0=..., t=...)``), and writes the trajectory (NetCDF)
and a figure of the joint angles and of the drift of the total energy
``T + V``, which an exact solution keeps constant.

The model has no joint stops: the arm swings through its joint limits, which
a real Panda would hit. The figure says so, and shades the motion from the
first time a joint leaves its range.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tumble.robot.chain import load
from tumble.simulate import simulate
from tumble._files import write_atomic

__all__ = ["demo_robot"]

# Released from Franka's "ready" pose with the elbow and wrist bent further.
_Q0 = (0.0, -0.2, 0.0, -1.2, 0.0, 1.0, 0.7)
_DURATION = 2.0  # s
_SAMPLES = 401
_TOLERANCE = 1e-12
# The drift axis is linear below this (under float64 rounding of E ≈ 100 J) and logarithmic above.
_LINTHRESH = 1e-14


def demo_robot(out_dir: Path, robot_file: Path) -> dict:
    """Simulate an arm (the Panda: ``tumble.examples.path("panda.urdf")``) falling for 2 s from a bent pose
    (dop853, rtol = atol = 1e-12); write ``robot_fall.nc`` and ``.png``.

    Returns a summary: the written paths, the largest energy drift (J), the
    energy scale (J), the steps taken, and the first time (s) a joint leaves
    its limits (None if none does). ``out_dir`` must exist.
    """
    out_dir = Path(out_dir)
    chain = load(robot_file)
    t = np.linspace(0.0, _DURATION, _SAMPLES)
    run = simulate(chain, q0=np.array(_Q0), t=t, method="dop853", rtol=_TOLERANCE, atol=_TOLERANCE)
    drift = run.energy - run.energy[0]
    outside = np.logical_not(chain.within_limits(run.joint_position))
    first = int(outside.argmax()) if outside.any() else None  # the first sample beyond the limits
    nc, png = out_dir / "robot_fall.nc", out_dir / "robot_fall.png"
    run.save(nc)
    figure = _figure(run, drift, chain, first)
    write_atomic(png, lambda tmp: figure.savefig(tmp, format="png", dpi=120))
    return {"written": [str(nc), str(png)], "max_energy_drift_J": float(np.abs(drift).max()),
            "energy_scale_J": float(np.abs(run.energy).max()), "steps": run.info["n_steps"],
            "leaves_joint_limits_s": None if first is None else float(t[first])}


def _figure(run, drift, chain, first):
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8.0, 5.5), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    for i, name in enumerate(chain.joint_names):
        top.plot(run.t, run.joint_position[:, i], label=str(name))
    top.set_ylabel("joint angle q (rad)")
    title = f"{chain.name}: released under gravity, no joint torque"
    if first is not None:
        q = run.joint_position[first]
        names = [str(name) for name, out in zip(chain.joint_names, (q < chain.lower) | (q > chain.upper)) if out]
        top.axvspan(run.t[first], run.t[-1], color="0.88", zorder=0)
        title += (f"\njoint limits not enforced (no stops): {', '.join(names)} leaves its range at "
                  f"t = {run.t[first]:g} s (shaded after)")
    top.set_title(title)
    top.legend(ncol=4, fontsize="small", loc="lower left")
    bottom.plot(run.t, np.abs(drift))
    bottom.set_yscale("symlog", linthresh=_LINTHRESH)  # exact zeros stay on the plot
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("|E(t) − E(0)| (J)")
    bottom.set_title("energy drift, dop853 at rtol = atol = 1e-12")
    return figure
