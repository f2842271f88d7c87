"""The figures and demos of passive attitude stability: gravity-gradient regions and libration, Explorer 1.

:func:`gravity_gradient_stability_figure` draws the (k_R, k_Y) plane; :func:`demo_gravity_gradient` and
:func:`demo_explorer1` run the satellites of :mod:`tumble.spacecraft.passive` (``tumble demo gravity-gradient``,
``tumble demo explorer1``, ``docs/passive_stability.md``).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from tumble.rigid_body import RigidBody
from tumble.simulate import simulate
from tumble.spacecraft import damper as _damper
from tumble.spacecraft.orbit import Orbit, attitude_in_lvlh
from tumble.spacecraft.passive import (EXPLORER1, GG_ORBIT, GG_SATELLITE, Explorer1, gravity_gradient_libration,
                                       gravity_gradient_stability, roll_yaw_conditions)
from tumble.trajectory import Trajectory
from tumble.viz._output import out_directory, save_png

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["demo_explorer1", "demo_gravity_gradient", "explorer1_figure", "gravity_gradient_stability_figure"]

def gravity_gradient_stability_figure(spacecraft_inertia: RigidBody | ArrayLike | None = None, *,
                                      label: str = "spacecraft", resolution: int = 801) -> Figure:
    """The gravity-gradient stability regions in the (k_R, k_Y) plane, with a spacecraft placed on it.

    Shaded: the Lagrange region (stable, also with dissipation) and the
    DeBra–Delp region (gyroscopically stable only); hatched lines: the pitch
    boundary ``k_R = k_Y`` and the roll/yaw boundary
    ``1 + 3k_R + k_R k_Y = 4 √(k_R k_Y)``. Physical bodies lie in
    ``|k_R|, |k_Y| ≤ 1`` (triangle inequality). ``spacecraft_inertia`` (as in
    :func:`gravity_gradient_stability`) is marked with its region.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    k = np.linspace(-1.0, 1.0, resolution)
    kr, ky = np.meshgrid(k, k)  # k_R along x, k_Y along y
    _, _, roll_yaw = roll_yaw_conditions(kr, ky)
    stable = roll_yaw & (kr > ky)
    region = np.where(stable & (kr > 0), 2, np.where(stable & (kr < 0), 1, 0))

    fig = Figure(figsize=(6.4, 6.0), layout="constrained")
    ax = fig.add_subplot()
    colours = ListedColormap(["white", "tab:orange", "tab:green"])
    ax.pcolormesh(kr, ky, region, cmap=colours, vmin=0, vmax=2, shading="auto", alpha=0.45, rasterized=True)
    ax.plot([-1, 1], [-1, 1], color="k", lw=1.0, label="pitch boundary $k_R = k_Y$")
    b, c, _ = roll_yaw_conditions(kr, ky)
    with np.errstate(invalid="ignore"):
        margin = np.where(kr * ky > 0, b - 2.0 * np.sqrt(np.abs(c)), np.nan)
    ax.contour(kr, ky, margin, levels=[0.0], colors="tab:red", linewidths=1.0)
    ax.plot([], [], color="tab:red", lw=1.0, label=r"roll/yaw boundary $1 + 3k_R + k_Rk_Y = 4\sqrt{k_Rk_Y}$")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.axvline(0.0, color="0.5", lw=0.6)
    ax.text(0.55, 0.18, "Lagrange\n(stable)", ha="center", fontsize=10)
    ax.annotate("DeBra–Delp\n(gyroscopic)", xy=(-0.06, -0.55), xytext=(-0.6, -0.75), ha="center", fontsize=9,
                arrowprops={"arrowstyle": "->", "lw": 0.8})
    ax.text(-0.55, 0.5, "unstable", ha="center", color="0.3")
    if spacecraft_inertia is not None:
        s = gravity_gradient_stability(spacecraft_inertia)
        ax.plot(s.k_roll, s.k_yaw, "k*", ms=14, label=f"{label}: {s.region}")
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$k_R = (I_2 - I_3)/I_1$  (1 roll, 2 pitch, 3 yaw)")
    ax.set_ylabel(r"$k_Y = (I_2 - I_1)/I_3$")
    ax.set_title("Gravity-gradient stability of the LVLH attitude (circular orbit)")
    ax.legend(loc="upper left", fontsize=8)
    return fig


