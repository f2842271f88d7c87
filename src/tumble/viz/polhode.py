"""Poinsot's construction drawn: polhodes on the energy ellipsoid and the herpolhode on the invariable plane.

:func:`polhode_figure` draws, for a body and a body rate ``ω``, (a) the energy
ellipsoid ``Σ Iᵢωᵢ² = 2T`` in principal axes with a family of polhodes (blue:
around the axis of smallest moment; orange: around the largest), the
separatrix through the intermediate axis (black) and the polhode of this motion
(red, bold, from its start point); (b) the herpolhode, the path of ``ω`` on the
invariable plane, between the circles that bound it. Geometry and equations:
:mod:`tumble.analytic._geometry` and ``docs/stability.md``. :func:`demo_polhode` is ``tumble demo polhode``:
the figure of a T-handle and its motion in the offline 3-D viewer.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from tumble._files import write_atomic_all
from tumble._validate import ValidationError, as_array
from tumble.analytic._free import torque_free
from tumble.analytic._geometry import herpolhode, polhode_family, polhode_through, separatrix
from tumble.analytic._stability import stability
from tumble.rigid_body import RigidBody
from tumble.simulate import simulate
from tumble.trajectory import Trajectory
from tumble.viz._output import out_directory, png_writer, text_writer

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["demo_polhode", "polhode_figure", "write_polhode"]

_CURVE_POINTS = 721          # points per drawn polhode
_MOTION_PERIODS = 2.0        # a default trajectory spans this many polhode periods ...
_SAMPLES_PER_PERIOD = 1000   # ... with this many samples per period
_FALLBACK_TURNS = 20.0       # without a period (steady rotation, separatrix): this many turns 2π/|ω|
_VIEW = (22.0, -50.0)        # elevation, azimuth of the 3-D panel (deg)
_COLOURS = {"minor": "tab:blue", "major": "tab:orange", "separatrix": "black", "motion": "crimson"}
_HIDDEN_ALPHA = 0.18         # opacity of the parts of curves behind the ellipsoid
# The demo's motion: the T-handle at 10 rad/s about its intermediate principal axis and 1 rad/s about each of
# the others (principal axes), just inside the "major" regime, so that its polhode stands apart from the
# separatrix; its viewer page shows one polhode period (4K/λ) in the viewer's default frame budget.
DEMO_OMEGA = (1.0, 10.0, 1.0)
_DEMO_FRAMES = 600
_DEMO_TOLERANCE = 1e-12


def polhode_figure(body: RigidBody, omega: ArrayLike, trajectory: Trajectory | None = None, *,
                   n_curves: int = 5) -> Figure:
    """A matplotlib figure of the polhodes and the herpolhode of the motion with body rate ``omega``.

    ``omega`` (3,) rad/s in body axes, at the start of the motion. Panels:
    (a) principal axes (rad/s): the energy ellipsoid of ``T = ½ ω·Iω``
    (light surface), ``n_curves`` levels of polhodes about each stable axis
    coloured by regime, the separatrix ``L² = 2T I₂`` emphasised, and the
    polhode of ``omega`` drawn bold from its start point (a dot); the parts
    of the curves behind the ellipsoid are faded. (b) The herpolhode (rad/s,
    in-plane axes of :class:`~tumble.analytic._geometry.Herpolhode`),
    coloured by time, with the circles that bound it. ``trajectory`` is a
    torque-free trajectory of this body starting at ``omega`` (from
    :func:`tumble.simulate`, say); by default the exact solution
    (:func:`~tumble.analytic._free.torque_free`) over two polhode periods.
    Nothing is shown or saved. A spherical body (no polhodes) is refused.
    """
    from matplotlib.figure import Figure
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    if not isinstance(body, RigidBody):
        raise ValidationError(f"body: must be a RigidBody, got {type(body).__name__}")
    report = stability(body, omega)
    if trajectory is None:
        trajectory = _default_trajectory(body, as_array(omega, "omega", tail=(3,)), report.polhode_period)
    motion = polhode_through(body, omega, n=_CURVE_POINTS)
    energy = report.energy

    fig = Figure(figsize=(13.0, 6.4), layout="constrained")
    engine = fig.get_layout_engine()
    assert isinstance(engine, ConstrainedLayoutEngine)  # layout="constrained"
    engine.set(wspace=0.12)  # room for the 3-D panel's ω₃ label, which the layout does not see
    grid = fig.add_gridspec(1, 2, width_ratios=[1.25, 1.0])
    ax3d = fig.add_subplot(grid[0], projection="3d", computed_zorder=False)
    ax2d = fig.add_subplot(grid[1])
    view = _view_direction(*_VIEW)
    semi_axes = np.sqrt(2.0 * energy / body.moments)

    _draw_ellipsoid(ax3d, semi_axes)
    for curve in polhode_family(body, energy, n_curves, n=_CURVE_POINTS):
        _draw_on_ellipsoid(ax3d, curve.points, body.moments, view, color=_COLOURS[curve.regime], lw=0.9)
    for ellipse in separatrix(body, energy, n=_CURVE_POINTS):
        _draw_on_ellipsoid(ax3d, ellipse, body.moments, view, color=_COLOURS["separatrix"], lw=1.8)
    _draw_on_ellipsoid(ax3d, motion.points, body.moments, view, color=_COLOURS["motion"], lw=3.0)
    start = motion.points[0]
    ax3d.plot(*start[:, None], "o", color=_COLOURS["motion"], mec="white", mew=1.2, ms=9, zorder=10)
    _style_3d(ax3d, semi_axes)
    ax3d.legend(handles=_legend_handles(body), loc="upper left", fontsize="small", framealpha=0.9)
    ax3d.set_title("(a) polhodes on the energy ellipsoid (principal axes)", loc="left")

    _draw_herpolhode(ax2d, trajectory, motion.points)

    fig.suptitle(_title(body, report))
    return fig


def _default_trajectory(body: RigidBody, omega: np.ndarray, period: float) -> Trajectory:
    """The exact torque-free motion from ``omega`` over ``_MOTION_PERIODS`` polhode periods."""
    if np.isfinite(period):
        span, n = _MOTION_PERIODS * period, int(_MOTION_PERIODS * _SAMPLES_PER_PERIOD)
    else:
        span, n = _FALLBACK_TURNS * 2.0 * np.pi / float(np.linalg.norm(omega)), int(_FALLBACK_TURNS * 100)
    return torque_free(body, omega, t=np.linspace(0.0, span, n + 1))


def _view_direction(elev: float, azim: float) -> np.ndarray:
    """Unit vector from the centre towards the viewer of a matplotlib 3-D axes at ``elev``, ``azim`` (deg)."""
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _draw_ellipsoid(ax, semi_axes: np.ndarray) -> None:
    u, v = np.meshgrid(np.linspace(0.0, 2.0 * np.pi, 73), np.linspace(0.0, np.pi, 37))
    x, y, z = (semi_axes[:, None, None] * [np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)])
    ax.plot_surface(x, y, z, color="0.88", alpha=0.35, linewidth=0.0, antialiased=True, shade=True, zorder=0)
    for k in range(3):  # the principal axes through the ellipsoid
        end = np.zeros(3)
        end[k] = 1.15 * semi_axes[k]
        ax.plot(*np.stack([-end, end]).T, color="0.45", lw=0.7, ls=(0, (4, 3)), zorder=1)
        ax.text(*(1.3 * end), rf"$e_{k + 1}$", color="0.3", ha="center", va="center", zorder=11)


def _draw_on_ellipsoid(ax, points: np.ndarray, moments: np.ndarray, view: np.ndarray, **style) -> None:
    """Draw a curve lying on the energy ellipsoid, faded where the surface hides it.

    A point is in front when the outward normal there, ``∝ I ω``, points towards the viewer.
    """
    front = (points * moments) @ view >= 0.0
    for visible, alpha, zorder in ((False, _HIDDEN_ALPHA, 2), (True, 1.0, 5)):
        shown = points.copy()
        mask = front if visible else ~front
        # Keep the segments that touch a point of this side, so the two parts join up.
        keep = mask | np.roll(mask, 1) | np.roll(mask, -1)
        shown[~keep] = np.nan
        ax.plot(*shown.T, alpha=alpha, zorder=zorder, solid_capstyle="round", **style)


def _style_3d(ax, semi_axes: np.ndarray) -> None:
    ax.view_init(*_VIEW)
    ax.set_box_aspect(tuple(semi_axes), zoom=1.05)  # a copy: matplotlib scales the array it is given in place
    for k, set_lim in enumerate((ax.set_xlim, ax.set_ylim, ax.set_zlim)):
        set_lim(-1.25 * semi_axes[k], 1.25 * semi_axes[k])
    ax.set_xlabel(r"$\omega_1$ (rad/s)")
    ax.set_ylabel(r"$\omega_2$ (rad/s)")
    ax.set_zlabel(r"$\omega_3$ (rad/s)")
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_pane_color((1.0, 1.0, 1.0, 0.0))
        axis._axinfo["grid"]["color"] = (0.85, 0.85, 0.85, 1.0)
    ax.tick_params(labelsize="x-small")


def _legend_handles(body: RigidBody) -> list:
    from matplotlib.lines import Line2D

    handles = []
    if body.moments[0] < body.moments[1]:
        handles.append(Line2D([], [], color=_COLOURS["minor"], lw=1.2, label=r"around $e_1$ (smallest moment)"))
    if body.moments[1] < body.moments[2]:
        handles.append(Line2D([], [], color=_COLOURS["major"], lw=1.2, label=r"around $e_3$ (largest moment)"))
    label = r"separatrix $L^2 = 2TI_2$" if body.symmetry(rtol=0.0) == "asymmetric" else "steady rotations"
    handles.append(Line2D([], [], color=_COLOURS["separatrix"], lw=1.8, label=label))
    handles.append(Line2D([], [], color=_COLOURS["motion"], lw=3.0, marker="o", mec="white",
                          label="this motion (dot: start)"))
    return handles


def _draw_herpolhode(ax, trajectory: Trajectory, polhode_points: np.ndarray) -> None:
    """Panel (b): the herpolhode coloured by time, its bounding circles and the foot of L."""
    from matplotlib.collections import LineCollection

    path = herpolhode(trajectory)
    points = path.points
    segments = np.stack([points[:-1], points[1:]], axis=1)
    lines = LineCollection(list(segments), cmap="viridis", linewidths=1.4)  # the segments' stubs: a sequence
    lines.set_array(trajectory.t[:-1])
    ax.add_collection(lines)
    colorbar = ax.figure.colorbar(lines, ax=ax, shrink=0.85, pad=0.02)
    colorbar.set_label("time t (s)")

    # |ω|² = h² + r² on the plane: the extremes of |ω| along the polhode bound r.
    radii = np.sqrt(np.maximum(np.sum(polhode_points**2, axis=1) - path.height**2, 0.0))
    ring = np.linspace(0.0, 2.0 * np.pi, 361)
    for k, r in enumerate((radii.min(), radii.max())):
        ax.plot(r * np.cos(ring), r * np.sin(ring), color="0.4", ls="--", lw=0.8,
                label="bounds $r_{min}$, $r_{max}$" if k == 0 else None)
    ax.plot(0.0, 0.0, "+", color="k", ms=12, mew=1.5, label=r"foot of $L$ (plane's centre)")
    ax.plot(*points[0], "o", color=_COLOURS["motion"], mec="white", mew=1.2, ms=9, label="start")
    ax.set_aspect("equal")
    extent = 1.12 * max(radii.max(), np.abs(points).max()) or 0.1 * path.height  # a steady rotation: one point
    ax.set_xlim(-extent, extent)
    ax.set_ylim(-extent, extent)
    ax.set_xlabel("in-plane axis a (rad/s)")
    ax.set_ylabel("in-plane axis b (rad/s)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize="small", framealpha=0.9)
    ax.set_title("(b) herpolhode: ω on the invariable plane (inertial)", loc="left")
    ax.text(0.02, 0.02, f"plane normal to L, at 2T/|L| = {path.height:.4g} rad/s from the origin",
            transform=ax.transAxes, fontsize="small", color="0.25")


def _title(body: RigidBody, report) -> str:
    moments = ", ".join(f"{m:.3g}" for m in body.moments)
    w = ", ".join(f"{x:.3g}" for x in report.omega_principal)
    name = f"{body.name}: " if body.name else ""
    timing = (f"flips every 2K/λ = {report.flip_interval:.4g} s, polhode period 4K/λ = {report.polhode_period:.4g} s"
              if np.isfinite(report.flip_interval) else "no flips")
    return (f"{name}moments {moments} kg m², ω = [{w}] rad/s (principal axes), regime '{report.regime}'\n"
            f"T = {report.energy:.4g} J, |L| = {report.momentum:.4g} N m s; {timing}")


def write_polhode(output: str | os.PathLike[str]) -> dict:
    """:func:`polhode_figure` of :meth:`RigidBody.t_handle` at ω = ``body.axes @ DEMO_OMEGA`` (rad/s) written
    to ``output`` (PNG) and, beside it with ``.html``, one polhode period of the motion (dop853,
    rtol = atol = 1e-12) in the offline 3-D viewer, together and atomically. Returns the principal moments
    (kg m²), the stability of each axis, the regime, the time between flips 2K/λ and the polhode period
    4K/λ (s), and the paths written."""
    from tumble.viz.viewer import Cylinder, html_page
    from tumble.viz.racket import T_HANDLE_PIECES

    page = Path(output).with_suffix(".html")
    body = RigidBody.t_handle()
    omega0 = body.axes @ np.array(DEMO_OMEGA)
    report = stability(body, omega0)
    figure = polhode_figure(body, omega0)
    traj = simulate(body, omega0, t=np.linspace(0.0, report.polhode_period, _DEMO_FRAMES),
                    method="dop853", rtol=_DEMO_TOLERANCE, atol=_DEMO_TOLERANCE)
    html = html_page(traj, model=body, shape=[Cylinder(**piece) for piece in T_HANDLE_PIECES])
    write_atomic_all([(output, png_writer(figure)), (page, text_writer(html))])
    return {"moments": tuple(float(m) for m in report.moments), "axis_stability": tuple(report.axis_stability),
            "regime": report.regime, "flip_interval_s": report.flip_interval,
            "polhode_period_s": report.polhode_period, "omega_principal": DEMO_OMEGA,
            "png": os.fspath(output), "html": os.fspath(page)}


def demo_polhode(out_dir: str | os.PathLike[str]) -> dict:
    """``tumble demo polhode``: :func:`write_polhode` into ``polhode.png`` and ``polhode.html`` of ``out_dir``
    (an existing directory)."""
    return write_polhode(os.path.join(out_directory(out_dir), "polhode.png"))
