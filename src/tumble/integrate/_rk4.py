"""Classical fourth-order Runge–Kutta with a fixed step that lands on every output time.

Between consecutive output times ``t_j`` and ``t_{j+1}`` the step is
``h = (t_{j+1} − t_j) / m`` with ``m = ⌈(t_{j+1} − t_j)/dt⌉``: never longer
than the requested ``dt`` (to 1e-9 relative), and the output lands exactly on
``t_{j+1}``. The quaternion is normalised after every step.

Tableau (Kutta 1901)::

    k₁ = f(t, y)            k₂ = f(t + h/2, y + h k₁/2)
    k₃ = f(t + h/2, y + h k₂/2)   k₄ = f(t + h, y + h k₃)
    y ← y + h (k₁ + 2k₂ + 2k₃ + k₄)/6
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble._model import project, rhs, state_size

ORDER = 4

#: Bodies advanced together in one structure-of-arrays block (SIMD lanes × unrolling).
LANES = 64


@njit(cache=True)
def rk4_block(model, b0, Y, t_out, dt, out):
    """Advance ``Y`` (in place) through ``t_out``: a block (state × lanes) of bodies ``b0, b0+1, …``,
    or the state vector of body ``b0``.

    ``out[k]`` receives ``Y.T`` at ``t_out[k]``. Returns the number of steps taken.
    """
    k1, k2, k3, k4, tmp = np.empty_like(Y), np.empty_like(Y), np.empty_like(Y), np.empty_like(Y), np.empty_like(Y)
    # flat views: each stage update is one loop over state × lanes (contiguous, vectorised)
    y_, k1_, k2_, k3_, k4_, tmp_ = Y.ravel(), k1.ravel(), k2.ravel(), k3.ravel(), k4.ravel(), tmp.ravel()
    # a compile-time constant for one body, so LLVM unrolls the stage loops
    size = state_size(model) if Y.ndim == 1 else Y.size
    out[0] = Y.T
    steps = 0
    for k in range(1, t_out.shape[0]):
        t0 = t_out[k - 1]
        span = t_out[k] - t0
        m = max(1, int(math.ceil(span / dt - 1e-9)))
        h = span / m
        for s in range(m):
            t = t0 + s * h
            rhs(model, b0, t, Y, k1)
            for i in range(size):
                tmp_[i] = y_[i] + 0.5 * h * k1_[i]
            rhs(model, b0, t + 0.5 * h, tmp, k2)
            for i in range(size):
                tmp_[i] = y_[i] + 0.5 * h * k2_[i]
            rhs(model, b0, t + 0.5 * h, tmp, k3)
            for i in range(size):
                tmp_[i] = y_[i] + h * k3_[i]
            rhs(model, b0, t + h, tmp, k4)
            for i in range(size):
                y_[i] += h / 6.0 * (k1_[i] + 2.0 * k2_[i] + 2.0 * k3_[i] + k4_[i])
            project(model, Y)
        steps += m
        out[k] = Y.T
    return steps


@njit(cache=True)
def rk4_run_block(model, k, y, t_out, dt, out, stats):
    """Integrate block ``k`` (bodies ``k·LANES …``) of the batch ``y`` (bodies × state, updated in place)."""
    b0 = k * LANES
    b1 = min(y.shape[0], b0 + LANES)
    if b1 - b0 == 1:  # a lone body runs on its state vector (no lane loops)
        steps = rk4_block(model, b0, y[b0], t_out, dt, out[:, b0])
    else:
        Y = np.ascontiguousarray(y[b0:b1].T)
        steps = rk4_block(model, b0, Y, t_out, dt, out[:, b0:b1])
        y[b0:b1] = Y.T
    for b in range(b0, b1):
        stats[b, 0] += steps


@njit(cache=True, parallel=True)
def rk4_batch(model, y, t_out, dt, out, stats):
    """Integrate the bodies ``y[b]`` (updated in place), blocks in parallel over the cores.

    ``out[:, b]`` receives body ``b``'s path and ``stats[b, 0]`` its number of steps.
    """
    for k in prange((y.shape[0] + LANES - 1) // LANES):
        rk4_run_block(model, np.int64(k), y, t_out, dt, out, stats)
