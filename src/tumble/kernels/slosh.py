"""A rigid hub with a spherical slosh pendulum as a model for the integrators (see :mod:`tumble._protocol`).

State ``y = [q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃, s₁, s₂, s₃, ν₁, ν₂, ν₃]``: the
attitude of the hub (body → inertial), its rate ω (rad/s, body axes), the unit
direction ``s`` of the pendulum from its hinge (body axes) and the angular
velocity ``ν`` of the pendulum relative to the hub (rad/s, body axes,
``ν ⊥ s``). With the reduced mass ``μ``, hinge ``b`` and length ``l``, the
relative position of the slosh mass is ``r = b + l s`` and (see
:mod:`tumble.slosh` for the derivation)::

    v  = l ν × s                                   (velocity of r relative to the hub)
    a₀ = l ν × (ν × s) + 2 ω × v + ω × (ω × r)     (acceleration of r, all but the ω̇ and ν̇ terms)
    p  = −d ν − s × a₀ / l
    (I_B + μ g gᵀ) ω̇ = τ − ω × I_B ω − μ r × a₀ + μ l r × (s × p),    g = r × s
    ν̇ = p + s × (r × ω̇) / l,      ṡ = ν × s,      q̇ = ½ q ⊗ [0, ω]

The 3×3 system is solved with the Sherman–Morrison formula from the
precomputed ``I_B⁻¹``. ``project`` keeps ``|s| = 1`` and ``ν·s = 0`` (both
invariants of the exact flow).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _block, _protocol, _quat, torques
from tumble._block import matrix_view
from tumble._vec import cross, matvec

STATE_SIZE = 13


class SloshModel(NamedTuple):
    """Compiled parameters of a hub with one slosh pendulum (shared by a batch).

    inertia   : (3, 3) hub inertia about the hub's centre of mass, kg·m², body axes
    inverse   : (3, 3) its inverse, 1/(kg·m²)
    hinge     : (3,) hinge point from the hub's centre of mass, m, body axes
    constants : (3,) reduced mass μ (kg), length l (m), damping rate d (1/s)
    params, codes : the torque program in body axes (``codes`` may be empty)
    """

    inertia: np.ndarray
    inverse: np.ndarray
    hinge: np.ndarray
    constants: np.ndarray
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
    mu, length, damping = model.constants[0], model.constants[1], model.constants[2]
    b = model.hinge
    qw, qx, qy, qz, w1, w2, w3 = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
    s1, s2, s3, n1, n2, n3 = y[7], y[8], y[9], y[10], y[11], y[12]
    tau1, tau2, tau3 = torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, model.params, 0, model.codes)
    r1, r2, r3 = b[0] + length * s1, b[1] + length * s2, b[2] + length * s3
    e1, e2, e3 = cross(n1, n2, n3, s1, s2, s3)                      # ṡ = ν × s
    v1, v2, v3 = length * e1, length * e2, length * e3
    x1, x2, x3 = cross(n1, n2, n3, e1, e2, e3)                      # ν × (ν × s)
    c1, c2, c3 = cross(w1, w2, w3, v1, v2, v3)                      # ω × v
    u1, u2, u3 = cross(w1, w2, w3, r1, r2, r3)
    z1, z2, z3 = cross(w1, w2, w3, u1, u2, u3)                      # ω × (ω × r)
    a1 = length * x1 + 2.0 * c1 + z1
    a2 = length * x2 + 2.0 * c2 + z2
    a3 = length * x3 + 2.0 * c3 + z3
    f1, f2, f3 = cross(s1, s2, s3, a1, a2, a3)
    p1, p2, p3 = -damping * n1 - f1 / length, -damping * n2 - f2 / length, -damping * n3 - f3 / length
    h1, h2, h3 = matvec(model.inertia, w1, w2, w3)
    k1, k2, k3 = cross(w1, w2, w3, h1, h2, h3)
    m1, m2, m3 = cross(r1, r2, r3, a1, a2, a3)
    sp1, sp2, sp3 = cross(s1, s2, s3, p1, p2, p3)
    o1, o2, o3 = cross(r1, r2, r3, sp1, sp2, sp3)
    R1 = tau1 - k1 - mu * m1 + mu * length * o1
    R2 = tau2 - k2 - mu * m2 + mu * length * o2
    R3 = tau3 - k3 - mu * m3 + mu * length * o3
    g1, g2, g3 = cross(r1, r2, r3, s1, s2, s3)
    jg1, jg2, jg3 = matvec(model.inverse, g1, g2, g3)
    jr1, jr2, jr3 = matvec(model.inverse, R1, R2, R3)
    factor = mu * (g1 * jr1 + g2 * jr2 + g3 * jr3) / (1.0 + mu * (g1 * jg1 + g2 * jg2 + g3 * jg3))
    d1, d2, d3 = jr1 - factor * jg1, jr2 - factor * jg2, jr3 - factor * jg3
    l1, l2, l3 = cross(r1, r2, r3, d1, d2, d3)
    t1, t2, t3 = cross(s1, s2, s3, l1, l2, l3)
    d = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
    out[0], out[1], out[2], out[3] = 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]
    out[4], out[5], out[6] = d1, d2, d3
    out[7], out[8], out[9] = e1, e2, e3
    out[10], out[11], out[12] = p1 + t1 / length, p2 + t2 / length, p3 + t3 / length


@njit(cache=True)
def project_state(y):
    """Normalise ``q`` and ``s`` of one state vector and remove the component of ``ν`` along ``s``."""
    _protocol.normalize_quaternion(y)
    scale = 1.0 / math.sqrt(y[7] * y[7] + y[8] * y[8] + y[9] * y[9])  # math: a scalar function on a GPU too
    y[7], y[8], y[9] = y[7] * scale, y[8] * scale, y[9] * scale
    along = y[10] * y[7] + y[11] * y[8] + y[12] * y[9]
    y[10], y[11], y[12] = y[10] - along * y[7], y[11] - along * y[8], y[12] - along * y[9]


def pack(model) -> tuple[np.ndarray, np.ndarray]:
    """``(data, ints)`` of the kernel for its block functions (:mod:`tumble._block`): ``inertia``, ``inverse``,
    ``hinge``, ``constants`` and the torque parameters, flat, one after another; the torque program's sizes and
    codes."""
    floats, ints = _block.torque_pieces(model)
    pieces = [model.inertia, model.inverse, model.hinge, model.constants]
    return np.concatenate([p.ravel() for p in pieces] + floats), np.array(ints, dtype=np.int64)


@njit(cache=True)
def unpack(data, ints):
    """The :class:`SloshModel` whose arrays are views of :func:`pack`'s ``data`` and ``ints``."""
    params, codes = _block.torque_views(data, 24, ints, 0)
    return SloshModel(matrix_view(data, 0, 3, 3), matrix_view(data, 9, 3, 3), data[18:21], data[21:24], params,
                      codes)


