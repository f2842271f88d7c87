"""``tumble warmup`` and ``tumble cache``: compile every model kind into Numba's on-disk cache; where it is, clear it."""

from __future__ import annotations

from typing import Annotated

import typer

from tumble._validate import ValidationError
from tumble.cli.common import print_rows, progress_bar, stderr
from tumble.cli.errors import exit_codes

__all__ = ["cache_app", "warmup"]


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
    with exit_codes():
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
            with progress_bar("compiling", enabled=not quiet, unit="paths") as progress:
                for done, name in enumerate(chosen):
                    if progress is not None:
                        progress(done, len(chosen), name)
                    elif not quiet:
                        stderr.print(f"compiling {name} ({done + 1}/{len(chosen)})", highlight=False)
                    known[name]()
                if progress is not None:
                    progress(len(chosen), len(chosen), "compiled")
        finally:
            notices.setLevel(level)
    print_rows([("compiled", f"{len(chosen)} paths in {time.perf_counter() - start:.1f} s"),
                 ("cache", cache_where())])


def cache_where() -> str:
    """Where Numba caches tumble's compiled code (docs/architecture.md, "The compiled-code cache")."""
    from numba.core import config

    return config.CACHE_DIR or "__pycache__ beside tumble's source"


cache_app = typer.Typer(help="Numba's on-disk cache of tumble's compiled code.", no_args_is_help=True)


@cache_app.command("info")
def cache_info() -> None:
    """Where tumble's compiled code is cached, the content key it is stamped with (docs/architecture.md, "The
    compiled-code cache"), and how many compiled functions it holds, in how many bytes."""
    from tumble import _cache

    files = _cache.cached_files()
    print_rows([("cache", cache_where()), ("key", _cache.content_key()),
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
    print_rows([("cache", cache_where()), ("removed", f"{len(files)} files, {size / 1e6:.1f} MB")])
