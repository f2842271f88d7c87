"""Scenario kind ``"fluid"``: a rigid body in an ideal fluid, Kirchhoff's equations
(:class:`tumble.fluid.KirchhoffBody`).

The body is the shared ``[body]`` table, with its ``mass`` (kg; inertia about
its centre of mass, the body origin, body axes); the fluid is ``[fluid]``:
either its ``added_mass`` (6×6, Fossen's order: surge, sway, heave, roll,
pitch, yaw; kg, kg m, kg m^2), or the semi-axes of an ``ellipsoid`` (m, along
the body axes) and the fluid's ``density`` (kg/m^3), whose added mass is
Lamb's (:func:`tumble.fluid.ellipsoid_added_mass`)::

    kind = "fluid"

    [body]
    shape = "ellipsoid"
    semi_axes = [1.0, 0.2, 0.2]       # m
    mass = 171.74                     # kg: the displaced water, neutrally buoyant

    [fluid]
    ellipsoid = [1.0, 0.2, 0.2]       # m: the hull's semi-axes, body axes
    density = 1025.0                  # kg/m^3

    [initial]
    omega = [0.0, 0.01, 0.0]          # rad/s, body axes: a small pitch rate
    velocity = [2.0, 0.0, 0.0]        # m/s, body axes: along the long axis
    position = [0.0, 0.0, 0.0]        # m, inertial (default 0)

The body is free: no ``[[torque]]``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, cast

import numpy as np
from pydantic import Field, model_validator

from tumble import attitude, fluid
from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Number, _Positive, _Table, _Vector
from tumble.scenario.tables import Body, Initial, Solver, Time
from tumble.trajectory import Trajectory
from tumble.viz.fluid import motion_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["FluidScenario"]

_Row6 = Annotated[list[_Number], Field(min_length=6, max_length=6)]
_Matrix6 = Annotated[list[_Row6], Field(min_length=6, max_length=6)]


class FluidTable(_Table):
    """``[fluid]``: ``added_mass`` (6×6, Fossen's order), or ``ellipsoid`` (semi-axes, m) with ``density``
    (kg/m^3)."""

    added_mass: _Matrix6 | None = None
    ellipsoid: _Vector | None = None
    density: _Positive | None = None

    @model_validator(mode="after")
    def _one_description(self):
        if (self.added_mass is None) == (self.ellipsoid is None):
            raise ValueError("give exactly one of added_mass or ellipsoid")
        if self.ellipsoid is not None and self.density is None:
            raise ValueError("ellipsoid needs the fluid's density (kg/m^3)")
        if self.added_mass is not None and self.density is not None:
            raise ValueError("density is read with ellipsoid only (added_mass is given in kg, kg m, kg m^2)")
        return self

    def build(self) -> np.ndarray:
        """``M_A`` (6, 6): as given, or Lamb's for the ellipsoid."""
        if self.added_mass is not None:
            return np.array(self.added_mass)
        assert self.ellipsoid is not None and self.density is not None  # _one_description
        return fluid.ellipsoid_added_mass(self.ellipsoid, self.density)


class FluidInitial(Initial):
    """``[initial]``: ``omega``, ``q`` or ``euler`` as in every kind, plus the ``velocity`` of the body origin
    (m/s, body axes; default 0) and its ``position`` (m, inertial; default 0)."""

    velocity: _Vector | None = None
    position: _Vector | None = None


class FluidScenario(Scenario):
    """A validated scenario of a rigid body in an ideal fluid (``kind = "fluid"``, or a ``[fluid]`` table)."""

    body: Body
    fluid: FluidTable
    initial: FluidInitial
    time: Time
    solver: Solver = Solver()

    def build(self) -> Run:
        """The :class:`~tumble.fluid.KirchhoffBody` and its initial state; a refusal names the key."""
        with in_file(self.source):
            with keyed(self.body.argument_keys("body"), "body"):
                body = self.body.build()
            with keyed({"semi_axes": "fluid.ellipsoid", "density": "fluid.density"}, "fluid"):
                added_mass = self.fluid.build()
            with keyed({"added_mass": "fluid.added_mass" if self.fluid.added_mass is not None else "fluid"},
                       "body"):
                model = fluid.KirchhoffBody(body, added_mass)
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS}
            with keyed(keys, "initial"):
                initial = self.initial.state()
            return Run(model, initial, self.time.times(), self.solver.method, self.solver.options(), None, keys,
                       self.source)

    def figure(self, traj: Trajectory) -> Figure:
        """:func:`tumble.viz.fluid.motion_figure`: velocities, the path and the integrals."""
        figure = motion_figure(traj, self.model)
        if self.name:
            figure.suptitle(self.name)
        return figure

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """The distance travelled and the turn of the body's x axis from its start."""
        x = traj.position
        ends = attitude.rotate(cast(np.ndarray, traj.q)[[0, -1]], np.array([1.0, 0.0, 0.0]))  # body x, inertial, at both ends
        turn = np.degrees(np.arccos(np.clip(ends[0] @ ends[1], -1.0, 1.0)))
        return [("path", f"{np.linalg.norm(x[-1] - x[0]):.4g} m from the start; body x turned {turn:.4g} deg")]
