"""Scenario kind ``"variable"``: a body whose inertia changes, tabulated in the file
(:class:`tumble.variable.VariableBody`).

The body's inertia ``I(t)`` about its centre of mass and the angular momentum
``A(t)`` of its shape change (body axes) are samples, interpolated by cubic
splines; the rotation obeys ``L = I(t) ω + A(t)``, ``dL/dt + ω × L = 0``
(:mod:`tumble.variable.body`). The samples are data, never code::

    kind = "variable"

    [variable]
    times = [0.0, 1.0, 2.0, 3.0, 4.0]                 # s, strictly increasing, at least 4
    moments = [[3.0, 3.0, 1.0], [3.0, 3.0, 1.0],      # kg m^2: I(t) = diag(moments), one row per time
               [1.5, 1.5, 0.5], [1.5, 1.5, 0.5], [1.5, 1.5, 0.5]]
    # or inertia = [[[Ixx, Ixy, Ixz], [...], [...]], ...]: one 3×3 tensor per time
    # shape_momentum = [[Ax, Ay, Az], ...]            # kg m^2/s, one per time (default 0)

    [initial]
    omega = [0.0, 0.0, 6.0]                            # rad/s, body axes

The output times must lie within ``[times[0], times[-1]]`` (no extrapolation).
The body takes no external torque.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar, cast

import numpy as np
from numpy.typing import ArrayLike
from pydantic import model_validator

from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Bool, _InertiaOrMoments, _Matrix, _Number, _Vector
from tumble.scenario.tables import Initial, Solver, Time
from tumble.trajectory import Trajectory
from tumble.variable import VariableBody

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["VariableScenario", "rate_and_energy_rows"]


class VariableTable(_InertiaOrMoments):
    """``[variable]``: sample ``times`` (s), ``inertia`` (3×3 tensors, kg m², body axes) or ``moments``
    (their diagonals), optional ``shape_momentum`` (kg m²/s, body axes) and ``check_triangle``: the arguments
    of :class:`tumble.variable.VariableBody`."""

    times: list[_Number]
    inertia: list[_Matrix] | None = None
    moments: list[_Vector] | None = None
    shape_momentum: list[_Vector] | None = None
    check_triangle: _Bool = True
    renamed: ClassVar[dict[str, str]] = {"t": "times"}

    @model_validator(mode="after")
    def _one_description(self):
        if (self.inertia is None) == (self.moments is None):
            raise ValueError("give exactly one of inertia (3×3 tensors) or moments (their diagonals), one per time")
        return self

    def build(self) -> VariableBody:
        # exactly one is given
        inertia = cast(ArrayLike, self.inertia if self.moments is None else [np.diag(m) for m in self.moments])
        return VariableBody(self.times, inertia, self.shape_momentum, check_triangle=self.check_triangle)


class VariableScenario(Scenario):
    """A validated scenario of a body with tabulated inertia (``kind = "variable"``, or a ``[variable]`` table)."""

    variable: VariableTable
    initial: Initial
    time: Time
    solver: Solver = Solver()

    def build(self) -> Run:
        """The :class:`~tumble.variable.VariableBody` and its initial state; a refusal names the key."""
        with in_file(self.source):
            with keyed(self.variable.argument_keys("variable"), "variable"):
                model = self.variable.build()
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS}
            with keyed(keys, "initial"):
                initial = self.initial.state()
            return Run(model, initial, self.time.times(), self.solver.method, self.solver.options(), keys=keys,
                       source=self.source)

    def figure(self, traj: Trajectory) -> Figure:
        """:meth:`tumble.Trajectory.plot` of the run, titled with the scenario's name."""
        return traj.plot(title=self.name)

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        return rate_and_energy_rows(traj)


def rate_and_energy_rows(traj: Trajectory) -> list[tuple[str, str]]:
    """Summary rows of a body that changes shape: ``|ω|`` and the energy at the start and the end."""
    assert traj.omega is not None  # the body's rate
    rate = np.linalg.norm(traj.omega, axis=-1)
    return [("rate", f"|omega| {rate[0]:.6g} rad/s at the start, {rate[-1]:.6g} rad/s at the end"),
            ("energy", f"{traj.energy[0]:.6g} J at the start, {traj.energy[-1]:.6g} J at the end "
                       "(the shape change works on the body)")]
