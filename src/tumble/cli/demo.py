"""``tumble demo NAME [-o DIRECTORY] [options]``: one command per row of the demo table
:data:`tumble.viz.demos.DEMOS`; ``tumble demo`` (or ``tumble demo --list``) lists them, one line each.

Every demo writes the files of its row into an existing directory (``-o``, default ``.``), each checked before
it runs, and prints its numbers and the files written; its row's options are its command's options. A bad
option, value or demo name is one ``error:`` line naming it (exit 2).

Until 0.5 the spellings of ``racket`` and ``polhode`` that named files rather than a directory
(``tumble demo racket -o FILE.nc --plot FILE.png``, ``tumble demo polhode -o FILE.png``) still work and write the
same files, after a ``warning:`` line naming the new spelling (:data:`_OLD_SPELLINGS`).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer
from typer.core import TyperCommand, TyperGroup

try:  # the recent typer releases carry their own copy of click
    from typer._click import Command, Context
    from typer._click.exceptions import BadParameter, NoSuchOption, UsageError
except ImportError:  # the earlier ones raise click's own
    from click import Command, Context  # type: ignore[assignment]
    from click.exceptions import BadParameter, NoSuchOption, UsageError  # type: ignore[assignment]

from tumble._validate import ValidationError
from tumble.cli.common import check_outputs, print_rows, progress_bar
from tumble.cli.errors import exit_codes, fail
from tumble.viz.demos import DEMOS, Demo, resolve

__all__ = ["demo_app"]


def _usage(exc: UsageError, command: str, options: list[str]) -> str:
    """The one line of a command-line mistake: the option or value it names, and the rule."""
    if isinstance(exc, NoSuchOption):
        return f"{exc.option_name}: not an option of {command} (its options: {', '.join(options)})"
    if isinstance(exc, BadParameter) and exc.param is not None and exc.param.opts:
        return f"{'/'.join(exc.param.opts)}: {exc.message}"
    return f"{command}: {exc.format_message()}"


class _OneLineUsage:
    """A command whose command-line mistakes are one ``error:`` line (exit 2), not a usage box."""

    params: list[Any]

    def make_context(self, info_name: str | None, args: list[str], parent: Context | None = None,
                     **extra: Any) -> Context:
        try:
            return super().make_context(info_name, args, parent=parent, **extra)  # type: ignore[misc]
        except UsageError as exc:
            options = ["/".join(param.opts) for param in self.params if param.opts and not param.hidden]
            fail(_usage(exc, f"tumble demo{'' if info_name == 'demo' else f' {info_name}'}", options))


class _DemoCommand(_OneLineUsage, TyperCommand):
    """A demo's command."""


class _DemoGroup(_OneLineUsage, TyperGroup):
    """``tumble demo``: a name that is no demo is one ``error:`` line naming the demos (exit 2)."""

    def resolve_command(self, ctx: Context, args: list[str]) -> tuple[str | None, Command | None, list[str]]:
        if args and args[0] not in DEMOS and not args[0].startswith("-"):
            fail(f"{args[0]}: not a demo of tumble demo (the demos: {', '.join(DEMOS)})")
        return super().resolve_command(ctx, args)


demo_app = typer.Typer(cls=_DemoGroup, invoke_without_command=True, rich_markup_mode="markdown",
                       help="Built-in demonstrations: `tumble demo` lists them; `tumble demo NAME --help` tells one.")


@demo_app.callback()
def demos(ctx: typer.Context,
          list_: Annotated[bool, typer.Option("--list", help="List the demos, one line each.")] = False) -> None:
    """Built-in demonstrations: ``tumble demo NAME [-o DIRECTORY] [options]``; ``tumble demo`` lists them."""
    if ctx.invoked_subcommand is None:
        width = max(map(len, DEMOS)) + 2
        for name, demo in DEMOS.items():
            typer.echo(f"{name:<{width}}{demo.shows}")


@dataclass(frozen=True)
class _OldSpelling:
    """A demo's spelling before 0.4, kept until 0.5: ``-o`` named a file (with ``suffix``), and ``--plot`` the
    figure where ``plot`` is set; ``write`` (``"module:function"``, ``(output[, plot], **options) -> dict``)
    writes them, the viewer page beside the figure."""

    suffix: str
    plot: str | None
    write: str


