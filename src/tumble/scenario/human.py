"""Scenario kind ``"human"``: a human body in flight moving its joints (:class:`tumble.variable.MovingHuman`).

The body is the 9-segment model of de Leva (J. Biomech. 29(9), 1996, Table 4;
:meth:`tumble.variable.Human.de_leva`), scaled to ``mass`` and ``height``; its
joint angles (rad; all zero: standing straight, arms at the sides; names and
axes in ``docs/diver.md``) are tables of :class:`tumble.variable.Motion` moves,
each a minimum-jerk move from the angle it has to ``target`` between ``begin``
and ``end`` (s)::

    kind = "human"

    [human]
    mass = 73.0                  # kg (default)
    height = 1.741               # m (default)

    [human.angles.right_shoulder_abduction]
    start = 3.141592653589793    # rad: overhead, held

    [human.angles.left_shoulder_abduction]
    start = 3.141592653589793
    moves = [{ begin = 0.2, end = 0.6, target = 0.0 }]   # s, s, rad: the left arm drops

    [initial]
    omega = [5.06, 0.0, 0.0]     # rad/s, trunk axes (x right, y forward, z head)

The trunk frame B is the body frame of the run; ``I(t)`` and ``A(t)`` are
sampled every ``sample_step`` (s, default 2e-3) over ``[time.start,
time.stop]`` and interpolated by cubic splines (:meth:`tumble.variable.Human.moving`).
The body takes no external torque (in the air).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar, cast

import numpy as np
from pydantic import create_model

from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Number, _Table
from tumble.scenario.tables import Initial, Solver, Time
from tumble.scenario.variable import rate_and_energy_rows
from tumble.trajectory import Trajectory
from tumble.variable import Human, Motion
from tumble.viz.diver import figure_dive
from tumble.variable.diver import Dive, orientation_angles

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["HumanScenario"]

# figure_dive draws the poses seen along inertial x, the somersault axis of tumble.variable.diver: it is
# the figure of a run whose angular momentum lies along x to this fraction of |L| (rounding of I⁻¹).
_ALONG_X = 1e-9


class MoveTable(_Table):
    """One move of a joint angle: from the angle it has to ``target`` (rad) between ``begin`` and ``end`` (s)."""

    begin: _Number
    end: _Number
    target: _Number


class AngleTable(_Table):
    """A joint angle (:class:`tumble.variable.Motion`): ``start`` (rad, default 0), then ``moves`` in time order."""

    start: _Number = 0.0
    moves: list[MoveTable] = []

    def build(self) -> Motion:
        return Motion(self.start, [(move.begin, move.end, move.target) for move in self.moves])


if TYPE_CHECKING:  # a model made at import time, one field per joint angle: to mypy, a table of any keys
    HumanAngles = _Table
else:
    HumanAngles = create_model("HumanAngles", __base__=_Table,
                               __doc__="``[human.angles]``: an optional :class:`AngleTable` per joint angle of de "
                                       "Leva's body, by its name (a missing angle is 0).",
                               **{name: (AngleTable | None, None) for name in Human.de_leva().dofs})


class HumanTable(_Table):
    """``[human]``: ``mass`` (kg) and ``height`` (m) of the de Leva body (defaults: 73.0 kg, 1.741 m), the
    ``sample_step`` (s) of ``I(t)``, ``A(t)`` and the joint ``angles``."""

    mass: _Number | None = None
    height: _Number | None = None
    sample_step: _Number | None = None
    angles: HumanAngles = HumanAngles()
    renamed: ClassVar[dict[str, str]] = {"dt": "sample_step"}

    def body(self) -> Human:
        return Human.de_leva(**self.model_dump(include={"mass", "height"}, exclude_none=True))

    def motions(self) -> dict[str, Motion]:
        """The joint angles given, name → :class:`~tumble.variable.Motion`; a refusal names the key."""
        motions = {}
        for name, table in self.angles:
            if table is not None:
                key = f"human.angles.{name}"
                with keyed(table.argument_keys(key), key):
                    motions[name] = table.build()
        return motions


class HumanScenario(Scenario):
    """A validated scenario of a human body in flight (``kind = "human"``, or a ``[human]`` table)."""

    human: HumanTable
    initial: Initial
    time: Time
    solver: Solver = Solver()

    def build(self) -> Run:
        """The :class:`~tumble.variable.MovingHuman` over the output span and its initial state; a refusal names
        the key."""
        with in_file(self.source):
            motions = self.human.motions()
            with keyed(self.human.argument_keys("human"), "human"):
                options = {} if self.human.sample_step is None else {"dt": self.human.sample_step}
                model = self.human.body().moving(motions, t_span=(self.time.start, self.time.stop), **options)
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS}
            with keyed(keys, "initial"):
                initial = self.initial.state()
            return Run(model, initial, self.time.times(), self.solver.method, self.solver.options(), keys=keys,
                       source=self.source)

    def figure(self, traj: Trajectory) -> Figure:
        """:func:`tumble.viz.diver.figure_dive` (poses seen along ``L``, somersault and twist, tilt, arms,
        energy) when the angular momentum lies along inertial x, the somersault axis of
        :mod:`tumble.variable.diver`; else :meth:`tumble.Trajectory.plot`."""
        momentum = traj.momentum_inertial[0]
        if not np.linalg.norm(momentum[1:]) <= _ALONG_X * np.linalg.norm(momentum[0]):
            return traj.plot(title=self.name)
        dive = Dive(traj, orientation_angles(cast(np.ndarray, traj.q), momentum), float(momentum[0]))
        return figure_dive(self.human.body(), dive, self.name or "a human body in flight")

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """Somersaults and twists (Yeadon's angles about ``L``), ``|ω|`` and the energy at the start and the end."""
        momentum = traj.momentum_inertial[0]
        rows = rate_and_energy_rows(traj)
        if np.any(momentum):
            angles = orientation_angles(cast(np.ndarray, traj.q), momentum)
            rows.insert(0, ("turns", f"{angles.somersaults:+.4g} somersaults, {angles.twists:+.4g} twists "
                                     "(Yeadon's angles about L)"))
        return rows
