"""A gyro rotor in a two-axis gimbal as a model for the integrators (see :mod:`tumble._protocol`).

State ``y = [q_G (4), φ̇, θ̇, ω₃, ψ]``: the attitude of the inner gimbal G
(``R_G = R_z(φ) R_x(θ)``, G → inertial; ``q̇_G = ½ q_G ⊗ ω_G`` with
``ω_G = (θ̇, φ̇ sin θ, φ̇ cos θ)`` in G axes), the gimbal rates (rad/s), the
rotor's absolute spin ``ω₃`` (rad/s) and its angle ``ψ`` relative to G (rad).
``sin θ = R_G[2, 1]`` and ``cos θ = R_G[2, 2]`` are read from ``q_G``. The
right-hand side is Lagrange's equations of :mod:`tumble.ins.gimbal` (where they
are derived), with ``P = A + I_t``, ``Q = J + (B + I_t) sin²θ + C cos²θ``,
``Q' = 2 (B + I_t − C) sin θ cos θ``::

    I_s ω̇₃ = −c_s ψ̇,                                        ψ̇ = ω₃ − φ̇ cos θ
    P θ̈ = ½ Q' φ̇² − I_s ω₃ φ̇ sin θ + m g l sin θ + τ_θ
    Q φ̈ = τ_φ − c_φ φ̇ − Q' θ̇ φ̇ − I_s ω̇₃ cos θ + I_s ω₃ θ̇ sin θ

``project`` normalises ``q_G``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _block, _protocol, _quat
from tumble._block import matrix_view

STATE_SIZE = 8


class GimbalModel(NamedTuple):
    """Compiled parameters of a gimbaled gyro: ``params`` (1, 11) = I_t, I_s, A, B, C, J, m g l, τ_θ, τ_φ, c_φ, c_s."""

    params: np.ndarray

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side, which also runs on an NVIDIA
        GPU (``"cuda"``)."""
        return frozenset({"rhs", "cuda"})

    @property
    def calls_python(self) -> bool:
        """False: the gimbal equations run compiled."""
        return False


@njit(cache=True)
def _derivative(p, qw, qx, qy, qz, phi_dot, theta_dot, spin):
    """d/dt of the state (the equations of the module docstring); ψ does not enter."""
    It, Is, A, B, C, J, mgl, tau_theta, tau_phi, c_phi, c_spin = (
        p[0, 0], p[0, 1], p[0, 2], p[0, 3], p[0, 4], p[0, 5], p[0, 6], p[0, 7], p[0, 8], p[0, 9], p[0, 10])
    n2 = qw * qw + qx * qx + qy * qy + qz * qz
    s = 2.0 * (qy * qz + qw * qx) / n2           # R_G[2, 1] = sin θ
    c = 1.0 - 2.0 * (qx * qx + qy * qy) / n2     # R_G[2, 2] = cos θ
    psi_dot = spin - phi_dot * c
    spin_dot = -c_spin * psi_dot / Is
    P = A + It
    Q = J + (B + It) * s * s + C * c * c
    dQ = 2.0 * (B + It - C) * s * c
    theta_ddot = (0.5 * dQ * phi_dot * phi_dot - Is * spin * phi_dot * s + mgl * s + tau_theta) / P
    phi_ddot = (tau_phi - c_phi * phi_dot - dQ * theta_dot * phi_dot - Is * spin_dot * c
                + Is * spin * theta_dot * s) / Q
    d = _quat.qmul(qw, qx, qy, qz, 0.0, theta_dot, phi_dot * s, phi_dot * c)
    return 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3], phi_ddot, theta_ddot, spin_dot, psi_dot


@_protocol.implements(_protocol.rhs, GimbalModel)
def _gimbal_rhs(model, b0, t, Y, OUT):
    if Y.ndim == 1:

        def impl(model, b0, t, Y, OUT):
            (OUT[0], OUT[1], OUT[2], OUT[3], OUT[4], OUT[5], OUT[6], OUT[7]) = _derivative(
                model.params, Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6])

    else:

        def impl(model, b0, t, Y, OUT):
            for j in range(Y.shape[1]):
                (OUT[0, j], OUT[1, j], OUT[2, j], OUT[3, j], OUT[4, j], OUT[5, j], OUT[6, j], OUT[7, j]) = (
                    _derivative(model.params, Y[0, j], Y[1, j], Y[2, j], Y[3, j], Y[4, j], Y[5, j], Y[6, j]))

    return impl


@_protocol.implements(_protocol.project, GimbalModel)
def _gimbal_project(model, b0, t, Y):
    return _protocol.quaternion_projection(Y)


@_protocol.implements(_protocol.state_size, GimbalModel)
def _gimbal_state_size(model):
    return lambda model: STATE_SIZE


def pack(model) -> tuple[np.ndarray, np.ndarray]:
    """``(data, ints)`` of the kernel for its block functions (:mod:`tumble._block`): ``params`` flat, and its
    shape."""
    return model.params.ravel(), np.array(model.params.shape, dtype=np.int64)


@njit(cache=True)
def unpack(data, ints):
    """The :class:`GimbalModel` whose ``params`` are a view of :func:`pack`'s ``data``."""
    return GimbalModel(matrix_view(data, 0, ints[0], ints[1]))


def block_rhs(t, Y, OUT, data, ints):
    """The right-hand side of a block (:data:`tumble._block.RHS`)."""
    _protocol.rhs(unpack(data, ints), 0, t, Y, OUT)


_block.register(GimbalModel, pack, block_rhs, _block.quaternion_project, None)
