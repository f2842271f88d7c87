"""Classical fourth-order Runge–Kutta with a fixed step that lands on every output time.

The steps are those of :func:`tumble.integrate._fixed.landing_steps`: never
longer than the requested ``dt``, ending exactly on each output time. The
quaternion is normalised after every step.

Tableau (Kutta 1901)::

    k₁ = f(t, y)            k₂ = f(t + h/2, y + h k₁/2)
    k₃ = f(t + h/2, y + h k₂/2)   k₄ = f(t + h, y + h k₃)
    y ← y + h (k₁ + 2k₂ + 2k₃ + k₄)/6

A kernel that gives its right-hand side on one body's state in registers
(``point_rates``, :mod:`tumble._protocol`: the rigid body) runs *fused*: each
lane's four stages, update and normalisation are one pass over its seven
values, kept in registers, with the lanes of a block as SIMD lanes
(:func:`point_step`). The stage arithmetic is that of the GPU kernel
(:mod:`._cuda`), operation for operation, so both round alike. Other kernels
run the stages as passes over the block (state × lanes).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from numba.extending import register_jitable

from tumble import _protocol
from tumble._protocol import (evaluating, model_workspace, point_rates, project, quaternion_scale, rhs,
                              state_size)
from tumble.integrate import _fixed, _fused
from tumble.integrate._method import FIXED_STEP, Method


# Not inline="always": numba-cuda (0.68) binds the arguments of an IR-inlined register_jitable
# as omitted ones on a real GPU (the CUDA simulator does not compile); LLVM inlines it anyway.
@register_jitable
def weighted_sum(h, k1, k2, k3, k4):
    """``h (k₁ + 2k₂ + 2k₃ + k₄)/6``: the RK4 increment from the four stage slopes (scalars or arrays).

    The one place of the tableau's weights, used by the CPU step below, the
    torque kicks of :mod:`._exactsplit` and the GPU step of :mod:`._cuda`.
    """
    return h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


@register_jitable
def axpy(y, a, k):
    """``y + a k`` for 7-tuples (a stage state)."""
    return (y[0] + a * k[0], y[1] + a * k[1], y[2] + a * k[2], y[3] + a * k[3],
            y[4] + a * k[4], y[5] + a * k[5], y[6] + a * k[6])


@register_jitable
def update(h, y, k1, k2, k3, k4):
    """``y + h (k₁ + 2k₂ + 2k₃ + k₄)/6`` for 7-tuples, then ``q ← q/|q|`` (the state ``[q, ω]``)."""
    qw, qx, qy, qz, w1, w2, w3 = (y[0] + weighted_sum(h, k1[0], k2[0], k3[0], k4[0]),
                                  y[1] + weighted_sum(h, k1[1], k2[1], k3[1], k4[1]),
                                  y[2] + weighted_sum(h, k1[2], k2[2], k3[2], k4[2]),
                                  y[3] + weighted_sum(h, k1[3], k2[3], k3[3], k4[3]),
                                  y[4] + weighted_sum(h, k1[4], k2[4], k3[4], k4[4]),
                                  y[5] + weighted_sum(h, k1[5], k2[5], k3[5], k4[5]),
                                  y[6] + weighted_sum(h, k1[6], k2[6], k3[6], k4[6]))
    s = quaternion_scale(qw, qx, qy, qz)
    return qw * s, qx * s, qy * s, qz * s, w1, w2, w3


@njit(inline="always")
def point_step(model, r, t, h, y):
    """One RK4 step of length ``h`` (s) from ``(t, y)`` with the parameters of row ``r``
    (:func:`tumble._protocol.point_rates`), ``y = (q, ω)`` a 7-tuple in registers, then ``q ← q/|q|``."""
    k1 = point_rates(model, r, t, y)
    k2 = point_rates(model, r, t + 0.5 * h, axpy(y, 0.5 * h, k1))
    k3 = point_rates(model, r, t + 0.5 * h, axpy(y, 0.5 * h, k2))
    k4 = point_rates(model, r, t + h, axpy(y, h, k3))
    return update(h, y, k1, k2, k3, k4)


class RK4(NamedTuple):
    """The classical Runge–Kutta scheme (no parameters)."""


SCHEME = RK4()


@_protocol.implements(_fixed.workspace, RK4)
def _rk4_workspace(scheme, model, b0, Y):
    if _protocol.implemented(point_rates, model):
        return _fused.workspace(model, Y)
    # the stages k₁…k₄ and the stage state, then the model's scratch (a robot's), if any
    return lambda scheme, model, b0, Y: (np.empty_like(Y), np.empty_like(Y), np.empty_like(Y), np.empty_like(Y),
                                         np.empty_like(Y)) + model_workspace(model, Y)


@_protocol.implements(_fixed.advance, RK4)
def _rk4_advance(scheme, model, b0, t0, h, m, Y, work):
    if _protocol.implemented(point_rates, model):
        return _fused_advance(Y, model)  # one step of a lane in registers (_fused)

    # flat views: each stage update is one loop over state × lanes (contiguous, vectorised); one body's state
    # vector is its own (no new view: a function compiled for a GPU returns none)
    flat = _itself if Y.ndim == 1 else _raveled

    def impl(scheme, model, b0, t0, h, m, Y, work):
        k1, k2, k3, k4, tmp = work[0], work[1], work[2], work[3], work[4]
        model = evaluating(model, work)
        y_, k1_, k2_, k3_, k4_, tmp_ = flat(Y), flat(k1), flat(k2), flat(k3), flat(k4), flat(tmp)
        # a compile-time constant for one body, so LLVM unrolls the stage loops
        size = state_size(model) if Y.ndim == 1 else Y.size
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
                y_[i] += weighted_sum(h, k1_[i], k2_[i], k3_[i], k4_[i])
            project(model, b0, t + h, Y)

    return impl


_itself = njit(inline="always")(lambda a: a)
_raveled = njit(inline="always")(lambda a: a.ravel())

_fused_advance = _fused.advance(point_step)

METHODS = (
    Method("rk4", order=4, description="classical Runge–Kutta (Kutta 1901), fixed step dt",
           driver=_fixed.FixedSteps(SCHEME), evaluations=4, options=FIXED_STEP),
)
