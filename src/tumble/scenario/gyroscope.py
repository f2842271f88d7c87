"""Scenario kind ``"gyroscope"``: a spinning rotor on a pivot or in a two-axis gimbal (:mod:`tumble.ins`).

``[gyroscope]`` says its ``suspension`` and has the arguments of the class it
builds (SI units, rad):

* ``suspension = "pivot"``: :class:`tumble.ins.Gyroscope`, a symmetric rotor on
  a pivot under gravity on its imbalance and friction — ``spin_inertia``,
  ``transverse_inertia`` (about the pivot), ``spin`` (rad/s), ``mass``,
  ``offset``, ``g``, ``spin_friction``, ``pivot_friction``, ``tilt`` (rad);
  ``[initial]`` ``precession_rate`` (rad/s, default 0: released at rest);
* ``suspension = "gimbal"``: :class:`tumble.ins.GimbaledGyro`, a rotor in a
  Cardan suspension with gimbal inertia — ``spin_inertia``,
  ``transverse_inertia``, ``inner_gimbal`` (A, B, C), ``outer_gimbal`` (J),
  ``imbalance`` (m g l), ``inner_torque``, ``outer_torque``,
  ``outer_friction``, ``spin_friction``; ``[initial]`` ``spin`` (rad/s,
  required), ``theta`` (rad, default π/2), ``phi_dot``, ``theta_dot`` (rad/s).

::

    kind = "gyroscope"

    [gyroscope]
    suspension = "pivot"
    spin_inertia = 2e-4          # kg m^2
    transverse_inertia = 1.5e-4  # kg m^2, about the pivot
    spin = 600.0                 # rad/s
    mass = 0.2                   # kg
    offset = 0.002               # m: the imbalance

    [initial]
    precession_rate = 0.0        # rad/s: released at rest

Each key ``x`` of ``[initial]`` is the model's initial state ``x0`` (or ``x``)
of :func:`tumble.simulate`; a key the chosen rotor does not have is refused.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal, Union

import numpy as np
from pydantic import Field

from tumble.ins import GimbaledGyro, Gyroscope
from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Number, _Table, _Vector
from tumble.scenario.tables import ModelState, Solver, Time
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["GyroscopeScenario"]


class PivotTable(_Table):
    """``suspension = "pivot"``: the arguments of :class:`tumble.ins.Gyroscope` (defaults: the class's)."""

    suspension: Literal["pivot"]
    spin_inertia: _Number
    transverse_inertia: _Number
    spin: _Number
    mass: _Number | None = None
    offset: _Number | None = None
    g: _Number | None = None
    spin_friction: _Number | None = None
    pivot_friction: _Number | None = None
    tilt: _Number | None = None

    def build(self) -> Gyroscope:
        return Gyroscope(**self.model_dump(exclude={"suspension"}, exclude_none=True))


class GimbalTable(_Table):
    """``suspension = "gimbal"``: the arguments of :class:`tumble.ins.GimbaledGyro` (defaults: the class's)."""

    suspension: Literal["gimbal"]
    spin_inertia: _Number
    transverse_inertia: _Number
    inner_gimbal: _Vector | None = None
    outer_gimbal: _Number | None = None
    imbalance: _Number | None = None
    inner_torque: _Number | None = None
    outer_torque: _Number | None = None
    outer_friction: _Number | None = None
    spin_friction: _Number | None = None

    def build(self) -> GimbaledGyro:
        return GimbaledGyro(**self.model_dump(exclude={"suspension"}, exclude_none=True))


_Gyroscope = Annotated[Union[PivotTable, GimbalTable], Field(discriminator="suspension")]


class GyroscopeInitial(ModelState):
    """``[initial]``: ``precession_rate`` (rad/s) of a rotor on a pivot; ``spin``, ``phi_dot``, ``theta_dot``
    (rad/s) and ``theta`` (rad) of a gimbaled rotor."""

    precession_rate: _Number | None = None
    spin: _Number | None = None
    theta: _Number | None = None
    phi_dot: _Number | None = None
    theta_dot: _Number | None = None


class GyroscopeScenario(Scenario):
    """A validated gyroscope scenario (``kind = "gyroscope"``, or a ``[gyroscope]`` table)."""

    gyroscope: _Gyroscope
    initial: GyroscopeInitial = GyroscopeInitial()
    time: Time
    solver: Solver = Solver()

    def build(self) -> Run:
        """The :class:`~tumble.ins.Gyroscope` or :class:`~tumble.ins.GimbaledGyro` and its initial state; a
        refusal names the key."""
        with in_file(self.source):
            with keyed(self.gyroscope.argument_keys("gyroscope"), "gyroscope"):
                model = self.gyroscope.build()
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS}
            initial = self.initial.state(model)
            return Run(model, initial, self.time.times(), self.solver.method, self.solver.options(), keys=keys,
                       source=self.source)

    def figure(self, traj: Trajectory) -> Figure:
        """:meth:`tumble.Trajectory.plot` of the rotor, titled with the scenario's name."""
        return traj.plot(title=self.name)

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """The mean precession rate of the spin axis about the vertical and the range of its angle from it,
        with the steady precession rate of the rotor's theory."""
        model = self.model
        if isinstance(model, Gyroscope):
            axis = model.axis(traj)
            phi, theta, predicted = axis.phi, axis.theta, model.precession_rate
            theory = "m g l / (I_s w_s)"
        else:
            phi, theta = traj.phi, traj.theta
            predicted, theory = model.precession_rate(traj.spin[0]), "(tau_theta + m g l) / (I_s w_3)"
        mean = (phi[-1] - phi[0]) / (traj.t[-1] - traj.t[0])
        return [("precession", f"mean {mean:.6g} rad/s about the vertical; steady precession of a horizontal "
                               f"axis {theory} = {predicted:.6g} rad/s"),
                ("tilt", f"axis from the vertical between {np.degrees(theta.min()):.6g} and "
                         f"{np.degrees(theta.max()):.6g} deg")]
