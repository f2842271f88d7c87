"""Scenario kind ``"flexible"``: a hub with flexible appendages (:class:`tumble.flexible.FlexibleBody`).

The hybrid-coordinate equations of :mod:`tumble.flexible` (SI units, body
axes)::

    I ω̇ + Σₖ δₖ η̈ₖ + ω × (I ω + Σₖ δₖ η̇ₖ) = τ
    η̈ₖ + 2ζₖΩₖ η̇ₖ + Ωₖ² ηₖ + δₖ · ω̇ = 0

with ``I`` the shared ``[body]`` table (the whole spacecraft, appendages
undeformed) and one ``[[flexible.mode]]`` table per cantilever mode::

    kind = "flexible"

    [body]
    moments = [2000.0, 1500.0, 3000.0]   # kg m^2

    [[flexible.mode]]
    frequency = 1.2566370614359172       # Ω, rad/s (0.2 Hz)
    damping = 0.003                      # ζ
    participation = [0.0, 0.0, 25.0]     # δ, kg^½ m, body axes

    [initial]
    omega = [0.0, 0.0, 0.0]              # rad/s, body axes
    eta = [0.0]                          # η, kg^½ m (default 0)
    eta_rate = [0.0]                     # dη/dt, kg^½ m/s (default 0)

The external torque on the hub is the shared ``[[torque]]`` list
(:mod:`tumble.scenario.torques`), e.g. a tabulated bang-bang slew.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated

import numpy as np
from pydantic import Field

from tumble import flexible
from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import _Number, _Table, _Vector
from tumble.scenario.tables import Body, Initial, Solver, Time
from tumble.scenario.torques import TabulatedTorque, Torque, build_torque
from tumble.simulate import simulate
from tumble.trajectory import Trajectory
from tumble.viz.flexible import slew_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["FlexibleScenario"]

# A run whose attitude keeps |q_x|, |q_y| below this is a rotation about body z, the axis of
# viz.flexible.slew_figure (a tilt ε changes the angle about z by O(ε²)).
_ABOUT_Z = 1e-9


class ModeTable(_Table):
    """One cantilever mode (:class:`tumble.flexible.Mode`): ``frequency`` Ω (rad/s), ``damping`` ζ,
    ``participation`` δ (kg^½ m, body axes)."""

    frequency: _Number
    damping: _Number = 0.0
    participation: _Vector

    def build(self) -> flexible.Mode:
        return flexible.Mode(self.frequency, self.damping, np.array(self.participation))


class FlexibleTable(_Table):
    """``[flexible]``: the modes of the appendages, one ``[[flexible.mode]]`` table each."""

    mode: Annotated[list[ModeTable], Field(min_length=1)]


class FlexibleInitial(Initial):
    """``[initial]``: ``omega``, ``q`` or ``euler`` of the hub as in every kind, plus the modal coordinates
    ``eta`` (kg^½ m) and rates ``eta_rate`` (kg^½ m/s), one per mode (default zero)."""

    eta: list[_Number] | None = None
    eta_rate: list[_Number] | None = None


class FlexibleScenario(Scenario):
    """A validated scenario of a hub with flexible appendages (``kind = "flexible"``, or a ``[flexible]`` table)."""

    body: Body
    flexible: FlexibleTable
    initial: FlexibleInitial
    time: Time
    solver: Solver = Solver()
    torque: list[Torque] = []

    def build(self) -> Run:
        """The :class:`~tumble.flexible.FlexibleBody`, its initial state and torque; a refusal names the key."""
        with in_file(self.source):
            with keyed(self.body.argument_keys("body"), "body"):
                body = self.body.build()
            modes = []
            for i, mode in enumerate(self.flexible.mode):
                with keyed(mode.argument_keys(f"flexible.mode[{i}]"), f"flexible.mode[{i}]"):
                    modes.append(mode.build())
            with keyed({"modes": "flexible.mode"}, "flexible"):
                model = flexible.FlexibleBody(body, tuple(modes))
            torque = build_torque(self.torque, body)
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS}
            with keyed(keys, "initial"):
                initial = self.initial.state()
            return Run(model, initial, self.time.times(), self.solver.method, self.solver.options(), torque, keys,
                       self.source)

    def figure(self, traj: Trajectory) -> Figure:
        """:func:`tumble.viz.flexible.slew_figure` for a rotation about body z (the figure's slew axis), else
        :meth:`tumble.Trajectory.plot`.

        The slew figure compares the hub with the rigid body ``[body]`` under the same torque and
        solver, and shows the pointing error, from the rigid body's final angle, after the last
        sample time of the tabulated torques (the end of the manoeuvre; the start without one).
        """
        assert traj.q is not None  # the hub's attitude
        if np.abs(traj.q[:, 1:3]).max() > _ABOUT_Z:
            return traj.plot(title=self.name)
        run = self.build()
        assert isinstance(run.model, flexible.FlexibleBody)
        rigid = simulate(run.model.body, t=run.t, method=run.method, torque=run.torque,
                         omega0=run.initial["omega0"], q0=run.initial["q0"], **run.options)
        ends = [entry.times[-1] for entry in self.torque if isinstance(entry, TabulatedTorque)]
        end = float(np.clip(max(ends, default=traj.t[0]), traj.t[0], traj.t[-1]))
        assert rigid.q is not None
        figure = slew_figure(traj, rigid, end, float(flexible.slew_angle(rigid.q[-1])))
        if self.name:
            figure.suptitle(self.name)
        return figure

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """The largest and the final modal amplitude of each mode."""
        eta = np.abs(traj.modal_coordinate)
        text = "; ".join(f"{k + 1}: peak {eta[:, k].max():.3g}, final {eta[-1, k]:.3g}" for k in range(eta.shape[1]))
        return [("modes", f"|eta| (kg^1/2 m) of mode {text}")]
