"""Statistics of a large batch of bodies, streamed: memory bounded by a chunk, not by the batch.

A Monte-Carlo dispersion of a million bodies sampled at a hundred times would
need 5.6 GB for ``q`` and ``omega`` alone. :func:`ensemble_statistics` runs the
batch in chunks of ``chunk`` bodies (each chunk in parallel over the cores, as
:func:`tumble.simulate`), reduces every chunk to per-time statistics of the
quantities asked for, and merges the chunks' statistics exactly:

    n = n_a + n_b,   δ = x̄_b − x̄_a,   x̄ = x̄_a + δ n_b/n,
    M₂ = M₂,a + M₂,b + δ² n_a n_b / n           (σ² = M₂ / n)

(T. F. Chan, G. H. Golub & R. J. LeVeque, "Updating formulae and a pairwise
algorithm for computing sample variances", Stanford CS report 79-773, 1979),
with the minimum and maximum merged directly. The result does not depend on
the chunk size beyond rounding, and the memory is that of one chunk.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array
from tumble.body import RigidBody
from tumble.simulate import simulate
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    import xarray

__all__ = ["ensemble_statistics", "DEFAULT_QUANTITIES", "SAMPLES_PER_CHUNK", "STATISTICS"]

#: Default chunk size in body-samples (bodies × output times): states, trajectory and statistics of a chunk
#: take about 400 bytes per body-sample, so about 200 MB.
SAMPLES_PER_CHUNK = 2**19

#: The statistics computed for every quantity, in the order of the ``statistic`` dimension.
STATISTICS = ("mean", "std", "min", "max")


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
        and output time. Default: :data:`SAMPLES_PER_CHUNK` ``// len(t)``
        (at least 1024), about 200 MB.
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
    n_bodies = omega0.shape[0]
    if chunk is None:
        chunk = max(1024, SAMPLES_PER_CHUNK // max(1, np.size(t)))
    if int(chunk) < 1:
        raise ValidationError(f"chunk: must be >= 1 body, got {chunk}")
    chunk = int(chunk)
    take_body = _slicer(body, n_bodies, "body", (3, 3), RigidBody)
    take_q0 = None if q0 is None else _slicer(as_array(q0, "q0", tail=(4,)), n_bodies, "q0", (4,))
    funcs = {name: f for name, (f, _, _) in DEFAULT_QUANTITIES.items()} if quantities is None else dict(quantities)
    if not funcs:
        raise ValidationError("quantities: give at least one quantity to reduce")

    stats: dict[str, list[np.ndarray]] = {}  # name -> [count, mean, M2, min, max]
    for lo in range(0, n_bodies, chunk):
        hi = min(n_bodies, lo + chunk)
        traj = simulate(take_body(lo, hi), omega0[lo:hi], t=t, q0=None if take_q0 is None else take_q0(lo, hi),
                        **options)
        for name, f in funcs.items():
            values = np.asarray(f(traj), dtype=np.float64)
            if values.ndim < 2 or values.shape[:2] != (len(traj), hi - lo):
                raise ValidationError(f"quantities[{name!r}]: must return an array (n_times, bodies, ...) = "
                                      f"({len(traj)}, {hi - lo}, ...), got shape {values.shape}")
            part = moments(values)
            stats[name] = part if name not in stats else _merge(stats[name], part)
        if progress is not None:
            progress(hi, n_bodies)

    times = traj.t
    data_vars = {}
    for name, (count, mean, m2, low, high) in stats.items():
        _, units, description = DEFAULT_QUANTITIES.get(name, (None, "", ""))
        values = np.stack([mean, np.sqrt(m2 / count), low, high], axis=1)
        extra_dims = tuple(f"{name}_dim{k}" for k in range(values.ndim - 2))
        if name == "omega":
            extra_dims = ("axis",)
        data_vars[name] = (("time", "statistic") + extra_dims, values,
                           {"units": units, "description": description})
    return xr.Dataset(data_vars, coords={"time": ("time", times, {"units": "s"}), "statistic": list(STATISTICS)},
                      attrs={"bodies": n_bodies})


def moments(values: np.ndarray) -> list[np.ndarray]:
    """Statistics ``[count, mean, M₂, min, max]`` of ``values`` (n_times, members, ...) over the members
    (axis 1), ``M₂ = Σ (x − x̄)²``: one chunk's part, merged with :func:`_merge`."""
    mean = values.mean(axis=1)
    return [np.full(values.shape[:1] + values.shape[2:], float(values.shape[1])), mean,
            ((values - mean[:, None]) ** 2).sum(axis=1), values.min(axis=1), values.max(axis=1)]


def _merge(a: list[np.ndarray], b: list[np.ndarray]) -> list[np.ndarray]:
    """Statistics ``[count, mean, M₂, min, max]`` of the union of two disjoint samples (Chan et al. 1979)."""
    n_a, mean_a, m2_a, low_a, high_a = a
    n_b, mean_b, m2_b, low_b, high_b = b
    n = n_a + n_b
    delta = mean_b - mean_a
    return [n, mean_a + delta * (n_b / n), m2_a + m2_b + delta * delta * (n_a * n_b / n),
            np.minimum(low_a, low_b), np.maximum(high_a, high_b)]


def _slicer(value, n_bodies: int, name: str, tail: tuple[int, ...], single_type=None):
    """``take(lo, hi)``: the members ``lo:hi`` of a per-body argument, or the shared value itself."""
    if single_type is not None and isinstance(value, single_type):
        return lambda lo, hi: value
    if single_type is not None and isinstance(value, Sequence) and value and isinstance(value[0], single_type):
        if len(value) != n_bodies:
            raise ValidationError(f"{name}: {len(value)} bodies for a batch of {n_bodies} (omega0)")
        return lambda lo, hi: list(value[lo:hi])
    arr = as_array(value, name, tail=tail)
    if arr.ndim == len(tail):
        return lambda lo, hi: arr
    if arr.ndim != len(tail) + 1 or arr.shape[0] != n_bodies:
        raise ValidationError(f"{name}: must have shape {tail} or ({n_bodies}, {', '.join(map(str, tail))}) "
                              f"to match omega0, got {arr.shape}")
    return lambda lo, hi: arr[lo:hi]