_OLD_SPELLINGS = {
    "racket": _OldSpelling(".nc", "racket.png", "tumble.viz.racket:write_racket"),
    "polhode": _OldSpelling(".png", None, "tumble.viz.polhode:write_polhode"),
}


def _old_outputs(old: _OldSpelling, output: Path, plot: Path | None) -> list[tuple[str, Path | None]]:
    """The files of the old spelling, each with the option that names it: the viewer page is the figure's
    name with ``.html``."""
    if old.plot is None:
        return [("--output", output), ("--output's viewer page", output.with_suffix(".html"))]
    plot = Path(old.plot) if plot is None else plot
    return [("--output", output), ("--plot", plot), ("--plot's viewer page", plot.with_suffix(".html"))]


def _run(name: str, demo: Demo, output: Path, plot: Path | None, quiet: bool, options: dict[str, Any]) -> None:
    """Check the options and the outputs, run the demo (in its old spelling where ``output`` names a file or
    ``--plot`` is given), print its rows and the files written."""
    old = _OLD_SPELLINGS.get(name)
    if old is not None and not (plot is not None or (output.suffix == old.suffix and not output.is_dir())):
        old = None  # the new spelling
    if old is not None:
        typer.echo(f"warning: `tumble demo {name} -o FILE{old.suffix}"
                   + (" --plot FILE.png" if old.plot else "") + f"` is deprecated and removed in 0.5: use "
                   f"`tumble demo {name} -o DIRECTORY` (writes {', '.join(demo.files)} there)", err=True)
    with exit_codes():
        for option in demo.options:
            options[option.keyword] = resolve(option.check)(options[option.keyword], option.flag)
        outputs: list[tuple[str, Path | None]]
        if old is not None:
            outputs = _old_outputs(old, output, plot)
        elif output.is_dir():
            outputs = [("--output", output / file) for file in demo.files]
        else:
            raise ValidationError(f"--output: {str(output)!r} is not an existing directory")
        check_outputs(outputs)
        with progress_bar("simulating", enabled=demo.progress and not quiet) as progress:
            if demo.progress:
                options["progress"] = progress
            if old is not None:
                numbers = resolve(old.write)(*(path for option, path in outputs if "page" not in option), **options)
            else:
                numbers = resolve(demo.target)(output, **options)
    print_rows([*demo.rows(numbers), ("wrote", ", ".join(str(path) for _, path in outputs))])


def _command(name: str, demo: Demo) -> Callable[..., None]:
    """The command of a row: ``-o DIRECTORY``, the row's options, ``--quiet`` where it draws a progress bar,
    and the hidden ``--plot`` of an old spelling."""

    def command(*, output: Path, plot: Path | None = None, quiet: bool = False, **options: Any) -> None:
        _run(name, demo, output, plot, quiet, options)

    keyword = inspect.Parameter.KEYWORD_ONLY
    parameters = [inspect.Parameter("output", keyword, default=Path("."), annotation=Annotated[
        Path, typer.Option("-o", "--output", help="Existing directory to write the files in.")])]
    parameters += [inspect.Parameter(option.keyword, keyword, default=option.default,
                                     annotation=Annotated[option.type, typer.Option(option.flag, help=option.help)])
                   for option in demo.options]
    if demo.progress:
        parameters.append(inspect.Parameter("quiet", keyword, default=False, annotation=Annotated[
            bool, typer.Option("--quiet", "-q", help="No progress bar.")]))
    old = _OLD_SPELLINGS.get(name)
    if old is not None and old.plot is not None:
        parameters.append(inspect.Parameter("plot", keyword, default=None, annotation=Annotated[
            Path | None, typer.Option("--plot", hidden=True, help="Deprecated (until 0.5): the figure's file.")]))
    command.__signature__ = inspect.Signature(parameters)  # type: ignore[attr-defined]
    command.__doc__ = demo.help
    return command


for _name, _demo in DEMOS.items():
    demo_app.command(_name, cls=_DemoCommand)(_command(_name, _demo))
