"""Scenario files: a simulation described as data, in TOML, for every kind of model.

One dialect for every model: a file gives its ``kind`` (a row of
:data:`KINDS`: ``"rigid"``, ``"spacecraft"``, ``"flexible"``, ``"slosh"``,
``"variable"``, ``"human"``, ``"gyroscope"``, ``"robot"``; without ``kind``, the
kind whose marker table the file has — ``[spacecraft]``, ``[robot]``, ... —
else a rigid body), the model's tables and the shared ones — ``[initial]``
state, output ``[time]``, ``[solver]``, ``[body]`` and ``[[torque]]`` where
the model has them, and wherever an orbit is needed the one ``orbit`` table
(SI units; ``omega`` in body axes; ``q`` scalar first, body → inertial)::

    name = "Tennis racket"

    [body]
    shape = "t_handle"

    [initial]
    omega = [0.001, 10.0, 0.001]      # rad/s, body axes

    [time]
    stop = 20.0                       # s
    step = 0.005                      # s between output times

    [solver]
    method = "dop853"
    rtol = 1e-12
    atol = 1e-12

    >>> scenario = tumble.scenario.load(tumble.examples.path("intermediate_axis.toml"))   # read, parsed, validated once
    >>> traj = scenario.run()          # a tumble.Trajectory; scenario.model is the tumble model

The schema is documented in ``docs/scenarios.md``. Files are parsed once
with the standard library's :mod:`tomllib` and validated by pydantic models
that refuse unknown keys; a scenario is data, never code. Every problem is
reported as a :class:`ScenarioError` naming the file, the key and the rule
it breaks, one line per problem::

    spin.toml: body.inertia: must be positive definite (principal moments ...)

Rules that the library already enforces (a positive-definite inertia, a
positive mass, increasing torque sample times, ...) are not repeated here:
the library's :class:`~tumble.ValidationError` names the argument it refuses
(``.field``), which each table maps to the key that fed it.
"""

from tumble.scenario._base import Scenario
from tumble.scenario._errors import ScenarioError
from tumble.scenario._read import load, parse, run_scenario, sweep_scenario
from tumble.scenario._run import Run
from tumble.scenario.kinds import DEFAULT_KIND, KINDS, Kind
from tumble.scenario.tables import Body, EulerAngles, Initial, ModelState, Solver, Time

#: The names of earlier releases (``docs/scenarios.md`` keeps them).
load_scenario = load
parse_scenario = parse

__all__ = [
    "DEFAULT_KIND",
    "KINDS",
    "Body",
    "EulerAngles",
    "Initial",
    "Kind",
    "ModelState",
    "Run",
    "Scenario",
    "ScenarioError",
    "Solver",
    "Time",
    "load",
    "load_scenario",
    "parse",
    "parse_scenario",
    "run_scenario",
    "sweep_scenario",
]
