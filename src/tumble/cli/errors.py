"""The one error path of the ``tumble`` command: every failure is one ``error: ...`` line and an exit code.

Exit codes (``docs/cli.md``): 0 success; 2 every error a user can act on:
bad input, the input files and options included (a
:class:`~tumble.ValidationError` — a scenario's problems one line each — and
whatever a hostile or damaged file makes a reader raise:
:class:`RecursionError` from a deeply nested TOML table,
:class:`OverflowError` from a number past float64, :class:`UnicodeDecodeError`,
:class:`ZeroDivisionError` and :class:`FloatingPointError` from numbers too
large to compute with), the integrator giving up
(:class:`~tumble.SolverError`: a diverged run, a step too small, more steps
than ``max_steps``), a file that cannot be read or written (:class:`OSError`)
and memory running out; 1 only for a bug in tumble (an unexpected
exception). No traceback reaches the user: a bug is reported in one line
with its type; ``TUMBLE_TRACEBACK=1`` in the environment lets it propagate
instead. NumPy's floating-point warnings are silenced inside a command: its
refusals say what was wrong, once.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import NoReturn

import numpy as np
import typer

from tumble._validate import ValidationError
from tumble.integrate import SolverError

__all__ = ["EXIT_ERROR", "EXIT_BUG", "exit_codes", "fail"]

EXIT_ERROR = 2
EXIT_BUG = 1

# What a hostile or damaged input makes Python or NumPy raise while it is read or used.
_BAD_INPUT = (RecursionError, OverflowError, UnicodeDecodeError, ZeroDivisionError, FloatingPointError)


@contextmanager
def exit_codes(*inputs: str | os.PathLike[str]) -> Iterator[None]:
    """Run a command's body: every error exits with code 2 and a bug with 1, each as ``error:`` lines on
    stderr; ``inputs`` (paths) name the file a reader's own exception came from."""
    source = f"{os.fspath(inputs[0])}: " if inputs else ""
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            yield
    except typer.Exit:
        raise
    except ValidationError as exc:
        _fail(str(exc), EXIT_ERROR)
    except _BAD_INPUT as exc:
        _fail(f"{source}cannot be used ({type(exc).__name__}: {_first_line(exc)})", EXIT_ERROR)
    except (SolverError, OSError) as exc:
        _fail(str(exc), EXIT_ERROR)
    except MemoryError:
        _fail("out of memory: ask for fewer output times, a shorter run or a smaller batch", EXIT_ERROR)
    except Exception as exc:  # noqa: BLE001 - the promise is one line, never a traceback
        if os.environ.get("TUMBLE_TRACEBACK"):
            raise
        _fail(f"unexpected {type(exc).__name__}: {_first_line(exc)} (a bug: please report it; "
              "TUMBLE_TRACEBACK=1 shows the traceback)", EXIT_BUG)


def fail(message: str) -> NoReturn:
    """Exit with code 2 and ``message`` as ``error:`` lines on stderr: a mistake found outside
    :func:`exit_codes` (a command line that does not parse)."""
    _fail(message, EXIT_ERROR)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else "(no message)"


def _fail(message: str, code: int) -> NoReturn:
    for line in message.splitlines() or [""]:
        typer.echo(f"error: {line}", err=True)
    raise typer.Exit(code) from None
