"""What the commands share: their output paths checked first, a progress bar, the writers of their files, the rows
they print (a run's times, method and drifts)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from tumble._files import check_distinct, check_output
from tumble.viz._rows import summary

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["check_outputs", "png", "print_rows", "progress_bar", "stderr", "summary", "text", "written"]

stderr = Console(stderr=True)


def check_outputs(outputs: list[tuple[str, Path | None]], *, inputs: tuple[Path, ...] = ()) -> None:
    """Refuse, before any work, the ``(option, path)`` outputs of a command (``None``: not asked for) that
    cannot be written (:func:`tumble._files.check_output`: a missing or unwritable directory, a name that is
    not a regular file or new), two that are one file, and one that is an input."""
    given = [(option, path) for option, path in outputs if path is not None]
    for option, path in given:
        check_output(path, option)
    check_distinct([*((f"the input {str(path)!r}", path) for path in inputs), *given])


@contextmanager
def progress_bar(description: str, *, enabled: bool,
                  unit: str = "samples") -> Iterator[Callable[..., None] | None]:
    """A rich progress bar on stderr, as a ``progress(done, total[, description])`` callback; ``None`` when not
    a terminal."""
    if not (enabled and stderr.is_terminal):
        yield None
        return
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn(unit),
               TimeRemainingColumn())
    with Progress(*columns, console=stderr, transient=True) as bar:
        task = bar.add_task(description, total=None)
        yield lambda done, total, what=description: bar.update(task, completed=done, total=total, description=what)


def png(figure: Figure | None, path: Path | None) -> list[tuple[Path, Callable[[str], None]]]:
    """The write of ``figure`` as a PNG file at ``path`` for :func:`~tumble._files.write_atomic_all`; none
    without a path (the figure is then not drawn: None)."""
    if path is None:
        return []
    assert figure is not None, "a figure is drawn for every path asked"
    return [(path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))]


def text(text: str) -> Callable[[str], None]:
    """A writer of ``text`` (UTF-8) for :func:`~tumble._files.write_atomic_all`."""
    def write(tmp_path: str) -> None:
        Path(tmp_path).write_text(text, encoding="utf-8")

    return write


def written(output: Path, plot: Path | None) -> str:
    return ", ".join(str(p) for p in (output, plot) if p is not None)


def print_rows(rows: list[tuple[str, str]]) -> None:
    for label, value in rows:
        typer.echo(f"{label:<10}{value}" if len(label) < 10 else f"{label} {value}")
