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

from tumble._model import project, rhs

ORDER = 4


@njit(cache=True)
def rk4_path(model, b, y, t_out, dt, out):
    """Advance body ``b``'s state ``y`` (in place) through ``t_out``; ``out[j]`` = state at ``t_out[j]``.

    Returns the number of steps taken.
    """
    n = y.shape[0]
    k1, k2, k3, k4, tmp = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    out[0, :] = y
    steps = 0
    for j in range(1, t_out.shape[0]):
        t0 = t_out[j - 1]
        span = t_out[j] - t0
        m = max(1, int(math.ceil(span / dt - 1e-9)))
        h = span / m
        for s in range(m):
            t = t0 + s * h
            rhs(model, b, t, y, k1)
            for i in range(n):
                tmp[i] = y[i] + 0.5 * h * k1[i]
            rhs(model, b, t + 0.5 * h, tmp, k2)
            for i in range(n):
                tmp[i] = y[i] + 0.5 * h * k2[i]
            rhs(model, b, t + 0.5 * h, tmp, k3)
            for i in range(n):
                tmp[i] = y[i] + h * k3[i]
            rhs(model, b, t + h, tmp, k4)
            for i in range(n):
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            project(model, y)
        steps += m
        out[j, :] = y
    return steps


@njit(cache=True, parallel=True)
def rk4_batch(model, y, t_out, dt, out, stats):
    """Integrate the bodies ``y[b]`` in parallel; ``out[:, b]`` receives body ``b``'s path
    and ``stats[b, 0]`` its number of steps."""
    for i in prange(y.shape[0]):
        b = np.int64(i)  # prange indices may be unsigned
        stats[b, 0] += rk4_path(model, b, y[b], t_out, dt, out[:, b, :])
