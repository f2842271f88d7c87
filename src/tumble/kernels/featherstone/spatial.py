"""Spatial vector algebra on a tree's rows, with 3-vectors held in registers.

Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008, ch. 2: a
motion vector is ``(ω, v)`` (angular velocity, velocity of the body point at
the frame origin), a force vector ``(n, f)`` (moment about the frame origin,
force), both in body axes. A pose ``(R, p)`` of frame i in frame λ(i) (the
axes of i in λ(i)'s, and its origin) gives the transform ``X_i`` of motion
vectors from λ(i) to i and ``X_iᵀ`` of forces from i to λ(i). Each function
returns its 3- or 6-vector as a tuple; the columns are those of
:mod:`.layout`.
"""

from __future__ import annotations

import math

from numba import njit

from tumble._vec import cross
from tumble.kernels.featherstone.layout import (COORDINATE, FIRST_MOMENT, INERTIA, INLINE, JOINT_FRAME, JOINT_TYPE,
                                                MASS, MULTIPLIER, OFFSET, ORIGIN, PARENT_POSE, REVOLUTE, USER_FRAME)


@njit(**INLINE)
def free_transform(q, W):
    """Pose of the floating body 0 in the world, from ``q[0:7] = (r, quat)``, into ``W[0]``'s parent pose."""
    qw, qx, qy, qz = q[3], q[4], q[5], q[6]
    xx, yy, zz, xy, xz, yz = qx * qx, qy * qy, qz * qz, qx * qy, qx * qz, qy * qz
    wx, wy, wz = qw * qx, qw * qy, qw * qz
    o, p = PARENT_POSE, PARENT_POSE + ORIGIN  # where R (row-major) and p go
    W[0, o], W[0, o + 1], W[0, o + 2] = 1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy)
    W[0, o + 3], W[0, o + 4], W[0, o + 5] = 2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx)
    W[0, o + 6], W[0, o + 7], W[0, o + 8] = 2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy)
    W[0, p], W[0, p + 1], W[0, p + 2] = q[0], q[1], q[2]


@njit(**INLINE)
def joint_transform(P, i, x, W):
    """Pose of body frame i in body frame λ(i) at the joint variable ``x``, into ``W[i]``'s parent pose, from
    the joint frame ``(R_o, p_o)``: revolute ``R = R_o Rz(x)``, ``p = p_o``; prismatic ``R = R_o``,
    ``p = p_o + x R_o e_z``."""
    if P[i, JOINT_TYPE] == REVOLUTE:
        c, s = math.cos(x), math.sin(x)
        for r in range(3):
            a, b = P[i, JOINT_FRAME + 3 * r], P[i, JOINT_FRAME + 3 * r + 1]
            W[i, PARENT_POSE + 3 * r] = a * c + b * s
            W[i, PARENT_POSE + 3 * r + 1] = b * c - a * s
            W[i, PARENT_POSE + 3 * r + 2] = P[i, JOINT_FRAME + 3 * r + 2]
        for r in range(3):
            W[i, PARENT_POSE + ORIGIN + r] = P[i, JOINT_FRAME + ORIGIN + r]
    else:
        for k in range(9):
            W[i, PARENT_POSE + k] = P[i, JOINT_FRAME + k]
        for r in range(3):
            W[i, PARENT_POSE + ORIGIN + r] = P[i, JOINT_FRAME + ORIGIN + r] + x * P[i, JOINT_FRAME + 3 * r + 2]


@njit(**INLINE)
def joint(P, i, q, fl):
    """``(c, k, θ)``: coordinate index, multiplier and joint variable ``θ = k q[c] + offset`` of joint i (not
    the free joint; ``fl`` the configuration index shift of a floating base)."""
    c = int(P[i, COORDINATE])
    k = P[i, MULTIPLIER]
    return c, k, k * q[c + fl] + P[i, OFFSET]


@njit(**INLINE)
def subspace(P, i):
    """``j`` with the motion subspace ``S_i = e_j`` in a 6-vector: 2 for a revolute joint (``(e_z, 0)``), 5 for
    a prismatic one (``(0, e_z)``); ``S_i q̇`` and ``S_iᵀ f`` are that one component."""
    return 2 if P[i, JOINT_TYPE] == REVOLUTE else 5


