"""Explicit Runge–Kutta of order 8 with adaptive steps: Dormand–Prince DOP853.

The method of Hairer, Nørsett & Wanner, *Solving Ordinary Differential
Equations I* (2nd ed., Springer 1993), §II.10: 12 stages (first same as last),
an embedded error estimate that combines 5th- and 3rd-order estimators, and
the step-size control used by scipy's ``solve_ivp(method="DOP853")``. The
coefficients are read from SciPy, so the tableau is not retyped here.

Error control: a step is accepted when ``‖err‖ ≤ 1`` with components scaled by
``atol + rtol·max(|y|, |y_new|)``. Steps are shortened to land exactly on each
output time (no interpolation), and the step the controller proposed is
resumed after such a landing. The quaternion is normalised after every
accepted step.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import njit, prange

from tumble._protocol import evaluating, model_workspace, project, rhs, state_size
from tumble.integrate._fixed import store
from tumble.integrate._method import ADAPTIVE, Driver, Method

ORDER = 8
_STAGES = 12


@cache
def tableau():
    """The DOP853 coefficients ``(A, B, C, E3, E5)``, read from SciPy on first use.

    (Importing ``scipy.integrate`` costs half a second, so it is not done at
    ``import tumble``.)
    """
    from scipy.integrate._ivp import dop853_coefficients as coef

    assert coef.N_STAGES == _STAGES
    return (
        np.ascontiguousarray(coef.A[:_STAGES, :_STAGES]),
        np.ascontiguousarray(coef.B),
        np.ascontiguousarray(coef.C[:_STAGES]),
        np.ascontiguousarray(coef.E3),
        np.ascontiguousarray(coef.E5),
    )


SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
_EXPONENT = -1.0 / 8.0  # the error estimate is of order 7
_EPS, _TINY = float(np.finfo(np.float64).eps), 5e-324  # float64's relative spacing, and its smallest step (at t = 0)

# Status codes written to stats[b, 3].
OK, STEP_TOO_SMALL, TOO_MANY_STEPS, TOO_MANY_PROJECTED = 0, 1, 2, 3
#: A run stops early (``TOO_MANY_PROJECTED``) when, after at least ``PROJECT_AFTER`` steps, the rest of its
#: span at the mean step size so far would take more than ``PROJECT_MARGIN × max_steps`` steps: a run that
#: could only end at ``max_steps`` hours later (``stop = 1e300``, rates of 1e19 rad/s) fails in a fraction of
#: a second. The mean step, not the last one, so that a step cut short at a discontinuity does not trigger it.
#: Once a run has used ``PROJECT_LATE`` of ``max_steps`` (1 %: a second or two of a rigid body), its projection
#: rests on that many steps and the margin drops to ``PROJECT_LATE_MARGIN``: a run projected past twice
#: ``max_steps`` stops then, not a minute later at ``max_steps``. (A run whose rest goes more than twice as
#: fast as its start is stopped too: the message gives the projection; a larger ``max_steps`` lets it run.)
PROJECT_AFTER, PROJECT_MARGIN, PROJECT_LATE, PROJECT_LATE_MARGIN = 1000, 100.0, 0.01, 2.0


#: Sums of squares above this are recomputed from the terms divided by the largest (they may have overflowed).
_SQUARES_OVERFLOW = 1e290


@njit(cache=True)
def _rms(v):
    """Root mean square ``√(Σ vᵢ² / n)``, finite whenever it is representable: when the sum of squares
    overflows (``atol = 1e-300`` under a rate of order 1), it is ``m √(Σ (vᵢ/m)² / n)`` with ``m = max |vᵢ|``."""
    squares = np.sum(v * v)
    if squares <= _SQUARES_OVERFLOW:
        return math.sqrt(squares / v.size)
    largest = np.max(np.abs(v))
    if not largest < math.inf:  # inf or nan: the result
        return largest
    u = v / largest
    return largest * math.sqrt(np.sum(u * u) / v.size)


@njit(cache=True)
def _error_sums(K, E5, E3, y, y_new, rtol, atol, inverse):
    """``(Σ (e5ᵢ/sᵢ · inverse)², Σ (e3ᵢ/sᵢ · inverse)², max(|e5ᵢ|, |e3ᵢ|)/sᵢ)`` of the two embedded error
    estimates ``e5 = h Σ E5ᵣ Kᵣ``, ``e3`` likewise (without the factor ``h``), scaled by
    ``sᵢ = atol + rtol max(|yᵢ|, |y_newᵢ|)``."""
    e5 = 0.0
    e3 = 0.0
    largest = 0.0
    for i in range(y.size):
        scale = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        a5 = 0.0
        a3 = 0.0
        for r in range(_STAGES + 1):
            a5 += E5[r] * K[r, i]
            a3 += E3[r] * K[r, i]
        a5 /= scale
        a3 /= scale
        largest = max(largest, abs(a5), abs(a3))
        e5 += (a5 * inverse) ** 2
        e3 += (a3 * inverse) ** 2
    return e5, e3, largest


@njit(cache=True)
def error_norm(K, E5, E3, y, y_new, rtol, atol, step):
    """The scaled error of a step of size ``step`` (HNW I, eq. 10.17, as scipy's DOP853):
    ``err = |h| e5 / √((e5 + 0.01 e3) n)`` with ``e5, e3`` the sums of squares of :func:`_error_sums`;
    the step is accepted when ``err ≤ 1``.

    Where those sums overflow (|ω| ≥ 1e75 rad/s, or ``atol`` below 1e-160 under rates of order 1) they are
    taken of the terms divided by the largest, ``m``: ``err = |h| m e5' / √((e5' + 0.01 e3') n)``, the same
    number without the overflow. Elsewhere the arithmetic is that of the plain formula, bit for bit.
    """
    e5, e3, largest = _error_sums(K, E5, E3, y, y_new, rtol, atol, 1.0)
    if e5 == 0.0:
        return 0.0
    if e5 + e3 <= _SQUARES_OVERFLOW or not largest < math.inf:
        return step * e5 / math.sqrt((e5 + 0.01 * e3) * y.size)
    e5, e3, _ = _error_sums(K, E5, E3, y, y_new, rtol, atol, 1.0 / largest)
    return step * largest * e5 / math.sqrt((e5 + 0.01 * e3) * y.size)


@njit(cache=True)
def initial_step(model, b, t, y, f0, rtol, atol, span):
    """Hairer's starting step (HNW I, §II.4): from ‖y‖, ‖f‖ and a difference estimate ``d2`` of ‖f'‖.

    ``h1 = (0.01 / max(d1, d2))^(1/8)``; where ``d2 = ‖f(y + h0 f) − f‖ / h0`` overflows (rates near the
    1e150 rad/s bound) the root is taken of its two factors. The step is at least the smallest float64
    (5e-324 s): never 0, which would not move ``t``.
    """
    scale = atol + np.abs(y) * rtol
    d0, d1 = _rms(y / scale), _rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = max(min(h0, span), _TINY)
    f1 = np.empty_like(y)
    rhs(model, b, t + h0, y + h0 * f0, f1)
    change = _rms((f1 - f0) / scale)
    d2 = change / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, 1e-3 * h0)
    elif d2 < math.inf:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / ORDER)
    else:
        h1 = (0.01 / change) ** (1.0 / ORDER) * h0 ** (1.0 / ORDER)
    return max(min(100.0 * h0, h1, span), _TINY)


@njit(cache=True)
def dop853_path(model, b, y, t_out, rtol, atol, max_steps, tab, out, stats):
    """Advance body ``b``'s state ``y`` (in place) through ``t_out``; ``out[k, b]`` = state at ``t_out[k]``.

    ``tab`` is :func:`tableau`. ``out`` is the whole batch's output (times × bodies × state), so that a lone
    body and a member of a parallel batch reach this function with the same argument types, and it is
    compiled once for both.
    ``stats`` = [steps, rejected steps, evaluations, status, next step size]:
    the step size is carried in and out, so a run split in chunks continues
    exactly as one run would (0 on entry means "choose a starting step"). On
    the status ``TOO_MANY_PROJECTED`` the last entry is instead the projected
    number of steps to the end of ``t_out`` (see :data:`PROJECT_AFTER`).
    """
    A, B, C, E3, E5 = tab
    model = evaluating(model, model_workspace(model, y))  # the model's scratch (a robot's), if any
    n = state_size(model)
    K = np.empty((_STAGES + 1, n))
    y_new, tmp = np.empty(n), np.empty(n)
    store(out[0, b], y)
    t = t_out[0]
    rhs(model, b, t, y, K[0])
    stats[2] += 1
    h = stats[4]
    if h <= 0.0 and t_out.shape[0] > 1:
        h = initial_step(model, b, t, y, K[0], rtol, atol, t_out[-1] - t)
        stats[2] += 1
    k = 1
    rejected_last = False
    steps0 = stats[0]
    while k < t_out.shape[0]:
        target = t_out[k]
        # land on the output time when the proposed step reaches it or nearly (1 %)
        landing = t + 1.01 * h >= target
        step = target - t if landing else h
        for s in range(1, _STAGES):
            store(tmp, y)
            for r in range(s):
                a = step * A[s, r]
                for i in range(n):
                    tmp[i] += a * K[r, i]
            rhs(model, b, t + C[s] * step, tmp, K[s])
        store(y_new, y)
        for r in range(_STAGES):
            a = step * B[r]
            for i in range(n):
                y_new[i] += a * K[r, i]
        rhs(model, b, t + step, y_new, K[_STAGES])
        stats[2] += _STAGES
        err = error_norm(K, E5, E3, y, y_new, rtol, atol, step)
        stats[0] += 1
        if err <= 1.0:
            factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**_EXPONENT)
            if rejected_last:
                factor = min(1.0, factor)
            h_next = step * factor
            h = max(h, h_next) if landing else h_next
            t = target if landing else t + step
            store(y, y_new)
            project(model, b, t, y)
            store(K[0], K[_STAGES])  # by loops: a row assignment's shape check compiles a message formatter
            rejected_last = False
            if landing:
                store(out[k, b], y)
                k += 1
        else:
            stats[1] += 1
            factor = SAFETY * err**_EXPONENT  # NaN for err = NaN (a stage overflowed): the smallest factor
            h = step * (factor if factor > MIN_FACTOR else MIN_FACTOR)
            rejected_last = True
            if h < 10.0 * max(_EPS * abs(t), _TINY):  # ten spacings of float64 at t: t + h would barely move
                stats[3] = STEP_TOO_SMALL
                break
        if stats[0] >= max_steps:
            stats[3] = TOO_MANY_STEPS
            break
        taken = stats[0] - steps0
        if taken >= PROJECT_AFTER and t > t_out[0]:
            projected = stats[0] + taken * ((t_out[-1] - t) / (t - t_out[0]))
            margin = PROJECT_MARGIN if stats[0] < PROJECT_LATE * max_steps else PROJECT_LATE_MARGIN
            if projected > margin * max_steps:
                stats[3] = TOO_MANY_PROJECTED
                h = projected
                break
    stats[4] = h


@njit(cache=True, parallel=True)
def dop853_batch(model, y, t_out, rtol, atol, max_steps, tab, out, stats):
    """Integrate the bodies ``y[b]`` in parallel, each with its own step sizes;
    ``stats[b]`` is body ``b``'s statistics row (see :func:`dop853_path`)."""
    for i in prange(y.shape[0]):
        b = np.int64(i)  # prange indices may be unsigned
        if stats[b, 3] == OK:
            dop853_path(model, b, y[b], t_out, rtol, atol, max_steps, tab, out, stats[b])


class Adaptive(Driver):
    """The driver of DOP853: each member's own steps, chosen by error control (:func:`dop853_path`); the
    step size and the step count are carried in ``stats`` from one chunk of output times to the next."""

    adaptive = True

    def __repr__(self) -> str:
        return "Adaptive(DOP853)"

    def plan(self, t, options):
        return options["rtol"], options["atol"], options["max_steps"], tableau()

    def advance(self, model, y, t, lo, hi, out, stats, plan, serial) -> None:
        rtol, atol, max_steps, tab = plan
        t = t[lo:hi + 1]
        if serial:
            for b in range(y.shape[0]):
                dop853_path(model, b, y[b], t, rtol, atol, max_steps, tab, out, stats[b])
        else:
            dop853_batch(model, y, t, rtol, atol, max_steps, tab, out, stats)


METHODS = (
    Method("dop853", order=ORDER, description="Dormand–Prince 8(5,3), adaptive rtol/atol", driver=Adaptive(),
           evaluations=_STAGES, options=ADAPTIVE),
)
