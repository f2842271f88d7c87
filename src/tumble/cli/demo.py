"""``tumble demo``: the T-handle's flips (``racket``), Poinsot's construction (``polhode``), the heavy top (``top``),
and one command per row of the demo table :data:`tumble.viz.demos.DEMOS`."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from tumble._files import write_atomic_all
from tumble._validate import ValidationError, require_memory, require_positive
from tumble.measure import flip_times
from tumble.analytic._stability import flip_interval, stability
from tumble.rigid_body import RigidBody
from tumble.cli.common import check_outputs, png, print_rows, progress_bar, summary, text, written
from tumble.cli.errors import exit_codes
from tumble.simulate import simulate
from tumble.viz.demos import DEMOS, Demo

__all__ = ["demo_app"]

demo_app = typer.Typer(help="Built-in demonstrations.", no_args_is_help=True, rich_markup_mode="markdown")

# Tennis-racket demo: spin about the intermediate axis, perturbation on the
# other two (rad/s, principal axes), and output rate. A flip of the default
# T-handle at 10 rad/s lasts about 1/λ = 0.14 s (λ = |ω| √((I₂−I₁)(I₃−I₂)/(I₁I₃))
# = 7.2 /s), so 200 samples per second put ~28 samples on each flip.
_RACKET_SPIN = 10.0
_RACKET_PERTURBATION = 1e-3
_RACKET_SAMPLES_PER_SECOND = 200
_RACKET_TOLERANCE = 1e-12
# Polhode demo: the same T-handle, 10 rad/s about the intermediate axis and
# 1 rad/s about each of the others (principal axes): a motion just inside the
# "major" regime, so that its polhode stands apart from the separatrix.
_POLHODE_OMEGA = (1.0, 10.0, 1.0)
# Samples of its viewer page: one polhode period (4K/λ) at the viewer's default frame budget.
_POLHODE_FRAMES = 600
# The T-handle as the viewer draws it: RigidBody.t_handle()'s handle (along x, from the origin) and cross bar
# (along y, centred on the handle's end), solid cylinders of its default radius and lengths (m).
_T_HANDLE_PIECES: list[dict[str, Any]] = [dict(radius=0.004, length=0.08, axis="x", position=(0.04, 0.0, 0.0)),
                                          dict(radius=0.004, length=0.08, axis="y", position=(0.08, 0.0, 0.0))]


@demo_app.command("racket")
def racket(
    output: Annotated[Path, typer.Option("-o", "--output", help="NetCDF file to write.")] = Path("racket.nc"),
    plot: Annotated[Path, typer.Option("--plot", help="PNG figure of the flips to write.")] = Path("racket.png"),
    duration: Annotated[float, typer.Option("--duration", help="Simulated time, s.")] = 20.0,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Tennis-racket (Dzhanibekov) effect: a T-handle spun about its intermediate axis flips over and over.

    The default RigidBody.t_handle() starts at 10 rad/s about its intermediate principal axis
    with 1e-3 rad/s about the other two, integrated by dop853 at rtol = atol = 1e-12. A flip
    is a sign change of the intermediate-axis rate; the command prints their number, the
    mean time between them, and the time between flips predicted by the exact (elliptic)
    solution, 2K(m)/lambda. Beside the figure it writes the flips in the offline 3-D viewer
    (the figure's name with .html).
    """
    from tumble.viz.viewer import Cylinder, html_page
    from tumble.viz.racket import racket_figure

    with exit_codes():
        require_positive(duration, "--duration")
        page = plot.with_suffix(".html")
        check_outputs([("--output", output), ("--plot", plot), ("--plot's viewer page", page)])
        body = RigidBody.t_handle()
        omega0 = body.axes @ np.array([_RACKET_PERTURBATION, _RACKET_SPIN, _RACKET_PERTURBATION])
        # t, q, omega and the totals (energy, momentum): 11 float64 per sample, twice over (states and result)
        samples = duration * _RACKET_SAMPLES_PER_SECOND + 1
        require_memory(2 * 11 * 8 * samples, "--duration", f"the samples of {duration:g} s "
                                                           f"({_RACKET_SAMPLES_PER_SECOND} per second)")
        n = int(np.ceil(duration * _RACKET_SAMPLES_PER_SECOND))
        with progress_bar("simulating", enabled=not quiet) as progress:
            traj = simulate(body, omega0, t=np.linspace(0.0, duration, n + 1),
                            method="dop853", rtol=_RACKET_TOLERANCE, atol=_RACKET_TOLERANCE, progress=progress)
        flips = flip_times(traj, body)
        html = html_page(traj, model=body, shape=[Cylinder(**piece) for piece in _T_HANDLE_PIECES])
        write_atomic_all([(output, traj._write_netcdf), *png(racket_figure(traj, body, flips), plot),
                          (page, text(html))])
    mean = f", mean time between flips {np.diff(flips).mean():.6g} s" if flips.size > 1 else ""
    print_rows([*summary(traj), ("flips", f"{flips.size} in {duration:g} s{mean}"),
                 ("predicted", f"time between flips 2K/lambda = {flip_interval(body, omega0):.6g} s (exact solution)"),
                 ("wrote", f"{written(output, plot)}, {page}")])


