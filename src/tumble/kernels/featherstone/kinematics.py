"""Poses, energies and momentum of a kinematic tree at a state ``(q, q̇)``: for outputs and checks, not hot loops.

The columns of ``P`` and ``W`` are those of :mod:`.layout`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tumble._vec import cross
from tumble.kernels.featherstone.inverse import rnea_one
from tumble.kernels.featherstone.layout import (FIRST_MOMENT, JIT, MASS, MOMENTUM, ORIGIN, PARENT, PARENT_POSE,
                                                USER_FRAME, VELOCITY, WORLD_POSE, floating, scratch)
from tumble.kernels.featherstone.spatial import free_transform, inertia_times, joint, joint_transform, rotate


@njit(**JIT)
def world_poses(P, q, W):
    """World poses of the canonical body frames into ``W[i, WORLD_POSE:WORLD_POSE + 12]`` (R row-major, then p),
    from the poses in their parents, ``W[i, PARENT_POSE:PARENT_POSE + 12]``: ``R_i = R_λ R``, ``p_i = p_λ + R_λ p``.
    """
    fl = floating(P)
    R, p, G = PARENT_POSE, PARENT_POSE + ORIGIN, WORLD_POSE
    for i in range(P.shape[0]):
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            free_transform(q, W)
        else:
            joint_transform(P, i, joint(P, i, q, fl)[2], W)
        if par < 0:
            for k in range(12):
                W[i, G + k] = W[i, R + k]
            continue
        for r in range(3):
            x, y, z = W[par, G + 3 * r], W[par, G + 3 * r + 1], W[par, G + 3 * r + 2]
            W[i, G + ORIGIN + r] = W[par, G + ORIGIN + r] + x * W[i, p] + y * W[i, p + 1] + z * W[i, p + 2]
            for c in range(3):
                W[i, G + 3 * r + c] = x * W[i, R + c] + y * W[i, R + 3 + c] + z * W[i, R + 6 + c]


@njit(**JIT)
def poses_one(P, q, W, T):
    """World poses of the user's body frames into ``T`` (nb, 4, 4) (homogeneous, base/world frame)."""
    world_poses(P, q, W)
    G, F = WORLD_POSE, USER_FRAME
    for i in range(P.shape[0]):
        for r in range(3):  # user frame = canonical frame ∘ (R_f, p_f)
            x, y, z = W[i, G + 3 * r], W[i, G + 3 * r + 1], W[i, G + 3 * r + 2]
            T[i, r, 3] = (W[i, G + ORIGIN + r] + x * P[i, F + ORIGIN] + y * P[i, F + ORIGIN + 1]
                          + z * P[i, F + ORIGIN + 2])
            for c in range(3):
                T[i, r, c] = x * P[i, F + c] + y * P[i, F + 3 + c] + z * P[i, F + 6 + c]
            T[i, 3, r] = 0.0
        T[i, 3, 3] = 1.0


@njit(**JIT)
def energy_one(P, q, qd, g, W):
    """``(T, V)``: kinetic energy ``Σ ½ vᵢᵀ Iᵢ vᵢ`` and potential ``−Σ g · (mᵢ pᵢ + R_i hᵢ)`` (J).

    ``pᵢ``, ``R_i``: pose of body frame i in the world (base) frame, whose origin is the zero of V.
    """
    rnea_one(P, q, qd, np.zeros(qd.shape[0]), np.zeros(3), np.zeros(6), W, np.empty(qd.shape[0]))
    v = VELOCITY  # the body velocities, left by the RNEA
    kinetic = 0.0
    for i in range(P.shape[0]):
        h = inertia_times(P, i, W[i, v], W[i, v + 1], W[i, v + 2], W[i, v + 3], W[i, v + 4], W[i, v + 5])
        for k in range(6):
            kinetic += 0.5 * W[i, v + k] * h[k]
    world_poses(P, q, W)
    G = WORLD_POSE
    potential = 0.0
    for i in range(P.shape[0]):
        for r in range(3):
            first = (P[i, MASS] * W[i, G + ORIGIN + r] + W[i, G + 3 * r] * P[i, FIRST_MOMENT]
                     + W[i, G + 3 * r + 1] * P[i, FIRST_MOMENT + 1] + W[i, G + 3 * r + 2] * P[i, FIRST_MOMENT + 2])
            potential -= g[r] * first
    return kinetic, potential


