"""A rigid body in an ideal fluid, Kirchhoff's equations, as a model for the integrators (see :mod:`tumble._protocol`).

State ``y = [q_w, q_x, q_y, q_z, K₁, K₂, K₃, P₁, P₂, P₃, x₁, x₂, x₃]``: the
attitude of the body axes B (body → inertial), the angular impulse ``K``
(N·m·s, body axes, about the body origin), the linear impulse ``P`` (N·s, body
axes) of body and fluid together, and the position ``x`` of the body origin
(m, inertial axes). With the inverse ``W`` of the 6×6 matrix of the kinetic
energy of body and fluid (Kirchhoff's order: angular, then linear; see
:mod:`tumble.fluid`)::

    [ω; v] = W [K; P]                          (rad/s, m/s; body axes)
    K̇ = K × ω + P × v,     Ṗ = P × ω           (Lamb, Hydrodynamics, §§ 123–124)
    q̇ = ½ q ⊗ [0, ω],      ẋ = R(q) v

``project`` normalises ``q``. The impulses, not the velocities, are the state:
the equations are explicit in them (one product with ``W`` per evaluation,
no 6×6 solve), and ``|P|²``, ``K·P`` and the inertial impulse ``R(q) P`` are
functions of the state itself.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _block, _protocol, _quat
from tumble._block import matrix_view
from tumble._vec import cross

STATE_SIZE = 13


class KirchhoffModel(NamedTuple):
    """Compiled parameters of a rigid body in an ideal fluid (shared by a batch).

    mobility : (6, 6) ``W``, the inverse of the kinetic-energy matrix ``[[A, B], [Bᵀ, C]]`` of body and fluid in
               Kirchhoff's order (angular, then linear), body axes: ``[ω; v] = W [K; P]``
    """

    mobility: np.ndarray

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side, the body rate, and ``"cuda"``
        (nothing calls Python or allocates)."""
        return frozenset({"rhs", "body_rate", "cuda"})

    @property
    def calls_python(self) -> bool:
        """False: no torque, no Python function."""
        return False

    @property
    def gpu_refusal(self) -> str | None:
        """None: the kernel runs on an NVIDIA GPU."""
        return None


@njit(cache=True, inline="always")
def velocities(W, k1, k2, k3, p1, p2, p3):
    """``(ω₁, ω₂, ω₃, v₁, v₂, v₃) = W [K; P]`` (rad/s, m/s, body axes) from the impulses."""
    return (W[0, 0] * k1 + W[0, 1] * k2 + W[0, 2] * k3 + W[0, 3] * p1 + W[0, 4] * p2 + W[0, 5] * p3,
            W[1, 0] * k1 + W[1, 1] * k2 + W[1, 2] * k3 + W[1, 3] * p1 + W[1, 4] * p2 + W[1, 5] * p3,
            W[2, 0] * k1 + W[2, 1] * k2 + W[2, 2] * k3 + W[2, 3] * p1 + W[2, 4] * p2 + W[2, 5] * p3,
            W[3, 0] * k1 + W[3, 1] * k2 + W[3, 2] * k3 + W[3, 3] * p1 + W[3, 4] * p2 + W[3, 5] * p3,
            W[4, 0] * k1 + W[4, 1] * k2 + W[4, 2] * k3 + W[4, 3] * p1 + W[4, 4] * p2 + W[4, 5] * p3,
            W[5, 0] * k1 + W[5, 1] * k2 + W[5, 2] * k3 + W[5, 3] * p1 + W[5, 4] * p2 + W[5, 5] * p3)


@njit(cache=True)
def derivative(model, t, y, out):
    """``out = dy/dt`` of one state vector ``y`` (see the module docstring)."""
    qw, qx, qy, qz = y[0], y[1], y[2], y[3]
    k1, k2, k3, p1, p2, p3 = y[4], y[5], y[6], y[7], y[8], y[9]
    w1, w2, w3, v1, v2, v3 = velocities(model.mobility, k1, k2, k3, p1, p2, p3)
    a1, a2, a3 = cross(k1, k2, k3, w1, w2, w3)
    b1, b2, b3 = cross(p1, p2, p3, v1, v2, v3)
    c1, c2, c3 = cross(p1, p2, p3, w1, w2, w3)
    d = _quat.qmul_vector(qw, qx, qy, qz, w1, w2, w3)
    x1, x2, x3 = _quat.qrotate(qw, qx, qy, qz, v1, v2, v3)
    out[0], out[1], out[2], out[3] = 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]
    out[4], out[5], out[6] = a1 + b1, a2 + b2, a3 + b3
    out[7], out[8], out[9] = c1, c2, c3
    out[10], out[11], out[12] = x1, x2, x3


@njit(cache=True)
def _rate_of_lane(model, Y, j):
    """``ω = W[0:3] [K; P]`` of lane ``j`` of a block."""
    w1, w2, w3, _, _, _ = velocities(model.mobility, Y[4, j], Y[5, j], Y[6, j], Y[7, j], Y[8, j], Y[9, j])
    return w1, w2, w3


@njit(cache=True)
def _rate_of_state(model, y):
    """``ω = W[0:3] [K; P]`` of one state vector."""
    w1, w2, w3, _, _, _ = velocities(model.mobility, y[4], y[5], y[6], y[7], y[8], y[9])
    return w1, w2, w3


def pack(model) -> tuple[np.ndarray, np.ndarray]:
    """``(data, ints)`` of the kernel for its block functions (:mod:`tumble._block`): the mobility, flat; no
    ints."""
    return model.mobility.ravel(), np.empty(0, dtype=np.int64)


@njit(cache=True)
def unpack(data, ints):
    """The :class:`KirchhoffModel` whose mobility is a view of :func:`pack`'s ``data``."""
    return KirchhoffModel(matrix_view(data, 0, 6, 6))


def block_rhs(t, Y, OUT, data, ints):
    """``OUT[:, j] = dy/dt`` of every lane of the block ``Y`` (:data:`tumble._block.RHS`): the kind's own ``rhs``."""
    _protocol.rhs(unpack(data, ints), 0, t, Y, OUT)


def block_body_rate(Y, W, data, ints):
    """``W[:, j] = ω`` of every lane of the block ``Y`` (:data:`tumble._block.BODY_RATE`)."""
    _block.lane_rates(unpack(data, ints), Y, W)


_block.register(KirchhoffModel, pack, block_rhs, _block.quaternion_project, block_body_rate)


@_protocol.implements(_protocol.rhs, KirchhoffModel, inline=True)
def _kirchhoff_rhs(model, b0, t, Y, OUT):
    return _protocol.lanewise_rhs(derivative, Y)


@_protocol.implements(_protocol.project, KirchhoffModel, inline=True)
def _kirchhoff_project(model, b0, t, Y):
    return _protocol.quaternion_projection(Y)


@_protocol.implements(_protocol.state_size, KirchhoffModel)
def _kirchhoff_state_size(model):
    return lambda model: STATE_SIZE


@_protocol.implements(_protocol.body_rate, KirchhoffModel, inline=True)
def _kirchhoff_body_rate(model, Y, j):
    if Y.ndim == 1:
        return lambda model, Y, j: _rate_of_state(model, Y)
    return lambda model, Y, j: _rate_of_lane(model, Y, j)
