"""Compiled rigid-body algorithms for serial chains: RNEA, CRBA, ABA, energies, link poses.

Spatial vector algebra (Featherstone, *Rigid Body Dynamics Algorithms*,
Springer 2008, ch. 2), written with 3-vectors so that every quantity lives in
registers: a motion vector is ``(ω, v)`` (angular velocity, velocity of the
body point at the frame origin), a force vector ``(n, f)`` (moment about the
frame origin, force), both in link axes.

The chain is one float64 array ``P`` of shape (n, PARAMS), built once by
:class:`tumble.robot.SerialChain`; row ``i`` describes joint ``i`` and the link
it moves, in *canonical* frames whose origin lies on the joint axis:

=========  ==============================================================
columns    meaning
=========  ==============================================================
0–8        ``R``: axes of joint frame i (before motion) in link frame i−1, row-major
9–11       ``p``: origin of joint frame i in link frame i−1 (m)
12–14      ``s``: unit joint axis (same in the joint and link frames)
15         joint type: 0 revolute, 1 prismatic
16         offset: the joint variable is ``q + offset`` (rad or m)
17         ``m``: link mass (kg)
18–20      ``h = m c``: first mass moment about the link origin (kg·m)
21–29      ``I_O``: rotational inertia about the link origin, row-major (kg·m²)
30–38      ``R_f``: axes of the user's link frame in the canonical link frame
39–41      ``p_f``: origin of the user's link frame in the canonical link frame (m)
=========  ==============================================================

Motion of joint i: revolute ``R_J = exp(θ [s]×)``, ``θ = q + offset``; prismatic
``p_J = (q + offset) s``. Link frame i = joint frame i moved by the joint.

The single-sample functions ``*_one`` take a scratch array ``W`` (allocated
once per call, or once per chunk of a batch). ``rnea_batch``, ``crba_batch``
and ``aba_batch`` run a batch of samples in parallel: ``prange`` over ``nc``
chunks of consecutive samples, one scratch allocation per chunk.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble._vec import cross

PARAMS = 42
REVOLUTE, PRISMATIC = 0, 1
# Compiler options: fused multiply-adds allowed (contraction only: no reassociation,
# NaN and inf keep their meaning, so the finiteness checks stay valid); a division
# by zero gives inf or NaN (found by those checks) rather than an exception; the
# small vector helpers are inlined in Numba's IR (measured 0.9 → 0.5 µs per
# 7-DOF RNEA).
_JIT = {"cache": True, "fastmath": {"contract"}, "error_model": "numpy"}
_INLINE = {**_JIT, "inline": "always"}
# Scratch columns per link.
_W_RNEA = 18   # transform (12), force (6)
_W_CRBA = 25   # transform (12), composite inertia m, h, I_O (13)
_W_ABA = 80    # transform (12), v (6), c (6), I^A (36), p^A (6), U (6), D, u, p^a (6)
_W_POSE = 12   # transform (12)


@njit(**_INLINE)
def _transform(P, i, qi, W):
    """Pose of link frame i in link frame i−1 into ``W[i, 0:12]`` (R row-major, then p)."""
    sx, sy, sz = P[i, 12], P[i, 13], P[i, 14]
    x = qi + P[i, 16]
    if P[i, 15] == REVOLUTE:
        # Rodrigues: R_J = cos θ E + (1 − cos θ) s sᵀ + sin θ [s]×
        c, s = math.cos(x), math.sin(x)
        k = 1.0 - c
        j00, j01, j02 = c + k * sx * sx, k * sx * sy - s * sz, k * sx * sz + s * sy
        j10, j11, j12 = k * sy * sx + s * sz, c + k * sy * sy, k * sy * sz - s * sx
        j20, j21, j22 = k * sz * sx - s * sy, k * sz * sy + s * sx, c + k * sz * sz
        for r in range(3):
            a, b, d = P[i, 3 * r], P[i, 3 * r + 1], P[i, 3 * r + 2]
            W[i, 3 * r] = a * j00 + b * j10 + d * j20
            W[i, 3 * r + 1] = a * j01 + b * j11 + d * j21
            W[i, 3 * r + 2] = a * j02 + b * j12 + d * j22
        W[i, 9], W[i, 10], W[i, 11] = P[i, 9], P[i, 10], P[i, 11]
    else:
        for k in range(9):
            W[i, k] = P[i, k]
        for r in range(3):
            W[i, 9 + r] = P[i, 9 + r] + x * (P[i, 3 * r] * sx + P[i, 3 * r + 1] * sy + P[i, 3 * r + 2] * sz)


@njit(**_INLINE)
def _rot_t(A, i, o, x, y, z):
    """``Rᵀ (x, y, z)`` with R row-major at ``A[i, o:o+9]`` (parent components → child)."""
    return (A[i, o] * x + A[i, o + 3] * y + A[i, o + 6] * z,
            A[i, o + 1] * x + A[i, o + 4] * y + A[i, o + 7] * z,
            A[i, o + 2] * x + A[i, o + 5] * y + A[i, o + 8] * z)


@njit(**_INLINE)
def _rot(A, i, o, x, y, z):
    """``R (x, y, z)`` with R row-major at ``A[i, o:o+9]`` (child components → parent)."""
    return (A[i, o] * x + A[i, o + 1] * y + A[i, o + 2] * z,
            A[i, o + 3] * x + A[i, o + 4] * y + A[i, o + 5] * z,
            A[i, o + 6] * x + A[i, o + 7] * y + A[i, o + 8] * z)


@njit(**_INLINE)
def _motion_to_child(W, i, wx, wy, wz, vx, vy, vz):
    """``X_i m``: motion vector (ω, v) of frame i−1 in frame i: ``(Rᵀ ω, Rᵀ (v − p × ω))``."""
    cx, cy, cz = cross(W[i, 9], W[i, 10], W[i, 11], wx, wy, wz)
    a = _rot_t(W, i, 0, wx, wy, wz)
    b = _rot_t(W, i, 0, vx - cx, vy - cy, vz - cz)
    return a[0], a[1], a[2], b[0], b[1], b[2]


@njit(**_INLINE)
def _force_to_parent(A, i, o, nx, ny, nz, fx, fy, fz):
    """``X_iᵀ f``: force (n, f) of the child frame in the parent frame: ``(R n + p × R f, R f)``.

    R row-major at ``A[i, o:o+9]``, p at ``A[i, o+9:o+12]``.
    """
    f = _rot(A, i, o, fx, fy, fz)
    n = _rot(A, i, o, nx, ny, nz)
    c = cross(A[i, o + 9], A[i, o + 10], A[i, o + 11], f[0], f[1], f[2])
    return n[0] + c[0], n[1] + c[1], n[2] + c[2], f[0], f[1], f[2]


@njit(**_INLINE)
def _inertia_times(P, i, wx, wy, wz, vx, vy, vz):
    """Rigid-body inertia of link i times a motion vector: ``(I_O ω + h × v, m v − h × ω)``."""
    hx, hy, hz = P[i, 18], P[i, 19], P[i, 20]
    a = cross(hx, hy, hz, vx, vy, vz)
    b = cross(hx, hy, hz, wx, wy, wz)
    m = P[i, 17]
    return (P[i, 21] * wx + P[i, 22] * wy + P[i, 23] * wz + a[0],
            P[i, 24] * wx + P[i, 25] * wy + P[i, 26] * wz + a[1],
            P[i, 27] * wx + P[i, 28] * wy + P[i, 29] * wz + a[2],
            m * vx - b[0], m * vy - b[1], m * vz - b[2])


@njit(**_INLINE)
def _external(P, fext):
    """The end-link wrench ``fext = (f, n)`` (user frame n, moment about its origin) in the canonical frame."""
    n = P.shape[0] - 1
    return _force_to_parent(P, n, 30, fext[3], fext[4], fext[5], fext[0], fext[1], fext[2])


# -- inverse dynamics: RNEA ----------------------------------------------------


@njit(**_JIT)
def rnea_one(P, q, qd, qdd, g, fext, W, tau):
    """``τ = ID(q, q̇, q̈)`` into ``tau``: Featherstone (2008) Table 5.1, the base accelerating at −g.

    Returns False when a torque is not finite (the caller then finds the bad input).
    """
    n = P.shape[0]
    wx = wy = wz = vx = vy = vz = 0.0
    ax = ay = az = 0.0
    lx, ly, lz = -g[0], -g[1], -g[2]
    for i in range(n):
        _transform(P, i, q[i], W)
        wx, wy, wz, vx, vy, vz = _motion_to_child(W, i, wx, wy, wz, vx, vy, vz)
        ax, ay, az, lx, ly, lz = _motion_to_child(W, i, ax, ay, az, lx, ly, lz)
        sx, sy, sz = P[i, 12], P[i, 13], P[i, 14]
        if P[i, 15] == REVOLUTE:
            wx, wy, wz = wx + sx * qd[i], wy + sy * qd[i], wz + sz * qd[i]
            c = cross(wx, wy, wz, sx * qd[i], sy * qd[i], sz * qd[i])
            d = cross(vx, vy, vz, sx * qd[i], sy * qd[i], sz * qd[i])
            ax, ay, az = ax + sx * qdd[i] + c[0], ay + sy * qdd[i] + c[1], az + sz * qdd[i] + c[2]
            lx, ly, lz = lx + d[0], ly + d[1], lz + d[2]
        else:
            vx, vy, vz = vx + sx * qd[i], vy + sy * qd[i], vz + sz * qd[i]
            c = cross(wx, wy, wz, sx * qd[i], sy * qd[i], sz * qd[i])
            lx, ly, lz = lx + sx * qdd[i] + c[0], ly + sy * qdd[i] + c[1], lz + sz * qdd[i] + c[2]
        # f = I a + v ×* (I v),  v ×* (n, f) = (ω × n + v × f, ω × f)
        f = _inertia_times(P, i, ax, ay, az, lx, ly, lz)
        h = _inertia_times(P, i, wx, wy, wz, vx, vy, vz)
        c1 = cross(wx, wy, wz, h[0], h[1], h[2])
        c2 = cross(vx, vy, vz, h[3], h[4], h[5])
        c3 = cross(wx, wy, wz, h[3], h[4], h[5])
        W[i, 12], W[i, 13], W[i, 14] = f[0] + c1[0] + c2[0], f[1] + c1[1] + c2[1], f[2] + c1[2] + c2[2]
        W[i, 15], W[i, 16], W[i, 17] = f[3] + c3[0], f[4] + c3[1], f[5] + c3[2]
    e = _external(P, fext)
    for k in range(6):
        W[n - 1, 12 + k] -= e[k]
    ok = True
    for i in range(n - 1, -1, -1):
        o = 12 if P[i, 15] == REVOLUTE else 15
        tau[i] = P[i, 12] * W[i, o] + P[i, 13] * W[i, o + 1] + P[i, 14] * W[i, o + 2]
        ok = ok and math.isfinite(tau[i])
        if i > 0:
            r = _force_to_parent(W, i, 0, W[i, 12], W[i, 13], W[i, 14], W[i, 15], W[i, 16], W[i, 17])
            for k in range(6):
                W[i - 1, 12 + k] += r[k]
    return ok


@njit(**_JIT)
def rnea(P, q, qd, qdd, g, fext, tau):
    """One sample: ``tau`` (n,) from ``q``, ``qd``, ``qdd`` (n,), ``g`` (3,), ``fext`` (6,)."""
    return rnea_one(P, q, qd, qdd, g, fext, np.empty((P.shape[0], _W_RNEA)), tau)


@njit(parallel=True, **_JIT)
def rnea_batch(P, Q, QD, QDD, g, F, TAU, nc):
    """A batch: ``TAU[b] = ID(Q[b], QD[b], QDD[b])``; ``F`` (1 or B, 6) the end-link wrenches."""
    B = Q.shape[0]
    wide = F.shape[0] > 1
    for c in prange(nc):
        W = np.empty((P.shape[0], _W_RNEA))
        for b in range(c * B // nc, (c + 1) * B // nc):
            rnea_one(P, Q[b], QD[b], QDD[b], g, F[b * wide], W, TAU[b])


# -- joint-space inertia: CRBA -------------------------------------------------


@njit(**_INLINE)
def _motion_subspace_force(W, i, o, s_rev, sx, sy, sz):
    """``F = I S`` for a composite rigid inertia (m, h, I_O) at ``W[i, o:o+13]`` and joint axis s."""
    m, hx, hy, hz = W[i, o], W[i, o + 1], W[i, o + 2], W[i, o + 3]
    if s_rev:  # S = (s, 0): (I_O s, s × h)
        c = cross(sx, sy, sz, hx, hy, hz)
        return (W[i, o + 4] * sx + W[i, o + 5] * sy + W[i, o + 6] * sz,
                W[i, o + 7] * sx + W[i, o + 8] * sy + W[i, o + 9] * sz,
                W[i, o + 10] * sx + W[i, o + 11] * sy + W[i, o + 12] * sz, c[0], c[1], c[2])
    c = cross(hx, hy, hz, sx, sy, sz)  # S = (0, s): (h × s, m s)
    return c[0], c[1], c[2], m * sx, m * sy, m * sz


@njit(**_INLINE)
def _project(P, j, F):
    """``S_jᵀ F`` for a force vector F = (n, f)."""
    o = 0 if P[j, 15] == REVOLUTE else 3
    return P[j, 12] * F[o] + P[j, 13] * F[o + 1] + P[j, 14] * F[o + 2]


@njit(**_JIT)
def crba_one(P, q, W, M):
    """Joint-space inertia matrix ``M(q)`` into ``M`` (n, n): Featherstone (2008) Table 6.2.

    The composite inertias stay rigid-body inertias (m, h, I_O), moved to the
    parent by ``h' = R h + m p``,
    ``I_O' = R I_O Rᵀ + (2 h'' · p + m|p|²) E − (h'' pᵀ + p h''ᵀ + m p pᵀ)``, ``h'' = R h``.
    """
    n = P.shape[0]
    for i in range(n):
        _transform(P, i, q[i], W)
        for k in range(13):
            W[i, 12 + k] = P[i, 17 + k]
    for i in range(n - 1, -1, -1):
        F = _motion_subspace_force(W, i, 12, P[i, 15] == REVOLUTE, P[i, 12], P[i, 13], P[i, 14])
        M[i, i] = _project(P, i, F)
        j = i
        while j > 0:
            F = _force_to_parent(W, j, 0, F[0], F[1], F[2], F[3], F[4], F[5])
            j -= 1
            M[i, j] = M[j, i] = _project(P, j, F)
        if i > 0:
            m = W[i, 12]
            hx, hy, hz = _rot(W, i, 0, W[i, 13], W[i, 14], W[i, 15])
            px, py, pz = W[i, 9], W[i, 10], W[i, 11]
            W[i - 1, 12] += m
            W[i - 1, 13] += hx + m * px
            W[i - 1, 14] += hy + m * py
            W[i - 1, 15] += hz + m * pz
            # R I_O Rᵀ
            for r in range(3):
                for c in range(3):
                    acc = 0.0
                    for a in range(3):
                        for b in range(3):
                            acc += W[i, 3 * r + a] * W[i, 16 + 3 * a + b] * W[i, 3 * c + b]
                    W[i - 1, 16 + 3 * r + c] += acc
            diag = 2.0 * (hx * px + hy * py + hz * pz) + m * (px * px + py * py + pz * pz)
            h = (hx, hy, hz)
            p = (px, py, pz)
            for r in range(3):
                for c in range(3):
                    W[i - 1, 16 + 3 * r + c] -= h[r] * p[c] + p[r] * h[c] + m * p[r] * p[c]
                W[i - 1, 16 + 4 * r] += diag


@njit(**_JIT)
def crba(P, q, M):
    crba_one(P, q, np.empty((P.shape[0], _W_CRBA)), M)


@njit(parallel=True, **_JIT)
def crba_batch(P, Q, M, nc):
    B = Q.shape[0]
    for c in prange(nc):
        W = np.empty((P.shape[0], _W_CRBA))
        for b in range(c * B // nc, (c + 1) * B // nc):
            crba_one(P, Q[b], W, M[b])


# -- forward dynamics: ABA -------------------------------------------------------


@njit(**_JIT)
def _add_articulated_to_parent(W, i, X, T):
    """``I^A_{i−1} += X_iᵀ I^a X_i`` with I^a at ``W[i, 24:60]``; X, T are (6, 6) scratch."""
    # X = [[E, 0], [−E [p]×, E]], E = Rᵀ
    for r in range(3):
        for c in range(3):
            e = W[i, 3 * c + r]
            X[r, c] = e
            X[3 + r, 3 + c] = e
            X[r, 3 + c] = 0.0
    for r in range(3):
        # row r of −E [p]× is −(eᵣᵀ [p]×) = −(eᵣ × p)ᵀ = (p × eᵣ)ᵀ,
        # eᵣ = row r of E = column r of R
        c = cross(W[i, 9], W[i, 10], W[i, 11], W[i, r], W[i, 3 + r], W[i, 6 + r])
        X[3 + r, 0], X[3 + r, 1], X[3 + r, 2] = c[0], c[1], c[2]
    for r in range(6):  # T = I^a X
        for c in range(6):
            acc = 0.0
            for k in range(6):
                acc += W[i, 24 + 6 * r + k] * X[k, c]
            T[r, c] = acc
    for r in range(6):  # I^A_{i−1} += Xᵀ T
        for c in range(6):
            acc = 0.0
            for k in range(6):
                acc += X[k, r] * T[k, c]
            W[i - 1, 24 + 6 * r + c] += acc


@njit(**_JIT)
def aba_one(P, q, qd, tau, g, fext, W, X, T, qdd):
    """``q̈ = FD(q, q̇, τ)`` into ``qdd``: the articulated-body algorithm, Featherstone (2008) Table 7.1.

    Returns False when an acceleration is not finite.
    """
    n = P.shape[0]
    wx = wy = wz = vx = vy = vz = 0.0
    for i in range(n):  # pass 1: velocities, bias accelerations c, rigid inertias, bias forces
        _transform(P, i, q[i], W)
        wx, wy, wz, vx, vy, vz = _motion_to_child(W, i, wx, wy, wz, vx, vy, vz)
        sx, sy, sz = P[i, 12] * qd[i], P[i, 13] * qd[i], P[i, 14] * qd[i]
        if P[i, 15] == REVOLUTE:
            wx, wy, wz = wx + sx, wy + sy, wz + sz
            c1 = cross(wx, wy, wz, sx, sy, sz)
            c2 = cross(vx, vy, vz, sx, sy, sz)
        else:
            vx, vy, vz = vx + sx, vy + sy, vz + sz
            c1 = (0.0, 0.0, 0.0)
            c2 = cross(wx, wy, wz, sx, sy, sz)
        W[i, 12], W[i, 13], W[i, 14], W[i, 15], W[i, 16], W[i, 17] = wx, wy, wz, vx, vy, vz
        W[i, 18], W[i, 19], W[i, 20], W[i, 21], W[i, 22], W[i, 23] = c1[0], c1[1], c1[2], c2[0], c2[1], c2[2]
        # I^A = [[I_O, [h]×], [−[h]×, m E]]
        m, hx, hy, hz = P[i, 17], P[i, 18], P[i, 19], P[i, 20]
        for r in range(3):
            for c in range(3):
                W[i, 24 + 6 * r + c] = P[i, 21 + 3 * r + c]
                W[i, 24 + 6 * (3 + r) + 3 + c] = m if r == c else 0.0
        hxm = ((0.0, -hz, hy), (hz, 0.0, -hx), (-hy, hx, 0.0))
        for r in range(3):
            for c in range(3):
                W[i, 24 + 6 * r + 3 + c] = hxm[r][c]
                W[i, 24 + 6 * (3 + r) + c] = -hxm[r][c]
        h = _inertia_times(P, i, wx, wy, wz, vx, vy, vz)
        d1 = cross(wx, wy, wz, h[0], h[1], h[2])
        d2 = cross(vx, vy, vz, h[3], h[4], h[5])
        d3 = cross(wx, wy, wz, h[3], h[4], h[5])
        W[i, 60], W[i, 61], W[i, 62] = d1[0] + d2[0], d1[1] + d2[1], d1[2] + d2[2]
        W[i, 63], W[i, 64], W[i, 65] = d3[0], d3[1], d3[2]
    e = _external(P, fext)
    for k in range(6):
        W[n - 1, 60 + k] -= e[k]
    for i in range(n - 1, -1, -1):  # pass 2: articulated inertias and bias forces
        o = 0 if P[i, 15] == REVOLUTE else 3
        sx, sy, sz = P[i, 12], P[i, 13], P[i, 14]
        for r in range(6):  # U = I^A S
            W[i, 66 + r] = (W[i, 24 + 6 * r + o] * sx + W[i, 24 + 6 * r + o + 1] * sy
                            + W[i, 24 + 6 * r + o + 2] * sz)
        D = W[i, 66 + o] * sx + W[i, 67 + o] * sy + W[i, 68 + o] * sz
        u = tau[i] - (W[i, 60 + o] * sx + W[i, 61 + o] * sy + W[i, 62 + o] * sz)
        W[i, 72], W[i, 73] = D, u
        if i > 0:
            # I^a = I^A − U Uᵀ/D (in place), p^a = p^A + I^a c + U u/D
            for r in range(6):
                for c in range(6):
                    W[i, 24 + 6 * r + c] -= W[i, 66 + r] * W[i, 66 + c] / D
            for r in range(6):
                acc = W[i, 60 + r] + W[i, 66 + r] * u / D
                for c in range(6):
                    acc += W[i, 24 + 6 * r + c] * W[i, 18 + c]
                W[i, 74 + r] = acc
            _add_articulated_to_parent(W, i, X, T)
            f = _force_to_parent(W, i, 0, W[i, 74], W[i, 75], W[i, 76], W[i, 77], W[i, 78], W[i, 79])
            for k in range(6):
                W[i - 1, 60 + k] += f[k]
    ax = ay = az = 0.0
    lx, ly, lz = -g[0], -g[1], -g[2]
    ok = True
    for i in range(n):  # pass 3: accelerations
        ax, ay, az, lx, ly, lz = _motion_to_child(W, i, ax, ay, az, lx, ly, lz)
        ax, ay, az = ax + W[i, 18], ay + W[i, 19], az + W[i, 20]
        lx, ly, lz = lx + W[i, 21], ly + W[i, 22], lz + W[i, 23]
        Ua = (W[i, 66] * ax + W[i, 67] * ay + W[i, 68] * az + W[i, 69] * lx + W[i, 70] * ly + W[i, 71] * lz)
        qdd[i] = (W[i, 73] - Ua) / W[i, 72]
        ok = ok and math.isfinite(qdd[i])
        sx, sy, sz = P[i, 12] * qdd[i], P[i, 13] * qdd[i], P[i, 14] * qdd[i]
        if P[i, 15] == REVOLUTE:
            ax, ay, az = ax + sx, ay + sy, az + sz
        else:
            lx, ly, lz = lx + sx, ly + sy, lz + sz
    return ok


@njit(**_JIT)
def aba_scratch(n):
    """Scratch arrays of :func:`aba_one` for a chain of n joints."""
    return np.empty((n, _W_ABA)), np.empty((6, 6)), np.empty((6, 6))


@njit(**_JIT)
def aba(P, q, qd, tau, g, fext, qdd):
    W, X, T = aba_scratch(P.shape[0])
    return aba_one(P, q, qd, tau, g, fext, W, X, T, qdd)


@njit(parallel=True, **_JIT)
def aba_batch(P, Q, QD, TAU, g, F, QDD, nc):
    B = Q.shape[0]
    wide = F.shape[0] > 1
    for c in prange(nc):
        W, X, T = aba_scratch(P.shape[0])
        for b in range(c * B // nc, (c + 1) * B // nc):
            aba_one(P, Q[b], QD[b], TAU[b], g, F[b * wide], W, X, T, QDD[b])


# -- kinematics and energy -----------------------------------------------------


@njit(**_JIT)
def poses_one(P, q, W, T):
    """World poses of the user's link frames into ``T`` (n, 4, 4) (homogeneous, base frame)."""
    n = P.shape[0]
    Rw = np.eye(3)
    pw = np.zeros(3)
    Rn = np.empty((3, 3))
    for i in range(n):
        _transform(P, i, q[i], W)
        for r in range(3):
            x, y, z = Rw[r, 0], Rw[r, 1], Rw[r, 2]
            pw[r] += x * W[i, 9] + y * W[i, 10] + z * W[i, 11]
            for c in range(3):
                Rn[r, c] = x * W[i, c] + y * W[i, 3 + c] + z * W[i, 6 + c]
        Rw[:, :] = Rn
        for r in range(3):  # user frame = canonical frame ∘ (R_f, p_f)
            x, y, z = Rw[r, 0], Rw[r, 1], Rw[r, 2]
            T[i, r, 3] = pw[r] + x * P[i, 39] + y * P[i, 40] + z * P[i, 41]
            for c in range(3):
                T[i, r, c] = x * P[i, 30 + c] + y * P[i, 33 + c] + z * P[i, 36 + c]
            T[i, 3, r] = 0.0
        T[i, 3, 3] = 1.0