@demo_app.command("polhode")
def polhode(
    output: Annotated[Path, typer.Option("-o", "--output", help="PNG figure to write.")] = Path("polhode.png"),
) -> None:
    """Poinsot's construction: polhodes on the energy ellipsoid and the herpolhode of a T-handle.

    RigidBody.t_handle() spinning at 10 rad/s about its intermediate principal axis and 1 rad/s
    about each of the other two. The figure (tumble.viz.polhode.polhode_figure) shows the energy
    ellipsoid with a family of polhodes, the separatrix and this motion's polhode, and the
    herpolhode on the invariable plane; the command prints the stability of the axes and the
    predicted times. Beside the PNG, the same name with .html: the 3-D viewer of one polhode
    period of the motion (the T-handle turning, omega and L, and its polhode on the energy ellipsoid).
    """
    from tumble.viz.viewer import Cylinder, html_page
    from tumble.viz.polhode import polhode_figure

    with exit_codes():
        page = output.with_suffix(".html")
        check_outputs([("--output", output), ("--output's viewer page", page)])
        body = RigidBody.t_handle()
        omega0 = body.axes @ np.array(_POLHODE_OMEGA)
        report = stability(body, omega0)
        figure = polhode_figure(body, omega0)
        traj = simulate(body, omega0, t=np.linspace(0.0, report.polhode_period, _POLHODE_FRAMES),
                        method="dop853", rtol=_RACKET_TOLERANCE, atol=_RACKET_TOLERANCE)
        html = html_page(traj, model=body, shape=[Cylinder(**piece) for piece in _T_HANDLE_PIECES])
        write_atomic_all([*png(figure, output), (page, text(html))])
    moments = ", ".join(f"{m:.4g}" for m in report.moments)
    print_rows([
        ("body", f"T-handle, principal moments {moments} kg m^2"),
        ("axes", ", ".join(f"{i + 1}: {kind}" for i, kind in enumerate(report.axis_stability))),
        ("omega", "[" + ", ".join(f"{w:g}" for w in _POLHODE_OMEGA) + f"] rad/s (principal axes), "
                  f"regime {report.regime!r}"),
        ("timing", f"flips every 2K/lambda = {report.flip_interval:.6g} s, "
                   f"polhode period 4K/lambda = {report.polhode_period:.6g} s"),
        ("wrote", f"{output}, {page}"),
    ])


@demo_app.command("top")
def top(
    output: Annotated[Path, typer.Option("-o", "--output", help="Existing directory to write top.nc, top.png and top.html in.")]
    = Path("."),
    duration: Annotated[float, typer.Option("--duration", help="Simulated time, s.")] = 1.5,
) -> None:
    """Heavy symmetric top: simulation (gravity torque on a pivot) against the exact theory.

    Runs tumble.viz.top.demo_top: a spinning top released at 60 deg from the vertical nutates
    between two angles while it precesses. Writes top.nc and top.png in the directory and prints
    the nutation bounds, the nutation period and the mean precession rate, exact and measured; and top.html,
    the 3-D viewer of the run.
    """
    from tumble.viz.top import demo_top

    with exit_codes():
        require_positive(duration, "--duration")
        if not output.is_dir():
            raise ValidationError(f"--output: {str(output)!r} is not an existing directory")
        check_outputs([("--output", output / name) for name in ("top.nc", "top.png", "top.html")])
        summary = demo_top(output, duration=duration)
    print_rows([
        ("nutation", f"theta from {summary['theta_min_deg']:.6g} to {summary['theta_max_deg']:.6g} deg (exact), "
                     f"{summary['theta_min_deg_measured']:.6g} to {summary['theta_max_deg_measured']:.6g} deg "
                     "(simulated)"),
        ("period", f"{summary['nutation_period_s']:.6g} s (exact), "
                   f"{summary['nutation_period_s_measured']:.6g} s (simulated)"),
        ("rate", f"mean precession rate {summary['mean_precession_rate']:.6g} rad/s (exact), "
                 f"{summary['mean_precession_rate_measured']:.6g} rad/s (simulated)"),
        ("spin", f"{summary['spin']:.6g} rad/s (critical spin {summary['critical_spin']:.6g} rad/s: "
                 "the upright top is stable above it)"),
        ("wrote", f"{summary['nc']}, {summary['png']}, {summary['html']}"),
    ])


def _demo_command(demo: Demo) -> Callable[..., None]:
    """The ``tumble demo NAME`` command of a row of :data:`tumble.viz.demos.DEMOS`: call its function on the
    output directory, print its rows and the files it wrote."""
    module, function = demo.target.split(":")

    def command(
        output: Annotated[Path, typer.Option("-o", "--output", help="Existing directory to write the files in.")]
        = Path("."),
    ) -> None:
        with exit_codes():
            summary = getattr(importlib.import_module(module), function)(output)
        written = [str(v) for v in summary.values() if isinstance(v, (str, Path)) and str(v).endswith((".png", ".nc", ".html"))]
        print_rows([*demo.rows(summary), ("wrote", ", ".join(written))])

    command.__doc__ = demo.help
    return command


for _name, _demo in DEMOS.items():
    demo_app.command(_name)(_demo_command(_demo))
