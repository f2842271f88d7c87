"""Commutator-free Lie-group method of order 4 (CF4): the attitude moves by exact rotations.

The attitude kinematics ``q̇ = ½ q ⊗ [0, ω]`` is an equation on the unit
quaternions; a Runge–Kutta step leaves the sphere and must be projected back.
A Lie-group method instead advances ``q`` only by products with quaternion
exponentials, so ``|q| = 1`` holds to rounding without projection, and the
rest of the state moves by the Euclidean method underneath.

CF4 of E. Celledoni, A. Marthinsen & B. Owren, "Commutator-free Lie group
methods", *Future Generation Computer Systems* 19 (2003) 341-352, written for
the right action ``q ⊗ exp`` of body rates (``qexp(r)`` is the unit quaternion
of the rotation vector ``r``; ``ωₛ`` is the body rate of stage ``s``, read
from the model with :func:`tumble._protocol.body_rate`)::

    Q₁ = q                                   ω₁ = ω(t,       Q₁, x₁)
    Q₂ = q ⊗ qexp(h ω₁/2)                    ω₂ = ω(t + h/2, Q₂, x₂)
    Q₃ = q ⊗ qexp(h ω₂/2)                    ω₃ = ω(t + h/2, Q₃, x₃)
    Q₄ = Q₂ ⊗ qexp(h (ω₃ − ω₁/2))            ω₄ = ω(t + h,   Q₄, x₄)
    q ← q ⊗ qexp(h (3ω₁ + 2ω₂ + 2ω₃ − ω₄)/12) ⊗ qexp(h (−ω₁ + 2ω₂ + 2ω₃ + 3ω₄)/12)

The rest of the state ``x`` (the body rate, and whatever a model adds) takes
the stages and weights of classical RK4 (``x₂ = x + h k₁/2``, …,
``x ← x + h (k₁ + 2k₂ + 2k₃ + k₄)/6``), which is what CF4 reduces to on a
vector space; the method is of order 4 for any torque model.

Every step ends, as with every stepper, with the model's
:func:`~tumble._protocol.project`: it renormalises a quaternion that the
exact rotations kept unit to rounding, and it is where a model updates what it
samples at step ends (a spacecraft's zero-order hold, its PWPF triggers).

A kernel that gives its right-hand side on one body's state in registers
(``point_rates``: the rigid body) runs *fused* (:mod:`._fused`): the whole
step of a lane, stages, exponentials, update and projection, on its seven
values (:func:`point_step`), with the same operations in the same order as
the stages of :func:`_cf4_step`, which the other models run: over a block
(state × lanes) of a batch, or over one body's state vector, as every other
method runs a lone body (its arrays read through :func:`cell`, :func:`put` and
:func:`stage`, which index either).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from tumble import _protocol, _quat
from tumble._block import body_rates
from tumble._protocol import body_rate, evaluating, model_workspace, point_rates, project, quaternion_scale, rhs
from tumble.integrate import _fixed, _fused
from tumble.integrate._method import FIXED_STEP, Method
from tumble.integrate._rk4 import weighted_sum

# Exponent weights of the two final exponentials (applied first: W1).
_W1 = (3.0 / 12.0, 2.0 / 12.0, 2.0 / 12.0, -1.0 / 12.0)
_W2 = (-1.0 / 12.0, 2.0 / 12.0, 2.0 / 12.0, 3.0 / 12.0)


class CF4(NamedTuple):
    """The commutator-free Lie-group method of order 4 (no parameters)."""


SCHEME = CF4()


@njit(cache=True)
def rotate_right(qw, qx, qy, qz, rx, ry, rz):
    """``q ⊗ qexp(r)``: ``q`` followed by the rotation of rotation vector ``r`` (rad, body axes)."""
    ew, ex, ey, ez = _quat.qexp(rx, ry, rz)
    return times_unit(qw, qx, qy, qz, ew, ex, ey, ez)


@njit(cache=True, inline="always")  # in its callers' IR, so that a lane loop holds no call
def times_unit(qw, qx, qy, qz, ew, ex, ey, ez):
    """``q ⊗ e`` for a unit quaternion ``e`` (an exponential of :func:`tumble._quat.qexp`), keeping ``|q|``.

    Computed as ``q + q ⊗ (e − 1)`` with the scalar part of ``e − 1`` formed
    as ``−|e_v|²/(1 + e_w)`` rather than ``e_w − 1``: ``e_w`` rounds to a value
    next to 1 whose error repeats when the rotation does (a uniform spin, a
    fixed step), and the plain product ``q ⊗ e`` then lets ``|q|`` drift
    linearly: after 1e6 equal rotations of 1e-3 rad, ``|q| − 1`` = 4.3e-11 with
    the plain product, 4.5e-14 this way (only the rounding of the small
    increment and of the final sums remains, and it averages out).
    """
    # e_w ≥ 0 for rotations up to π; beyond, e_w − 1 has no cancellation
    gw = -(ex * ex + ey * ey + ez * ez) / (1.0 + ew) if ew > 0.0 else ew - 1.0
    dw, dx, dy, dz = _quat.qmul(qw, qx, qy, qz, gw, ex, ey, ez)
    return qw + dw, qx + dx, qy + dy, qz + dz



# rotate_right inlined in Numba's IR, for the fused step: LLVM does not inline a function compiled on its own
# into its caller, and the call kept CF4's lane loop at 149 ns a step against 66 ns inlined (one body).
_rotate_right = njit(inline="always")(rotate_right.py_func)


@njit(inline="always")
def point_step(model, r, t, h, y):
    """One CF4 step of ``h`` (s) from ``(t, y)`` of a kernel with ``point_rates`` (row ``r`` of its
    parameters), ``y = (q, ω)`` a 7-tuple in registers, then ``q ← q/|q|``: the operations of
    :func:`_cf4_step` and of the kernel's projection, in the same order (the same roundings), with each
    stage's body rate the stage state's ``ω``."""
    qw, qx, qy, qz, w1, w2, w3 = y
    a = 0.5 * h
    k1 = point_rates(model, r, t, y)
    p = _rotate_right(qw, qx, qy, qz, a * w1, a * w2, a * w3)  # Q₂
    y2 = (p[0], p[1], p[2], p[3], w1 + a * k1[4], w2 + a * k1[5], w3 + a * k1[6])
    k2 = point_rates(model, r, t + a, y2)
    u = _rotate_right(qw, qx, qy, qz, a * y2[4], a * y2[5], a * y2[6])
    y3 = (u[0], u[1], u[2], u[3], w1 + a * k2[4], w2 + a * k2[5], w3 + a * k2[6])
    k3 = point_rates(model, r, t + a, y3)
    u = _rotate_right(p[0], p[1], p[2], p[3], h * (y3[4] - 0.5 * w1), h * (y3[5] - 0.5 * w2),
                     h * (y3[6] - 0.5 * w3))
    y4 = (u[0], u[1], u[2], u[3], w1 + h * k3[4], w2 + h * k3[5], w3 + h * k3[6])
    k4 = point_rates(model, r, t + h, y4)
    c0, c1, c2, c3 = _W1
    d0, d1, d2, d3 = _W2
    u = _rotate_right(qw, qx, qy, qz, h * (c0 * w1 + c1 * y2[4] + c2 * y3[4] + c3 * y4[4]),
                     h * (c0 * w2 + c1 * y2[5] + c2 * y3[5] + c3 * y4[5]),
                     h * (c0 * w3 + c1 * y2[6] + c2 * y3[6] + c3 * y4[6]))
    u = _rotate_right(u[0], u[1], u[2], u[3], h * (d0 * w1 + d1 * y2[4] + d2 * y3[4] + d3 * y4[4]),
                     h * (d0 * w2 + d1 * y2[5] + d2 * y3[5] + d3 * y4[5]),
                     h * (d0 * w3 + d1 * y2[6] + d2 * y3[6] + d3 * y4[6]))
    s = quaternion_scale(u[0], u[1], u[2], u[3])
    return (u[0] * s, u[1] * s, u[2] * s, u[3] * s,
            w1 + weighted_sum(h, k1[4], k2[4], k3[4], k4[4]),
            w2 + weighted_sum(h, k1[5], k2[5], k3[5], k4[5]),
            w3 + weighted_sum(h, k1[6], k2[6], k3[6], k4[6]))


@_protocol.implements(_fixed.workspace, CF4)
def _cf4_workspace(scheme, model, b0, Y):
    if _protocol.implemented(point_rates, model):
        return _fused.workspace(model, Y)

    def impl(scheme, model, b0, Y):
        n, tail = Y.shape[0], Y.shape[1:]  # tail: () for one body's state vector, (lanes,) for a block
        # derivatives k₁…k₄ and the stage state (state [× lanes]), stage rates ω₁…ω₄, Q₂,
        # then the model's scratch (a robot's), if any
        return (np.empty((4, n) + tail), np.empty((n,) + tail), np.empty((4, 3) + tail),
                np.empty((4,) + tail)) + model_workspace(model, Y)

    return impl


@_protocol.implements(_fixed.advance, CF4)
def _cf4_advance(scheme, model, b0, t0, h, m, Y, work):
    if _protocol.implemented(point_rates, model):
        return _fused_advance(Y, model)  # one step of a lane in registers (_fused)

    def impl(scheme, model, b0, t0, h, m, Y, work):
        K, S, W, Q2 = work[0], work[1], work[2], work[3]
        model = evaluating(model, work)
        for s in range(m):
            t = t0 + s * h
            _cf4_step(model, b0, t, h, Y, K, S, W, Q2)
            project(model, b0, t + h, Y)

    return impl


def cell(A, i, j):  # pragma: no cover - replaced by the overload in compiled code
    """``A[i]`` of an array of one body (a state vector, its stage rates), ``A[i, j]`` (lane ``j``) of a block's."""
    raise NotImplementedError


