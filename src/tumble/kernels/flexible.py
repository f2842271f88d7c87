"""A hub with flexible appendages as a model for the integrators (see :mod:`tumble._protocol`).

State ``y = [q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃, η₁ … η_m, η̇₁ … η̇_m]``: the
attitude of the body axes B (body → inertial), the body rate (rad/s, body
axes) and the modal coordinates and their rates (kg^½·m, kg^½·m/s). The
right-hand side solves the hybrid-coordinate equations (see
:mod:`tumble.flexible` for their derivation)::

    I ω̇ + Σₖ δₖ η̈ₖ + ω × h = τ,           h = I ω + Σₖ δₖ η̇ₖ
    η̈ₖ + 2ζₖΩₖ η̇ₖ + Ωₖ² ηₖ + δₖ · ω̇ = 0

for the accelerations by eliminating ``η̈`` (a Schur complement)::

    fₖ = −2ζₖΩₖ η̇ₖ − Ωₖ² ηₖ
    ω̇ = (I − Σ δₖδₖᵀ)⁻¹ (τ − ω × h − Σₖ δₖ fₖ),     η̈ₖ = fₖ − δₖ · ω̇

``τ`` is the torque program evaluated in body axes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _block, _protocol, _quat, torques
from tumble._block import matrix_view
from tumble._vec import cross, matvec


class FlexibleModel(NamedTuple):
    """Compiled parameters of a hub with ``m`` modal appendages (shared by a batch).

    inertia       : (3, 3) inertia of the undeformed spacecraft, kg·m², body axes
    inverse_hub   : (3, 3) ``(I − Σ δₖδₖᵀ)⁻¹``, 1/(kg·m²)
    participation : (m, 3) rotational participation vectors ``δₖ``, kg^½·m, body axes
    damping       : (m,) ``2ζₖΩₖ``, 1/s
    stiffness     : (m,) ``Ωₖ²``, 1/s²
    params, codes : the torque program in body axes (``codes`` may be empty)
    """

    inertia: np.ndarray
    inverse_hub: np.ndarray
    participation: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    params: np.ndarray
    codes: np.ndarray

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


@njit(cache=True)
def derivative(model, t, y, out):
    """``out = dy/dt`` of one state vector ``y`` (see the module docstring)."""
    m = model.stiffness.shape[0]
    D = model.participation
    qw, qx, qy, qz, w1, w2, w3 = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
    r1, r2, r3 = torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, model.params, 0, model.codes)
    h1, h2, h3 = matvec(model.inertia, w1, w2, w3)
    for k in range(m):
        rate = y[7 + m + k]
        f = -model.damping[k] * rate - model.stiffness[k] * y[7 + k]
        out[7 + m + k] = f  # the modal force, completed below
        h1 += D[k, 0] * rate
        h2 += D[k, 1] * rate
        h3 += D[k, 2] * rate
        r1 -= D[k, 0] * f
        r2 -= D[k, 1] * f
        r3 -= D[k, 2] * f
    c1, c2, c3 = cross(w1, w2, w3, h1, h2, h3)
    a1, a2, a3 = matvec(model.inverse_hub, r1 - c1, r2 - c2, r3 - c3)
    for k in range(m):
        out[7 + k] = y[7 + m + k]
        out[7 + m + k] -= D[k, 0] * a1 + D[k, 1] * a2 + D[k, 2] * a3
    d = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
    out[0], out[1], out[2], out[3] = 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]
    out[4], out[5], out[6] = a1, a2, a3


def pack(model) -> tuple[np.ndarray, np.ndarray]:
    """``(data, ints)`` of the kernel for its block functions (:mod:`tumble._block`): ``inertia``,
    ``inverse_hub``, ``participation``, ``damping``, ``stiffness`` and the torque parameters, flat, one after
    another; ``[m, the torque program's sizes and codes]``."""
    floats, ints = _block.torque_pieces(model)
    pieces = [model.inertia, model.inverse_hub, model.participation, model.damping, model.stiffness]
    return (np.concatenate([p.ravel() for p in pieces] + floats),
            np.array([model.stiffness.shape[0], *ints], dtype=np.int64))


@njit(cache=True)
def unpack(data, ints):
    """The :class:`FlexibleModel` whose arrays are views of :func:`pack`'s ``data`` and ``ints``."""
    m = ints[0]
    a = 18 + 3 * m
    params, codes = _block.torque_views(data, a + 2 * m, ints, 1)
    return FlexibleModel(matrix_view(data, 0, 3, 3), matrix_view(data, 9, 3, 3), matrix_view(data, 18, m, 3),
                         data[a:a + m], data[a + m:a + 2 * m], params, codes)


def block_rhs(t, Y, OUT, data, ints):
    """``OUT[:, j] = dy/dt`` of every lane of the block ``Y`` (:data:`tumble._block.RHS`): the kind's own ``rhs``."""
    _protocol.rhs(unpack(data, ints), 0, t, Y, OUT)


_block.register(FlexibleModel, pack, block_rhs, _block.quaternion_project, _block.rate_at_4)


@_protocol.implements(_protocol.rhs, FlexibleModel, inline=True)
def _flexible_rhs(model, b0, t, Y, OUT):
    return _protocol.lanewise_rhs(derivative, Y)


@_protocol.implements(_protocol.project, FlexibleModel, inline=True)
def _flexible_project(model, b0, t, Y):
    return _protocol.quaternion_projection(Y)


@_protocol.implements(_protocol.state_size, FlexibleModel)
def _flexible_state_size(model):
    return lambda model: 7 + 2 * model.stiffness.shape[0]


@_protocol.implements(_protocol.body_rate, FlexibleModel, inline=True)
def _flexible_body_rate(model, Y, j):
    return _protocol.rate_at(4, Y)
