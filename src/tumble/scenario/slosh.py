"""Scenario kind ``"slosh"``: a free-floating hub with a fuel-slosh pendulum (:class:`tumble.slosh.SloshBody`).

The hub is the shared ``[body]`` table, with its ``mass`` (kg; the reduced
mass of the pendulum needs it; inertia about the hub's own centre of mass,
body axes); the sloshing liquid is the spherical pendulum of
``[slosh.pendulum]`` (Abramson, NASA SP-106, 1966; see :mod:`tumble.slosh`)::

    kind = "slosh"

    [body]
    moments = [600.0, 600.0, 300.0]   # kg m^2, about the hub's centre of mass
    mass = 900.0                      # kg

    [slosh.pendulum]
    mass = 60.0                       # m, kg
    length = 0.6                      # l, m
    hinge = [0.2, 0.0, 0.0]           # b, m from the hub's centre of mass, body axes
    damping = 1.0                     # d, 1/s: hinge friction torque −μ l² d ν

    [initial]
    omega = [0.035, 0.0, 2.0]         # rad/s, body axes
    direction = [1.0, 0.0, 0.0]       # the rod from the hinge, body axes (normalised)
    rate = [0.0, 0.0, 0.0]            # ν, the rod's rate relative to the hub, rad/s (default 0)

``spin_axis`` of ``[slosh]`` (body axes, default z) is the nominal spin axis
from which the figure and the summary measure the nutation angle. The
external torque on the hub is the shared ``[[torque]]`` list.
"""

from __future__ import annotations

import numpy as np
from pydantic import field_validator
from typing import TYPE_CHECKING

from tumble import slosh
from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Number, _Table, _Vector
from tumble.scenario.tables import Body, Initial, Solver, Time
from tumble.scenario.torques import Torque, build_torque
from tumble.trajectory import Trajectory
from tumble.viz.slosh import nutation_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["SloshScenario"]


class PendulumTable(_Table):
    """``[slosh.pendulum]`` (:class:`tumble.slosh.Pendulum`): ``mass`` (kg), ``length`` (m), ``hinge`` (m,
    body axes, from the hub's centre of mass), ``damping`` (1/s, default 0)."""

    mass: _Number
    length: _Number
    hinge: _Vector
    damping: _Number | None = None

    def build(self) -> slosh.Pendulum:
        return slosh.Pendulum(**self.model_dump(exclude_none=True))


class SloshTable(_Table):
    """``[slosh]``: the ``pendulum`` table and the nominal ``spin_axis`` (body axes) of the nutation angle."""

    pendulum: PendulumTable
    spin_axis: _Vector = [0.0, 0.0, 1.0]

    @field_validator("spin_axis")
    @classmethod
    def _non_zero(cls, axis):
        if not any(axis):
            raise ValueError("must be a non-zero vector (body axes)")
        return axis


class SloshInitial(Initial):
    """``[initial]``: ``omega``, ``q`` or ``euler`` of the hub as in every kind, plus the rod's ``direction``
    (body axes, normalised; required) and ``rate`` (rad/s, body axes, relative to the hub; default 0)."""

    direction: _Vector
    rate: _Vector | None = None


class SloshScenario(Scenario):
    """A validated scenario of a hub with fuel slosh (``kind = "slosh"``, or a ``[slosh]`` table)."""

    body: Body
    slosh: SloshTable
    initial: SloshInitial
    time: Time
    solver: Solver = Solver()
    torque: list[Torque] = []

    def build(self) -> Run:
        """The :class:`~tumble.slosh.SloshBody`, its initial state and torque; a refusal names the key."""
        with in_file(self.source):
            with keyed(self.body.argument_keys("body"), "body"):
                body = self.body.build()
            with keyed(self.slosh.pendulum.argument_keys("slosh.pendulum"), "slosh.pendulum"):
                pendulum = self.slosh.pendulum.build()
            with keyed({"body": "body"}, "slosh"):
                model = slosh.SloshBody(body, pendulum)
            torque = build_torque(self.torque, body)
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS}
            with keyed(keys, "initial"):
                initial = self.initial.state()
            return Run(model, initial, self.time.times(), self.solver.method, self.solver.options(), torque, keys,
                       self.source)

    def nutation_angle(self, traj: Trajectory) -> np.ndarray:
        """Angle (rad) between ``slosh.spin_axis`` and the total angular momentum
        (:func:`tumble.slosh.nutation_angle`)."""
        return slosh.nutation_angle(self.model, traj, self.slosh.spin_axis)

    def figure(self, traj: Trajectory) -> Figure:
        """:func:`tumble.viz.slosh.nutation_figure`: the nutation angle from ``spin_axis``, the energy and ``|H|``."""
        figure = nutation_figure(traj, self.nutation_angle(traj), traj.momentum_norm, traj.energy)
        axis = ", ".join(f"{x:g}" for x in self.slosh.spin_axis)
        figure.axes[0].set_title(f"(a) nutation: angle between the body axis [{axis}] and the total angular momentum")
        if self.name:
            figure.suptitle(self.name)
        return figure

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """The nutation angle at the start and the end."""
        angle = np.degrees(self.nutation_angle(traj))
        return [("nutation", f"{angle[0]:.4g} deg at the start, {angle[-1]:.4g} deg at the end "
                             f"(from the spin axis, body axes)")]
