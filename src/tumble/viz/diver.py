"""``tumble demo diver``: the three experiments of ``docs/diver.md``, their figures and numbers."""

from __future__ import annotations

import functools
import os
from typing import TYPE_CHECKING

import numpy as np

from tumble import attitude
from tumble._files import write_atomic
from tumble.variable import diver
from tumble.variable.human import Human
from tumble.viz._output import out_directory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["demo_diver", "figure_dive", "figure_twist_rule"]

# Tilts of the rule-of-thumb sweep, degrees.
RULE_TILTS_DEG = (2.0, 3.0, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0, 30.0)
# Number of poses drawn in a dive figure, and the length (m) of the line drawn for the neck and head.
_POSES = 9
_NECK_AND_HEAD = 0.3


def demo_diver(out_dir: str | os.PathLike[str]) -> dict:
    """Run experiments (a)–(c) and write their figures and the dive's NetCDF into ``out_dir``.

    Files (each written atomically): ``diver_twisting_somersault.png`` (a),
    ``diver_twist_rule.png`` (b), ``diver_513xd.png`` (c) and ``diver_513xd.nc``
    (the dive as a :class:`~tumble.Trajectory`; extras: ``inertia_t``,
    ``shape_momentum``, ``angular_momentum``, ``energy_rotational``,
    ``joint_angles``, ``shape_energy``), and ``diver_513xd.html``, the dive
    in the offline viewer (:mod:`tumble.viz.viewer`). Returns the numbers: somersaults and
    twists of (a) and (c), the largest relative ``|L|`` drift, the final tilt
    of (c), the rule-of-thumb comparison of (b), and the paths written.
    ``out_dir`` must be an existing directory.
    """
    out_directory(out_dir)
    human = Human.de_leva()
    twisting = diver.twisting_somersault(human)
    sweep = diver.twist_rule_sweep(np.radians(RULE_TILTS_DEG), human)
    dive = diver.dive_513xd(human)

    names = ("twisting_somersault", "twist_rule", "513xd")
    paths = {name: os.path.join(out_dir, f"diver_{name}.png") for name in names}
    figures = {
        "twisting_somersault": figure_dive(human, twisting, "(a) a layout somersault acquires twist when the "
                                           "left arm drops"),
        "twist_rule": figure_twist_rule(sweep),
        "513xd": figure_dive(human, dive, "(c) forward 1½ somersaults with twists, arms out and back in"),
    }
    for name, fig in figures.items():
        write_atomic(paths[name], functools.partial(fig.savefig, format="png", dpi=110))
    nc_path, html_path = os.path.join(out_dir, "diver_513xd.nc"), os.path.join(out_dir, "diver_513xd.html")
    dive.trajectory.save(nc_path)
    dive.trajectory.to_html(html_path, model=human)
    tilts = np.array(RULE_TILTS_DEG)
    moderate = (tilts >= 10.0) & (tilts <= 30.0)
    return {
        "twisting_somersault_somersaults": twisting.somersaults,
        "twisting_somersault_twists": twisting.twists,
        "twisting_somersault_momentum_drift": twisting.momentum_drift,
        "rule_tilts_deg": list(RULE_TILTS_DEG),
        "rule_twists_per_somersault": sweep["rule"].tolist(),
        "simulated_twists_per_somersault": sweep["simulated"].tolist(),
        "rule_max_relative_error_10_30_deg": float(np.abs(sweep["simulated"] / sweep["rule"] - 1.0)[moderate].max()),
        "mean_tilts_deg": np.degrees(sweep["mean_tilt"]).tolist(),
        "rule_mean_tilt_max_relative_error": float(np.abs(sweep["simulated"] / sweep["rule_mean_tilt"] - 1.0).max()),
        "dive_somersaults": dive.somersaults,
        "dive_twists": dive.twists,
        "dive_final_tilt_deg": float(np.degrees(dive.angles.tilt[-1])),
        "dive_momentum_drift": dive.momentum_drift,
        "nc": nc_path,
        "html": html_path,
        **{f"png_{name}": path for name, path in paths.items()},
    }


