"""The deformable body as a model for the integrators (see :mod:`tumble._protocol`).

State ``y = [q_w, q_x, q_y, q_z, L_x, L_y, L_z, s]``: the attitude of the body
frame B (``q_NB``, B → inertial), the angular momentum about the centre of
mass in *inertial* axes ``L_N`` (kg·m²/s) and a clock ``s`` (s, ``ṡ = 1``).
The equations of a deformable body (Euler's ``dL/dt = τ`` in inertial axes,
equivalent to ``dL_B/dt + ω × L_B = τ_B`` in body axes) with the attitude
kinematics::

    L_B = q* ⊗ L_N ⊗ q,       ω = I(s)⁻¹ (L_B − A(s)),
    q̇ = ½ q ⊗ [0, ω],         L̇_N = q ⊗ τ_B ⊗ q*,       ṡ = 1

Without a torque ``L̇_N = 0`` exactly: every integrator leaves ``L_N`` as it
was, bit for bit, so ``|L|`` is conserved to rounding whatever the step. The
clock ``s`` carries the time into :func:`tumble._protocol.body_rate` (the rate
depends on time through ``I`` and ``A``); :func:`~tumble._protocol.project`
resets it to the step's end time and normalises ``q``.

``I(s)`` (6 components) and ``A(s)`` (3) are the cubic splines of
:meth:`tumble.variable.body.VariableBody.piecewise`, evaluated here.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types

from tumble import _block, _protocol, _quat, torques
from tumble._block import array_view

STATE_SIZE = 8


class VariableModel(NamedTuple):
    """Compiled parameters of a deformable body (shared by every batch member).

    breaks       : (m,) spline breakpoints, s
    coefficients : (m − 1, 4, 9) cubic coefficients of I_xx, I_yy, I_zz, I_xy, I_xz, I_yz, A_x, A_y, A_z
    params       : (1, n_p) torque-program parameters in body axes
    codes        : int64 torque-program codes, or None for a torque-free body
    """

    breaks: np.ndarray
    coefficients: np.ndarray
    params: np.ndarray
    codes: np.ndarray | None

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side and the body rate; ``"cuda"``
        without a Python torque function."""
        return frozenset({"rhs", "body_rate", *(() if self.calls_python else ("cuda",))})

    @property
    def calls_python(self) -> bool:
        """True when the torque program calls a Python function (the batch then runs on one core)."""
        return torques.program_calls_python(self)

    @property
    def gpu_refusal(self) -> str | None:
        """Why this kernel cannot run on an NVIDIA GPU (a ValidationError message), or None: a Python torque."""
        return _protocol.python_on_gpu("torque") if self.calls_python else None


def build(body, torque) -> VariableModel:
    """The :class:`VariableModel` of a :class:`~tumble.variable.body.VariableBody` under a torque model (or None)."""
    breaks, coefficients = body.piecewise()
    if torque is None:
        codes, params = None, np.zeros((1, 0))
    else:
        codes, p = torques.compile_program(torque, np.eye(3), offset=0)
        params = p[None]
    return VariableModel(breaks=breaks, coefficients=coefficients, params=np.ascontiguousarray(params), codes=codes)


@njit(cache=True, inline="always")
def _channel(c, k, x, i):
    return ((c[k, 0, i] * x + c[k, 1, i]) * x + c[k, 2, i]) * x + c[k, 3, i]


@njit(cache=True, inline="always")
def piece(breaks, s):
    """The spline piece ``k`` whose interval ``[breaks[k], breaks[k+1])`` holds the clock ``s`` (s), by
    bisection over the increasing ``breaks``: ``searchsorted(breaks, s, side="right") − 1``, clamped to the end
    pieces ``0 … len(breaks) − 2`` (the last for a NaN ``s``). A loop of comparisons, which code on a GPU runs
    (numba.cuda compiles no ``np.searchsorted``)."""
    lo, hi = 0, breaks.shape[0] - 1  # breaks[lo] <= s < breaks[hi], or s outside them: the end piece
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if s < breaks[mid]:
            hi = mid
        else:
            lo = mid
    return lo


@njit(cache=True)
def angular_rate(breaks, c, s, qw, qx, qy, qz, lx, ly, lz):
    """``ω = I(s)⁻¹ (q* L_N q − A(s))`` (rad/s, body axes) at clock ``s`` for attitude ``q`` and ``L_N``.

    The spline piece is found by bisection (:func:`piece`; times outside the
    breakpoints use the end pieces; the Python layer refuses such times).
    ``I⁻¹ b`` is solved by the adjugate (Cramer's rule): ``I`` is symmetric
    positive definite and its condition number for a human body is below 30.
    """
    k = piece(breaks, s)
    x = s - breaks[k]
    a = _channel(c, k, x, 0)
    d = _channel(c, k, x, 1)
    f = _channel(c, k, x, 2)
    b = _channel(c, k, x, 3)
    e = _channel(c, k, x, 4)
    g = _channel(c, k, x, 5)  # I = [[a, b, e], [b, d, g], [e, g, f]]
    bx, by, bz = _quat.qrotate_inv(qw, qx, qy, qz, lx, ly, lz)
    bx -= _channel(c, k, x, 6)
    by -= _channel(c, k, x, 7)
    bz -= _channel(c, k, x, 8)
    c00 = d * f - g * g
    c01 = e * g - b * f
    c02 = b * g - d * e
    c11 = a * f - e * e
    c12 = b * e - a * g
    c22 = a * d - b * b
    inv_det = 1.0 / (a * c00 + b * c01 + e * c02)
    return ((c00 * bx + c01 * by + c02 * bz) * inv_det,
            (c01 * bx + c11 * by + c12 * bz) * inv_det,
            (c02 * bx + c12 * by + c22 * bz) * inv_det)



