"""Euler's equations of rigid-body rotation, the attitude kinematics and the invariants.

Conventions (``docs/conventions.md``): SI units; ``omega`` is the angular
velocity of the body relative to inertial space in body axes (rad/s);
``torque`` is in body axes (N·m); ``inertia`` is the 3×3 tensor about the
centre of mass in body axes (kg·m²); ``q`` is the unit Hamilton quaternion,
scalar first, mapping body to inertial axes.

Full-tensor form (any body axes)::

    I ω̇ = τ − ω × (I ω)

Principal-axes form (``I = diag(I₁, I₂, I₃)``)::

    I₁ ω̇₁ = τ₁ + (I₂ − I₃) ω₂ ω₃     (and cyclic)

Kinematics::

    q̇ = ½ q ⊗ [0, ω]

Invariants: kinetic energy ``T = ½ ω·(I ω)``, angular momentum ``L_B = I ω``
(body axes) and ``L_N = R(q) I ω`` (inertial axes). Without torque, ``T``,
``|L|`` and ``L_N`` are constant.

Every function is batched over leading axes: ``inertia`` of shape (…, 3, 3)
broadcasts against ``omega`` of shape (…, 3).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.extending import register_jitable

from tumble import _quat
from tumble._validate import as_array
from tumble.attitude import rotate

__all__ = [
    "omega_dot",
    "omega_dot_principal",
    "quaternion_rate",
    "kinetic_energy",
    "angular_momentum",
    "angular_momentum_inertial",
]


def _inertia_omega(inertia, omega):
    inertia = as_array(inertia, "inertia", tail=(3, 3))
    omega = as_array(omega, "omega", tail=(3,))
    return inertia, omega


def _torque(torque, omega):
    if torque is None:
        return np.zeros_like(omega)
    return as_array(torque, "torque", tail=(3,))


def omega_dot(inertia, omega, torque=None) -> np.ndarray:
    """Angular acceleration from the full-tensor Euler equations, body axes (rad/s²).

    ``ω̇ = I⁻¹ (τ − ω × (I ω))``, with ``inertia`` (…, 3, 3) in kg·m² about the
    centre of mass, ``omega`` (…, 3) in rad/s and ``torque`` (…, 3) in N·m,
    all in the same body axes. ``torque=None`` means torque-free.
    """
    inertia, omega = _inertia_omega(inertia, omega)
    torque = _torque(torque, omega)
    momentum = np.einsum("...ij,...j->...i", inertia, omega)
    rhs = torque - np.cross(omega, momentum)
    shape = np.broadcast_shapes(inertia.shape[:-2], rhs.shape[:-1])
    inertia = np.broadcast_to(inertia, shape + (3, 3))
    rhs = np.broadcast_to(rhs, shape + (3,))
    return np.linalg.solve(inertia, rhs[..., None])[..., 0]


@register_jitable
def euler_coefficients(i1, i2, i3):
    """Coefficients of Euler's equations in principal axes, computed once per body.

    Returns ``(c₁, c₂, c₃, 1/I₁, 1/I₂, 1/I₃)`` with ``c₁ = (I₂ − I₃)/I₁`` and
    cyclic, so that :func:`euler_principal` needs no division. Plain Python
    too (it works on arrays of moments), and compiled into callers.
    """
    return (i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3, 1.0 / i1, 1.0 / i2, 1.0 / i3


@njit(cache=True)
def euler_principal(c1, c2, c3, r1, r2, r3, w1, w2, w3, t1, t2, t3):
    """Principal-axes Euler equations for one body: returns ``(ω̇₁, ω̇₂, ω̇₃)`` (rad/s²).

    ``ω̇₁ = c₁ ω₂ ω₃ + τ₁/I₁`` and cyclic, with ``(c₁, c₂, c₃, 1/I₁, 1/I₂, 1/I₃)``
    from :func:`euler_coefficients`; rates in rad/s, torques in N·m, all in
    principal axes. (Equal to ``(τ₁ + (I₂ − I₃) ω₂ ω₃)/I₁`` up to rounding.)
    """
    return (
        c1 * w2 * w3 + t1 * r1,
        c2 * w3 * w1 + t2 * r2,
        c3 * w1 * w2 + t3 * r3,
    )


@njit(cache=True)
def _omega_dot_principal_batch(moments, omega, torque, out):
    for k in range(omega.shape[0]):
        m, w, t = moments[k], omega[k], torque[k]
        c = euler_coefficients(m[0], m[1], m[2])
        out[k, 0], out[k, 1], out[k, 2] = euler_principal(
            c[0], c[1], c[2], c[3], c[4], c[5], w[0], w[1], w[2], t[0], t[1], t[2]
        )


def omega_dot_principal(moments, omega, torque=None) -> np.ndarray:
    """Angular acceleration from Euler's equations in principal axes (rad/s²).

    ``I₁ ω̇₁ = τ₁ + (I₂ − I₃) ω₂ ω₃`` and cyclic, with ``moments`` (…, 3) the
    principal moments (kg·m²) and ``omega``, ``torque`` (…, 3) in the same
    principal axes (rad/s, N·m).
    """
    moments = as_array(moments, "moments", tail=(3,))
    omega = as_array(omega, "omega", tail=(3,))
    torque = _torque(torque, omega)
    moments, omega, torque = np.broadcast_arrays(moments, omega, torque)
    shape = omega.shape
    out = np.empty(shape)
    _omega_dot_principal_batch(
        np.ascontiguousarray(moments).reshape(-1, 3),
        np.ascontiguousarray(omega).reshape(-1, 3),
        np.ascontiguousarray(torque).reshape(-1, 3),
        out.reshape(-1, 3),
    )
    return out


@njit(cache=True)
def _quaternion_rate_batch(q, omega, out):
    for k in range(q.shape[0]):
        a, w = q[k], omega[k]
        d = _quat.qmul(a[0], a[1], a[2], a[3], 0.0, w[0], w[1], w[2])
        for j in range(4):
            out[k, j] = 0.5 * d[j]


def quaternion_rate(q, omega) -> np.ndarray:
    """Time derivative of the attitude quaternion: ``q̇ = ½ q ⊗ [0, ω]`` (1/s).

    ``q`` (…, 4) maps body to inertial axes (scalar first); ``omega`` (…, 3)
    is the body rate in body axes (rad/s).
    """
    q = as_array(q, "q", tail=(4,))
    omega = as_array(omega, "omega", tail=(3,))
    shape = np.broadcast_shapes(q.shape[:-1], omega.shape[:-1])
    q = np.ascontiguousarray(np.broadcast_to(q, shape + (4,))).reshape(-1, 4)
    omega = np.ascontiguousarray(np.broadcast_to(omega, shape + (3,))).reshape(-1, 3)
    out = np.empty((q.shape[0], 4))
    _quaternion_rate_batch(q, omega, out)
    return out.reshape(shape + (4,))


def angular_momentum(inertia, omega) -> np.ndarray:
    """Angular momentum in body axes, ``L_B = I ω`` (N·m·s)."""
    inertia, omega = _inertia_omega(inertia, omega)
    return np.einsum("...ij,...j->...i", inertia, omega)


def kinetic_energy(inertia, omega) -> np.ndarray:
    """Rotational kinetic energy ``T = ½ ω·(I ω)`` (J)."""
    inertia, omega = _inertia_omega(inertia, omega)
    return 0.5 * np.einsum("...i,...ij,...j->...", omega, inertia, omega)


def angular_momentum_inertial(inertia, omega, q) -> np.ndarray:
    """Angular momentum in inertial axes, ``L_N = R(q) I ω`` (N·m·s).

    ``q`` (…, 4) is the body → inertial attitude (scalar-first unit quaternion).
    """
    return rotate(q, angular_momentum(inertia, omega))
