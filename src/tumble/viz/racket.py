"""The tennis-racket (Dzhanibekov) effect: a T-handle spun about its intermediate axis flips over and over.

:func:`racket_figure` draws its body rates in principal axes with the flips marked; :func:`write_racket`
simulates it and writes the run, the figure and the viewer page; :func:`demo_racket` is ``tumble demo racket``
(``docs/cli.md``, ``docs/stability.md``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble._files import write_atomic_all
from tumble._validate import require_memory, require_positive
from tumble.measure import flip_times, intermediate_rate
from tumble.analytic._stability import flip_interval
from tumble.rigid_body import RigidBody
from tumble.simulate import simulate
from tumble.trajectory import Trajectory
from tumble.viz._output import out_directory, png_writer, text_writer

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["T_HANDLE_PIECES", "check_duration", "demo_racket", "racket_figure", "write_racket"]

# The motion: 10 rad/s about the intermediate principal axis, 1e-3 rad/s about the other two. A flip of the
# default T-handle lasts about 1/λ = 0.14 s (λ = |ω| √((I₂−I₁)(I₃−I₂)/(I₁I₃)) = 7.2 /s), so 200 samples per
# second put ~28 samples on each flip.
RACKET_SPIN = 10.0
RACKET_PERTURBATION = 1e-3
RACKET_SAMPLES_PER_SECOND = 200
RACKET_TOLERANCE = 1e-12
#: The T-handle as the viewer draws it: RigidBody.t_handle()'s handle (along x, from the origin) and cross bar
#: (along y, centred on the handle's end), solid cylinders of its default radius and lengths (m).
T_HANDLE_PIECES: list[dict[str, Any]] = [dict(radius=0.004, length=0.08, axis="x", position=(0.04, 0.0, 0.0)),
                                         dict(radius=0.004, length=0.08, axis="y", position=(0.08, 0.0, 0.0))]


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


def check_duration(duration: float, name: str = "duration") -> float:
    """The simulated time ``duration`` (s) of :func:`write_racket`, refused (naming ``name``) unless finite,
    > 0 and small enough for its samples (t, q, ω and the totals: 11 float64 per sample, held twice) to fit
    in memory."""
    duration = require_positive(duration, name)
    samples = duration * RACKET_SAMPLES_PER_SECOND + 1
    require_memory(2 * 11 * 8 * samples, name, f"the samples of {duration:g} s ({RACKET_SAMPLES_PER_SECOND} per second)")
    return duration


def write_racket(output: str | os.PathLike[str], plot: str | os.PathLike[str], *, duration: float = 20.0,
                 progress: Callable[[int, int], None] | None = None) -> dict:
    """Spin :meth:`RigidBody.t_handle` about its intermediate axis for ``duration`` s and count its flips.

    ω₀ = ``body.axes @ [1e-3, 10, 1e-3]`` rad/s (principal axes), integrated by dop853 at
    rtol = atol = 1e-12 with 200 output samples per second. A flip is a sign change of the
    intermediate-axis rate (:func:`tumble.measure.flip_times`); the exact solution predicts the time
    between flips, 2K(m)/λ (:func:`tumble.analytic.flip_interval`). Writes the trajectory (NetCDF) to
    ``output``, :func:`racket_figure` to ``plot`` (PNG) and the flips in the offline 3-D viewer to ``plot``
    with ``.html``, together and atomically (:func:`tumble._files.write_atomic_all`). Returns the flips, their
    mean interval, the predicted one, the trajectory's summary numbers and the paths written.
    """
    from tumble.viz.viewer import Cylinder, html_page

    duration = check_duration(duration)
    page = Path(plot).with_suffix(".html")
    body = RigidBody.t_handle()
    omega0 = body.axes @ np.array([RACKET_PERTURBATION, RACKET_SPIN, RACKET_PERTURBATION])
    n = int(np.ceil(duration * RACKET_SAMPLES_PER_SECOND))
    traj = simulate(body, omega0, t=np.linspace(0.0, duration, n + 1), method="dop853",
                    rtol=RACKET_TOLERANCE, atol=RACKET_TOLERANCE, progress=progress)
    flips = flip_times(traj, body)
    html = html_page(traj, model=body, shape=[Cylinder(**piece) for piece in T_HANDLE_PIECES])
    figure = racket_figure(traj, body, flips)
    write_atomic_all([(output, traj._write_netcdf), (plot, png_writer(figure)), (page, text_writer(html))])
    return {"trajectory": traj, "duration_s": duration, "flips": flips.size,
            "mean_flip_interval_s": float(np.diff(flips).mean()) if flips.size > 1 else None,
            "predicted_flip_interval_s": flip_interval(body, omega0),
            "nc": os.fspath(output), "png": os.fspath(plot), "html": os.fspath(page)}


def demo_racket(out_dir: str | os.PathLike[str], *, duration: float = 20.0,
                progress: Callable[[int, int], None] | None = None) -> dict:
    """``tumble demo racket``: :func:`write_racket` into ``racket.nc``, ``racket.png`` and ``racket.html`` of
    ``out_dir`` (an existing directory)."""
    out_dir = out_directory(out_dir)
    return write_racket(os.path.join(out_dir, "racket.nc"), os.path.join(out_dir, "racket.png"),
                        duration=duration, progress=progress)
