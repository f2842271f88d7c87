"""Fixed-step integration: steps that land on every output time, blocks of bodies, batches.

Every fixed-step method (``rk4``, ``cf4``, ``splitting2``, ``splitting4``,
``exact_split2``, ``exact_split4``) runs through the drivers below
(:class:`FixedSteps`, the :class:`~._method.Driver` its file declares); a method is a *scheme*, a
:class:`typing.NamedTuple` (its coefficients, if any) that overloads two
generic functions, in the same way as models overload the protocol of
:mod:`tumble._protocol`::

    workspace(scheme, model, b0, Y)                 # scratch for Y, bodies b0, … (once per run)
    advance(scheme, model, b0, t0, h, m, Y, work)   # m steps of h from t0 (in place)

``Y`` is a block (state × lanes) of bodies ``b0, b0+1, …`` or the state vector
of body ``b0``; overloads specialise on ``Y.ndim``.

Steps land on the output times: between ``t_{k-1}`` and ``t_k`` a method takes
``m = ⌈(t_k − t_{k-1})/dt⌉`` equal steps of ``h = (t_k − t_{k-1})/m ≤ dt``
(:func:`landing_steps`), so no output is interpolated. The counts are
computed once, before the run, as exact integers and checked against
``max_steps`` (a count past 2⁶³ would otherwise wrap in compiled code).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit, prange
from numba.extending import overload

from tumble import _block
from tumble._validate import ValidationError
from tumble.integrate._method import Driver


#: Bodies advanced together in one structure-of-arrays block (SIMD lanes × unrolling).
LANES = 64

# The drivers compile with NumPy's error model: a float division by zero gives ±inf or nan (caught as
# divergence by tumble.integrate) instead of a check that raises ZeroDivisionError, which would keep
# every lane loop scalar (LLVM does not vectorise a loop that may raise).


def workspace(scheme, model, b0, Y):  # pragma: no cover - replaced by overloads in compiled code
    """Scratch ``scheme`` needs to advance ``Y``, bodies ``b0, b0+1, …`` (allocated once per run)."""
    raise NotImplementedError(f"no compiled workspace for {type(scheme).__name__}")


def advance(scheme, model, b0, t0, h, m, Y, work):  # pragma: no cover - replaced by overloads in compiled code
    """Advance ``Y`` (in place) by ``m`` steps of ``h`` (s) from ``t0`` (s) with ``scheme``."""
    raise NotImplementedError(f"no compiled step for {type(scheme).__name__}")


def store(dst, Y):  # pragma: no cover - replaced by the overload in compiled code
    """``dst[...] = Y.T`` by explicit loops: ``Y`` a state vector (n,) into ``dst`` (n,), or a block
    (state × lanes) into ``dst`` (lanes × state).

    Loops rather than an array assignment, whose shape check compiles an
    error-message formatter into every integrator (about 7 s of compile per
    model and method, measured with Numba 0.68).
    """
    raise NotImplementedError


@overload(store, inline="always", jit_options={"cache": True})
def _store(dst, Y):
    if Y.ndim == 1:
        def impl(dst, Y):
            for i in range(Y.shape[0]):
                dst[i] = Y[i]
    else:
        def impl(dst, Y):
            for i in range(Y.shape[0]):
                for j in range(Y.shape[1]):
                    dst[j, i] = Y[i, j]
    return impl


def landing_steps(t_out, dt: float, max_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """``(m, h)``: ``m[k] = ⌈(t_out[k+1] − t_out[k])/dt⌉`` equal steps (int64) of ``h[k]`` (s) that end
    exactly at ``t_out[k+1]``; the one rule of every fixed-step run, CPU and GPU.

    ``h ≤ dt`` to 1e-9 relative (a span that is a whole number of steps up to
    rounding is not given one extra step). The counts are whole float64
    numbers, exact while they are below ``max_steps ≤ 2⁵³``; their sum is the
    run's number of steps per body, summed exactly (:func:`math.fsum`) and
    refused (:class:`~tumble.ValidationError` naming ``max_steps``) when it is
    more than ``max_steps``, before anything is integrated.
    """
    t_out = np.asarray(t_out, dtype=np.float64)
    with np.errstate(over="ignore"):  # a span past 1.8e308 (t from -1e308 to 1e308): inf steps, refused below
        spans = t_out[1:] - t_out[:-1]
        counts = np.maximum(1.0, np.ceil(spans / dt - 1e-9))
    needed = math.fsum(counts)
    if not needed <= max_steps:
        steps = f"{needed:.3g}" if math.isfinite(needed) else "more than 1.8e308"
        allow = (f"give a larger dt, or max_steps={int(needed)} to allow it" if needed <= 2**53
                 else "give a larger dt (no max_steps allows it: at most 2**53)")
        raise ValidationError(f"max_steps: the run needs {steps} steps of dt = {dt:g} s from t = {t_out[0]:g} to "
                              f"{t_out[-1]:g} s, more than max_steps = {max_steps}; {allow}")
    m = counts.astype(np.int64)
    return m, spans / m


@njit(cache=True, error_model="numpy")
def fixed_path(scheme, model, b0, Y, t_out, m, h, out):
    """Advance ``Y`` (in place) through ``t_out``, ``m[k]`` steps of ``h[k]`` from ``t_out[k]`` to
    ``t_out[k+1]`` (:func:`landing_steps`): a block (state × lanes) of bodies ``b0, b0+1, …``, or the
    state vector of body ``b0``.

    ``out[k]`` receives ``Y.T`` at ``t_out[k]``. Returns the number of steps taken.
    """
    work = workspace(scheme, model, b0, Y)
    store(out[0], Y)
    steps = 0
    for k in range(1, t_out.shape[0]):
        advance(scheme, model, b0, t_out[k - 1], h[k - 1], m[k - 1], Y, work)
        steps += m[k - 1]
        store(out[k], Y)
    return steps


@njit(cache=True, error_model="numpy")
def run_one(scheme, model, y, t_out, m, h, out, stats):
    """Integrate the lone body ``y[0]`` (a batch of one, updated in place) on its state vector.

    Its own entry point, so that a single run compiles the state-vector path
    only, not the lane loops of a block as well (half the compile time).
    """
    stats[0, 0] += fixed_path(scheme, model, 0, y[0], t_out, m, h, out[:, 0])


@njit(cache=True, error_model="numpy")
def run_block(scheme, model, k, y, t_out, m, h, out, stats):
    """Integrate block ``k`` (bodies ``k·LANES …``) of the batch ``y`` (bodies × state, updated in place).

    Every block runs its lanes as a structure of arrays, a last block of one lane included.
    """
    b0 = k * LANES
    b1 = min(y.shape[0], b0 + LANES)
    Y = np.ascontiguousarray(y[b0:b1].T)
    steps = fixed_path(scheme, model, b0, Y, t_out, m, h, out[:, b0:b1])
    store(y[b0:b1], Y)
    for b in range(b0, b1):
        stats[b, 0] += steps


@njit(cache=True, parallel=True, error_model="numpy")
def run_batch(scheme, model, y, t_out, m, h, out, stats):
    """Integrate the bodies ``y[b]`` (updated in place), blocks in parallel over the cores.

    ``out[:, b]`` receives body ``b``'s path and ``stats[b, 0]`` its number of steps.
    """
    for k in prange((y.shape[0] + LANES - 1) // LANES):
        run_block(scheme, model, np.int64(k), y, t_out, m, h, out, stats)


class FixedSteps(Driver):
    """The driver of a fixed-step method: ``scheme`` advanced by steps that land on every output time.

    Its plan is :func:`landing_steps` for the whole run (so a run that needs more than ``max_steps`` is
    refused before it starts). A lone body runs on its state vector (:func:`run_one`, the kernel's
    right-hand side inlined); a batch runs in blocks of :data:`LANES`, in parallel over the cores
    (:func:`run_batch`) unless ``serial`` or the batch is one block (its one task runs on one core anyway, and
    the parallel driver is not compiled for it). A batch of a kind with block functions runs as its
    :class:`tumble._block.BlockModel` (:func:`tumble._block.block_model`, the one place of that choice): the
    block drivers are then compiled once per method for all those kinds.
    """

    def __init__(self, scheme: NamedTuple) -> None:
        self.scheme = scheme

    def __repr__(self) -> str:
        return f"FixedSteps({type(self.scheme).__name__})"

    def plan(self, t, options) -> tuple[np.ndarray, np.ndarray]:
        return landing_steps(t, options["dt"], options["max_steps"])

    def advance(self, model: Any, y, t, lo, hi, out, stats, plan, serial) -> None:
        m, h = plan[0][lo:hi], plan[1][lo:hi]
        t = t[lo:hi + 1]
        if y.shape[0] == 1:
            run_one(self.scheme, model, y, t, m, h, out, stats)
            return
        model = _block.block_model(model)
        if serial or y.shape[0] <= LANES:
            for k in range(-(-y.shape[0] // LANES)):
                run_block(self.scheme, model, k, y, t, m, h, out, stats)
        else:
            run_batch(self.scheme, model, y, t, m, h, out, stats)
