"""What ``tumble warmup`` compiles: the paths a first session takes, each run once so Numba caches them.

tumble's kernels are compiled by Numba on their first call and cached on
disk (``__pycache__`` beside the source, or ``NUMBA_CACHE_DIR``), one
compiled version per model type and integration method. A first call
therefore spends seconds compiling; every later process loads the cached
code in milliseconds. ``tumble warmup`` (or ``python -m tumble warmup``)
makes those first calls at install time instead: each path below runs a
tiny simulation (a few steps) of the kind a first session runs — the
quick-start demo, one body under every method, a batch, a heavy top.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from tumble.simulate import SolverOptions

__all__ = ["PATHS"]

_OMEGA0 = np.array([0.1, 1.0, 0.1])  # rad/s
_T = np.array([0.0, 0.02, 0.04])  # s: a few steps
_ONE_BODY = ("dop853", "rk4", "cf4", "splitting2", "splitting4", "exact_split2", "exact_split4", "exact")


def _simulate(method: str, *, members: int = 1, torque=None) -> Callable[[], None]:
    """A path: ``simulate`` of a rigid body (or ``members`` of them) under ``method``, with ``torque``."""

    def run() -> None:
        import tumble

        body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
        omega0 = _OMEGA0 if members == 1 else np.tile(_OMEGA0, (members, 1))
        options: SolverOptions = ({"rtol": 1e-10, "atol": 1e-12} if method == "dop853" else {} if method == "exact"
                                  else {"dt": 0.01})
        tumble.simulate(body, omega0, t=_T, method=method, torque=torque() if torque else None, **options)

    return run


def _heavy_top():
    """The heavy-top torque of the paths: 1 kg, centre of mass 0.1 m along body z from the pivot, standard
    gravity along −z inertial (:class:`tumble.torques.Gravity`)."""
    from tumble import torques

    return torques.Gravity(1.0, [0.0, 0.0, 0.1])


def _racket() -> None:
    """The quick start's ``tumble demo racket``: the T-handle under dop853, with a progress callback."""
    import tumble

    body = tumble.RigidBody.t_handle()
    tumble.simulate(body, body.axes @ _OMEGA0, t=_T, method="dop853", rtol=1e-12, atol=1e-12,
                    progress=lambda done, total: None)


#: name -> the call that compiles it, in the order ``tumble warmup`` runs them.
PATHS: dict[str, Callable[[], None]] = {
    "demo racket": _racket,
    **{f"one body, {method}": _simulate(method) for method in _ONE_BODY},
    "a batch, rk4": _simulate("rk4", members=2),
    "a batch, dop853": _simulate("dop853", members=2),
    "heavy top, rk4": _simulate("rk4", torque=_heavy_top),
    "heavy top, dop853": _simulate("dop853", torque=_heavy_top),
}