@njit(**JIT)
def energy_batch(P, Q, QD, g, OUT):
    """``OUT[b] = (T, V)`` of sample b (serial: energies are for checks and plots, not hot loops)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        OUT[b, 0], OUT[b, 1] = energy_one(P, Q[b], QD[b], g, W)


@njit(**JIT)
def centroidal_momentum_one(P, q, qd, W, out):
    """``out = (k_G, l)``: the angular momentum about the centre of mass and the linear momentum, world axes.

    Each body's spatial momentum about its origin, body axes, is ``(n, f) = I v = (I_O ω + h × v, m v −
    h × ω)``; in the world ``f_W = R f``, and about the world origin ``n_W = R n + p × f_W``. Summed: ``l = Σ
    f_W``, ``k_O = Σ n_W``, and with the centre of mass ``c = Σ (m p + R h) / Σ m``, ``k_G = k_O − c × l``
    (N·m·s, N·s; Orin, Goswami & Lee, Auton. Robots 35, 2013, eq. 1).
    """
    nb = P.shape[0]
    rnea_one(P, q, qd, np.zeros(qd.shape[0]), np.zeros(3), np.zeros(6), W, np.empty(qd.shape[0]))
    v, n = VELOCITY, MOMENTUM
    for i in range(nb):  # the body velocities, left by the RNEA, and their momenta
        h = inertia_times(P, i, W[i, v], W[i, v + 1], W[i, v + 2], W[i, v + 3], W[i, v + 4], W[i, v + 5])
        for k in range(6):
            W[i, n + k] = h[k]
    world_poses(P, q, W)
    G, p = WORLD_POSE, WORLD_POSE + ORIGIN
    kx = ky = kz = lx = ly = lz = cx = cy = cz = mass = 0.0  # k_O, l, Σ (m p + R h)
    for i in range(nb):
        nx, ny, nz = rotate(W, i, G, W[i, n], W[i, n + 1], W[i, n + 2])
        fx, fy, fz = rotate(W, i, G, W[i, n + 3], W[i, n + 4], W[i, n + 5])
        hx, hy, hz = rotate(W, i, G, P[i, FIRST_MOMENT], P[i, FIRST_MOMENT + 1], P[i, FIRST_MOMENT + 2])
        ax, ay, az = cross(W[i, p], W[i, p + 1], W[i, p + 2], fx, fy, fz)
        kx, ky, kz = kx + nx + ax, ky + ny + ay, kz + nz + az
        lx, ly, lz = lx + fx, ly + fy, lz + fz
        m = P[i, MASS]
        cx, cy, cz = cx + m * W[i, p] + hx, cy + m * W[i, p + 1] + hy, cz + m * W[i, p + 2] + hz
        mass += m
    bx, by, bz = cross(cx / mass, cy / mass, cz / mass, lx, ly, lz)
    out[0], out[1], out[2], out[3], out[4], out[5] = kx - bx, ky - by, kz - bz, lx, ly, lz


@njit(**JIT)
def centroidal_momentum_batch(P, Q, QD, OUT):
    """``OUT[b] = (k_G, l)`` of sample b (serial: the output samples of a run)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        centroidal_momentum_one(P, Q[b], QD[b], W, OUT[b])


@njit(**JIT)
def poses_batch(P, Q, T):
    """``T[b]`` = the body poses of sample b (serial)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        poses_one(P, Q[b], W, T[b])


@njit(**JIT)
def body_poses_batch(P, Q, OUT):
    """``OUT[b, i] = (R, p)`` (12,) of canonical body frame i in the world, sample b (serial; for Jacobians)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        world_poses(P, Q[b], W)
        OUT[b] = W[:, WORLD_POSE:WORLD_POSE + 12]
