"""What every scenario kind is: a validated file that builds a tumble model and runs it."""

from __future__ import annotations

import abc
from collections.abc import Callable

import pydantic
from pydantic import PrivateAttr

from tumble.scenario._errors import ScenarioError, describe
from tumble.scenario._values import _Table, _Text
from tumble.scenario.sweep import SweepTable
from tumble.trajectory import Trajectory

__all__ = ["Scenario"]


class Scenario(_Table):
    """A validated scenario of one kind (see ``docs/scenarios.md``): the base of every kind's top level.

    A kind (one module of :mod:`tumble.scenario`, one row of
    :data:`tumble.scenario.KINDS`) subclasses it with its tables and
    implements :meth:`build` (the model, its initial state, times and solver:
    a problem whose ``simulate(progress=...)`` runs it and whose ``model`` is
    the tumble model) and :meth:`figure`; it may add summary :meth:`rows`.
    Everything else — reading the file, choosing the kind, the messages —
    is shared.
    """

    name: _Text | None = None
    description: _Text | None = None
    #: The kind of the file (a row of tumble.scenario.KINDS): given, or inferred from its tables.
    kind: _Text

    #: ``[sweep]``: a Monte-Carlo or grid sweep of the scenario (:mod:`tumble.scenario.sweep`), or None.
    sweep: SweepTable | None = None

    _source: str = PrivateAttr("<scenario>")
    _data: dict = PrivateAttr(default_factory=dict)

    @classmethod
    def from_data(cls, data: dict, source: str) -> Scenario:
        """Validate the parsed TOML ``data`` as a scenario of this kind; it keeps ``data`` (a sweep rebuilds
        its model from it with dispersed values in place). Raises :class:`~tumble.scenario.ScenarioError`."""
        try:
            scenario = cls.model_validate(data)
        except pydantic.ValidationError as exc:
            raise ScenarioError(source, [describe(error, cls) for error in exc.errors()]) from None
        scenario._source = source
        scenario._data = data
        return scenario

    @property
    def source(self) -> str:
        """Where the scenario came from (its file name), as error messages give it."""
        return self._source

    @abc.abstractmethod
    def build(self):
        """The model, initial state, output times and solver options, checked by the library: a problem with
        ``.model`` and ``.simulate(*, progress=None) -> Trajectory``.

        Raises :class:`~tumble.scenario.ScenarioError` naming the key behind any
        argument the library refuses.
        """

    @abc.abstractmethod
    def figure(self, traj: Trajectory):
        """A matplotlib figure of a run of this scenario, titled with its name."""

    @property
    def model(self):
        """The tumble model the scenario describes (built on each access)."""
        return self.build().model

    def run(self, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
        """Build and simulate; ``progress(done, total)`` as in :func:`tumble.simulate`.

        Bad input raises :class:`~tumble.scenario.ScenarioError` before the
        integration starts; a failure of the integrator raises :class:`tumble.SolverError`.
        """
        return self.build().simulate(progress=progress)

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """Summary rows of a run that are particular to this kind (``tumble run`` prints them); none by default."""
        return []
