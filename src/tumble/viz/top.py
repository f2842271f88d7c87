"""Figures of the heavy symmetric top: the exact motion and a simulation side by side.

:func:`top_figure` draws the symmetry axis of a :class:`~tumble.analytic.HeavyTop`
(the exact theory) and, optionally, of a simulated trajectory; :func:`demo_top`
simulates a default top with ``tumble.simulate`` and ``tumble.torques.Gravity``
and writes ``top.nc`` and ``top.png``. Conventions and equations:
``docs/heavy_top.md``.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import require_positive
from tumble.analytic import HeavyTop, axis_motion, measure_nutation
from tumble.simulate import simulate
from tumble._files import write_atomic
from tumble.trajectory import Trajectory
from tumble.viz._output import out_directory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["DEMO_TOP", "demo_top", "top_figure"]

#: The demonstration top: a 0.5 kg top, centre of mass 5 cm above the pivot,
#: I₃ = 5e-4 kg·m², I₁ = 1.5e-3 kg·m² about the pivot, spun at 120 rad/s
#: (about 1.6 × the critical spin of the sleeping top, 76.7 rad/s) and
#: released at θ = 60° with φ̇ = −3 rad/s against its mean precession
#: (+4.12 rad/s): the axis nutates between 60° and 79.2° every 0.166 s and
#: draws a loop at each θ minimum, about 9 per precession revolution (1.52 s).
DEMO_TOP = HeavyTop(I1=1.5e-3, I3=5e-4, mass=0.5, length=0.05, g=9.81,
                    theta0=math.radians(60.0), theta_dot0=0.0, phi_dot0=-3.0, spin=120.0)
_DEMO_TOLERANCE = 1e-12          # dop853 rtol = atol
_DEMO_SAMPLES_PER_PERIOD = 500   # output samples per nutation period (turning points to ~1e-12)
_EXACT_SAMPLES_PER_PERIOD = 200  # points per nutation period of the exact curves
_MAX_EXACT_SAMPLES = 50_000
_MAX_MARKERS = 400               # simulated samples drawn as markers, at most, per panel


def top_figure(top: HeavyTop, trajectory: Trajectory | None = None, *, com: ArrayLike | None = None,
               g: ArrayLike | None = None, duration: float | None = None) -> Figure:
    """A matplotlib figure of the heavy top's symmetry axis (nothing is shown or saved).

    Panels: (a) the axis seen from above, at distance θ (deg) from the centre
    in the direction of its horizontal projection (``x = θ sin φ``,
    ``y = −θ cos φ``), with the nutation bounds θ_min, θ_max as dashed
    circles; (b) θ(t) (deg) with the bounds; (c) the precession rate φ̇(t)
    (rad/s) with its exact mean and the slow-top approximation
    ``m g l / (I₃ ω₃)``. Lines: the exact theory of ``top``; markers: the
    simulated ``trajectory`` (one body, started in ``top``'s state), whose
    axis is ``com`` (body axes) and vertical ``−g`` (inertial axes), by
    default the setup of :meth:`HeavyTop.simulation_inputs`. Times are
    seconds since the trajectory's first sample; ``duration`` (s) sets the
    span without a trajectory (default: four nutation periods).
    """
    from matplotlib.figure import Figure

    if com is None or g is None:
        gravity = top.simulation_inputs()["torque"]
        com = gravity.com if com is None else com
        g = gravity.g if g is None else g
    motion = None if trajectory is None else axis_motion(trajectory, com=com, g=g)
    period = top.nutation_period
    if motion is not None:
        span = float(motion.t[-1] - motion.t[0])
    elif duration is not None:
        span = require_positive(duration, "duration")
    else:
        span = 4.0 * period if math.isfinite(period) else 10.0
    n_exact = int(min(_MAX_EXACT_SAMPLES, max(2000, _EXACT_SAMPLES_PER_PERIOD * span / period)))
    t = np.linspace(0.0, span, n_exact)
    phi0 = 0.0 if motion is None else float(motion.phi[0])
    theta, phi = np.degrees(top.theta(t)), phi0 + top.precession_angle(t)

    fig = Figure(figsize=(12.0, 5.6), layout="constrained")
    axes = fig.subplot_mosaic([["above", "theta"], ["above", "rate"]], width_ratios=[1.0, 1.25])
    above, ax_theta, ax_rate = axes["above"], axes["theta"], axes["rate"]
    ax_rate.sharex(ax_theta)

    above.plot(theta * np.sin(phi), -theta * np.cos(phi), lw=1.0, label="exact")
    ring = np.linspace(0.0, 2.0 * np.pi, 361)
    for k, bound in enumerate(np.degrees([top.theta_min, top.theta_max])):
        above.plot(bound * np.cos(ring), bound * np.sin(ring), "k--", lw=0.8,
                   label=r"$\theta_{min}$, $\theta_{max}$" if k == 0 else None)
    above.plot(0.0, 0.0, "k+", ms=10, label="vertical")
    above.set_aspect("equal")
    above.set_xlabel(r"$\theta \sin\varphi$ (deg)")
    above.set_ylabel(r"$-\theta \cos\varphi$ (deg)")
    above.set_title("(a) symmetry axis seen from above", loc="left")

    ax_theta.plot(t, theta, lw=1.0, label="exact")
    for k, bound in enumerate(np.degrees([top.theta_min, top.theta_max])):
        ax_theta.axhline(bound, color="k", ls="--", lw=0.8, label="nutation bounds" if k == 0 else None)
    ax_theta.set_ylabel(r"nutation $\theta$ (deg)")
    ax_theta.set_title("(b) angle of the axis from the upward vertical", loc="left")

    ax_rate.plot(t, top.precession_rate(t), lw=1.0, label="exact")
    ax_rate.axhline(top.mean_precession_rate, color="k", ls="--", lw=0.8,
                    label=f"exact mean {top.mean_precession_rate:.4g} rad/s")
    ax_rate.axhline(top.slow_precession_rate, color="0.4", ls=":", lw=1.2,
                    label=f"$mgl/(I_3\\omega_3)$ = {top.slow_precession_rate:.4g} rad/s")
    ax_rate.set_xlabel("time t (s)")
    ax_rate.set_ylabel(r"precession rate $\dot\varphi$ (rad/s)")
    ax_rate.set_title("(c) precession rate", loc="left")

    if motion is not None:
        every = slice(None, None, max(1, len(motion.t) // _MAX_MARKERS))
        ts, th = motion.t[every] - motion.t[0], np.degrees(motion.theta[every])
        style: dict[str, Any] = dict(ls="none", marker=".", ms=3, color="C3", label="tumble.simulate")
        above.plot(th * np.sin(motion.phi[every]), -th * np.cos(motion.phi[every]), **style)
        ax_theta.plot(ts, th, **style)
        ax_rate.plot(ts, motion.phi_dot[every], **style)

    above.legend(loc="best", fontsize="small")
    for ax, values in ((ax_theta, theta), (ax_rate, top.precession_rate(t))):
        _room_for_legend(ax, values)
        ax.legend(loc="upper center", ncols=2, fontsize="small")
    for ax in (above, ax_theta, ax_rate):
        ax.grid(True, alpha=0.3)
    fig.suptitle(
        f"heavy symmetric top: $I_1$ = {top.I1:.3g}, $I_3$ = {top.I3:.3g} kg m² (about the pivot), "
        f"mgl = {top.weight_torque:.3g} N m, $\\omega_3$ = {top.spin:.4g} rad/s\n"
        f"nutation between {math.degrees(top.theta_min):.4g}° and {math.degrees(top.theta_max):.4g}°, "
        f"period {period:.4g} s; the upright top is stable above {top.critical_spin:.4g} rad/s"
    )
    return fig


def _room_for_legend(ax, values) -> None:
    """Y limits with the curve in the lower 2/3 of the panel, so that the legend stays clear of it."""
    lo, hi = float(np.min(values)), float(np.max(values))
    pad = max(hi - lo, 1e-3 * max(abs(lo), abs(hi), 1.0))
    ax.set_ylim(lo - 0.1 * pad, hi + 0.6 * pad)


def demo_top(out_dir: str | os.PathLike[str], *, duration: float = 1.5) -> dict:
    """Simulate :data:`DEMO_TOP` for ``duration`` s and compare it with the exact theory.

    Integrates with ``tumble.simulate`` (dop853, rtol = atol = 1e-12, 500
    samples per nutation period) and ``tumble.torques.Gravity``, writes
    ``out_dir/top.nc`` (:meth:`Trajectory.save`), ``out_dir/top.png``
    (:func:`top_figure`) and ``out_dir/top.html`` (the 3-D viewer,
    :mod:`tumble.viz.viewer`), each atomically, and returns a summary: nutation
    bounds (deg), exact and measured (:func:`measure_nutation`, mean over the
    turning points), nutation period (s) and mean precession rate (rad/s),
    exact and measured, the spin and critical spin (rad/s), and the paths
    written. ``out_dir`` must be an existing directory.
    """
    duration = require_positive(duration, "duration")
    out_directory(out_dir)
    top = DEMO_TOP
    n = math.ceil(_DEMO_SAMPLES_PER_PERIOD * duration / top.nutation_period)
    trajectory = simulate(**top.simulation_inputs(), t=np.linspace(0.0, duration, n + 1),
                          method="dop853", rtol=_DEMO_TOLERANCE, atol=_DEMO_TOLERANCE)
    gravity = top.simulation_inputs()["torque"]
    measured = measure_nutation(trajectory, com=gravity.com, g=gravity.g)
    figure = top_figure(top, trajectory)

    nc_path, png_path = os.path.join(out_dir, "top.nc"), os.path.join(out_dir, "top.png")
    html_path = os.path.join(out_dir, "top.html")
    trajectory.save(nc_path)
    write_atomic(png_path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))
    trajectory.to_html(html_path)
    return {
        "theta_min_deg": math.degrees(top.theta_min),
        "theta_min_deg_measured": float(np.degrees(np.arccos(measured.u_max)).mean()),
        "theta_max_deg": math.degrees(top.theta_max),
        "theta_max_deg_measured": float(np.degrees(np.arccos(measured.u_min)).mean()),
        "nutation_period_s": top.nutation_period,
        "nutation_period_s_measured": measured.period,
        "mean_precession_rate": top.mean_precession_rate,
        "mean_precession_rate_measured": measured.mean_precession_rate,
        "spin": top.spin,
        "critical_spin": top.critical_spin,
        "nc": nc_path,
        "png": png_path,
        "html": html_path,
    }
