"""Statistics of a large batch of bodies, streamed: memory bounded by a chunk, not by the batch.

A Monte-Carlo dispersion of a million bodies sampled at a hundred times would
need 5.6 GB for ``q`` and ``omega`` alone. :func:`ensemble_statistics` runs the
batch in chunks of ``chunk`` bodies with the sweeps' chunker
(:mod:`tumble.sweeps.chunks`; each chunk in parallel over the cores, as
:func:`tumble.simulate`), reduces every chunk to per-time statistics of the
quantities asked for, and merges the chunks' statistics exactly with Chan,
Golub & LeVeque's pairwise update (:mod:`tumble.sweeps.moments`). The result
does not depend on the chunk size beyond rounding, and the memory is that of
one chunk.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array
from tumble.rigid_body import RigidBody
from tumble.simulate import as_model
from tumble.sweeps.chunks import SAMPLES_PER_CHUNK, Chunks, batch_members, simulate_chunks
from tumble.sweeps.moments import STATISTICS, merge, moments, summary
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    import xarray

__all__ = ["ensemble_statistics", "DEFAULT_QUANTITIES", "LEAST_PER_CHUNK", "SAMPLES_PER_CHUNK", "STATISTICS"]

#: The fewest bodies in a chunk by default, so that a chunk of a long series still fills the cores.
LEAST_PER_CHUNK = 1024


def _omega(traj: Trajectory) -> np.ndarray:
    """The body rates of a chunk of rigid bodies (which have an attitude), rad/s, body axes."""
    assert traj.omega is not None
    return traj.omega


#: Quantities reduced by default: name -> (function of a chunk's Trajectory, units, description).
DEFAULT_QUANTITIES: dict[str, tuple[Callable[[Trajectory], np.ndarray], str, str]] = {
    "omega": (_omega, "rad/s", "angular velocity, body axes"),
    "energy_drift": (lambda traj: traj.energy_drift, "1", "(T - T0)/T0"),
    "momentum_norm_drift": (lambda traj: traj.momentum_norm_drift, "1", "(|L| - |L0|)/|L0|"),
    "momentum_inertial_drift": (lambda traj: traj.momentum_inertial_drift, "1", "|L_I - L_I0|/|L_I0|"),
}


def ensemble_statistics(
    body: RigidBody | Sequence[RigidBody] | ArrayLike,
    omega0: ArrayLike,
    *,
    t: ArrayLike,
    q0: ArrayLike | None = None,
    quantities: Mapping[str, Callable[[Trajectory], np.ndarray]] | None = None,
    chunk: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    **options: Any,
) -> xarray.Dataset:
    """Per-time mean, standard deviation, minimum and maximum over a batch of bodies, streamed by chunks.

    Parameters
    ----------
    body : RigidBody (shared), a sequence of N RigidBody, or a (3, 3) / (N, 3, 3) inertia array (kg·m²)
    omega0 : (N, 3) array_like
        Initial body rates, rad/s, body axes: their leading axis is the batch.
    t : (n,) array_like
        Output times, s.
    q0 : (4,) or (N, 4) array_like, optional
        Initial attitudes, body → inertial (default identity).
    quantities : mapping name -> ``f(traj) -> array (n, c, ...)``, optional
        What to reduce, computed on each chunk's :class:`~tumble.Trajectory`
        (``c`` bodies); default :data:`DEFAULT_QUANTITIES` (``omega`` and the
        drifts of energy and momentum).
    chunk : int, optional
        Bodies per chunk; the peak memory is about that of a
        :func:`~tumble.simulate` of ``chunk`` bodies, some 400 bytes per body
        and output time. Default:
        :data:`~tumble.sweeps.chunks.SAMPLES_PER_CHUNK` ``// len(t)`` (at
        least :data:`LEAST_PER_CHUNK`), about 200 MB.
    progress : callable ``progress(done, total)``, optional
        Called after each chunk with the number of bodies done.
    **options
        Passed to :func:`tumble.simulate` (``method``, ``dt``, ``rtol``,
        ``atol``, ``torque``, ...).

    Returns
    -------
    xarray.Dataset
        One variable per quantity, dimensions ``(time, statistic, ...)`` with
        ``statistic`` = ``mean``, ``std`` (population, ``ddof = 0``), ``min``,
        ``max``; attribute ``bodies`` = N.
    """
    import xarray as xr

    omega0 = as_array(omega0, "omega0", tail=(3,))
    if omega0.ndim != 2:
        raise ValidationError(f"omega0: must have shape (N, 3) (one rate per body), got {omega0.shape}")
    model = as_model(body)
    state = {"omega0": omega0} if q0 is None else {"omega0": omega0, "q0": as_array(q0, "q0", tail=(4,))}
    n_bodies = batch_members(model, state)
    chunks = Chunks.of(n_bodies, chunk, n_times=np.size(t), least=LEAST_PER_CHUNK)
    funcs = {name: f for name, (f, _, _) in DEFAULT_QUANTITIES.items()} if quantities is None else dict(quantities)
    if not funcs:
        raise ValidationError("quantities: give at least one quantity to reduce")

    stats: dict[str, list[np.ndarray]] = {}  # name -> [count, mean, M2, min, max]
    for lo, hi, traj in simulate_chunks(model, chunks, t=t, initial_state=state, **options):
        for name, f in funcs.items():
            values = np.asarray(f(traj), dtype=np.float64)
            if values.ndim < 2 or values.shape[:2] != (len(traj), hi - lo):
                raise ValidationError(f"quantities[{name!r}]: must return an array (n_times, bodies, ...) = "
                                      f"({len(traj)}, {hi - lo}, ...), got shape {values.shape}")
            part = moments(values)
            stats[name] = part if name not in stats else merge(stats[name], part)
        if progress is not None:
            progress(hi, n_bodies)

    times = traj.t
    data_vars = {}
    for name, merged in stats.items():
        _, units, description = DEFAULT_QUANTITIES.get(name, (None, "", ""))
        values = np.stack(summary(merged), axis=1)
        extra_dims = tuple(f"{name}_dim{k}" for k in range(values.ndim - 2))
        if name == "omega":
            extra_dims = ("axis",)
        data_vars[name] = (("time", "statistic") + extra_dims, values,
                           {"units": units, "description": description})
    return xr.Dataset(data_vars, coords={"time": ("time", times, {"units": "s"}), "statistic": list(STATISTICS)},
                      attrs={"bodies": n_bodies})