def put(A, i, j, value):  # pragma: no cover - replaced by the overload in compiled code
    """``A[i] = value`` of an array of one body, ``A[i, j] = value`` of a block's (see :func:`cell`)."""
    raise NotImplementedError


def stage(A, s, i, j):  # pragma: no cover - replaced by the overload in compiled code
    """``A[s, i]`` of a stage array of one body (stages × state, or stages × 3), ``A[s, i, j]`` (lane ``j``)
    of a block's: one element, without a view of stage ``s``."""
    raise NotImplementedError


def lanes(Y):  # pragma: no cover - replaced by the overload in compiled code
    """The lanes of a block (state × lanes); 1 for one body's state vector."""
    raise NotImplementedError


# In their callers' IR, so that a lane loop holds no call.
@overload(lanes, inline="always", jit_options={"cache": True})
def _lanes(Y):
    if Y.ndim == 1:
        return lambda Y: 1
    return lambda Y: Y.shape[1]


@overload(cell, inline="always", jit_options={"cache": True})
def _cell(A, i, j):
    if A.ndim == 1:
        return lambda A, i, j: A[i]
    return lambda A, i, j: A[i, j]


@overload(stage, inline="always", jit_options={"cache": True})
def _stage_cell(A, s, i, j):
    if A.ndim == 2:
        return lambda A, s, i, j: A[s, i]
    return lambda A, s, i, j: A[s, i, j]