@njit(**_JIT)
def energy_one(P, q, qd, g, W):
    """``(T, V)``: kinetic energy ``Σ ½ vᵢᵀ Iᵢ vᵢ`` and potential ``−Σ g · (mᵢ pᵢ + R_i hᵢ)`` (J).

    ``pᵢ``, ``R_i``: pose of link frame i in the base frame, whose origin is the zero of V.
    """
    n = P.shape[0]
    wx = wy = wz = vx = vy = vz = 0.0
    Rw = np.eye(3)
    Rn = np.empty((3, 3))
    pw = np.zeros(3)
    kinetic = potential = 0.0
    for i in range(n):
        _transform(P, i, q[i], W)
        wx, wy, wz, vx, vy, vz = _motion_to_child(W, i, wx, wy, wz, vx, vy, vz)
        sx, sy, sz = P[i, 12] * qd[i], P[i, 13] * qd[i], P[i, 14] * qd[i]
        if P[i, 15] == REVOLUTE:
            wx, wy, wz = wx + sx, wy + sy, wz + sz
        else:
            vx, vy, vz = vx + sx, vy + sy, vz + sz
        h = _inertia_times(P, i, wx, wy, wz, vx, vy, vz)
        kinetic += 0.5 * (wx * h[0] + wy * h[1] + wz * h[2] + vx * h[3] + vy * h[4] + vz * h[5])
        for r in range(3):
            x, y, z = Rw[r, 0], Rw[r, 1], Rw[r, 2]
            pw[r] += x * W[i, 9] + y * W[i, 10] + z * W[i, 11]
            for c in range(3):
                Rn[r, c] = x * W[i, c] + y * W[i, 3 + c] + z * W[i, 6 + c]
        Rw[:, :] = Rn
        for r in range(3):
            first = P[i, 17] * pw[r] + Rw[r, 0] * P[i, 18] + Rw[r, 1] * P[i, 19] + Rw[r, 2] * P[i, 20]
            potential -= g[r] * first
    return kinetic, potential


@njit(**_JIT)
def energy_batch(P, Q, QD, g, OUT):
    """``OUT[b] = (T, V)`` of sample b (serial: energies are for checks and plots, not hot loops)."""
    W = np.empty((P.shape[0], _W_POSE))
    for b in range(Q.shape[0]):
        OUT[b, 0], OUT[b, 1] = energy_one(P, Q[b], QD[b], g, W)


@njit(**_JIT)
def poses_batch(P, Q, T):
    """``T[b]`` = the link poses of sample b (serial)."""
    W = np.empty((P.shape[0], _W_POSE))
    for b in range(Q.shape[0]):
        poses_one(P, Q[b], W, T[b])
