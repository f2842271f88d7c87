"""A scenario turned into one call of the front door, :func:`tumble.simulate`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble.scenario._errors import in_file, keyed
from tumble.simulate import Model, SolverOptions, simulate
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from tumble.rigid_body import RigidBody

__all__ = ["RUN_KEYS", "Run"]

#: Where the arguments of a run come from in a scenario file, besides the initial state (key x → x0).
RUN_KEYS = {"t": "time", "method": "solver.method", "rtol": "solver.rtol", "atol": "solver.atol",
            "dt": "solver.dt", "torque": "torque"}


@dataclass(frozen=True)
class Run:
    """The arguments of ``tumble.simulate(model, t=t, method=method, torque=torque, **initial, **options)``.

    model   : the tumble model (:class:`tumble.model.Model`), or a :class:`~tumble.RigidBody`, which
              :func:`tumble.simulate` turns into its model
    initial : its initial state by name (the keywords of :meth:`~tumble.simulate.Model.state_fields`)
    t       : output times, s
    method  : integration method; ``options`` the solver options the file gives (``rtol``, ``atol``, ``dt``)
    torque  : what ``model.torque`` means (a torque model on a hub, joint torques of a robot), or None
    keys    : argument → scenario key, so that an argument the library refuses is reported against its key
    source  : the scenario file, for messages
    """

    model: Model | RigidBody
    initial: dict[str, Any]  # array_like values; keyword arguments of simulate, so typed as its **initial_state
    t: np.ndarray
    method: str
    options: SolverOptions
    torque: Any = None
    keys: dict[str, str] = field(default_factory=dict)
    source: str = "<scenario>"

    def simulate(self, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
        """Run :func:`tumble.simulate`; an argument it refuses is reported against its scenario key."""
        with in_file(self.source), keyed(self.keys, ""):
            return simulate(self.model, t=self.t, method=self.method, torque=self.torque, progress=progress,
                            **self.initial, **self.options)