def figure_dive(human: Human, dive: diver.Dive, title: str) -> Figure:
    """Figure of a dive: poses seen along ``L``; somersault and twist (turns); tilt; shoulder angles; energy."""
    from matplotlib.figure import Figure

    traj, angles = dive.trajectory, dive.angles
    t = traj.t
    fig = Figure(figsize=(10.0, 10.0), layout="constrained")
    grid = fig.add_gridspec(4, 1, height_ratios=[1.3, 1.0, 0.8, 0.8])
    ax_pose = fig.add_subplot(grid[0])
    _draw_poses(ax_pose, human, dive)
    ax_turns = fig.add_subplot(grid[1])
    sign = np.sign(angles.somersault[-1] - angles.somersault[0]) or 1.0
    ax_turns.plot(t, sign * (angles.somersault - angles.somersault[0]) / (2 * np.pi),
                  label=f"somersaults ({abs(dive.somersaults):.2f})")
    ax_turns.plot(t, (angles.twist - angles.twist[0]) / (2 * np.pi), label=f"twists ({dive.twists:+.2f})")
    ax_turns.set_ylabel("turns")
    ax_turns.set_title("somersault φ and twist ψ (Yeadon's angles about L)", loc="left")
    ax_tilt = fig.add_subplot(grid[2], sharex=ax_turns)
    ax_tilt.plot(t, np.degrees(angles.tilt), label="tilt θ", color="C2")
    joints = traj.joint_angles
    for name, style in (("left_shoulder_abduction", "-"), ("right_shoulder_abduction", "--")):
        k = human.dofs.index(name)
        ax_tilt.plot(t, np.degrees(joints[:, k]) / 10.0, style, color="0.5", label=f"{name} / 10")
    ax_tilt.set_ylabel("deg")
    ax_tilt.set_title("tilt of the long axis and the arm angles (shoulder abduction, scaled by 1/10)", loc="left")
    ax_energy = fig.add_subplot(grid[3], sharex=ax_turns)
    ax_energy.plot(t, traj.energy, label="kinetic energy ½ω·Iω + ω·A + T_shape")
    ax_energy.plot(t, traj.energy_rotational, label="½ω·I(t)ω")
    ax_energy.set_ylabel("J")
    ax_energy.set_xlabel("time t (s)")
    ax_energy.set_title(f"energy (the muscles do work); |L| drift {dive.momentum_drift:.1e}", loc="left")
    for ax in (ax_turns, ax_tilt, ax_energy):
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    fig.suptitle(title)
    return fig


def _draw_poses(ax, human, dive):
    """Stick figures at evenly spaced times, seen along L (the somersault axis), drawn side by side."""
    traj = dive.trajectory
    picks = np.linspace(0, traj.t.size - 1, _POSES).astype(int)
    kin = human.kinematics(traj.t[picks], _angles_at(human, traj, picks))
    L_hat = np.sign(dive.momentum) * np.array([1.0, 0.0, 0.0])
    view_x, view_y = np.cross([0.0, 0.0, 1.0], L_hat), np.array([0.0, 0.0, 1.0])
    parents = [None if s.parent is None else human.names.index(s.parent) for s in human.segments]
    for j, k in enumerate(picks):
        R = attitude.to_matrix(traj.q[k])
        offset = np.array([2.2 * j, 0.0])

        def project(p, R=R, k=j, offset=offset):
            v = R @ (p - kin.com[k])
            return np.array([v @ view_x, v @ view_y]) + offset

        ends = _segment_ends(human, kin, j)
        for i, (a, b) in enumerate(ends):
            pa, pb = project(a), project(b)
            color = "C3" if "left" in human.names[i] else "C0" if "right" in human.names[i] else "k"
            ax.plot([pa[0], pb[0]], [pa[1], pb[1]], color=color, lw=2.5 if parents[i] is None else 1.8)
        ax.text(offset[0], -1.25, f"{traj.t[k]:.2f} s", ha="center", fontsize="small")
    ax.set_aspect("equal")
    ax.set_xlim(-1.2, 2.2 * (_POSES - 1) + 1.2)
    ax.set_ylim(-1.4, 1.2)
    ax.axis("off")
    ax.set_title("poses seen along L (red: left limbs, blue: right limbs; black: trunk and head)", loc="left")


