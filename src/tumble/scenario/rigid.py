"""Scenario kind ``"rigid"``: a rigid body under external torques, optionally with a nutation damper.

Tables: ``[body]``, ``[initial]``, ``[time]``, ``[solver]`` (shared,
:mod:`tumble.scenario.tables`), ``[[torque]]`` (:mod:`tumble.scenario.torques`)
and ``[damper]``: a spherical viscous damper inside the body
(:mod:`tumble.spacecraft.damper`), ``[body]`` then being the hub without the
sphere. The body is a :class:`tumble.RigidBody` simulated by
:func:`tumble.simulate` (Euler's equations ``I ω̇ + ω × (I ω) = τ``, body axes).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble import torques
from tumble.rigid_body import RigidBody
from tumble.scenario._base import Scenario
from tumble.scenario._errors import in_file, keyed
from tumble.scenario._run import Run
from tumble.scenario._values import _Vector
from tumble.scenario.damper import SphericalDamperTable
from tumble.scenario.tables import Body, Initial, Solver, Time
from tumble.scenario.torques import Torque, build_torque
from tumble.simulate import SolverOptions, simulate
from tumble.spacecraft import Spacecraft, SphericalDamper
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["DamperTable", "Problem", "RigidScenario"]


class DamperTable(SphericalDamperTable):
    """``[damper]``: a spherical viscous nutation damper in the body (:mod:`tumble.scenario.damper`): sphere
    ``inertia`` J (kg m²), ``damping`` c (N m s), initial sphere rate ``omega`` (rad/s, body axes; default:
    the body's)."""

    omega: _Vector | None = None


# Where the arguments of a run come from in the file (those of the tables' own builds aside).
_RUN_KEYS = {
    "omega0": "initial.omega", "q0": "initial", "t": "time", "method": "solver.method", "rtol": "solver.rtol",
    "atol": "solver.atol", "dt": "solver.dt", "torque": "torque", "damper_omega0": "damper.omega",
}


@dataclass(frozen=True)
class Problem:
    """A rigid-body scenario turned into the arguments of :func:`tumble.simulate`.

    ``body`` the :class:`~tumble.RigidBody` (with a damper: the hub without
    the sphere); ``omega0`` rad/s in body axes; ``q0`` unit quaternion
    ``[w, x, y, z]``, body → inertial; ``t`` output times, s; ``options`` the
    solver options given in the file (``rtol``, ``atol``, ``dt``); ``torque``
    a torque model or ``None`` (torque-free); ``source`` the file, for error
    messages; ``damper`` a nutation damper in the body and ``damper_omega0``
    its initial rate (rad/s, body axes; ``None``: the body's), or ``None``.
    """

    body: RigidBody
    omega0: np.ndarray
    q0: np.ndarray
    t: np.ndarray
    method: str
    options: SolverOptions
    torque: torques.TorqueModel | None
    source: str = "<scenario>"
    damper: SphericalDamper | None = None
    damper_omega0: np.ndarray | None = None

    @property
    def model(self) -> RigidBody | Spacecraft:
        """The tumble model: the body, or with a damper the spacecraft of hub and damper."""
        if self.damper is None:
            return self.body
        return Spacecraft(hub=self.body, damper=self.damper)

    def as_run(self) -> Run:
        """The same arguments as a :class:`~tumble.scenario.Run` (what a sweep of the scenario reads)."""
        damper = {} if self.damper_omega0 is None else {"damper_omega0": self.damper_omega0}
        return Run(model=self.model, initial={"omega0": self.omega0, "q0": self.q0, **damper}, t=self.t,
                   method=self.method, options=self.options, torque=self.torque, keys=_RUN_KEYS, source=self.source)

    def simulate(self, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
        """Run :func:`tumble.simulate`; an argument it refuses is reported against its scenario key."""
        damper: dict[str, Any] = {} if self.damper_omega0 is None else {"damper_omega0": self.damper_omega0}
        with in_file(self.source), keyed(_RUN_KEYS, ""):
            return simulate(self.model, t=self.t, method=self.method, torque=self.torque, progress=progress,
                            omega0=self.omega0, q0=self.q0, **damper, **self.options)


class RigidScenario(Scenario):
    """A validated rigid-body scenario (``kind = "rigid"``, the default); :meth:`build` makes the
    simulation's inputs, :meth:`run` simulates it."""

    body: Body
    initial: Initial
    time: Time
    solver: Solver = Solver()
    torque: list[Torque] = []
    damper: DamperTable | None = None

    def build(self) -> Problem:
        """Build the body, initial state, times, torque model and damper.

        Raises :class:`~tumble.scenario.ScenarioError` naming the key behind
        any argument the library refuses (e.g. ``body.moments`` for moments
        that break the triangle inequality).
        """
        with in_file(self.source):
            with keyed(self.body.argument_keys("body"), "body"):
                body = self.body.build()
            with keyed(self.initial.argument_keys("initial"), "initial"):
                state = self.initial.state()
            torque = build_torque(self.torque, body)
            damper, damper_omega0 = None, None
            if self.damper is not None:
                with keyed(self.damper.argument_keys("damper"), "damper"):
                    damper = self.damper.build()
                damper_omega0 = None if self.damper.omega is None else np.array(self.damper.omega)
            return Problem(body=body, omega0=state["omega0"], q0=state["q0"], t=self.time.times(),
                           method=self.solver.method, options=self.solver.options(), torque=torque,
                           source=self.source, damper=damper, damper_omega0=damper_omega0)

    def figure(self, traj: Trajectory) -> Figure:
        """:meth:`tumble.Trajectory.plot` of the run, titled with the scenario's name."""
        return traj.plot(title=self.name)
