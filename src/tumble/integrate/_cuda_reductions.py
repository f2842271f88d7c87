"""The compiled CUDA kernels of a sweep's reductions on the GPU (:mod:`tumble.sweeps.device` launches them and
reads their results): per-block moments, a bitonic sorting network, the count of numbers in a sorted row, and
the gather of order statistics. Here, in a compiled layer, so that their code is in the cache's content key
(:mod:`tumble._cache`); the sweeps layer above compiles nothing.

Import this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import cuda
from numpy.typing import ArrayLike

from tumble.integrate._cuda import THREADS_PER_BLOCK, on_device

__all__ = ["bitonic_kernel", "block_moments", "block_moments_kernel", "count_kernel", "gather", "gather_kernel",
           "launch", "numbers_in_rows", "sorted_columns"]


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
