"""Demonstrations of the extension packages, as ``tumble demo NAME [-o DIRECTORY]``.

Each demo is a function of its package, ``demo_xxx(out_dir) -> dict``, that
writes its files atomically into an existing directory and returns its numbers;
this module turns it into a command and prints the numbers as rows. Registered
on the ``demo`` group by :mod:`tumble.cli` (imported at its end).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Annotated

import typer

from tumble.cli import _exit_codes, _print_rows, demo_app

Rows = Callable[[dict], list[tuple[str, str]]]


def _written(summary: dict) -> tuple[str, str]:
    """The row listing every path the demo wrote (keys ``nc``, ``png``, ``png_*``, ...)."""
    paths = [str(v) for k, v in summary.items() if k in ("nc", "png", "csv") or k.startswith(("png_", "nc_"))]
    return "wrote", ", ".join(paths)


def _register(name: str, target: str, help_text: str, rows: Rows) -> None:
    """Add ``tumble demo NAME``: call ``target`` (``"module:function"``) and print ``rows(summary)``."""
    module, function = target.split(":")

    def command(
        output: Annotated[Path, typer.Option("-o", "--output", help="Existing directory to write the files in.")]
        = Path("."),
    ) -> None:
        with _exit_codes():
            summary = getattr(importlib.import_module(module), function)(output)
        _print_rows([*rows(summary), _written(summary)])

    command.__doc__ = help_text
    demo_app.command(name)(command)


_register(
    "diver", "tumble.variable.demo:demo_diver",
    """A diver's twisting somersaults: a segment model (de Leva 1996) whose arms move in flight.

    Runs the three experiments of docs/diver.md: (a) a layout somersault that acquires twist
    when one arm drops; (b) the rule of thumb twists/somersault = sin(tilt) (I_s/I_l - 1)
    against simulation over tilts of 2-30 deg; (c) a forward 1.5-somersault dive with twists.
    Writes diver_twisting_somersault.png, diver_twist_rule.png, diver_513xd.png and
    diver_513xd.nc in the directory.
    """,
    lambda s: [
        ("(a)", f"{s['twisting_somersault_twists']:.2f} twists in {s['twisting_somersault_somersaults']:.2f} "
                "somersaults after the left arm drops"),
        ("(b)", f"rule of thumb within {s['rule_max_relative_error_10_30_deg']:.1%} of the simulation "
                "for tilts of 10-30 deg"),
        ("(c)", f"{abs(s['dive_somersaults']):.2f} somersaults, {abs(s['dive_twists']):.2f} twists, "
                f"final tilt {s['dive_final_tilt_deg']:.1f} deg"),
        ("|L|", f"largest relative drift {max(s['dive_momentum_drift'], s['twisting_somersault_momentum_drift']):.1e} "
                "(torque-free flight: L is conserved)"),
    ],
)
