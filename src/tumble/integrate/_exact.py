"""The exact method: the closed-form torque-free motion evaluated at each output time, no steps.

For a model that provides ``"free_flow"`` and ``"torque_free"`` (a free rigid
body, :mod:`tumble._protocol`), each body's motion is set up once from its
state at ``t[0]`` (:func:`~tumble._protocol.free_setup`) and evaluated at
``t[i] − t[0]`` (:func:`~tumble._protocol.free_evaluate`): no error
accumulates from one output to the next, so the states are exact to a few
roundings at any time (Jacobi elliptic functions; :mod:`tumble._free_flow`).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from tumble._protocol import free_evaluate, free_setup
from tumble._validate import ValidationError
from tumble._vec import norm
from tumble.integrate._method import Driver, Method, options

#: Output times per task of the parallel loop: one task sets a body up (about a
#: microsecond) and evaluates up to this many times, so that a single body with
#: many times also runs on every core.
CHUNK = 512

#: The largest turn ``|ω| (t − t₀)`` (rad) the exact motion is evaluated over: past it float64 phases are 2 rad
#: apart, so no attitude is defined (as :func:`tumble.attitude.from_rotvec` refuses such angles).
MAX_TURN = 1e16


@njit(cache=True)
def exact_task(model, y, t, out, task):
    """One task of :func:`exact_batch`: body ``task // n_chunks``, output times of chunk ``task % n_chunks``."""
    n_chunks = (t.shape[0] + CHUNK - 1) // CHUNK
    b, chunk = task // n_chunks, task % n_chunks
    motion = free_setup(model, b, (y[b, 0], y[b, 1], y[b, 2], y[b, 3], y[b, 4], y[b, 5], y[b, 6]))
    for i in range(chunk * CHUNK, min(t.shape[0], (chunk + 1) * CHUNK)):
        x = free_evaluate(model, motion, t[i] - t[0])
        out[i, b, 0], out[i, b, 1], out[i, b, 2], out[i, b, 3] = x[0], x[1], x[2], x[3]
        out[i, b, 4], out[i, b, 5], out[i, b, 6] = x[4], x[5], x[6]


@njit(cache=True, parallel=True)
def exact_batch(model, y, t, out):
    """``out[i, b] = [q_NP, ω_P]`` at ``t[i]`` for each body ``b`` from ``y[b] = [q_NP, ω_P]`` at ``t[0]``.

    Tasks (a body and a chunk of its output times) run in parallel over the cores.
    """
    n_chunks = (t.shape[0] + CHUNK - 1) // CHUNK
    for task in prange(y.shape[0] * n_chunks):
        exact_task(model, y, t, out, np.int64(task))  # prange indices may be unsigned: one signature with run's


def run(model, y, t, out):
    """Fill ``out`` (len(t), N, 7) with the exact states of the bodies ``y`` (N, 7) at ``t``.

    A run over which a body would turn more than :data:`MAX_TURN` rad is refused, naming ``t``.
    """
    rate = float(norm(y[:, 4:]).max())
    with np.errstate(over="ignore"):
        turn = rate * (t[-1] - t[0])
    if not turn <= MAX_TURN:
        turned = f"{turn:.3g} rad" if turn < np.inf else "more than 1.8e308 rad"
        raise ValidationError(f"t: the exact motion from t = {t[0]:g} to {t[-1]:g} s at |ω| = {rate:.3g} rad/s would "
                              f"turn {turned}, past {MAX_TURN:g} rad, where float64 phases are 2 rad apart and define "
                              "no attitude; shorten the span")
    tasks = y.shape[0] * -(-t.shape[0] // CHUNK)
    if tasks == 1:  # a short run of one body: no parallel region (its start-up dominates)
        exact_task(model, y, t, out, 0)
    else:
        exact_batch(model, y, t, out)


class ClosedForm(Driver):
    """The driver of ``exact``: :func:`run` over the output times, no steps (and no options)."""

    steps = False

    def __repr__(self) -> str:
        return "ClosedForm(free motion)"

    def advance(self, model, y, t, lo, hi, out, stats, plan, serial) -> None:
        run(model, y, t[lo:hi + 1], out)
        y[...] = out[-1]


METHODS = (
    Method("exact", order=None, description="closed-form torque-free motion (tumble.analytic.torque_free), no steps",
           driver=ClosedForm(), evaluations=0, options=options(),
           needs=frozenset({"free_flow", "torque_free"}),
           conserves="T, |L|, L_N and |q| = 1 to rounding (the exact flow)"),
)