@njit(**INLINE)
def rotate_t(A, i, o, x, y, z):
    """``Rᵀ (x, y, z)`` with R row-major at ``A[i, o:o+9]`` (parent components → child)."""
    return (A[i, o] * x + A[i, o + 3] * y + A[i, o + 6] * z,
            A[i, o + 1] * x + A[i, o + 4] * y + A[i, o + 7] * z,
            A[i, o + 2] * x + A[i, o + 5] * y + A[i, o + 8] * z)


@njit(**INLINE)
def rotate(A, i, o, x, y, z):
    """``R (x, y, z)`` with R row-major at ``A[i, o:o+9]`` (child components → parent)."""
    return (A[i, o] * x + A[i, o + 1] * y + A[i, o + 2] * z,
            A[i, o + 3] * x + A[i, o + 4] * y + A[i, o + 5] * z,
            A[i, o + 6] * x + A[i, o + 7] * y + A[i, o + 8] * z)


@njit(**INLINE)
def motion_to_child(W, i, wx, wy, wz, vx, vy, vz):
    """``X_i m``: motion vector (ω, v) of frame λ(i) in frame i: ``(Rᵀ ω, Rᵀ (v − p × ω))``."""
    p = PARENT_POSE + ORIGIN
    cx, cy, cz = cross(W[i, p], W[i, p + 1], W[i, p + 2], wx, wy, wz)
    a = rotate_t(W, i, PARENT_POSE, wx, wy, wz)
    b = rotate_t(W, i, PARENT_POSE, vx - cx, vy - cy, vz - cz)
    return a[0], a[1], a[2], b[0], b[1], b[2]


@njit(**INLINE)
def force_to_parent(A, i, o, nx, ny, nz, fx, fy, fz):
    """``X_iᵀ f``: force (n, f) of the child frame in the parent frame: ``(R n + p × R f, R f)``, the pose
    ``(R, p)`` at ``A[i, o:o+12]``."""
    f = rotate(A, i, o, fx, fy, fz)
    n = rotate(A, i, o, nx, ny, nz)
    p = o + ORIGIN
    c = cross(A[i, p], A[i, p + 1], A[i, p + 2], f[0], f[1], f[2])
    return n[0] + c[0], n[1] + c[1], n[2] + c[2], f[0], f[1], f[2]


@njit(**INLINE)
def inertia_times(P, i, wx, wy, wz, vx, vy, vz):
    """Rigid-body inertia of body i times a motion vector: ``(I_O ω + h × v, m v − h × ω)``."""
    hx, hy, hz = P[i, FIRST_MOMENT], P[i, FIRST_MOMENT + 1], P[i, FIRST_MOMENT + 2]
    a = cross(hx, hy, hz, vx, vy, vz)
    b = cross(hx, hy, hz, wx, wy, wz)
    m = P[i, MASS]
    return (P[i, INERTIA] * wx + P[i, INERTIA + 1] * wy + P[i, INERTIA + 2] * wz + a[0],
            P[i, INERTIA + 3] * wx + P[i, INERTIA + 4] * wy + P[i, INERTIA + 5] * wz + a[1],
            P[i, INERTIA + 6] * wx + P[i, INERTIA + 7] * wy + P[i, INERTIA + 8] * wz + a[2],
            m * vx - b[0], m * vy - b[1], m * vz - b[2])


@njit(**INLINE)
def bias_force(P, i, wx, wy, wz, vx, vy, vz):
    """``v ×* (I v)``, with ``v ×* (n, f) = (ω × n + v × f, ω × f)``."""
    h = inertia_times(P, i, wx, wy, wz, vx, vy, vz)
    c1 = cross(wx, wy, wz, h[0], h[1], h[2])
    c2 = cross(vx, vy, vz, h[3], h[4], h[5])
    c3 = cross(wx, wy, wz, h[3], h[4], h[5])
    return c1[0] + c2[0], c1[1] + c2[1], c1[2] + c2[2], c3[0], c3[1], c3[2]


@njit(**INLINE)
def external_wrench(P, fext):
    """The last body's wrench ``fext = (f, n)`` (user frame, moment about its origin) in its canonical frame."""
    n = P.shape[0] - 1
    return force_to_parent(P, n, USER_FRAME, fext[3], fext[4], fext[5], fext[0], fext[1], fext[2])


@njit(**INLINE)
def gravity_in_body0(W, g):
    """``R₀ᵀ g``: gravity (world axes) in the axes of the floating body 0 (its pose in ``W[0]``)."""
    return rotate_t(W, 0, PARENT_POSE, g[0], g[1], g[2])
