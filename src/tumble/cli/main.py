"""The ``tumble`` command: run scenario files, the demos, inspect results.

    tumble run SCENARIO.toml -o out.nc [--plot out.png] [--quiet]
    tumble demo [--list]
    tumble demo NAME [-o DIRECTORY] [options]   (the rows of tumble.viz.demos.DEMOS: racket, polhode, top, ...)
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

from pathlib import Path
from typing import Annotated

import numpy as np
import typer

import tumble
from tumble import examples as _examples
from tumble import scenario as scenarios
from tumble._files import write_atomic_all
from tumble._validate import ValidationError
from tumble.cli.cache import cache_app, warmup
from tumble.cli.common import check_outputs, png, print_rows, progress_bar, summary, written
from tumble.cli.demo import demo_app
from tumble.cli.errors import exit_codes
from tumble.cli.robot import app as robot_app
from tumble.cli.sweep import info_store, sweep_command
from tumble.trajectory import load

__all__ = ["app"]

app = typer.Typer(
    name="tumble",
    help="Rotational dynamics of rigid bodies (Euler's equations): run scenarios, demos, inspect results.",
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="markdown",
    pretty_exceptions_show_locals=False,
)
app.add_typer(demo_app, name="demo")
app.add_typer(robot_app, name="robot", help="Robot arms (serial chains from DH tables or URDF): joint torques.")
examples_app = typer.Typer(help="The example files installed with tumble: scenarios, robots, INS data.",
                           no_args_is_help=True, rich_markup_mode="markdown")
app.add_typer(examples_app, name="examples")


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
    with exit_codes(scenario):
        spec = scenarios.load(scenario)  # the file is read and parsed once; its kind picks the model
        problem = spec.build()  # every rule of the file is checked before anything runs
        check_outputs([("--output", output), ("--plot", plot)], inputs=(scenario,))
        with progress_bar("simulating", enabled=not quiet) as progress:
            traj = problem.simulate(progress=progress)
        figure = spec.figure(traj) if plot is not None else None
        write_atomic_all([(output, traj._write_netcdf), *png(figure, plot)])
    print_rows([("scenario", f"{scenario}" + (f" ({spec.name})" if spec.name else "")),
                 *summary(traj), *spec.rows(traj), ("wrote", written(output, plot))])


@examples_app.command("list")
def examples_list() -> None:
    """Print every example file, one per line, as ``tumble.examples.path(NAME)`` takes it, and where it is."""
    with exit_codes():
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
    with exit_codes():
        written = _examples.copy(directory)
    print_rows([("copied", f"{len(written)} files into {directory}")])


app.command("sweep")(sweep_command)


@app.command()
def info(path: Annotated[Path, typer.Argument(help="NetCDF file written by tumble run / tumble demo, or a Zarr "
                                                    "store written by tumble sweep or simulate_to_store.")]) -> None:
    """Print what a trajectory file or a sweep's store holds: times, bodies, method, solver info and drifts.

    A trajectory file is validated as it is read (tumble.load): not a regular file, damaged, too large for the
    memory, not unit quaternions or not a physical inertia: one line on stderr, exit code 2.
    """
    if path.is_dir():
        info_store(path)
        return
    with exit_codes(path):
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
        rows += summary(traj)
        rows += [("solver" if i == 0 else "", f"{key} = {value}") for i, (key, value) in enumerate(traj.info.items())]
    print_rows(rows)


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
    from tumble.viz.viewer import write_html

    with exit_codes(path):
        check_outputs([("--output", output)], inputs=(path,) + (() if scenario is None else (scenario,)))
        model = None if scenario is None else scenarios.load(scenario).model
        write_html(path, output, model=model, frames=frames, axis=axis)
    print_rows([("trajectory", str(path)), ("wrote", str(output))])


app.command()(warmup)
app.add_typer(cache_app, name="cache")