def _angles_at(human, traj, picks):
    joints = traj.extras["joint_angles"].data
    return {name: _Sampled(traj.t[picks], joints[picks, i]) for i, name in enumerate(human.dofs)}


class _Sampled:
    """Angles known at the drawn times only (rates are not needed to draw a pose)."""

    def __init__(self, t, values):
        self._t, self._values = t, values

    def angle(self, t):
        return np.interp(t, self._t, self._values)

    def rate(self, t):
        return np.zeros_like(np.asarray(t, dtype=np.float64))


def _segment_ends(human, kin, k):
    """(start, end) of each segment's line (body axes, from the hip centre): joint to child joint, or to the
    joint's mirror image through the segment's centre of mass; the trunk from the hip centre to the neck."""
    names = human.names
    ends = []
    for i, seg in enumerate(human.segments):
        start = kin.joint[k, i]
        children = [j for j, s in enumerate(human.segments) if s.parent == seg.name]
        if seg.parent is None:
            shoulders = [j for j in children if "arm" in names[j]]
            tip = kin.joint[k, shoulders].mean(axis=0) + np.array([0.0, 0.0, _NECK_AND_HEAD])
        elif children:
            tip = kin.joint[k, children[0]]
        else:
            tip = start + 2.0 * (kin.segment_com[k, i] - start)
        ends.append((start, tip))
    return ends


def figure_twist_rule(sweep: dict) -> Figure:
    """Figure (b): twists per somersault against the tilt, simulation and rule of thumb."""
    from matplotlib.figure import Figure

    tilt = np.degrees(sweep["tilt"])
    i_x, i_y, i_z = sweep["moments"]
    fine = np.linspace(0.0, tilt.max(), 200)
    fig = Figure(figsize=(8.0, 6.0), layout="constrained")
    ax, ax_err = fig.subplots(2, 1, sharex=True, height_ratios=[2.0, 1.0])
    ax.plot(fine, diver.twist_rule(np.radians(fine), i_x, i_z), color="k",
            label=f"rule of thumb sin θ (I_s/I_l − 1), I_s = I_x = {i_x:.2f}, I_l = {i_z:.2f} kg m²")
    ax.plot(tilt, sweep["simulated"], "o", color="C0", label=f"simulated, layout (I_y = {i_y:.2f} kg m²)")
    ax.plot(tilt, sweep["axisymmetric"], "x", color="C1", label="simulated, axisymmetric diag(I_x, I_x, I_z)")
    ax.plot(tilt, sweep["rule_mean_tilt"], "+", color="C2", ms=9, label="rule at the layout's mean tilt θ̄")
    ax.set_ylabel("twists per somersault")
    ax.set_title("(b) twists per somersault of a rigid layout against the initial tilt", loc="left")
    ax_err.plot(tilt, 100.0 * (sweep["simulated"] / sweep["rule"] - 1.0), "o-", color="C0",
                label="rule at the initial tilt θ₀")
    ax_err.plot(tilt, 100.0 * (sweep["simulated"] / sweep["rule_mean_tilt"] - 1.0), "+-", color="C2",
                label="rule at the mean tilt θ̄")
    ax_err.axhline(0.0, color="k", lw=0.8)
    ax_err.set_ylabel("simulated / rule − 1 (%)")
    ax_err.set_xlabel("initial tilt θ₀ (deg)")
    ax_err.legend(loc="upper right", fontsize="small")
    for a in (ax, ax_err):
        a.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize="small")
    return fig