@_protocol.implements(_protocol.rhs, VariableModel)
def _variable_rhs(model, b0, t, Y, OUT):
    if isinstance(model.types[3], types.NoneType):

        def torque_rate(model, t, qw, qx, qy, qz, w1, w2, w3):
            return 0.0, 0.0, 0.0

    else:

        def torque_rate(model, t, qw, qx, qy, qz, w1, w2, w3):  # dL_N/dt = R(q) τ_B
            t1, t2, t3 = torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, model.params, 0, model.codes)
            return _quat.qrotate(qw, qx, qy, qz, t1, t2, t3)

    torque_rate = njit(inline="always")(torque_rate)

    @njit(inline="always")
    def derivative(model, t, qw, qx, qy, qz, lx, ly, lz, s):
        w1, w2, w3 = angular_rate(model.breaks, model.coefficients, s, qw, qx, qy, qz, lx, ly, lz)
        d = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
        dl = torque_rate(model, t, qw, qx, qy, qz, w1, w2, w3)
        return 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3], dl[0], dl[1], dl[2], 1.0

    return _protocol.rhs_of_eight(derivative, Y)


@_protocol.implements(_protocol.project, VariableModel)
def _variable_project(model, b0, t, Y):

    if Y.ndim == 1:

        def impl(model, b0, t, Y):
            _protocol.normalize_quaternion(Y)
            Y[7] = t

    else:

        def impl(model, b0, t, Y):
            _protocol.normalize_quaternions(Y)
            for j in range(Y.shape[1]):
                Y[7, j] = t

    return impl


@_protocol.implements(_protocol.state_size, VariableModel)
def _variable_state_size(model):
    return lambda model: STATE_SIZE


@_protocol.implements(_protocol.body_rate, VariableModel, inline=True)
def _variable_body_rate(model, Y, j):
    if Y.ndim == 1:
        return lambda model, Y, j: angular_rate(model.breaks, model.coefficients, Y[7],
                                                Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6])
    return lambda model, Y, j: angular_rate(model.breaks, model.coefficients, Y[7, j],
                                            Y[0, j], Y[1, j], Y[2, j], Y[3, j], Y[4, j], Y[5, j], Y[6, j])


# Blocks behind function pointers (tumble._block): two variants of the right-hand side, as the kernel type has two
# (``codes`` None: torque-free); the projection and the body rate read no torque and serve both.


def pack(model) -> tuple[np.ndarray, np.ndarray]:
    """``(data, ints)`` of the kernel for its block functions (:mod:`tumble._block`): ``breaks``,
    ``coefficients`` and the torque parameters, flat, one after another; ``[m, the torque program's sizes and
    codes]``."""
    floats, ints = _block.torque_pieces(model)
    return (np.concatenate([model.breaks, model.coefficients.ravel()] + floats),
            np.array([model.breaks.shape[0], *ints], dtype=np.int64))


@njit(cache=True)
def unpack(data, ints):
    """The :class:`VariableModel` with a torque program whose arrays are views of :func:`pack`'s."""
    m = ints[0]
    params, codes = _block.torque_views(data, m + 36 * (m - 1), ints, 1)
    return VariableModel(data[:m], array_view(data, m, (m - 1, 4, 9)), params, codes)


@njit(cache=True)
def unpack_free(data, ints):
    """The torque-free :class:`VariableModel` whose arrays are views of :func:`pack`'s."""
    m = ints[0]
    params, _ = _block.torque_views(data, m + 36 * (m - 1), ints, 1)
    return VariableModel(data[:m], array_view(data, m, (m - 1, 4, 9)), params, None)


def block_rhs(t, Y, OUT, data, ints):
    """The right-hand side of a block (:data:`tumble._block.RHS`) under a torque program."""
    _protocol.rhs(unpack(data, ints), 0, t, Y, OUT)


def block_rhs_free(t, Y, OUT, data, ints):
    """The right-hand side of a block of torque-free bodies (:data:`tumble._block.RHS`)."""
    _protocol.rhs(unpack_free(data, ints), 0, t, Y, OUT)


def block_project(t, Y, data, ints):
    """``q ← q/|q|`` and the clock ``s ← t`` of every lane (:data:`tumble._block.PROJECT`)."""
    _protocol.project(unpack_free(data, ints), 0, t, Y)


def block_body_rate(Y, W, data, ints):
    """``W[:, j] = ω`` of every lane (:data:`tumble._block.BODY_RATE`)."""
    _block.lane_rates(unpack_free(data, ints), Y, W)


_block.register_variants(
    VariableModel, pack,
    lambda model: (block_rhs_free if model.codes is None else block_rhs, block_project, block_body_rate))