def block_rhs(t, Y, OUT, data, ints):
    """``OUT[:, j] = dy/dt`` of every lane of the block ``Y`` (:data:`tumble._block.RHS`): the kind's own ``rhs``."""
    _protocol.rhs(unpack(data, ints), 0, t, Y, OUT)


def block_project(t, Y, data, ints):
    """:func:`project_state` of every lane of the block ``Y`` (:data:`tumble._block.PROJECT`): the kind's own
    ``project``."""
    _protocol.project(unpack(data, ints), 0, t, Y)


_block.register(SloshModel, pack, block_rhs, block_project, _block.rate_at_4)


@_protocol.implements(_protocol.rhs, SloshModel, inline=True)
def _slosh_rhs(model, b0, t, Y, OUT):
    return _protocol.lanewise_rhs(derivative, Y)


@_protocol.implements(_protocol.project, SloshModel, inline=True)
def _slosh_project(model, b0, t, Y):
    if Y.ndim == 1:
        return lambda model, b0, t, Y: project_state(Y)

    def impl(model, b0, t, Y):
        for j in range(Y.shape[1]):
            project_state(Y[:, j])

    return impl


@_protocol.implements(_protocol.state_size, SloshModel)
def _slosh_state_size(model):
    return lambda model: STATE_SIZE


@_protocol.implements(_protocol.body_rate, SloshModel, inline=True)
def _slosh_body_rate(model, Y, j):
    return _protocol.rate_at(4, Y)
