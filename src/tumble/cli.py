"""The ``tumble`` command: run scenario files, the demos, inspect results.

    tumble run SCENARIO.toml -o out.nc [--plot out.png] [--quiet]
    tumble demo racket [-o racket.nc] [--plot racket.png] [--duration 20]
    tumble demo polhode [-o polhode.png]
    tumble demo top [-o DIRECTORY] [--duration 1.5]
    tumble demo NAME [-o DIRECTORY]        (the demos of tumble.viz.demos.DEMOS: diver, flexible, ...)
    tumble robot torques ROBOT_FILE --q ...
    tumble examples list | tumble examples copy DIRECTORY
    tumble sweep SCENARIO.toml -o out.zarr [--samples N] [--scheduler ADDR] [--workers N] [--plot out.png]
    tumble info out.nc | out.zarr
    tumble view out.nc -o out.html [--scenario SCENARIO.toml] [--frames 600] [--axis x]
    tumble warmup [PATH ...] [--list]
    tumble cache info | clear
    tumble --version

Exit codes: 0 success; 2 an error (a one-line message per problem on
stderr, naming the file, the key and the rule; nothing is written): bad
input, the integrator giving up, a file that cannot be read or written; 1 a
bug.
Results are written atomically, the outputs of a command together (:func:`tumble._files.write_atomic_all`),
after every output path was checked (a new name or a regular file, in a writable directory, one file each).
Documented in ``docs/cli.md``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

import tumble
from tumble import examples as _examples
from tumble import scenario as scenarios
from tumble._cli_errors import exit_codes as _exit_codes
from tumble.viz.demos import DEMOS, Demo
from tumble._files import check_distinct, check_output, write_atomic_all
from tumble._validate import ValidationError, require_memory, require_positive
from tumble.analysis import flip_times, intermediate_rate
from tumble.analytic._stability import flip_interval, stability
from tumble.body import RigidBody
from tumble.robot.cli import app as robot_app
from tumble.simulate import simulate
from tumble.trajectory import Trajectory, load

__all__ = ["app"]

app = typer.Typer(
    name="tumble",
    help="Rotational dynamics of rigid bodies (Euler's equations): run scenarios, demos, inspect results.",
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="markdown",
    pretty_exceptions_show_locals=False,
)
demo_app = typer.Typer(help="Built-in demonstrations.", no_args_is_help=True, rich_markup_mode="markdown")
app.add_typer(demo_app, name="demo")
app.add_typer(robot_app, name="robot", help="Robot arms (serial chains from DH tables or URDF): joint torques.")
examples_app = typer.Typer(help="The example files installed with tumble: scenarios, robots, INS data.",
                           no_args_is_help=True, rich_markup_mode="markdown")
app.add_typer(examples_app, name="examples")

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

_stderr = Console(stderr=True)


# --------------------------------------------------------------------------
# Commands
# --------------------------------------------------------------------------


def _show_version(value: bool) -> None:
    if value:
        typer.echo(f"tumble {tumble.__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[bool, typer.Option("--version", callback=_show_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
) -> None:
    """Rotational dynamics of rigid bodies, built on Euler's equations.

    SI units; omega in body axes; attitude q = [w, x, y, z] (scalar first), body -> inertial.
    """


@app.command()
def run(
    scenario: Annotated[Path, typer.Argument(help="Scenario file (TOML); see docs/scenarios.md.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="NetCDF file to write (e.g. out.nc).")],
    plot: Annotated[Path | None, typer.Option("--plot", help="Also write a PNG figure of the trajectory.")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Validate and simulate a scenario of any kind, write the trajectory (NetCDF) and optionally a figure (PNG).

    A bad scenario is reported on stderr (file, key, rule) with exit code 2, and nothing is written.
    """
    with _exit_codes(scenario):
        spec = scenarios.load(scenario)  # the file is read and parsed once; its kind picks the model
        problem = spec.build()  # every rule of the file is checked before anything runs
        _check_outputs([("--output", output), ("--plot", plot)], inputs=(scenario,))
        with _progress_bar("simulating", enabled=not quiet) as progress:
            traj = problem.simulate(progress=progress)
        figure = spec.figure(traj) if plot is not None else None
        write_atomic_all([(output, traj._write_netcdf), *_png(figure, plot)])
    _print_rows([("scenario", f"{scenario}" + (f" ({spec.name})" if spec.name else "")),
                 *_summary(traj), *spec.rows(traj), ("wrote", _written(output, plot))])


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
    from tumble.viewer import Cylinder, html_page

    with _exit_codes():
        require_positive(duration, "--duration")
        page = plot.with_suffix(".html")
        _check_outputs([("--output", output), ("--plot", plot), ("--plot's viewer page", page)])
        body = RigidBody.t_handle()
        omega0 = body.axes @ np.array([_RACKET_PERTURBATION, _RACKET_SPIN, _RACKET_PERTURBATION])
        # t, q, omega and the totals (energy, momentum): 11 float64 per sample, twice over (states and result)
        samples = duration * _RACKET_SAMPLES_PER_SECOND + 1
        require_memory(2 * 11 * 8 * samples, "--duration", f"the samples of {duration:g} s "
                                                           f"({_RACKET_SAMPLES_PER_SECOND} per second)")
        n = int(np.ceil(duration * _RACKET_SAMPLES_PER_SECOND))
        with _progress_bar("simulating", enabled=not quiet) as progress:
            traj = simulate(body, omega0, t=np.linspace(0.0, duration, n + 1),
                            method="dop853", rtol=_RACKET_TOLERANCE, atol=_RACKET_TOLERANCE, progress=progress)
        flips = flip_times(traj, body)
        html = html_page(traj, model=body, shape=[Cylinder(**piece) for piece in _T_HANDLE_PIECES])
        write_atomic_all([(output, traj._write_netcdf), *_png(_racket_figure(traj, body, flips), plot),
                          (page, _text(html))])
    mean = f", mean time between flips {np.diff(flips).mean():.6g} s" if flips.size > 1 else ""
    _print_rows([*_summary(traj), ("flips", f"{flips.size} in {duration:g} s{mean}"),
                 ("predicted", f"time between flips 2K/lambda = {flip_interval(body, omega0):.6g} s (exact solution)"),
                 ("wrote", f"{_written(output, plot)}, {page}")])


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
    from tumble.viewer import Cylinder, html_page
    from tumble.viz.polhode import polhode_figure

    with _exit_codes():
        page = output.with_suffix(".html")
        _check_outputs([("--output", output), ("--output's viewer page", page)])
        body = RigidBody.t_handle()
        omega0 = body.axes @ np.array(_POLHODE_OMEGA)
        report = stability(body, omega0)
        figure = polhode_figure(body, omega0)
        traj = simulate(body, omega0, t=np.linspace(0.0, report.polhode_period, _POLHODE_FRAMES),
                        method="dop853", rtol=_RACKET_TOLERANCE, atol=_RACKET_TOLERANCE)
        html = html_page(traj, model=body, shape=[Cylinder(**piece) for piece in _T_HANDLE_PIECES])
        write_atomic_all([*_png(figure, output), (page, _text(html))])
    moments = ", ".join(f"{m:.4g}" for m in report.moments)
    _print_rows([
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

    with _exit_codes():
        require_positive(duration, "--duration")
        if not output.is_dir():
            raise ValidationError(f"--output: {str(output)!r} is not an existing directory")
        _check_outputs([("--output", output / name) for name in ("top.nc", "top.png", "top.html")])
        summary = demo_top(output, duration=duration)
    _print_rows([
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
        with _exit_codes():
            summary = getattr(importlib.import_module(module), function)(output)
        written = [str(v) for v in summary.values() if isinstance(v, (str, Path)) and str(v).endswith((".png", ".nc", ".html"))]
        _print_rows([*demo.rows(summary), ("wrote", ", ".join(written))])

    command.__doc__ = demo.help
    return command


for _name, _demo in DEMOS.items():
    demo_app.command(_name)(_demo_command(_demo))


@examples_app.command("list")
def examples_list() -> None:
    """Print every example file, one per line, as ``tumble.examples.path(NAME)`` takes it, and where it is."""
    with _exit_codes():
        names = _examples.names()
    typer.echo(f"# in {_examples.directory()}")
    for name in names:
        typer.echo(name)


@examples_app.command("copy")
def examples_copy(
    directory: Annotated[Path, typer.Argument(help="Directory to copy the examples into (created if missing; "
                                                   "an existing file there is never overwritten).")],
) -> None:
    """Copy every example file into DIRECTORY, keeping the sub-directories, to edit and run."""
    with _exit_codes():
        written = _examples.copy(directory)
    _print_rows([("copied", f"{len(written)} files into {directory}")])


@app.command("sweep")
def sweep_command(
    scenario: Annotated[Path, typer.Argument(help="Scenario file (TOML) with a [sweep] table; see docs/sweeps.md.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Zarr store to write or resume (e.g. out.zarr).")],
    samples: Annotated[int | None, typer.Option("--samples", help="Number of samples (default: the file's).")] = None,
    scheduler: Annotated[str | None, typer.Option("--scheduler", help="Address of a running Dask scheduler, "
                                                  "e.g. tcp://host:8786 (default: a local cluster).")] = None,
    workers: Annotated[int | None, typer.Option("--workers", help="Worker processes of the local cluster "
                                                "(default: one per core; 0: this process only).")] = None,
    plot: Annotated[Path | None, typer.Option("--plot", help="Also write a PNG figure of the outcomes.")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Run the Monte-Carlo or grid sweep of a scenario's [sweep] table on Dask; write its results to a Zarr store.

    Running it again on the same store computes only the chunks not yet written. A bad file or a store of
    another sweep is reported on stderr with exit code 2, and nothing is written.
    """
    from tumble.sweep import sweep_scenario
    from tumble.sweep.figure import sweep_figure

    with _exit_codes():
        spec = scenarios.load(scenario)
        if not output.parent.is_dir():
            raise ValidationError(f"--output: directory {str(output.parent)!r} does not exist")
        if plot is not None:
            _check_outputs([("--plot", plot)], inputs=(scenario, output))
        if scheduler is not None and workers is not None:
            raise ValidationError("--workers: give it only without --scheduler (a scheduler has its own workers)")
        client = None
        if scheduler is not None:
            from distributed import Client

            try:
                client = Client(scheduler, timeout=30)
            except ValueError as exc:  # distributed's parse of the address
                raise ValidationError(f"--scheduler: must be a scheduler address such as tcp://host:8786, "
                                      f"got {scheduler!r} ({exc})") from None
            except OSError as exc:
                raise ValidationError(f"--scheduler: cannot reach {scheduler} ({exc})") from None
        try:
            with _progress_bar("sweeping", enabled=not quiet, unit="chunks") as progress:
                ds = sweep_scenario(spec, samples=samples, store=output, client=client, workers=workers,
                                    progress=progress)
        except KeyboardInterrupt:  # Ctrl-C: one line, exit 130 (the chunks written stay in the store)
            typer.echo(f"error: interrupted; the chunks written are kept in {output}: the same command resumes "
                       "the sweep", err=True)
            raise typer.Exit(130) from None
        finally:
            if client is not None:
                client.close()
        if plot is not None:
            figure = sweep_figure(ds, title=spec.name)
            write_atomic_all(_png(figure, plot))
    _print_rows([("scenario", f"{scenario}" + (f" ({spec.name})" if spec.name else "")), *_sweep_rows(ds),
                 ("wrote", _written(output, plot))])


def _sweep_rows(ds) -> list[tuple[str, str]]:
    """Rows: samples and chunks, and each scalar outcome's percentiles."""
    settings = ds.attrs["tumble_sweep"]
    done = int(ds["done"].sum())
    rows = [("samples", f"{settings['samples']} (seed {settings['seed']}), {done} of {ds.sizes['chunk']} chunks "
                        f"of {settings['chunk']} done"),
            ("method", f"{settings['method']} {settings['options']}, {settings['t']}")]
    if "chunks_computed" in ds.attrs:
        rows.append(("computed", f"{ds.attrs['chunks_computed']} chunks in this run"))
    if "percentile" in ds.coords:
        for name in settings["outcomes"]:
            if ds[f"{name}_percentiles"].ndim == 1:
                values = ", ".join(f"{p:g}%: {v:.6g}" for p, v in zip(ds.percentile.values,
                                                                      ds[f"{name}_percentiles"].values, strict=True))
                rows.append((name, values))
    return rows


@app.command()
def info(path: Annotated[Path, typer.Argument(help="NetCDF file written by tumble run / tumble demo, or a Zarr "
                                                    "store written by tumble sweep or simulate(store=).")]) -> None:
    """Print what a trajectory file or a sweep's store holds: times, bodies, method, solver info and drifts.

    A trajectory file is validated as it is read (tumble.load): not a regular file, damaged, too large for the
    memory, not unit quaternions or not a physical inertia: one line on stderr, exit code 2.
    """
    if path.is_dir():
        _info_store(path)
        return
    with _exit_codes(path):
        try:
            traj = load(path)
        except OSError as exc:
            raise ValidationError(f"{path}: not a readable tumble trajectory ({exc})") from None
        if traj.inertia is None:
            moments = np.zeros((0, 3))
        else:
            moments = np.linalg.eigvalsh(traj.inertia.reshape(-1, 3, 3))
        bodies = "1" if traj.batch_size is None else f"{traj.batch_size} (batch)"
        rows = [("file", str(path)), ("bodies", bodies)]
        rows += [("moments" if i == 0 else "", f"{m[0]:.6g}, {m[1]:.6g}, {m[2]:.6g} kg m^2 (principal)")
                 for i, m in enumerate(moments[:5])]
        if len(moments) > 5:
            rows.append(("", f"... {len(moments) - 5} more"))
        rows += _summary(traj)
        rows += [("solver" if i == 0 else "", f"{key} = {value}") for i, (key, value) in enumerate(traj.info.items())]
    _print_rows(rows)


@app.command()
def view(
    path: Annotated[Path, typer.Argument(help="NetCDF trajectory written by tumble run / tumble demo / save().")],
    output: Annotated[Path, typer.Option("-o", "--output", help="HTML file to write (e.g. run.html).")],
    scenario: Annotated[Path | None, typer.Option(
        "--scenario", help="The scenario file of the run: its model draws what a trajectory alone cannot tell "
                           "(a robot's links, a spacecraft's wheels and thrusters).")] = None,
    frames: Annotated[int, typer.Option("--frames", help="Frame budget: at most this many samples are shown "
                                                         "(2 to 100000).")] = 600,
    axis: Annotated[str | None, typer.Option("--axis", help="Body axis whose trace on the unit sphere is drawn: "
                                                            "x, y or z (default: the one along omega(0)).")] = None,
) -> None:
    """Write the offline 3-D viewer of a trajectory: one HTML file that opens by double-click, with no network.

    The body (the uniform box of its principal moments), its axes, omega and L as arrows, the trace of a body
    axis, the model's parts, the body rates beside it; play/pause, speed and a time slider (docs/viewer.md).
    Bad input (not a tumble trajectory, an empty one, --frames < 2 or > 100000) exits with code 2 and writes
    nothing.
    """
    from tumble.viewer import write_html

    with _exit_codes(path):
        _check_outputs([("--output", output)], inputs=(path,) + (() if scenario is None else (scenario,)))
        model = None if scenario is None else scenarios.load(scenario).model
        write_html(path, output, model=model, frames=frames, axis=axis)
    _print_rows([("trajectory", str(path)), ("wrote", str(output))])

@app.command()
def warmup(
    paths: Annotated[list[str] | None, typer.Argument(
        help="Paths to compile, by name (default: all of them; --list shows them).", show_default=False)] = None,
    list_paths: Annotated[bool, typer.Option("--list", help="List the paths and exit.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False,
) -> None:
    """Compile every built-in model kind under every method it provides into Numba's on-disk cache, so that a
    session's first simulation starts at once.

    Each path ("RigidBody, rk4", ..., "RobotTree, dop853", then the quick-start demo, a batch, a heavy top)
    runs a simulation of a few steps; the compiled code is cached beside tumble's source (or in
    NUMBA_CACHE_DIR), where every later process loads it in milliseconds. The progress display names the path
    being compiled (a bar on a terminal, one line per path otherwise). Run it once after installing.
    """
    import logging
    import time

    from tumble import _warmup

    known = _warmup.paths()
    if list_paths:
        typer.echo("\n".join(known))
        return
    with _exit_codes():
        unknown = [name for name in paths or () if name not in known]
        if unknown:
            raise ValidationError(f"PATH: unknown {', '.join(map(repr, unknown))}; the paths are "
                                  f"{', '.join(map(repr, known))}")
        chosen = list(paths or known)
        start = time.perf_counter()
        notices = logging.getLogger("tumble")
        level = notices.level
        notices.setLevel(logging.WARNING)  # the display names what is compiled: no compile notices besides
        try:
            with _progress_bar("compiling", enabled=not quiet, unit="paths") as progress:
                for done, name in enumerate(chosen):
                    if progress is not None:
                        progress(done, len(chosen), name)
                    elif not quiet:
                        _stderr.print(f"compiling {name} ({done + 1}/{len(chosen)})", highlight=False)
                    known[name]()
                if progress is not None:
                    progress(len(chosen), len(chosen), "compiled")
        finally:
            notices.setLevel(level)
    _print_rows([("compiled", f"{len(chosen)} paths in {time.perf_counter() - start:.1f} s"),
                 ("cache", _cache_where())])


def _cache_where() -> str:
    """Where Numba caches tumble's compiled code (docs/architecture.md, "The compiled-code cache")."""
    from numba.core import config

    return config.CACHE_DIR or "__pycache__ beside tumble's source"


cache_app = typer.Typer(help="Numba's on-disk cache of tumble's compiled code.", no_args_is_help=True)
app.add_typer(cache_app, name="cache")


@cache_app.command("info")
def cache_info() -> None:
    """Where tumble's compiled code is cached, the content key it is stamped with (docs/architecture.md, "The
    compiled-code cache"), and how many compiled functions it holds, in how many bytes."""
    from tumble import _cache

    files = _cache.cached_files()
    _print_rows([("cache", _cache_where()), ("key", _cache.content_key()),
                 ("functions", str(sum(path.suffix == ".nbi" for path in files))),
                 ("size", f"{sum(path.stat().st_size for path in files) / 1e6:.1f} MB")])


@cache_app.command("clear")
def cache_clear() -> None:
    """Delete tumble's compiled code from Numba's cache: each model kind and method compiles again on its next
    use (or run tumble warmup). Never needed for correctness: stale code is found by its key."""
    from tumble import _cache

    files = _cache.cached_files()
    size = sum(path.stat().st_size for path in files)
    for path in files:
        path.unlink(missing_ok=True)
    _print_rows([("cache", _cache_where()), ("removed", f"{len(files)} files, {size / 1e6:.1f} MB")])


def _info_store(path: Path) -> None:
    """``tumble info`` of a Zarr store: a sweep's samples and outcomes, or a streamed run's dimensions."""
    import xarray as xr

    with _exit_codes(path):
        try:
            ds = xr.open_zarr(path, consolidated=False)
        except Exception as exc:  # noqa: BLE001 - a damaged store may make zarr raise anything
            raise ValidationError(f"{path}: not a readable Zarr store ({type(exc).__name__}: {exc})") from None
        if "tumble_sweep" in ds.attrs:
            complete = "complete" if ds.attrs.get("tumble_sweep_complete") else "incomplete (run tumble sweep again)"
            rows = [("store", f"{path}: a sweep, {complete}"), *_sweep_rows(ds)]
        else:
            sizes = ", ".join(f"{name} {size}" for name, size in ds.sizes.items())
            rows = [("store", f"{path}: a run streamed by simulate(store=)"),
                    ("model", str(ds.attrs.get("model", "?"))), ("sizes", sizes),
                    ("times", f"{float(ds.time[0]):g} to {float(ds.time[-1]):g} s, {ds.sizes['time']} samples"),
                    ("method", str(ds.attrs.get("method", "?")))]
            rows += [("solver" if i == 0 else "", f"{key[7:]} = {value}")
                     for i, (key, value) in enumerate((k, v) for k, v in ds.attrs.items() if k.startswith("solver_"))]
    _print_rows(rows)


# --------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------


def _check_outputs(outputs: list[tuple[str, Path | None]], *, inputs: tuple[Path, ...] = ()) -> None:
    """Refuse, before any work, the ``(option, path)`` outputs of a command (``None``: not asked for) that
    cannot be written (:func:`tumble._files.check_output`: a missing or unwritable directory, a name that is
    not a regular file or new), two that are one file, and one that is an input."""
    given = [(option, path) for option, path in outputs if path is not None]
    for option, path in given:
        check_output(path, option)
    check_distinct([*((f"the input {str(path)!r}", path) for path in inputs), *given])


@contextmanager
def _progress_bar(description: str, *, enabled: bool,
                  unit: str = "samples") -> Iterator[Callable[..., None] | None]:
    """A rich progress bar on stderr, as a ``progress(done, total[, description])`` callback; ``None`` when not
    a terminal."""
    if not (enabled and _stderr.is_terminal):
        yield None
        return
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn(unit),
               TimeRemainingColumn())
    with Progress(*columns, console=_stderr, transient=True) as bar:
        task = bar.add_task(description, total=None)
        yield lambda done, total, what=description: bar.update(task, completed=done, total=total, description=what)


def _png(figure, path: Path | None) -> list[tuple[Path, Callable[[str], None]]]:
    """The write of ``figure`` as a PNG file at ``path`` for :func:`~tumble._files.write_atomic_all`; none
    without a path."""
    return [] if path is None else [(path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))]


def _text(text: str) -> Callable[[str], None]:
    """A writer of ``text`` (UTF-8) for :func:`~tumble._files.write_atomic_all`."""
    def write(tmp_path: str) -> None:
        Path(tmp_path).write_text(text, encoding="utf-8")

    return write


def _racket_figure(traj: Trajectory, body: RigidBody, flips: np.ndarray):
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


def _drift(drift: np.ndarray, initial: np.ndarray) -> str:
    """Largest |relative change|, or "n/a" where the initial value is 0 (the drift is then absolute) or there
    is no body (an empty batch)."""
    return "n/a" if drift.size == 0 or np.any(initial == 0.0) else f"{np.max(np.abs(drift)):.3g}"


def _setting(value: float | int | str) -> str:
    """A solver setting as printed: a number in ``%g``, a string as it is."""
    return value if isinstance(value, str) else f"{value:g}"


def _summary(traj: Trajectory) -> list[tuple[str, str]]:
    """Rows: output times, method and its settings, the largest relative change of the energy, |L| and L_I
    (the energy alone for a model without an attitude, e.g. a robot arm)."""
    options = ", ".join(f"{key} {_setting(traj.info[key])}" for key in ("rtol", "atol", "dt") if key in traj.info)
    steps = f", {traj.info['n_steps']} steps" if "n_steps" in traj.info else ""
    torque = traj.info.get("torque", "none")
    drift = f"energy {_drift(traj.energy_drift, traj.energy[0])}"
    if traj.q is not None:
        drift += (f", |L| {_drift(traj.momentum_norm_drift, traj.momentum_norm[0])}, "
                  f"L_I {_drift(traj.momentum_inertial_drift, traj.momentum_norm[0])}")
    rows = [
        ("times", f"{traj.t[0]:g} to {traj.t[-1]:g} s, {len(traj)} samples"),
        ("method", f"{traj.method or 'unknown'}" + (f" ({options})" if options else "") + steps),
        ("drift", f"{drift} (max relative change)"),
    ]
    if torque != "none":
        kept = "T and |L|" if traj.q is not None else "the energy"
        rows.append(("", f"(torque {torque} acts: {kept} need not be conserved)"))
    if traj.extras and not traj.totals:
        rows.append(("", f"(drifts of the rigid hub alone: it exchanges momentum and energy with the model's "
                         f"{len(traj.extras)} other states, saved with it)"))
    return rows


def _written(output: Path, plot: Path | None) -> str:
    return ", ".join(str(p) for p in (output, plot) if p is not None)


def _print_rows(rows: list[tuple[str, str]]) -> None:
    for label, value in rows:
        typer.echo(f"{label:<10}{value}" if len(label) < 10 else f"{label} {value}")
