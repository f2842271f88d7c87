"""A sweep's reductions on the GPU: per-column moments, extremes and exact percentiles over the samples.

The values are a table (S, m): S samples (rows), m columns (the output times of
a series, or the components of an outcome). ``tumble.sweep(..., device="cuda")``
reduces its series and outcomes here when it writes the store
(:meth:`tumble.sweeps.store.SweepStore.finalize`).

* :func:`moments`: ``[count, mean, M₂, min, max]`` per column, as
  :func:`tumble.sweeps.moments.moments` gives them. One thread per column and
  block of :data:`BLOCK` samples sums its block in order (``x̄ = Σx / n``, then
  ``M₂ = Σ (x − x̄)²``); the blocks' parts are merged on the host in block order
  by :func:`tumble.sweeps.moments.merge` (Chan, Golub & LeVeque 1979), so the
  result does not depend on the launch. The minimum and maximum are exact; the
  mean and ``M₂`` differ from NumPy's (pairwise summation) by rounding only:
  a few units in the last place times ``log₂ S`` (and a GPU fuses
  multiply–adds), which ``tests/sweeps/test_sweep_device.py`` bounds.
* :func:`percentiles`: exact, bit for bit those of ``numpy.percentile`` (or,
  with ``ignore_nan``, ``numpy.nanpercentile``; method ``"linear"``). Each
  column is sorted on the device (a bitonic sorting network over the column
  padded with NaN to a power of two, NaN sorting last: K. E. Batcher, "Sorting
  networks and their applications", AFIPS 1968), the two order statistics
  around each percentile are gathered there, and only they come back: the
  host interpolates them with NumPy's own arithmetic, index
  ``v = (n − 1) p/100``, ``x = a + (b − a) γ`` (``b − (b − a)(1 − γ)`` for
  ``γ ≥ 0.5``), ``γ = v − ⌊v⌋``, so no fused multiply–add enters.

A chunk's own series and outcomes are evaluated here too, where its results
stay on the GPU (``simulate(..., output="device")``: a chunk of rigid bodies,
or the ``q`` and ``omega`` of a chunk of spacecraft, flexible, slosh, fluid or
variable bodies):
:func:`series` and :func:`outcome` evaluate the built-ins of
:mod:`tumble.sweeps.outcomes` there, so that only their values (a series'
table, an outcome's value per sample) come back, not the trajectories. They
return None for what the host evaluates, from a copy of the results: a Python
function, a :class:`~tumble.sweeps.outcomes.Component` of another field than
``q``, ``omega``, ``momentum_body`` and ``energy``, or one whose ``index``
(or a :class:`~tumble.sweeps.outcomes.Max` whose ``after``) the host refuses
with its message, and what reads the angular momentum or the energy of a model
other than a rigid body (a spacecraft's includes its wheels'): its totals are
made on the host (:attr:`tumble.Trajectory.rest_on_host`).

The device work is :mod:`tumble.integrate._cuda_reductions`'s; this module merges and interpolates on the
host. Import it only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tumble.integrate._cuda import on_device
from tumble.integrate._cuda_reductions import (block_moments, component_kernel, crossing_kernel, energy_kernel, gather,
                                               max_kernel, momentum_kernel, numbers_in_rows, nutation_kernel,
                                               per_sample, pointing_kernel, series_table, settling_kernel,
                                               sorted_columns)
from tumble.sweeps.moments import merge
from tumble.sweeps.outcomes import Component, CrossingTime, Final, Max, NutationAngle, PointingError, SettlingTime
from tumble.trajectory import Trajectory

__all__ = ["BLOCK", "moments", "outcome", "percentiles", "series"]

#: Samples per thread in :func:`moments`: a column of 10⁶ samples is summed by 245 threads.
BLOCK = 4096


def moments(values: ArrayLike) -> list[np.ndarray]:
    """Statistics ``[count, mean, M₂, min, max]`` (each (m,)) of ``values`` (S, m) over the samples (axis 0),
    ``M₂ = Σ (x − x̄)²``, reduced on the GPU (see the module docstring)."""
    host = block_moments(values, BLOCK)
    stats = list(host[0])
    for k in range(1, host.shape[0]):
        stats = merge(stats, list(host[k]))
    return stats


def _linear_indices(n: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """NumPy's ``"linear"`` method: per fraction ``q`` (P,) and count ``n`` (m,), the previous and next
    order statistics (P, m) and the weight ``γ`` (P, m): ``v = (n − 1) q``, previous ``⌊v⌋``, next ``⌊v⌋ + 1``,
    both the last where ``v ≥ n − 1``; ``γ = v − previous`` (the last's index counted as −1, as NumPy does)."""
    virtual = (n[None, :] - 1) * q[:, None]
    previous = np.floor(virtual)
    following = previous + 1
    last = virtual >= n[None, :] - 1
    previous[last] = following[last] = -1
    gamma = virtual - previous
    ends = np.broadcast_to(np.maximum(n - 1, 0)[None, :], previous.shape)
    previous = np.where(previous < 0, ends, previous).astype(np.intp)
    following = np.where(following < 0, ends, following).astype(np.intp)
    return previous, following, gamma


def percentiles(values: ArrayLike, p: ArrayLike, *, ignore_nan: bool = False) -> np.ndarray:
    """``numpy.percentile(values, p, axis=0)`` (or ``numpy.nanpercentile`` with ``ignore_nan``) of ``values``
    (S, m), (len(p), m), bit for bit, with the columns sorted on the GPU (see the module docstring). A column
    with a NaN gives NaN (without ``ignore_nan``); a column of NaN only, NaN."""
    q = np.true_divide(np.asarray(p, dtype=np.float64), 100)
    keys = sorted_columns(values)
    columns = keys.shape[0]
    n = numbers_in_rows(keys)
    samples = np.shape(values)[0]
    previous, following, gamma = _linear_indices(n if ignore_nan else np.full(columns, samples), q)
    a, b = gather(keys, previous, following)
    diff = b - a
    out = np.where(gamma >= 0.5, b - diff * (1 - gamma), a + diff * gamma)
    out[:, (n == 0) if ignore_nan else (n < samples)] = np.nan
    return out


def _samples(traj: Trajectory) -> tuple[int, int]:
    """The output times and samples ``(n, m)`` of a device trajectory."""
    q: Any = traj.q  # a device array
    return q.shape[0], q.shape[1]


def _inertia(traj: Trajectory) -> Any:
    """The inertia tensors of a device trajectory as (m or 1, 3, 3) (kg·m², body axes): one per sample, or the
    one they share."""
    inertia: Any = traj.inertia  # a device array
    return inertia if len(inertia.shape) == 3 else inertia.reshape((1, 3, 3))


def _component(f: Component, traj: Trajectory) -> Any:
    """A :class:`Component` of ``q``, ``omega``, ``momentum_body`` (``I ω``) or ``energy`` (``½ ω·Iω``) as a
    device table (n, m), or None: another field, an ``index`` the host refuses, or the momentum or energy
    of a model whose own totals are made on the host (:attr:`~tumble.Trajectory.rest_on_host`)."""
    n, m = _samples(traj)
    if f.name in ("energy", "momentum_body") and traj.rest_on_host:
        return None
    if f.name == "energy":
        return series_table(energy_kernel, n, m, traj.omega, _inertia(traj)) if f.index == () else None
    size = {"q": 4, "omega": 3, "momentum_body": 3}.get(f.name)
    if size is None or len(f.index) != 1 or not -size <= f.index[0] < size:
        return None
    i = f.index[0] % size
    if f.name == "momentum_body":
        return series_table(momentum_kernel, n, m, traj.omega, _inertia(traj), i)
    return series_table(component_kernel, n, m, getattr(traj, f.name), i)


def series(f: Any, traj: Trajectory) -> Any:
    """The series ``f`` (a built-in of :mod:`tumble.sweeps.outcomes`) of the device trajectory ``traj`` as a
    device table (n, m), evaluated on the GPU; None where the host evaluates it (the module docstring)."""
    n, m = _samples(traj)
    if isinstance(f, PointingError):
        return series_table(pointing_kernel, n, m, traj.q, *f.target)
    if isinstance(f, NutationAngle) and not traj.rest_on_host:  # L = I ω: a rigid body's
        axis = np.asarray(f.axis)
        axis = axis / np.linalg.norm(axis)  # as nutation_angle normalises it
        return series_table(nutation_kernel, n, m, traj.omega, _inertia(traj), *axis)
    if isinstance(f, Component):
        return _component(f, traj)
    return None


def outcome(f: Any, traj: Trajectory) -> np.ndarray | None:
    """The outcome ``f`` (a built-in reduction of a built-in series, :mod:`tumble.sweeps.outcomes`) of the device
    trajectory ``traj``, (m,), reduced on the GPU and copied back; None where the host evaluates it."""
    if not isinstance(f, (Final, Max, SettlingTime, CrossingTime)):
        return None
    first = 0
    if isinstance(f, Max):
        after = np.flatnonzero(traj.t >= f.after)  # the output times increase: a tail of them
        if not after.size:
            return None
        first = int(after[0])
    table = series(f.of, traj)
    if table is None:
        return None
    if isinstance(f, Final):
        return table[table.shape[0] - 1].copy_to_host()
    m = table.shape[1]
    if isinstance(f, Max):
        return per_sample(max_kernel, m, table, first)
    if isinstance(f, SettlingTime):
        return per_sample(settling_kernel, m, table, on_device(traj.t), float(f.below))
    return per_sample(crossing_kernel, m, table, on_device(traj.t), float(f.above))
