"""``[sweep]``: a Monte-Carlo or grid sweep of a scenario of any kind (:func:`tumble.sweep`).

::

    [sweep]
    samples = 1000
    seed = 1
    chunk = 100                         # samples per Dask task (optional)
    percentiles = [1, 50, 99]           # optional

    [sweep.dispersions]
    "initial.omega" = { normal = { mean = [0.0, 0.0, 1.0], std = [0.01, 0.01, 0.05] } }
    "body.inertia" = { inertia = { moments = [1.0, 2.0, 2.5], std = [0.01, 0.02, 0.02], angle = 0.01 } }
    "initial.q" = { uniform_attitude = true }

    [sweep.outcomes]
    nutation = { series = "nutation_angle", axis = [0.0, 0.0, 1.0], reduce = "final" }

    [sweep.statistics]
    pointing = { series = "pointing_error", target = [1.0, 0.0, 0.0, 0.0] }

A dispersion's key is the dotted key of the value it replaces in the file
(``"initial.omega"``, ``"body.moments"``, ``"damper.damping"``,
``"spacecraft.inertia"``, ...). Keys of the initial state are drawn as a batch;
any other key rebuilds the model per sample from the file with the drawn
value in place (every rule of the file applies to it). The output times, the
solver and the torques are shared by every sample, so ``time``, ``solver``
and ``torque`` keys are refused. Each dispersion is one of ``normal = {mean,
std}``, ``uniform = {low, high}``, ``truncated_normal = {mean, std, low,
high}``, ``grid = [values]``, ``uniform_attitude = true``, ``inertia =
{moments, std, angle, truncation}`` (:class:`tumble.sweeps.Inertia`) and
``misalignment = {axes, angle}`` (rad). An outcome or a series names a series
(``pointing_error`` with a ``target`` quaternion, ``nutation_angle`` with a
body ``axis``, ``component`` with a ``name`` and ``index``); an outcome adds
how it is reduced: ``reduce = "max"`` (with ``after``, s), ``"final"``,
``"settling_time"`` (with ``below``) or ``"crossing_time"`` (with ``above``).
Angles are in rad.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, Literal, cast

from pydantic import model_validator

from tumble._validate import ValidationError, as_array
from tumble.scenario._errors import ScenarioError, in_file
from tumble.scenario._run import Run
from tumble.scenario._values import _Bool, _Number, _Table, _Text
from tumble.sweeps import dispersions as _d
from tumble.sweeps import outcomes as _o
from tumble.sweeps.plan import store_name_problem

if TYPE_CHECKING:
    import numpy as np

    from tumble.rigid_body import RigidBody
    from tumble.scenario._base import Scenario
    from tumble.scenario.rigid import Problem
    from tumble.simulate import Model
    from tumble.trajectory import Trajectory

__all__ = ["SweepTable", "ScenarioModel", "sweep_arguments"]

# Keys a sweep shares between its samples.
_SHARED = ("time", "solver", "torque")


class DispersionTable(_Table):
    """One dispersed key: exactly one of the forms of :mod:`tumble.sweeps.dispersions`."""

    normal: dict | None = None
    uniform: dict | None = None
    truncated_normal: dict | None = None
    grid: list | None = None
    uniform_attitude: _Bool | None = None
    inertia: dict | None = None
    misalignment: dict | None = None

    @model_validator(mode="after")
    def _one(self):
        given = [name for name in type(self).model_fields if getattr(self, name) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of {', '.join(type(self).model_fields)}, got {given or 'none'}")
        return self

    def build(self) -> _d.Dispersion:
        kinds = {"normal": _d.Normal, "uniform": _d.Uniform, "truncated_normal": _d.TruncatedNormal,
                 "inertia": _d.Inertia, "misalignment": _d.Misalignment}
        for name, cls in kinds.items():
            value = getattr(self, name)
            if value is not None:
                try:
                    return cls(**value)
                except TypeError as exc:
                    raise ValueError(f"{name}: {exc}") from None
        if self.grid is not None:
            return _d.Grid(as_array(self.grid, "points"))  # the check Grid makes, and an array for its type
        return _d.UniformAttitude()


class SeriesTable(_Table):
    """A series (:mod:`tumble.sweeps.outcomes`), and for an outcome how it is reduced."""

    series: Literal["pointing_error", "nutation_angle", "component"]
    target: list[_Number] | None = None
    axis: list[_Number] | None = None
    name: _Text | None = None
    index: list[int] | int | None = None
    reduce: Literal["max", "final", "settling_time", "crossing_time"] | None = None
    after: _Number | None = None
    below: _Number | None = None
    above: _Number | None = None

    def series_function(self) -> Callable[[Trajectory], np.ndarray]:
        if self.series == "pointing_error":
            return _o.PointingError(*(() if self.target is None else (tuple(self.target),)))
        if self.series == "nutation_angle":
            return _o.NutationAngle(*(() if self.axis is None else (tuple(self.axis),)))
        if self.name is None:
            raise ValueError("component: needs name (a field or extra of the trajectory, e.g. 'omega')")
        return _o.Component(self.name, () if self.index is None else cast(Any, self.index))  # made a tuple there

    def outcome_function(self) -> Callable[[Trajectory], np.ndarray]:
        of = self.series_function()
        if self.reduce is None:
            raise ValueError("reduce: an outcome needs one of 'max', 'final', 'settling_time', 'crossing_time'")
        if self.reduce == "max":
            return _o.Max(of, -float("inf") if self.after is None else self.after)
        if self.reduce == "final":
            return _o.Final(of)
        bound: dict[str, tuple[str, type[_o.SettlingTime] | type[_o.CrossingTime]]] = {
            "settling_time": ("below", _o.SettlingTime), "crossing_time": ("above", _o.CrossingTime)}
        key, cls = bound[self.reduce]
        if getattr(self, key) is None:
            raise ValueError(f"{key}: reduce = {self.reduce!r} needs it")
        return cls(of, getattr(self, key))


class SweepTable(_Table):
    """``[sweep]``: samples, seed, chunk, percentiles, dispersions, outcomes and statistics (see the module)."""

    samples: int | None = None
    seed: int = 0
    chunk: int | None = None
    percentiles: list[_Number] | None = None
    dispersions: dict[str, DispersionTable] = {}
    outcomes: dict[str, SeriesTable] = {}
    statistics: dict[str, SeriesTable] = {}


class ScenarioModel:
    """``build(**values) -> model``: the scenario's model with the dotted keys ``values`` replaced, validated
    and built with every rule of the file (the model-side ``build`` of :func:`tumble.sweep`)."""

    def __init__(self, scenario: Scenario, keys: Iterable[str]) -> None:
        self.cls, self.data, self.source = type(scenario), scenario._data, scenario.source
        self.parameters = tuple(keys)

    def __call__(self, **values: Any) -> Model | RigidBody:
        data = copy.deepcopy(self.data)
        for key, value in values.items():
            *tables, last = key.split(".")
            node = data
            for name in tables:
                node = node.setdefault(name, {})
            node[last] = value.tolist() if hasattr(value, "tolist") else value
        return as_run(self.cls.from_data(data, self.source).build()).model

    def __repr__(self):
        return f"ScenarioModel({self.source!r}, keys={list(self.parameters)})"


def _component_problems(run: Run, table: SweepTable) -> list[tuple[str, str]]:
    """``(key, problem)`` for each ``component`` series whose field the scenario's trajectory lacks or whose
    index is out of range, found on a run of the nominal model over the first two output times (before any
    chunk runs: a sweep refused after it ran every chunk is an hour lost)."""
    import dataclasses

    import numpy as np

    components = [(f"sweep.{kind}.{name}", entry.series_function())
                  for kind, group in (("outcomes", table.outcomes), ("statistics", table.statistics))
                  for name, entry in group.items() if entry.series == "component" and entry.name is not None]
    if not components:
        return []
    one = {name: np.reshape(value, (1, -1)) for name, value in run.initial.items()}  # a batch of one, as a chunk
    probe = dataclasses.replace(run, t=run.t[:2], initial=one).simulate()
    problems = []
    for where, component in components:
        try:
            component(probe)
        except ValidationError as exc:
            problems.append((where, f"component: {exc}"))
    return problems


def as_run(problem: Run | Problem) -> Run:
    """The :class:`~tumble.scenario.Run` of a built scenario (the rigid kind's problem converts itself)."""
    return problem if isinstance(problem, Run) else problem.as_run()


def sweep_arguments(scenario: Scenario, samples: int | None = None) -> dict:
    """The arguments of :func:`tumble.sweep` for a scenario with a ``[sweep]`` table (``samples`` overrides
    the file's)."""
    table = scenario.sweep
    if table is None:
        raise ScenarioError(scenario.source, [("sweep", "missing required table: a sweep needs [sweep]")])
    with in_file(scenario.source):
        run = as_run(scenario.build())
        problems, dispersions, states, parameters = [], {}, {}, []
        for key, entry in table.dispersions.items():
            where = f"sweep.dispersions.{key}"
            if not all(part.isidentifier() for part in key.split(".")):
                problems.append((where, "a dispersion replaces a whole value, named by its dotted key (e.g. "
                                        "'initial.omega'): no index into an array or an array of tables"))
                continue
            if key.split(".")[0] in _SHARED:
                problems.append((where, f"the samples of a sweep share {', '.join(_SHARED)}: cannot disperse {key}"))
                continue
            try:
                dispersions[key] = entry.build()
            except (ValueError, TypeError) as exc:
                problems.append((where, str(exc).partition("\n")[0]))
                continue
            state = next((arg for arg, k in run.keys.items() if arg in run.initial and
                          (k == key or (key == "initial.q" and k == "initial"))), None)
            if state is not None:
                states[key] = state
            else:
                parameters.append(key)
        outcomes: dict[str, Callable] = {}  # name → f(traj): the sweep's outcomes and statistics
        statistics: dict[str, Callable] = {}
        for group, out, make in ((table.outcomes, outcomes, "outcome_function"),
                                 (table.statistics, statistics, "series_function")):
            kind = "outcomes" if out is outcomes else "statistics"
            for name, series in group.items():
                taken = store_name_problem(name)
                if taken is not None:
                    problems.append((f"sweep.{kind}.{name}", f"{taken}; give another name"))
                    continue
                try:
                    out[name] = getattr(series, make)()
                except ValueError as exc:
                    problems.append((f"sweep.{kind}.{name}", str(exc).partition("\n")[0]))
        problems += _component_problems(run, table)
        if problems:
            raise ScenarioError(scenario.source, problems)
    model = ScenarioModel(scenario, parameters) if parameters else run.model
    named = {states.get(key, key): d for key, d in dispersions.items()}
    fixed = {name: value for name, value in run.initial.items() if name not in named}
    arguments = dict(model=model, dispersions=named, samples=table.samples if samples is None else samples,
                     seed=table.seed, chunk=table.chunk, t=run.t, method=run.method, torque=run.torque,
                     outcomes=outcomes, statistics=statistics, **run.options, **fixed)
    if table.percentiles is not None:
        arguments["percentiles"] = table.percentiles
    return arguments