@overload(put, inline="always", jit_options={"cache": True})
def _put(A, i, j, value):
    if A.ndim == 1:
        def impl(A, i, j, value):
            A[i] = value
    else:
        def impl(A, i, j, value):
            A[i, j] = value
    return impl


# The stage functions take the stage's rows (K[s], W[s]), not the index s: a literal index would make Numba
# compile one version per stage (four of _stage per model, 1-1.6 s of CPU each, measured with Numba 0.68).
# Each runs on a block (state × lanes) or on one body's state vector (its own, as every other method runs a lone
# body: so a model compiles its right-hand side on state vectors once for every method, not also on blocks of
# one lane for this one).
@njit(cache=True)
def _stage(model, b0, t, S, k, w):
    """Evaluate a stage at the stage state ``S``: ``k = f(t, S)`` and ``w = ω(S)`` (3 [× lanes])."""
    rhs(model, b0, t, S, k)
    stage_rates(model, S, w)


def stage_rates(model, S, w):  # pragma: no cover - replaced by the overload in compiled code
    """``w[:, j] = body_rate(model, S, j)`` of every lane ``j`` (3 [× lanes]): one call of the kind's
    function for a :class:`tumble._block.BlockModel` (:func:`tumble._block.body_rates`), a loop over the lanes
    otherwise."""
    raise NotImplementedError


@overload(stage_rates, inline="always", jit_options={"cache": True})
def _stage_rates(model, S, w):
    if _protocol.implemented(body_rates, model):
        return lambda model, S, w: body_rates(model, S, w)

    def impl(model, S, w):
        for j in range(lanes(S)):
            w1, w2, w3 = body_rate(model, S, j)
            put(w, 0, j, w1)
            put(w, 1, j, w2)
            put(w, 2, j, w3)

    return impl



@njit(cache=True)
def _euclidean(Y, k, c, S):
    """``S[4:] = Y[4:] + c k[4:]``: the Runge–Kutta stage of the state after the quaternion."""
    for i in range(4, Y.shape[0]):
        for j in range(lanes(Y)):
            put(S, i, j, cell(Y, i, j) + c * cell(k, i, j))


