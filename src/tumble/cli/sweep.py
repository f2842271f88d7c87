"""``tumble sweep``: a scenario's Monte-Carlo or grid sweep on Dask, into a Zarr store; ``tumble info`` of a store."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from tumble import scenario as scenarios
from tumble._files import write_atomic_all
from tumble._validate import ValidationError
from tumble.cli.common import check_outputs, png, print_rows, progress_bar, written
from tumble.cli.errors import exit_codes

if TYPE_CHECKING:
    import xarray

__all__ = ["info_store", "sweep_command"]


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
    from tumble.scenario import sweep_scenario
    from tumble.viz.sweep import sweep_figure

    with exit_codes():
        spec = scenarios.load(scenario)
        if not output.parent.is_dir():
            raise ValidationError(f"--output: directory {str(output.parent)!r} does not exist")
        if plot is not None:
            check_outputs([("--plot", plot)], inputs=(scenario, output))
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
            with progress_bar("sweeping", enabled=not quiet, unit="chunks") as progress:
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
            write_atomic_all(png(figure, plot))
    print_rows([("scenario", f"{scenario}" + (f" ({spec.name})" if spec.name else "")), *sweep_rows(ds),
                 ("wrote", written(output, plot))])


def sweep_rows(ds: xarray.Dataset) -> list[tuple[str, str]]:
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


def info_store(path: Path) -> None:
    """``tumble info`` of a Zarr store: a sweep's samples and outcomes, or a streamed run's dimensions."""
    import xarray as xr

    with exit_codes(path):
        try:
            ds = xr.open_zarr(path, consolidated=False)
        except Exception as exc:  # noqa: BLE001 - a damaged store may make zarr raise anything
            raise ValidationError(f"{path}: not a readable Zarr store ({type(exc).__name__}: {exc})") from None
        if "tumble_sweep" in ds.attrs:
            complete = "complete" if ds.attrs.get("tumble_sweep_complete") else "incomplete (run tumble sweep again)"
            rows = [("store", f"{path}: a sweep, {complete}"), *sweep_rows(ds)]
        else:
            sizes = ", ".join(f"{name} {size}" for name, size in ds.sizes.items())
            rows = [("store", f"{path}: a run streamed by simulate_to_store"),
                    ("model", str(ds.attrs.get("model", "?"))), ("sizes", sizes),
                    ("times", f"{float(ds.time[0]):g} to {float(ds.time[-1]):g} s, {ds.sizes['time']} samples"),
                    ("method", str(ds.attrs.get("method", "?")))]
            rows += [("solver" if i == 0 else "", f"{key[7:]} = {value}")
                     for i, (key, value) in enumerate((k, v) for k, v in ds.attrs.items() if k.startswith("solver_"))]
    print_rows(rows)
