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
  multiply–adds), which ``tests/test_sweep_device.py`` bounds.
* :func:`percentiles`: exact, bit for bit those of ``numpy.percentile`` (or,
  with ``ignore_nan``, ``numpy.nanpercentile``; method ``"linear"``). Each
  column is sorted on the device (a bitonic sorting network over the column
  padded with NaN to a power of two, NaN sorting last: K. E. Batcher, "Sorting
  networks and their applications", AFIPS 1968), the two order statistics
  around each percentile are gathered there, and only they come back: the
  host interpolates them with NumPy's own arithmetic, index
  ``v = (n − 1) p/100``, ``x = a + (b − a) γ`` (``b − (b − a)(1 − γ)`` for
  ``γ ≥ 0.5``), ``γ = v − ⌊v⌋``, so no fused multiply–add enters.

Import this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from numba import cuda

from tumble.integrate._cuda import THREADS_PER_BLOCK, on_device
from tumble.sweeps.moments import merge

__all__ = ["BLOCK", "moments", "percentiles"]

#: Samples per thread in :func:`moments`: a column of 10⁶ samples is summed by 245 threads.
BLOCK = 4096


def _launch(n: int) -> tuple[int, int]:
    return max(1, math.ceil(n / THREADS_PER_BLOCK)), THREADS_PER_BLOCK


@cuda.jit(cache=True)
def _block_moments_kernel(values, block, parts):
    """Thread ``(k, c)``: ``parts[k, :, c] = [n, x̄, M₂, min, max]`` of the rows ``k·block`` … of column ``c``
    (a NaN is the minimum and the maximum of a block that holds one, as NumPy's ``min`` and ``max`` say)."""
    index = cuda.grid(1)
    columns = values.shape[1]
    k, c = index // columns, index % columns
    lo = k * block
    if lo >= values.shape[0]:
        return
    hi = min(values.shape[0], lo + block)
    total = 0.0
    for r in range(lo, hi):
        total += values[r, c]
    n = hi - lo
    mean = total / n
    m2 = 0.0
    low = high = values[lo, c]
    for r in range(lo, hi):
        x = values[r, c]
        d = x - mean
        m2 += d * d
        if x < low or x != x:
            low = x if low == low else low
        if x > high or x != x:
            high = x if high == high else high
    parts[k, 0, c], parts[k, 1, c], parts[k, 2, c], parts[k, 3, c], parts[k, 4, c] = n, mean, m2, low, high


def moments(values: ArrayLike) -> list[np.ndarray]:
    """Statistics ``[count, mean, M₂, min, max]`` (each (m,)) of ``values`` (S, m) over the samples (axis 0),
    ``M₂ = Σ (x − x̄)²``, reduced on the GPU (see the module docstring)."""
    table = on_device(values)
    samples, columns = table.shape
    blocks = math.ceil(samples / BLOCK)
    parts = cuda.device_array((blocks, 5, columns))
    _block_moments_kernel[_launch(blocks * columns)](table, BLOCK, parts)
    host = parts.copy_to_host()
    stats = list(host[0])
    for k in range(1, blocks):
        stats = merge(stats, list(host[k]))
    return stats


@cuda.jit(cache=True)
def _bitonic_kernel(keys, j, k):
    """One stage ``(k, j)`` of a bitonic sorting network on each row of ``keys`` (rows of a power-of-two
    length): element ``i`` and its partner ``i ⊕ j`` are put in order, ascending where ``i & k == 0`` and
    descending elsewhere. NaN sorts after every number."""
    index = cuda.grid(1)
    length = keys.shape[1]
    row, i = index // length, index % length
    if row >= keys.shape[0]:
        return
    partner = i ^ j
    if partner <= i:
        return
    a, b = keys[row, i], keys[row, partner]
    a_after_b = a > b or (a != a and b == b)
    b_after_a = b > a or (b != b and a == a)
    if (a_after_b if (i & k) == 0 else b_after_a):
        keys[row, i], keys[row, partner] = b, a


@cuda.jit(cache=True)
def _count_kernel(keys, count):
    """Thread ``c``: ``count[c]``, the numbers (not NaN) of the sorted row ``c``, by bisection (NaN last)."""
    c = cuda.grid(1)
    if c >= keys.shape[0]:
        return
    lo, hi = 0, keys.shape[1]
    while lo < hi:
        mid = (lo + hi) // 2
        if keys[c, mid] == keys[c, mid]:
            lo = mid + 1
        else:
            hi = mid
    count[c] = lo


@cuda.jit(cache=True)
def _gather_kernel(keys, previous, following, out):
    """Thread ``(p, c)``: ``out[0, p, c] = keys[c, previous[p, c]]``, ``out[1, p, c] = keys[c, following[p, c]]``."""
    index = cuda.grid(1)
    columns = keys.shape[0]
    p, c = index // columns, index % columns
    if p >= previous.shape[0]:
        return
    out[0, p, c] = keys[c, previous[p, c]]
    out[1, p, c] = keys[c, following[p, c]]


def sorted_columns(values: ArrayLike) -> Any:
    """The columns of ``values`` (S, m) sorted ascending on the GPU, as rows of a device array (m, 2^⌈log₂ S⌉)
    padded with NaN (NaN sorts last)."""
    host = np.asarray(values, dtype=np.float64)
    samples, columns = host.shape
    length = 1 << max(0, (samples - 1).bit_length())
    padded = np.full((columns, length), np.nan)
    padded[:, :samples] = host.T
    keys = cuda.to_device(padded)
    k = 2
    while k <= length:
        j = k // 2
        while j >= 1:
            _bitonic_kernel[_launch(columns * length)](keys, j, k)
            j //= 2
        k *= 2
    return keys


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
    count = cuda.device_array(columns, dtype=np.int64)
    _count_kernel[_launch(columns)](keys, count)
    n = count.copy_to_host()
    samples = np.shape(values)[0]
    previous, following, gamma = _linear_indices(n if ignore_nan else np.full(columns, samples), q)
    ends = cuda.device_array((2, q.size, columns))
    _gather_kernel[_launch(q.size * columns)](keys, cuda.to_device(previous), cuda.to_device(following), ends)
    a, b = ends.copy_to_host()
    diff = b - a
    out = np.where(gamma >= 0.5, b - diff * (1 - gamma), a + diff * gamma)
    out[:, (n == 0) if ignore_nan else (n < samples)] = np.nan
    return out
