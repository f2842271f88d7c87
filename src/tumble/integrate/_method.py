"""What a method declares: its name, order, needs, options, evaluations per step and driver.

Each method file of :mod:`tumble.integrate` ends with the :class:`Method`
values it defines (its ``METHODS``), as scipy's ``solve_ivp`` names its
solvers in one ``METHODS`` table and diffrax's solvers carry their own
``order`` and ``term_structure``; :data:`tumble.integrate.METHODS` is built
from those declarations and read by everything that names a method (the
front door, sweeps, scenario files, ``tumble warmup``, the tests).

A method is advanced by a :class:`Driver`: the fixed-step driver
(:class:`tumble.integrate._fixed.FixedSteps`, over a *scheme*), the adaptive
DOP853 driver, or the closed form of ``exact``. A driver advances a batch of
states in place from one output time to a later one, so that the engine can
run a method in chunks of output times (progress, analyses that act on the
state between output times), taking the steps of one run.
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from tumble._validate import ValidationError, require_positive

#: Default ``max_steps``: the most steps per body of one run, for every method (about 10 s of ``rk4`` on a
#: torque-free rigid body; a run past it is refused, before it starts for the fixed-step methods).
MAX_STEPS = 10**8

#: The largest ``max_steps`` accepted: step counts stay exact whole float64 numbers and fit an int64.
MAX_STEPS_LIMIT = 2**53

#: The smallest ``rtol`` accepted: float64 cannot do better.
RTOL_MIN = 1e-15


@dataclass(frozen=True)
class Option:
    """A solver option a method reads: its name, its default (None: the caller must give it) and its rule.

    ``check(value, method)`` refuses a value that breaks the rule (:class:`~tumble.ValidationError`
    naming the option) and returns it as the number the driver reads.
    """

    name: str
    default: float | int | None
    check: Callable[[Any, str], float | int]
    description: str

    def value(self, given: Any, method: str) -> float | int:
        """The value of the option for a run of ``method``: ``given``, or the default when None, checked."""
        return self.check(self.default if given is None else given, method)


def _step(dt: Any, method: str) -> float:
    if dt is None:
        raise ValidationError(f"dt: method {method!r} has a fixed step: give dt > 0 (s)")
    require_positive(dt, "dt")
    return float(dt)


def _relative_tolerance(rtol: Any, method: str) -> float:
    require_positive(rtol, "rtol")
    if rtol < RTOL_MIN:
        raise ValidationError(f"rtol: must be >= {RTOL_MIN:g} (float64 cannot do better), got {rtol}")
    return float(rtol)


def _absolute_tolerance(atol: Any, method: str) -> float:
    require_positive(atol, "atol")
    return float(atol)


def _step_limit(max_steps: Any, method: str) -> int:
    """Refuse a ``max_steps`` that is not a whole number from 1 to :data:`MAX_STEPS_LIMIT`."""
    whole = (isinstance(max_steps, (int, float, np.integer, np.floating)) and not isinstance(max_steps, bool)
             and float(max_steps).is_integer())
    if whole and max_steps < 1:
        raise ValidationError(f"max_steps: must be >= 1, got {max_steps!r}")
    if not whole or max_steps > MAX_STEPS_LIMIT:
        raise ValidationError(f"max_steps: must be a whole number from 1 to 2**53 = {MAX_STEPS_LIMIT}, "
                              f"got {max_steps!r}")
    return int(max_steps)


DT = Option("dt", None, _step, "the largest step, s: the steps land on every output time")
RTOL = Option("rtol", 1e-10, _relative_tolerance, "relative tolerance of the error control")
ATOL = Option("atol", 1e-12, _absolute_tolerance, "absolute tolerance of the error control")
STEP_LIMIT = Option("max_steps", MAX_STEPS, _step_limit, "the most steps per body of one run")


def options(*declared: Option) -> Mapping[str, Option]:
    """The options of a method by name, in the order given (the order they are checked and listed in)."""
    return MappingProxyType({option.name: option for option in declared})


#: The options of the fixed-step methods and of the adaptive ones.
FIXED_STEP = options(DT, STEP_LIMIT)
ADAPTIVE = options(RTOL, ATOL, STEP_LIMIT)


class Driver(abc.ABC):
    """How a method advances a batch of states (N, n) through output times: the compiled loops it calls.

    adaptive : the steps are chosen by error control (``rtol``, ``atol``)
    steps    : False for a closed form evaluated at the output times, with no step
    """

    adaptive: ClassVar[bool] = False
    steps: ClassVar[bool] = True

    def plan(self, t: np.ndarray, options: Mapping[str, Any]) -> Any:
        """What every chunk of a run through the output times ``t`` (s) needs, made (and checked) before the
        run starts, from the method's validated ``options``."""
        return None

    @abc.abstractmethod
    def advance(self, model: Any, y: np.ndarray, t: np.ndarray, lo: int, hi: int, out: np.ndarray,
                stats: np.ndarray, plan: Any, serial: bool) -> None:
        """Advance the states ``y`` (N, n; in place) of the compiled ``model`` from ``t[lo]`` to ``t[hi]``.

        ``out[k]`` (N, n) receives the states at ``t[lo + k]``; ``stats[b]`` is member ``b``'s row
        ``[steps, rejected steps, evaluations, status, next step size]`` (:mod:`._dop853`), kept from one
        chunk to the next. ``serial``: no parallel region (one member, or a model that calls Python).
        """


@dataclass(frozen=True)
class Method:
    """An integration method, as its file declares it.

    name        : the name ``simulate(method=...)`` takes
    order       : the order of its global error in the step (None: a closed form, exact to rounding)
    description : one line: the scheme, its source, its step policy
    driver      : the :class:`Driver` that advances it
    evaluations : right-hand-side (or torque) evaluations per step (an adaptive driver counts its own,
                  rejected steps and the starting step included)
    options     : the solver options it reads (:func:`options`), with their defaults and rules
    needs       : the capabilities it needs from the compiled model (:data:`tumble._protocol.CAPABILITIES`)
    conserves   : what it keeps exactly, up to rounding (in words)
    """

    name: str
    order: int | None
    description: str
    driver: Driver
    evaluations: int
    options: Mapping[str, Option]
    needs: frozenset[str] = frozenset({"rhs"})
    conserves: str = "|q| = 1 by projection"

    @property
    def adaptive(self) -> bool:
        """Whether error control chooses its steps."""
        return self.driver.adaptive

    @property
    def stepper(self) -> bool:
        """Whether it takes steps (False for the closed form ``"exact"``)."""
        return self.driver.steps

    def resolve(self, given: Mapping[str, Any]) -> dict[str, float | int]:
        """The options this method reads, from ``given`` (name → value, None when not given): defaults filled
        in, each checked against its rule. An option given that the method does not read is refused."""
        for name, value in given.items():
            if value is not None and name not in self.options:
                reads = f"it reads {', '.join(self.options)}" if self.options else "it has no options"
                raise ValidationError(f"{name}: method {self.name!r} does not use {name} ({reads})")
        return {name: option.value(given.get(name), self.name) for name, option in self.options.items()}
