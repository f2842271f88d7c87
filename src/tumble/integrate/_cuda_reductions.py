"""The compiled CUDA kernels of a sweep's reductions on the GPU (:mod:`tumble.sweeps.device` launches them and
reads their results): per-block moments, a bitonic sorting network, the count of numbers in a sorted row, and
the gather of order statistics; and the built-in series and outcomes of :mod:`tumble.sweeps.outcomes` evaluated
on a chunk's results left on the GPU. Here, in a compiled layer, so that their code is in the cache's content
key (:mod:`tumble._cache`); the sweeps layer above compiles nothing.

The series are tables (n, m): output time ``k``, sample ``b``, one thread each, from the chunk's ``q`` (n, m, 4)
and ``omega`` (n, m, 3) (body axes) and its inertia (m or 1, 3, 3) (kg·m², body axes), with the host's
arithmetic, operation for operation: :func:`pointing_angle` that of :func:`tumble.attitude.relative_angle`,
:func:`nutation_kernel` that of :func:`tumble.spacecraft.damper.nutation_angle` over ``L = I ω``
(:func:`tumble.dynamics.angular_momentum`), :func:`energy_kernel` ``T = ½ Σᵢⱼ ωᵢ Iᵢⱼ ωⱼ``
(:func:`tumble.dynamics.kinetic_energy`, its terms in the order of NumPy's ``einsum``). The reductions of a
series over the output times run one thread per sample. On a GPU, NVVM fuses multiply–adds and libdevice
evaluates ``atan2`` and ``sqrt``: the results differ from the host's in the last bits (docs/gpu.md).

Import this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import cuda
from numba.extending import register_jitable
from numpy.typing import ArrayLike

from tumble._quat import qlog, qmul
from tumble.integrate._cuda import THREADS_PER_BLOCK, on_device

__all__ = ["bitonic_kernel", "block_moments", "block_moments_kernel", "component_kernel", "count_kernel",
           "crossing_kernel", "energy_kernel", "gather", "gather_kernel", "launch", "max_kernel", "momentum_kernel",
           "numbers_in_rows", "nutation_kernel", "per_sample", "pointing_angle", "pointing_kernel", "series_table",
           "settling_kernel", "sorted_columns"]


def launch(n: int) -> tuple[int, int]:
    """Blocks and threads per block of a launch over ``n`` threads."""
    return max(1, math.ceil(n / THREADS_PER_BLOCK)), THREADS_PER_BLOCK


@cuda.jit(cache=True)
def block_moments_kernel(values, block, parts):
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


@cuda.jit(cache=True)
def bitonic_kernel(keys, j, k):
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
def count_kernel(keys, count):
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
def gather_kernel(keys, previous, following, out):
    """Thread ``(p, c)``: ``out[0, p, c] = keys[c, previous[p, c]]``, ``out[1, p, c] = keys[c, following[p, c]]``."""
    index = cuda.grid(1)
    columns = keys.shape[0]
    p, c = index // columns, index % columns
    if p >= previous.shape[0]:
        return
    out[0, p, c] = keys[c, previous[p, c]]
    out[1, p, c] = keys[c, following[p, c]]


def block_moments(values: ArrayLike, block: int) -> np.ndarray:
    """``[n, x̄, M₂, min, max]`` (blocks, 5, m) of each block of ``block`` rows of each column of ``values``
    (S, m), summed on the GPU (:func:`block_moments_kernel`), copied to the host."""
    table = on_device(values)
    samples, columns = table.shape
    blocks = math.ceil(samples / block)
    parts = cuda.device_array((blocks, 5, columns))
    block_moments_kernel[launch(blocks * columns)](table, block, parts)
    return parts.copy_to_host()


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
            bitonic_kernel[launch(columns * length)](keys, j, k)
            j //= 2
        k *= 2
    return keys


def numbers_in_rows(keys: Any) -> np.ndarray:
    """The count of numbers (not NaN) of each sorted row of the device array ``keys`` (:func:`count_kernel`)."""
    count = cuda.device_array(keys.shape[0], dtype=np.int64)
    count_kernel[launch(keys.shape[0])](keys, count)
    return count.copy_to_host()


def gather(keys: Any, previous: np.ndarray, following: np.ndarray) -> np.ndarray:
    """``(a, b)`` (2, P, m): ``a[p, c] = keys[c, previous[p, c]]``, ``b[p, c] = keys[c, following[p, c]]``,
    gathered on the GPU (:func:`gather_kernel`) and copied to the host."""
    ends = cuda.device_array((2,) + previous.shape)
    gather_kernel[launch(previous.size)](keys, cuda.to_device(previous), cuda.to_device(following), ends)
    return ends.copy_to_host()


# -- the built-in series and outcomes of tumble.sweeps.outcomes on a chunk's device arrays ---------------------


@register_jitable
def pointing_angle(tw, tx, ty, tz, qw, qx, qy, qz):
    """The angle θ ∈ [0, π] (rad) of ``t* ⊗ q``, as :func:`tumble.attitude.relative_angle` computes it: the
    product scaled by the power of two that brings its largest |component| into [0.5, 1) (exact), then
    ``θ = |qlog(·)|``."""
    w, x, y, z = qmul(tw, -tx, -ty, -tz, qw, qx, qy, qz)
    e = math.frexp(max(abs(w), abs(x), abs(y), abs(z)))[1]
    rx, ry, rz = qlog(math.ldexp(w, -e), math.ldexp(x, -e), math.ldexp(y, -e), math.ldexp(z, -e))
    return math.sqrt(rx * rx + ry * ry + rz * rz)


@register_jitable
def _momentum(inertia, b, w1, w2, w3):
    """``L = I ω`` (N·m·s, body axes) of sample ``b`` (its row of ``inertia``, or the one shared), the terms of
    each component summed in order."""
    r = b if inertia.shape[0] > 1 else 0
    return (inertia[r, 0, 0] * w1 + inertia[r, 0, 1] * w2 + inertia[r, 0, 2] * w3,
            inertia[r, 1, 0] * w1 + inertia[r, 1, 1] * w2 + inertia[r, 1, 2] * w3,
            inertia[r, 2, 0] * w1 + inertia[r, 2, 1] * w2 + inertia[r, 2, 2] * w3)


@register_jitable
def _table_cell(out):
    """The cell ``(k, b)`` (output time, sample) of the table ``out`` (n, m) that this thread fills: thread
    ``k·m + b`` of the launch (``k ≥ n`` for a thread past the table)."""
    index = cuda.grid(1)
    return index // out.shape[1], index % out.shape[1]


@cuda.jit(cache=True)
def pointing_kernel(q, tw, tx, ty, tz, out):
    """Thread ``(k, b)``: ``out[k, b]``, the pointing error (rad) of ``q[k, b]`` from the target ``t``."""
    k, b = _table_cell(out)
    if k >= out.shape[0]:
        return
    out[k, b] = pointing_angle(tw, tx, ty, tz, q[k, b, 0], q[k, b, 1], q[k, b, 2], q[k, b, 3])


@cuda.jit(cache=True)
def nutation_kernel(omega, inertia, a1, a2, a3, out):
    """Thread ``(k, b)``: ``out[k, b] = atan2(|L × a|, L · a)`` (rad), ``L = I ω``, ``a`` a unit body axis."""
    k, b = _table_cell(out)
    if k >= out.shape[0]:
        return
    x, y, z = _momentum(inertia, b, omega[k, b, 0], omega[k, b, 1], omega[k, b, 2])
    along = x * a1 + y * a2 + z * a3
    c1, c2, c3 = y * a3 - z * a2, z * a1 - x * a3, x * a2 - y * a1
    out[k, b] = math.atan2(math.sqrt(c1 * c1 + c2 * c2 + c3 * c3), along)


@cuda.jit(cache=True)
def momentum_kernel(omega, inertia, i, out):
    """Thread ``(k, b)``: ``out[k, b]``, component ``i`` of ``L = I ω`` (N·m·s, body axes)."""
    k, b = _table_cell(out)
    if k >= out.shape[0]:
        return
    out[k, b] = _momentum(inertia, b, omega[k, b, 0], omega[k, b, 1], omega[k, b, 2])[i]


@cuda.jit(cache=True)
def energy_kernel(omega, inertia, out):
    """Thread ``(k, b)``: ``out[k, b] = ½ Σᵢⱼ ωᵢ Iᵢⱼ ωⱼ`` (J), the nine terms summed in the order of ``(i, j)``."""
    k, b = _table_cell(out)
    if k >= out.shape[0]:
        return
    r = b if inertia.shape[0] > 1 else 0
    total = 0.0
    for i in range(3):
        for j in range(3):
            total += omega[k, b, i] * inertia[r, i, j] * omega[k, b, j]
    out[k, b] = 0.5 * total


@cuda.jit(cache=True)
def component_kernel(values, i, out):
    """Thread ``(k, b)``: ``out[k, b] = values[k, b, i]``."""
    k, b = _table_cell(out)
    if k >= out.shape[0]:
        return
    out[k, b] = values[k, b, i]


@cuda.jit(cache=True)
def max_kernel(series, first, out):
    """Thread ``b``: ``out[b]``, the largest of ``series[first:, b]``; NaN where one is NaN (NumPy's ``max``)."""
    b = cuda.grid(1)
    if b >= out.shape[0]:
        return
    best = series[first, b]
    for k in range(first + 1, series.shape[0]):
        x = series[k, b]
        if x > best or x != x:
            best = x if best == best else best
    out[b] = best


@cuda.jit(cache=True)
def settling_kernel(series, t, below, out):
    """Thread ``b``: ``out[b] = t[k]`` for the first ``k`` from which ``|series[k:, b]| <= below`` holds (a NaN
    is not outside the band), NaN if the last sample is outside it."""
    b = cuda.grid(1)
    if b >= out.shape[0]:
        return
    n = series.shape[0]
    first_in = 0
    for k in range(n - 1, -1, -1):
        if abs(series[k, b]) > below:
            first_in = k + 1
            break
    out[b] = t[first_in] if first_in < n else math.nan


@cuda.jit(cache=True)
def crossing_kernel(series, t, above, out):
    """Thread ``b``: ``out[b] = t[k]`` for the first ``k`` with ``series[k, b] >= above``, NaN if there is none."""
    b = cuda.grid(1)
    if b >= out.shape[0]:
        return
    out[b] = math.nan
    for k in range(series.shape[0]):
        if series[k, b] >= above:
            out[b] = t[k]
            return


def series_table(kernel, n: int, m: int, *args) -> Any:
    """The device table (n, m) that ``kernel(*args, out)`` fills, one thread per output time and sample."""
    out = cuda.device_array((n, m))
    kernel[launch(n * m)](*args, out)
    return out


def per_sample(kernel, m: int, *args) -> np.ndarray:
    """The host array (m,) that ``kernel(*args, out)`` fills on the device, one thread per sample."""
    out = cuda.device_array(m)
    kernel[launch(m)](*args, out)
    return out.copy_to_host()
