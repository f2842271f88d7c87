"""Fixed-step integration: steps that land on every output time, blocks of bodies, batches.

Every fixed-step method (``rk4``, ``splitting2``, ``splitting4``, ``cf4``)
runs through the drivers below; a method is a *scheme*, a
:class:`typing.NamedTuple` (its coefficients, if any) that overloads two
generic functions, in the same way as models overload the protocol of
:mod:`tumble._protocol`::

    workspace(scheme, model, Y)                     # scratch arrays for Y (allocated once per run)
    advance(scheme, model, b0, t0, h, m, Y, work)   # m steps of h from t0 (in place)

``Y`` is a block (state × lanes) of bodies ``b0, b0+1, …`` or the state vector
of body ``b0``; overloads specialise on ``Y.ndim``.

Steps land on the output times: between ``t_{k-1}`` and ``t_k`` a method takes
``m = ⌈(t_k − t_{k-1})/dt⌉`` equal steps of ``h = (t_k − t_{k-1})/m ≤ dt``
(:func:`landing_steps`), so no output is interpolated.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

#: Bodies advanced together in one structure-of-arrays block (SIMD lanes × unrolling).
LANES = 64


def workspace(scheme, model, Y):  # pragma: no cover - replaced by overloads in compiled code
    """Scratch arrays ``scheme`` needs to advance ``Y`` (a tuple; allocated once per run)."""
    raise NotImplementedError(f"no compiled workspace for {type(scheme).__name__}")


def advance(scheme, model, b0, t0, h, m, Y, work):  # pragma: no cover - replaced by overloads in compiled code
    """Advance ``Y`` (in place) by ``m`` steps of ``h`` (s) from ``t0`` (s) with ``scheme``."""
    raise NotImplementedError(f"no compiled step for {type(scheme).__name__}")


@njit(cache=True)
def landing_steps(span, dt):
    """``(m, h)``: ``m = ⌈span/dt⌉`` equal steps of ``h = span/m`` that end exactly at ``span``.

    ``h ≤ dt`` to 1e-9 relative (a span that is a whole number of steps up to
    rounding is not given one extra step).
    """
    m = max(1, int(math.ceil(span / dt - 1e-9)))
    return m, span / m


@njit(cache=True)
def fixed_path(scheme, model, b0, Y, t_out, dt, out):
    """Advance ``Y`` (in place) through ``t_out``: a block (state × lanes) of bodies ``b0, b0+1, …``,
    or the state vector of body ``b0``.

    ``out[k]`` receives ``Y.T`` at ``t_out[k]``. Returns the number of steps taken.
    """
    work = workspace(scheme, model, Y)
    out[0] = Y.T
    steps = 0
    for k in range(1, t_out.shape[0]):
        m, h = landing_steps(t_out[k] - t_out[k - 1], dt)
        advance(scheme, model, b0, t_out[k - 1], h, m, Y, work)
        steps += m
        out[k] = Y.T
    return steps


@njit(cache=True)
def run_block(scheme, model, k, y, t_out, dt, out, stats):
    """Integrate block ``k`` (bodies ``k·LANES …``) of the batch ``y`` (bodies × state, updated in place)."""
    b0 = k * LANES
    b1 = min(y.shape[0], b0 + LANES)
    if b1 - b0 == 1:  # a lone body runs on its state vector (no lane loops)
        steps = fixed_path(scheme, model, b0, y[b0], t_out, dt, out[:, b0])
    else:
        Y = np.ascontiguousarray(y[b0:b1].T)
        steps = fixed_path(scheme, model, b0, Y, t_out, dt, out[:, b0:b1])
        y[b0:b1] = Y.T
    for b in range(b0, b1):
        stats[b, 0] += steps


@njit(cache=True, parallel=True)
def run_batch(scheme, model, y, t_out, dt, out, stats):
    """Integrate the bodies ``y[b]`` (updated in place), blocks in parallel over the cores.

    ``out[:, b]`` receives body ``b``'s path and ``stats[b, 0]`` its number of steps.
    """
    for k in prange((y.shape[0] + LANES - 1) // LANES):
        run_block(scheme, model, np.int64(k), y, t_out, dt, out, stats)
