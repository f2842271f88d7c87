"""Reading a scenario: the file is read once, parsed once (``tomllib``), its kind picked, its tables validated."""

from __future__ import annotations

import os
import tomllib
from collections.abc import Callable
from typing import TYPE_CHECKING

from tumble._files import read_input
from tumble._validate import ValidationError
from tumble.scenario._base import Scenario
from tumble.scenario._errors import ScenarioError, in_file, toml_problem
from tumble.scenario.kinds import kind_of, scenario_class
from tumble.scenario.sweep import sweep_arguments
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    import xarray
    from distributed import Client

__all__ = ["load", "parse", "run_scenario"]


def parse(text: str, *, source: str = "<string>") -> Scenario:
    """Parse and validate a scenario from TOML ``text``: the :class:`Scenario` of its kind
    (:data:`tumble.scenario.KINDS`); ``source`` names it in error messages.

    Raises :class:`ScenarioError` with every schema problem of the file.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, [toml_problem(exc)]) from None
    with in_file(source):
        kind = kind_of(data)
    return scenario_class(kind).from_data({**data, "kind": kind}, source)


def load(path) -> Scenario:
    """Read and validate the scenario file ``path`` (UTF-8 TOML); raises :class:`ScenarioError`."""
    source = str(path)
    try:
        text = read_input(path).decode("utf-8")
    except ValidationError as exc:  # not a regular file, or too large
        raise ScenarioError(source, [("", exc.rule)]) from None
    except OSError as exc:
        raise ScenarioError(source, [("", f"cannot read the file ({exc.strerror or exc})")]) from None
    except UnicodeDecodeError as exc:
        rule = f"not UTF-8 text, as TOML requires ({exc.reason} at byte {exc.start})"
        raise ScenarioError(source, [("", rule)]) from None
    return parse(text, source=source)


def run_scenario(scenario, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
    """Simulate a scenario (a :class:`Scenario`, or the path of a scenario file): ``load(path).run(progress=...)``."""
    if not isinstance(scenario, Scenario):
        scenario = load(scenario)
    return scenario.run(progress=progress)


def sweep_scenario(scenario: Scenario | str | os.PathLike[str], *, samples: int | None = None,
                   store: str | os.PathLike[str] | None = None, client: Client | None = None,
                   workers: int | None = None, progress: Callable[[int, int], None] | None = None,
                   retries: int = 2) -> xarray.Dataset:
    """:func:`tumble.sweep` of a scenario (a :class:`tumble.scenario.Scenario` or the path of its file) as its
    ``[sweep]`` table describes (:mod:`tumble.scenario.sweep`); ``samples`` overrides the table's."""
    from tumble.sweeps import sweep

    if not isinstance(scenario, Scenario):
        scenario = load(scenario)
    arguments = sweep_arguments(scenario, samples=samples)
    return sweep(arguments.pop("model"), arguments.pop("dispersions"), store=store, client=client,
                 workers=workers, progress=progress, retries=retries, **arguments)