def _libration_figure(traj: Trajectory, orbit: Orbit, moments) -> Figure:
    from matplotlib.figure import Figure

    rel = attitude_in_lvlh(traj, orbit)
    s = gravity_gradient_stability(moments)
    fig = Figure(figsize=(7.5, 4.2), layout="constrained")
    ax = fig.add_subplot()
    for name, values in (("roll", rel.roll), ("pitch", rel.pitch), ("yaw", rel.yaw)):
        ax.plot(traj.t / orbit.period, np.degrees(values), lw=1.0, label=name)
    ax.set_xlabel("time (orbits)")
    ax.set_ylabel("angle from LVLH (deg)")
    freqs = ", ".join(f"{f:.3f}" for f in s.roll_yaw_frequencies)
    ax.set_title(f"Gravity-gradient libration, moments {tuple(moments)} kg m$^2$ ({s.region} region)\n"
                 f"linear theory: pitch {s.pitch_frequency:.3f} n, roll/yaw {freqs} n", fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def demo_gravity_gradient(out_dir: str | os.PathLike[str]) -> dict:
    """A boom satellite (:data:`GG_SATELLITE`) released 5° pitch, 3° roll, 2° yaw off LVLH, 10 orbits.

    Writes ``gravity_gradient.nc`` (the trajectory), ``gravity_gradient.png``
    (roll, pitch, yaw from LVLH against orbits),
    ``passive_gg_regions.png`` (the stability regions with the satellite) and
    ``gravity_gradient.html`` (the offline viewer, :mod:`tumble.viz.viewer`) in
    ``out_dir``, atomically. Returns the stability classification, the
    linear-theory frequencies (units of the orbit rate), the largest angle
    from LVLH (deg) and the paths written.
    """
    out_directory(out_dir)
    angles = np.radians([3.0, 5.0, 2.0])
    traj = gravity_gradient_libration(GG_SATELLITE, GG_ORBIT, angles)
    rel = attitude_in_lvlh(traj, GG_ORBIT)
    s = gravity_gradient_stability(GG_SATELLITE)
    paths = {key: os.path.join(out_dir, name) for key, name in
             (("nc", "gravity_gradient.nc"), ("png", "gravity_gradient.png"), ("regions", "passive_gg_regions.png"),
              ("html", "gravity_gradient.html"))}
    traj.save(paths["nc"])
    traj.to_html(paths["html"])
    save_png(_libration_figure(traj, GG_ORBIT, GG_SATELLITE), paths["png"])
    save_png(gravity_gradient_stability_figure(GG_SATELLITE, label="boom satellite"), paths["regions"])
    return {
        "region": s.region,
        "k_roll": s.k_roll,
        "k_yaw": s.k_yaw,
        "pitch_frequency": s.pitch_frequency,
        "roll_yaw_frequencies": s.roll_yaw_frequencies.tolist(),
        "orbit_period_s": GG_ORBIT.period,
        "max_angle_deg": float(np.degrees(np.max(np.abs([rel.roll, rel.pitch, rel.yaw])))),
        **paths,
    }


def explorer1_figure(traj: Trajectory, spacecraft: Explorer1 = EXPLORER1) -> Figure:
    """(a) nutation angle (deg, log scale) with the energy-sink estimate; (b) spin about the long axis and
    transverse rate; (c) kinetic energy of hub + damper and the flat-spin floor ``L²/(2 I_t)``."""
    from matplotlib.figure import Figure

    dm = spacecraft.damper()
    i_s, i_t = spacecraft.locked_moments()
    tau = _damper.energy_sink_time_constant(i_s, i_t, dm, spacecraft.spin)
    assert traj.omega is not None  # the hub's rate
    theta = _damper.nutation_angle(traj, [0.0, 0.0, 1.0])
    energy = traj.energy
    momentum = np.linalg.norm(traj.momentum_body[0])
    minutes = traj.t / 60.0

    fig = Figure(figsize=(7.5, 8.0), layout="constrained")
    ax = fig.subplots(3, 1, sharex=True)
    ax[0].semilogy(minutes, np.degrees(theta), lw=1.2, label="simulated")
    estimate = spacecraft.nutation0 * np.exp(traj.t / tau)
    early = estimate < 0.5
    ax[0].semilogy(minutes[early], np.degrees(estimate[early]), "k--", lw=1.0,
                   label=f"energy-sink estimate, τ = {tau:.0f} s")
    ax[0].axhline(90.0, color="0.5", lw=0.6)
    ax[0].set_ylabel("nutation angle (deg)")
    ax[0].legend(loc="lower right", fontsize=8)
    ax[1].semilogy(minutes, np.abs(traj.omega[:, 2]), lw=1.0, label=r"spin about the long axis $|\omega_z|$")
    ax[1].semilogy(minutes, np.hypot(traj.omega[:, 0], traj.omega[:, 1]), lw=1.0,
                   label=r"transverse rate $\sqrt{\omega_x^2 + \omega_y^2}$")
    ax[1].set_ylim(bottom=1e-4)
    ax[1].set_ylabel("rate (rad/s)")
    ax[1].legend(loc="center right", fontsize=8)
    ax[2].semilogy(minutes, energy, lw=1.2, label="kinetic energy (hub + damper)")
    ax[2].axhline(momentum**2 / (2.0 * i_t), color="k", ls="--", lw=1.0,
                  label=r"flat spin $L^2/(2I_t)$ (least energy for $|L|$)")
    ax[2].set_ylabel("energy (J)")
    ax[2].set_xlabel("time (min)")
    ax[2].legend(loc="upper right", fontsize=8)
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("Explorer 1: a spin about the minor axis decays into a flat spin", fontsize=11)
    return fig


def demo_explorer1(out_dir: str | os.PathLike[str], spacecraft: Explorer1 = EXPLORER1) -> dict:
    """Simulate the Explorer 1 flat spin and compare its nutation time constant with the energy-sink estimate.

    Integrates hub + damper (:meth:`Explorer1.spacecraft` through :func:`tumble.simulate`,
    dop853, rtol 1e-12) for ``spacecraft.duration`` s, writes
    ``explorer1.nc``, ``explorer1.png`` and ``explorer1.html`` (the offline viewer,
    :mod:`tumble.viz.viewer`) in ``out_dir`` atomically, and
    returns: the time constant measured (fit of ln θ for θ between 2θ₀ and
    0.2 rad) and estimated (s), the final nutation angle (deg) and spin axis
    (unit ``L`` in body axes), the relative drift of ``|L|`` and of the
    inertial ``L``, the largest energy increase between samples (relative;
    ≤ 0 when the energy falls monotonically), and the paths.
    """
    out_directory(out_dir)
    dm = spacecraft.damper()
    t = np.linspace(0.0, spacecraft.duration, int(round(spacecraft.duration * 2)) + 1)
    craft = spacecraft.spacecraft()
    traj = simulate(craft, spacecraft.omega0(), t=t, rtol=1e-12, atol=1e-12)
    theta = _damper.nutation_angle(traj, [0.0, 0.0, 1.0])
    i_s, i_t = spacecraft.locked_moments()
    momentum = traj.momentum_inertial
    size = np.linalg.norm(momentum, axis=-1)
    energy = traj.energy
    final_axis = traj.momentum_body[-1] / size[-1]
    paths = {name: os.path.join(out_dir, f"explorer1.{name}") for name in ("nc", "png", "html")}
    traj.save(paths["nc"])
    traj.to_html(paths["html"], model=craft)
    save_png(explorer1_figure(traj, spacecraft), paths["png"])
    return {
        "time_constant_s": _damper.measured_time_constant(t, theta, window=(2 * spacecraft.nutation0, 0.2)),
        "time_constant_estimate_s": _damper.energy_sink_time_constant(i_s, i_t, dm, spacecraft.spin),
        "final_nutation_deg": float(np.degrees(theta[-1])),
        "final_spin_axis_body": final_axis.tolist(),
        "momentum_drift": float(np.max(np.abs(size / size[0] - 1.0))),
        "momentum_vector_drift": float(np.max(np.linalg.norm(momentum - momentum[0], axis=-1)) / size[0]),
        "max_energy_increase": float(np.max(np.diff(energy)) / energy[0]),
        "energy_initial_J": float(energy[0]),
        "energy_final_J": float(energy[-1]),
        **paths,
    }