@njit(cache=True, inline="always")
def _quaternion(Y, j):
    """The quaternion ``Y[0:4]`` of lane ``j``."""
    return cell(Y, 0, j), cell(Y, 1, j), cell(Y, 2, j), cell(Y, 3, j)


@njit(cache=True, inline="always")
def _put_quaternion(Y, j, q):
    """``Y[0:4] = q`` in lane ``j``."""
    put(Y, 0, j, q[0])
    put(Y, 1, j, q[1])
    put(Y, 2, j, q[2])
    put(Y, 3, j, q[3])


# error_model="numpy": IEEE division without Python's zero check (2x in the
# rotation loops of the splitting methods); no divisor here can be zero.
@njit(cache=True, error_model="numpy")
def _cf4_step(model, b0, t, h, Y, K, S, W, Q2):
    """One CF4 step of ``h`` (s) from ``t`` for the block ``Y`` (state × lanes) or one body's state vector, in
    place."""
    n_lanes = lanes(Y)
    _stage(model, b0, t, Y, K[0], W[0])
    for j in range(n_lanes):
        qw, qx, qy, qz = _quaternion(Y, j)
        q = rotate_right(qw, qx, qy, qz, 0.5 * h * stage(W, 0, 0, j), 0.5 * h * stage(W, 0, 1, j),
                         0.5 * h * stage(W, 0, 2, j))
        _put_quaternion(S, j, q)
        _put_quaternion(Q2, j, q)
    _euclidean(Y, K[0], 0.5 * h, S)
    _stage(model, b0, t + 0.5 * h, S, K[1], W[1])
    for j in range(n_lanes):
        qw, qx, qy, qz = _quaternion(Y, j)
        _put_quaternion(S, j, rotate_right(qw, qx, qy, qz, 0.5 * h * stage(W, 1, 0, j), 0.5 * h * stage(W, 1, 1, j),
                                           0.5 * h * stage(W, 1, 2, j)))
    _euclidean(Y, K[1], 0.5 * h, S)
    _stage(model, b0, t + 0.5 * h, S, K[2], W[2])
    for j in range(n_lanes):
        qw, qx, qy, qz = _quaternion(Q2, j)
        _put_quaternion(S, j, rotate_right(qw, qx, qy, qz, h * (stage(W, 2, 0, j) - 0.5 * stage(W, 0, 0, j)),
                                           h * (stage(W, 2, 1, j) - 0.5 * stage(W, 0, 1, j)),
                                           h * (stage(W, 2, 2, j) - 0.5 * stage(W, 0, 2, j))))
    _euclidean(Y, K[2], h, S)
    _stage(model, b0, t + h, S, K[3], W[3])
    for j in range(n_lanes):
        r1 = _combine(W, _W1, h, j)
        r2 = _combine(W, _W2, h, j)
        qw, qx, qy, qz = _quaternion(Y, j)
        q = rotate_right(qw, qx, qy, qz, r1[0], r1[1], r1[2])
        _put_quaternion(Y, j, rotate_right(q[0], q[1], q[2], q[3], r2[0], r2[1], r2[2]))
    for i in range(4, Y.shape[0]):
        for j in range(n_lanes):
            put(Y, i, j, cell(Y, i, j) + h / 6.0 * (stage(K, 0, i, j) + 2.0 * stage(K, 1, i, j)
                                                     + 2.0 * stage(K, 2, i, j) + stage(K, 3, i, j)))


@njit(cache=True)
def _combine(W, weights, h, j):
    """The rotation vector ``h Σₛ weights[s] ωₛ`` of lane ``j`` (rad)."""
    a, b, c, d = weights
    return (
        h * (a * stage(W, 0, 0, j) + b * stage(W, 1, 0, j) + c * stage(W, 2, 0, j) + d * stage(W, 3, 0, j)),
        h * (a * stage(W, 0, 1, j) + b * stage(W, 1, 1, j) + c * stage(W, 2, 1, j) + d * stage(W, 3, 1, j)),
        h * (a * stage(W, 0, 2, j) + b * stage(W, 1, 2, j) + c * stage(W, 2, 2, j) + d * stage(W, 3, 2, j)),
    )


_fused_advance = _fused.advance(point_step)


METHODS = (
    Method("cf4", order=4,
           description="commutator-free Lie-group method CF4 (Celledoni–Marthinsen–Owren 2003), fixed step dt",
           driver=_fixed.FixedSteps(SCHEME), evaluations=4, options=FIXED_STEP,
           needs=frozenset({"rhs", "body_rate"}), conserves="|q| = 1 without projection (exact rotations)"),
)
