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

Frame form for an axisymmetric body (transverse moment ``I_t``, axial moment
``I_s`` about the symmetry axis ``e₃``), in principal axes F that turn at
``ω_F = (ω₁, ω₂, Ω₃)``: the body rate and ω_F differ only about ``e₃``
(:func:`euler_frame`)::

    I_t ω̇₁ = N₁ − (I_s ω₃ − I_t Ω₃) ω₂
    I_t ω̇₂ = N₂ + (I_s ω₃ − I_t Ω₃) ω₁
    I_s ω̇₃ = N₃

Invariants: kinetic energy ``T = ½ ω·(I ω)``, angular momentum ``L_B = I ω``
(body axes) and ``L_N = R(q) I ω`` (inertial axes). Without torque, ``T``,
``|L|`` and ``L_N`` are constant.

Every function is batched over leading axes: ``inertia`` of shape (…, 3, 3)
broadcasts against ``omega`` of shape (…, 3).
"""

from __future__ import annotations

from typing import TypeVar

import numpy as np
from numba import njit
from numba.extending import register_jitable
from numpy.typing import ArrayLike

from tumble import _quat
from tumble._validate import as_array
from tumble.attitude import rotate

__all__ = [
    "omega_dot",
    "omega_dot_principal",
    "omega_dot_frame",
    "quaternion_rate",
    "kinetic_energy",
    "angular_momentum",
    "angular_momentum_inertial",
]

# A scalar or an array of them: the functions compiled into kernels (float arguments) that also work on arrays
Real = TypeVar("Real", float, np.ndarray)


def _inertia_omega(inertia: ArrayLike, omega: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    inertia = as_array(inertia, "inertia", tail=(3, 3))
    omega = as_array(omega, "omega", tail=(3,))
    return inertia, omega


def _torque(torque: ArrayLike | None, omega: np.ndarray) -> np.ndarray:
    if torque is None:
        return np.zeros_like(omega)
    return as_array(torque, "torque", tail=(3,))


def omega_dot(inertia: ArrayLike, omega: ArrayLike, torque: ArrayLike | None = None) -> np.ndarray:
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
def euler_coefficients(i1: Real, i2: Real, i3: Real) -> tuple[Real, Real, Real, Real, Real, Real]:
    """Coefficients of Euler's equations in principal axes, computed once per body.

    Returns ``(c₁, c₂, c₃, 1/I₁, 1/I₂, 1/I₃)`` with ``c₁ = (I₂ − I₃)/I₁`` and
    cyclic, so that :func:`euler_principal` needs no division. Plain Python
    too (it works on arrays of moments), and compiled into callers.
    """
    return (i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3, 1.0 / i1, 1.0 / i2, 1.0 / i3


@njit(cache=True)
def euler_principal(c1: float, c2: float, c3: float, r1: float, r2: float, r3: float, w1: float, w2: float, w3: float,
                    t1: float, t2: float, t3: float) -> tuple[float, float, float]:
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


@register_jitable
def rigid_rates(c1: float, c2: float, c3: float, r1: float, r2: float, r3: float, qw: float, qx: float, qy: float,
                qz: float, w1: float, w2: float, w3: float,
                torque: tuple[float, float, float] | None) -> tuple[float, float, float, float, float, float, float]:
    """``dy/dt`` of one rigid body from its state ``(q, ω)`` and torque ``τ`` (N·m, principal axes):
    ``(½ q ⊗ [0, ω], ω̇)`` with ``ω̇₁ = c₁ ω₂ ω₃ + τ₁/I₁`` and cyclic (:func:`euler_principal`,
    coefficients ``(c₁, c₂, c₃, 1/I₁, 1/I₂, 1/I₃)``).

    ``torque`` is ``(τ₁, τ₂, τ₃)``, or None for a torque-free body: compiled
    code then holds no torque terms at all (``c₁ ω₂ ω₃ + 0·(1/I₁)`` is not
    folded to ``c₁ ω₂ ω₃`` by a compiler that keeps IEEE semantics; the values
    are the same, up to the sign of a zero).

    The one right-hand side of the rigid body, compiled into the CPU kernel
    (:mod:`tumble.kernels.rigid`) and the GPU kernel of
    :mod:`tumble.integrate._cuda` alike, so that both round alike.
    """
    d = _quat.qmul_vector(qw, qx, qy, qz, w1, w2, w3)
    a1, a2, a3 = c1 * w2 * w3, c2 * w3 * w1, c3 * w1 * w2
    if torque is not None:  # the order of euler_principal: (c₁ ω₂ ω₃) + τ₁ (1/I₁)
        a1, a2, a3 = a1 + torque[0] * r1, a2 + torque[1] * r2, a3 + torque[2] * r3
    return 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3], a1, a2, a3


@njit(cache=True)
def _omega_dot_principal_batch(moments, omega, torque, out):
    for k in range(omega.shape[0]):
        m, w, t = moments[k], omega[k], torque[k]
        c = euler_coefficients(m[0], m[1], m[2])
        out[k, 0], out[k, 1], out[k, 2] = euler_principal(
            c[0], c[1], c[2], c[3], c[4], c[5], w[0], w[1], w[2], t[0], t[1], t[2]
        )


def omega_dot_principal(moments: ArrayLike, omega: ArrayLike, torque: ArrayLike | None = None) -> np.ndarray:
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


@register_jitable
def euler_frame(ratio: Real, r_t: Real, r_s: Real, w1: Real, w2: Real, w3: Real, frame3: Real, n1: Real, n2: Real,
                n3: Real) -> tuple[Real, Real, Real]:
    """Euler's equations of an axisymmetric body in a principal frame F turning at ``(ω₁, ω₂, Ω₃)``.

    The body rate is ``ω = ω₁e₁ + ω₂e₂ + ω₃e₃`` and the frame's rate
    ``ω_F = ω₁e₁ + ω₂e₂ + Ω₃e₃`` (``Ω₃ = frame3``): they differ only about the
    symmetry axis ``e₃``, so F stays principal. With ``L = I_t(ω₁e₁ + ω₂e₂) + I_s ω₃ e₃``,
    ``dL/dt|_F + ω_F × L = N`` reads in components::

        I_t ω̇₁ = N₁ − (I_s ω₃ − I_t Ω₃) ω₂
        I_t ω̇₂ = N₂ + (I_s ω₃ − I_t Ω₃) ω₁
        I_s ω̇₃ = N₃

    ``Ω₃ = ω₃`` (F fixed in the body) gives the principal-axes Euler equations
    with ``I₁ = I₂ = I_t``; ``Ω₃ = 0`` is the non-spinning (Resal) frame of
    gyroscope and projectile analyses. Sources: the article "Euler's
    equations (rigid body dynamics)" (Wikipedia: the equations hold in
    principal axes not fixed to the body, with ω replaced by the axes' rate);
    J. H. Ginsberg, *Advanced Engineering Dynamics*, 2nd ed., 1995, on the
    equations of axisymmetric bodies in a non-body-fixed frame; R. L.
    McCoy, *Modern Exterior Ballistics*, 1999, for the non-rolling frame of
    spinning projectiles.

    Arguments: ``ratio = I_s/I_t``, ``r_t = 1/I_t``, ``r_s = 1/I_s``
    (1/(kg·m²)); rates in rad/s and torques ``N`` in N·m, all in F
    components. Returns ``(ω̇₁, ω̇₂, ω̇₃)`` (rad/s², F components: the rates of
    change of the components, i.e. ``dω/dt|_F``). Plain Python too (it works
    on arrays), and compiled into callers.
    """
    gyro = ratio * w3 - frame3  # (I_s ω₃ − I_t Ω₃)/I_t, rad/s
    return n1 * r_t - gyro * w2, n2 * r_t + gyro * w1, n3 * r_s


def omega_dot_frame(moments: ArrayLike, omega: ArrayLike, frame_rate: ArrayLike,
                    torque: ArrayLike | None = None) -> np.ndarray:
    """Rates of change of the body-rate components in a principal frame F of an axisymmetric body (rad/s²).

    ``moments`` (…, 2) are ``(I_t, I_s)``: the transverse and the axial
    moment (kg·m²); ``omega`` (…, 3) the body rate in F components, with
    ``e₃`` the symmetry axis (rad/s); ``frame_rate`` (…) the frame's rate
    ``Ω₃`` about ``e₃`` (rad/s; the frame's transverse rate is the body's);
    ``torque`` (…, 3) in F components (N·m). The equations are those of
    :func:`euler_frame`.
    """
    moments = as_array(moments, "moments", tail=(2,))
    omega = as_array(omega, "omega", tail=(3,))
    frame_rate = as_array(frame_rate, "frame_rate")
    torque = _torque(torque, omega)
    i_t, i_s = moments[..., 0], moments[..., 1]
    rates = euler_frame(i_s / i_t, 1.0 / i_t, 1.0 / i_s, omega[..., 0], omega[..., 1], omega[..., 2], frame_rate,
                        torque[..., 0], torque[..., 1], torque[..., 2])
    return np.stack(np.broadcast_arrays(*rates), axis=-1)


@njit(cache=True)
def _quaternion_rate_batch(q, omega, out):
    for k in range(q.shape[0]):
        a, w = q[k], omega[k]
        d = _quat.qmul(a[0], a[1], a[2], a[3], 0.0, w[0], w[1], w[2])
        for j in range(4):
            out[k, j] = 0.5 * d[j]


def quaternion_rate(q: ArrayLike, omega: ArrayLike) -> np.ndarray:
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


def angular_momentum(inertia: ArrayLike, omega: ArrayLike) -> np.ndarray:
    """Angular momentum in body axes, ``L_B = I ω`` (N·m·s)."""
    inertia, omega = _inertia_omega(inertia, omega)
    return np.einsum("...ij,...j->...i", inertia, omega)


def kinetic_energy(inertia: ArrayLike, omega: ArrayLike) -> np.ndarray:
    """Rotational kinetic energy ``T = ½ ω·(I ω)`` (J)."""
    inertia, omega = _inertia_omega(inertia, omega)
    return 0.5 * np.einsum("...i,...ij,...j->...", omega, inertia, omega)


def angular_momentum_inertial(inertia: ArrayLike, omega: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Angular momentum in inertial axes, ``L_N = R(q) I ω`` (N·m·s).

    ``q`` (…, 4) is the body → inertial attitude (scalar-first unit quaternion).
    """
    return rotate(q, angular_momentum(inertia, omega))
