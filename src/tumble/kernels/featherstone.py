"""Compiled rigid-body algorithms for kinematic trees: RNEA, CRBA, ABA, energies, body poses.

Spatial vector algebra (Featherstone, *Rigid Body Dynamics Algorithms*,
Springer 2008, ch. 2), written with 3-vectors so that every quantity lives in
registers: a motion vector is ``(ω, v)`` (angular velocity, velocity of the
body point at the frame origin), a force vector ``(n, f)`` (moment about the
frame origin, force), both in body axes.

A robot is a kinematic tree in Featherstone's form (2008, §4.1.2): bodies
numbered so that every parent comes before its children, ``λ(i) < i``. It is
one float64 array ``P`` of shape (nb, PARAMS), built once by
:class:`tumble.robot.RobotTree`; row ``i`` describes joint ``i`` and body ``i``
it moves, in *canonical* frames whose origin lies on the joint axis and whose
z axis is that axis:

=========  ==============================================================
columns    meaning
=========  ==============================================================
0–8        ``R``: axes of joint frame i (before motion) in body frame λ(i), row-major
9–11       ``p``: origin of joint frame i in body frame λ(i) (m)
12–14      ``s = e_z = (0, 0, 1)``: the joint axis in the canonical frames
           (always z: the algorithms below turn about and slide along z only)
15         joint type: 0 revolute, 1 prismatic, 2 free (the floating base)
16         offset: the joint variable is ``k q[c] + offset`` (rad or m)
17         ``m``: body mass (kg)
18–20      ``h = m c``: first mass moment about the body origin (kg·m)
21–29      ``I_O``: rotational inertia about the body origin, row-major (kg·m²)
30–38      ``R_f``: axes of the user's body frame in the canonical frame
39–41      ``p_f``: origin of the user's body frame in the canonical frame (m)
42         ``λ(i)``: the parent body, −1 for the fixed base (or the world, for the free body)
43         ``c``: index of the joint's velocity coordinate in ``q̇``
44         ``k``: multiplier; a mimic joint shares the coordinate ``c`` of the joint it copies
=========  ==============================================================

Motion of joint i: revolute ``R_J = Rz(θ)``; prismatic ``p_J = θ e_z``,
``θ = k q[c] + offset``, ``θ̇ = k q̇[c]``; the motion subspace ``S = (e_z, 0)``
or ``(0, e_z)``, so that ``S q̇`` and ``Sᵀ f`` are one component. A *floating
base* is body 0 with a free joint (type 2) to the world: its configuration ``q[0:7] = (r, quat)``,
the origin of body 0 in the world frame (m) and the unit quaternion
``[w, x, y, z]`` of body 0 → world, its velocity ``q̇[0:6] = (ω, v)`` in body
0 axes; the joint coordinates follow, so the configuration index of
coordinate ``c`` is ``c + 1``. Gravity ``g`` is given in the world (base)
frame and enters as a base acceleration ``−g`` (Featherstone 2008, §5.3).

Mimic joints (several bodies on one coordinate) are constrained coordinates
``θ = G q + offset``: RNEA returns ``Gᵀ τ`` and CRBA ``Gᵀ M G``; the
articulated-body algorithm does not apply and :func:`forward_one` solves
``M q̈ = τ − h`` by Cholesky instead.

The single-sample functions ``*_one`` take a scratch array ``W`` (nb,
_WIDTH), allocated once per chunk of a batch; ``*_batch`` run a batch in
parallel: ``prange`` over ``nc`` chunks of consecutive samples. The
single-state entries :func:`rnea`, :func:`crba`, :func:`aba` take their
scratch as one flat :func:`workspace` kept by the model and allocate nothing.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble._vec import cross

PARAMS = 45
REVOLUTE, PRISMATIC, FREE = 0, 1, 2
PARENT, COORDINATE, MULTIPLIER = 42, 43, 44
# Compiler options: fused multiply-adds allowed (contraction only: no reassociation,
# NaN and inf keep their meaning, so the finiteness checks stay valid); a division
# by zero gives inf or NaN (found by those checks) rather than an exception; the
# small vector helpers are inlined in Numba's IR (measured 0.9 → 0.5 µs per
# 7-DOF RNEA).
_JIT = {"cache": True, "fastmath": {"contract"}, "error_model": "numpy"}
_INLINE = {**_JIT, "inline": "always"}
# The sweeps and the single-state entries allocate nothing, so they are compiled without
# Numba's reference counting (``_nrt=False``): else every array argument, every array handed
# to an inlined helper and every row view of a batch costs an atomic increment and decrement
# of a shared counter, 16 per call and 4 per body in RNEA (measured: 7-DOF RNEA sweep 413 →
# 341 ns), and a call from Python wraps each array in a counted record (measured: the entry
# of a one-link RNEA called from Python 0.43 → 0.22 µs).
_NO_REFCOUNT = {**_JIT, "_nrt": False}
# Scratch columns per body: transform (0–11), v (12–17), a or c (18–23), f or I^A (24–59),
# p^A or the body momentum I v of centroidal_momentum_one (60–65), U (66–71), D, u (72, 73), p^a (74–79),
# ABA's a (80–85); CRBA's composite inertia (m, h, I_O) at 12–24 and I_O Rᵀ at 25–33; world poses at 12–23.
_WIDTH = 86


@njit(**_JIT)
def floating(P):
    """1 when body 0 is a floating base (free joint), else 0 (also the configuration index shift)."""
    return 1 if P[0, 15] == FREE else 0


@njit(**_INLINE)
def _free_transform(q, W):
    """Pose of the floating body 0 in the world, from ``q[0:7] = (r, quat)``, into ``W[0, 0:12]``."""
    qw, qx, qy, qz = q[3], q[4], q[5], q[6]
    xx, yy, zz, xy, xz, yz = qx * qx, qy * qy, qz * qz, qx * qy, qx * qz, qy * qz
    wx, wy, wz = qw * qx, qw * qy, qw * qz
    W[0, 0], W[0, 1], W[0, 2] = 1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy)
    W[0, 3], W[0, 4], W[0, 5] = 2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx)
    W[0, 6], W[0, 7], W[0, 8] = 2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy)
    W[0, 9], W[0, 10], W[0, 11] = q[0], q[1], q[2]


@njit(**_INLINE)
def _transform(P, i, x, W):
    """Pose of body frame i in body frame λ(i), joint variable ``x``, into ``W[i, 0:12]`` (R row-major, p):
    revolute ``R = R_o Rz(x)``, ``p = p_o``; prismatic ``R = R_o``, ``p = p_o + x R_o e_z``."""
    if P[i, 15] == REVOLUTE:
        c, s = math.cos(x), math.sin(x)
        for r in range(3):
            a, b = P[i, 3 * r], P[i, 3 * r + 1]
            W[i, 3 * r] = a * c + b * s
            W[i, 3 * r + 1] = b * c - a * s
            W[i, 3 * r + 2] = P[i, 3 * r + 2]
        W[i, 9], W[i, 10], W[i, 11] = P[i, 9], P[i, 10], P[i, 11]
    else:
        for k in range(9):
            W[i, k] = P[i, k]
        for r in range(3):
            W[i, 9 + r] = P[i, 9 + r] + x * P[i, 3 * r + 2]


@njit(**_INLINE)
def _joint(P, i, q, fl):
    """``(c, k, θ)``: coordinate index, multiplier and joint variable of joint i (not the free joint)."""
    c = int(P[i, COORDINATE])
    k = P[i, MULTIPLIER]
    return c, k, k * q[c + fl] + P[i, 16]


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
    """``X_i m``: motion vector (ω, v) of frame λ(i) in frame i: ``(Rᵀ ω, Rᵀ (v − p × ω))``."""
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
    """Rigid-body inertia of body i times a motion vector: ``(I_O ω + h × v, m v − h × ω)``."""
    hx, hy, hz = P[i, 18], P[i, 19], P[i, 20]
    a = cross(hx, hy, hz, vx, vy, vz)
    b = cross(hx, hy, hz, wx, wy, wz)
    m = P[i, 17]
    return (P[i, 21] * wx + P[i, 22] * wy + P[i, 23] * wz + a[0],
            P[i, 24] * wx + P[i, 25] * wy + P[i, 26] * wz + a[1],
            P[i, 27] * wx + P[i, 28] * wy + P[i, 29] * wz + a[2],
            m * vx - b[0], m * vy - b[1], m * vz - b[2])


@njit(**_INLINE)
def _bias_force(P, i, wx, wy, wz, vx, vy, vz):
    """``v ×* (I v)``, with ``v ×* (n, f) = (ω × n + v × f, ω × f)``."""
    h = _inertia_times(P, i, wx, wy, wz, vx, vy, vz)
    c1 = cross(wx, wy, wz, h[0], h[1], h[2])
    c2 = cross(vx, vy, vz, h[3], h[4], h[5])
    c3 = cross(wx, wy, wz, h[3], h[4], h[5])
    return c1[0] + c2[0], c1[1] + c2[1], c1[2] + c2[2], c3[0], c3[1], c3[2]


@njit(**_INLINE)
def _external(P, fext):
    """The last body's wrench ``fext = (f, n)`` (user frame, moment about its origin) in its canonical frame."""
    n = P.shape[0] - 1
    return _force_to_parent(P, n, 30, fext[3], fext[4], fext[5], fext[0], fext[1], fext[2])


@njit(**_INLINE)
def _gravity_in_body0(W, g):
    """``R₀ᵀ g``: gravity (world axes) in the axes of the floating body 0 (transform at ``W[0]``)."""
    return _rot_t(W, 0, 0, g[0], g[1], g[2])


# -- inverse dynamics: RNEA ----------------------------------------------------


@njit(**_NO_REFCOUNT)
def rnea_one(P, q, qd, qdd, g, fext, W, tau):
    """``τ = ID(q, q̇, q̈)`` into ``tau``: Featherstone (2008) Table 5.1 on a tree, the base accelerating at −g.

    With a floating base, ``qdd[0:6]`` is the base's spatial acceleration and
    ``tau[0:6]`` the wrench ``(n, f)`` on it (body 0 axes) that this motion
    needs (Featherstone 2008, §9.3). Returns False when a torque is not finite.
    """
    nb = P.shape[0]
    fl = floating(P)
    for k in range(tau.shape[0]):
        tau[k] = 0.0
    for i in range(nb):
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            _free_transform(q, W)
            gx, gy, gz = _gravity_in_body0(W, g)
            wx, wy, wz, vx, vy, vz = qd[0], qd[1], qd[2], qd[3], qd[4], qd[5]
            ax, ay, az, lx, ly, lz = qdd[0], qdd[1], qdd[2], qdd[3] - gx, qdd[4] - gy, qdd[5] - gz
        else:
            c, k, x = _joint(P, i, q, fl)
            _transform(P, i, x, W)
            if par < 0:
                wx = wy = wz = vx = vy = vz = 0.0
                ax, ay, az, lx, ly, lz = _motion_to_child(W, i, 0.0, 0.0, 0.0, -g[0], -g[1], -g[2])
            else:
                wx, wy, wz, vx, vy, vz = _motion_to_child(W, i, W[par, 12], W[par, 13], W[par, 14],
                                                          W[par, 15], W[par, 16], W[par, 17])
                ax, ay, az, lx, ly, lz = _motion_to_child(W, i, W[par, 18], W[par, 19], W[par, 20],
                                                          W[par, 21], W[par, 22], W[par, 23])
            xd, xdd = k * qd[c], k * qdd[c]
            if P[i, 15] == REVOLUTE:  # v += S ẋ, a += S ẍ + v × S ẋ with S ẋ = (ẋ e_z, 0)
                wz += xd
                ax, ay, az = ax + wy * xd, ay - wx * xd, az + xdd
                lx, ly = lx + vy * xd, ly - vx * xd
            else:  # S ẋ = (0, ẋ e_z)
                vz += xd
                lx, ly, lz = lx + wy * xd, ly - wx * xd, lz + xdd
        W[i, 12], W[i, 13], W[i, 14], W[i, 15], W[i, 16], W[i, 17] = wx, wy, wz, vx, vy, vz
        W[i, 18], W[i, 19], W[i, 20], W[i, 21], W[i, 22], W[i, 23] = ax, ay, az, lx, ly, lz
        # f = I a + v ×* (I v)
        f = _inertia_times(P, i, ax, ay, az, lx, ly, lz)
        b = _bias_force(P, i, wx, wy, wz, vx, vy, vz)
        for k in range(6):
            W[i, 24 + k] = f[k] + b[k]
    e = _external(P, fext)
    for k in range(6):
        W[nb - 1, 24 + k] -= e[k]
    for i in range(nb - 1, -1, -1):
        if fl == 1 and i == 0:
            for k in range(6):
                tau[k] = W[0, 24 + k]
            break
        c = int(P[i, COORDINATE])  # τ = Sᵀ f: n_z or f_z
        tau[c] += P[i, MULTIPLIER] * W[i, 26 if P[i, 15] == REVOLUTE else 29]
        par = int(P[i, PARENT])
        if par >= 0:
            r = _force_to_parent(W, i, 0, W[i, 24], W[i, 25], W[i, 26], W[i, 27], W[i, 28], W[i, 29])
            for k in range(6):
                W[par, 24 + k] += r[k]
    ok = True
    for k in range(tau.shape[0]):
        ok = ok and math.isfinite(tau[k])
    return ok


@njit(**_JIT)
def scratch(nb):
    """The scratch array of the ``*_one`` functions for a tree of nb bodies."""
    return np.empty((nb, _WIDTH))


def workspace(nb: int, nv: int) -> np.ndarray:
    """The flat scratch of the single-state entries for a tree of nb bodies and nv velocity coordinates, in
    order: the per-body scratch (nb, _WIDTH); ABA's two 6×6 blocks; for mimic joints M (nv, nv) and nv zeros;
    a contiguous copy of the state (q, nq ≤ nv + 1, and two nv-vectors)."""
    return np.empty(nb * _WIDTH + 72 + nv * nv + 4 * nv + 1)


@njit(**_INLINE)
def _fits(P, S, q, nv):
    """True when ``q`` has the tree's nq = nv + (1 with a floating base) entries and ``S`` is its workspace."""
    return q.shape[0] == nv + floating(P) and S.shape[0] == P.shape[0] * _WIDTH + 72 + nv * nv + 4 * nv + 1


@njit(**_INLINE)
def _state_fits(P, S, q, qd, other, g, fext, nv):
    """:func:`_fits`, and ``qd`` and ``other`` of nv entries, ``g`` of 3 and ``fext`` of 6."""
    return (_fits(P, S, q, nv) and qd.shape[0] == nv and other.shape[0] == nv and g.shape[0] == 3
            and fext.shape[0] == 6)


@njit(**_INLINE)
def _body_scratch(P, S):
    """The per-body scratch ``W`` (nb, _WIDTH) at the start of a :func:`workspace` ``S``."""
    return S[:P.shape[0] * _WIDTH].reshape(P.shape[0], _WIDTH)


@njit(**_INLINE)
def _state_offset(P, nv):
    """Where the copy of the state starts in a :func:`workspace`."""
    return P.shape[0] * _WIDTH + 72 + nv * nv + nv


@njit(**_INLINE)
def _copy(x, S, o):
    """``x`` (n,) copied into ``S[o:o + n]``, returned as that contiguous view: the array type of a batch's
    rows, so that one compiled version of each sweep serves single states and batches."""
    for k in range(x.shape[0]):
        S[o + k] = x[k]
    return S[o:o + x.shape[0]]


@njit(**_NO_REFCOUNT)
def rnea(P, q, qd, qdd, g, fext, S, tau):
    """One sample: ``tau`` (nv,) from ``q`` (nq,), ``qd``, ``qdd`` (nv,), ``g`` (3,), ``fext`` (6,), scratch
    ``S`` = :func:`workspace`.

    Returns False when a size does not fit (then ``tau`` is left as it was) or a torque is not finite.
    """
    nq, nv = q.shape[0], tau.shape[0]
    if not _state_fits(P, S, q, qd, qdd, g, fext, nv):
        return False
    o = _state_offset(P, nv)
    return rnea_one(P, _copy(q, S, o), _copy(qd, S, o + nq), _copy(qdd, S, o + nq + nv), g, fext,
                    _body_scratch(P, S), tau)


@njit(**_NO_REFCOUNT)
def _rnea_rows(P, Q, QD, QDD, g, F, W, TAU, start, stop):
    """Samples ``start ≤ b < stop`` of :func:`rnea_batch`, scratch ``W``."""
    wide = F.shape[0] > 1
    for b in range(start, stop):
        rnea_one(P, Q[b], QD[b], QDD[b], g, F[b * wide], W, TAU[b])


@njit(parallel=True, **_JIT)
def rnea_batch(P, Q, QD, QDD, g, F, TAU, nc):
    """A batch: ``TAU[b] = ID(Q[b], QD[b], QDD[b])``; ``F`` (1 or B, 6) the last body's wrenches."""
    B = Q.shape[0]
    for c in prange(nc):
        _rnea_rows(P, Q, QD, QDD, g, F, scratch(P.shape[0]), TAU, c * B // nc, (c + 1) * B // nc)


# -- joint-space inertia: CRBA -------------------------------------------------


@njit(**_INLINE)
def _motion_subspace_force(W, i, revolute):
    """``F = I S`` for the composite rigid inertia (m, h, I_O) at ``W[i, 12:25]``: S = (e_z, 0) gives
    ``(I_O e_z, e_z × h)``, S = (0, e_z) gives ``(h × e_z, m e_z)``."""
    if revolute:
        return W[i, 18], W[i, 21], W[i, 24], -W[i, 14], W[i, 13], 0.0
    return W[i, 14], -W[i, 13], 0.0, 0.0, 0.0, W[i, 12]


@njit(**_INLINE)
def _project(P, j, F):
    """``S_jᵀ F`` for a force vector F = (n, f): n_z or f_z."""
    return F[2] if P[j, 15] == REVOLUTE else F[5]


@njit(**_NO_REFCOUNT)
def _add_composite_to_parent(W, i, par):
    """``I^c_λ += X_iᵀ I^c_i X_i`` for rigid inertias (m, h, I_O): ``h' = R h + m p``,
    ``I_O' = R I_O Rᵀ + (2 h'' · p + m|p|²) E − (h'' pᵀ + p h''ᵀ + m p pᵀ)``, ``h'' = R h``.

    ``R I_O Rᵀ`` as ``R (I_O Rᵀ)``, the product kept in ``W[i, 25:34]``; symmetric, so its upper triangle is
    computed and mirrored."""
    m = W[i, 12]
    hx, hy, hz = _rot(W, i, 0, W[i, 13], W[i, 14], W[i, 15])
    px, py, pz = W[i, 9], W[i, 10], W[i, 11]
    W[par, 12] += m
    W[par, 13] += hx + m * px
    W[par, 14] += hy + m * py
    W[par, 15] += hz + m * pz
    for a in range(3):  # I_O Rᵀ: row a of I_O against row c of R
        for c in range(3):
            W[i, 25 + 3 * a + c] = (W[i, 16 + 3 * a] * W[i, 3 * c] + W[i, 17 + 3 * a] * W[i, 3 * c + 1]
                                    + W[i, 18 + 3 * a] * W[i, 3 * c + 2])
    diag = 2.0 * (hx * px + hy * py + hz * pz) + m * (px * px + py * py + pz * pz)
    h = (hx, hy, hz)
    p = (px, py, pz)
    for r in range(3):
        for c in range(r, 3):
            x = (W[i, 3 * r] * W[i, 25 + c] + W[i, 3 * r + 1] * W[i, 28 + c] + W[i, 3 * r + 2] * W[i, 31 + c]
                 - (h[r] * p[c] + p[r] * h[c] + m * p[r] * p[c]))
            if r == c:
                W[par, 16 + 4 * r] += x + diag
            else:
                W[par, 16 + 3 * r + c] += x
                W[par, 16 + 3 * c + r] += x


@njit(**_NO_REFCOUNT)
def crba_one(P, q, W, M):
    """Joint-space inertia matrix ``M(q)`` into ``M`` (nv, nv): Featherstone (2008) Table 6.2 on a tree.

    With a floating base, ``M[0:6, 0:6]`` is the composite inertia of the
    whole robot in body 0 axes (Featherstone 2008, §9.3); with mimic joints
    the result is ``Gᵀ M G`` in the independent coordinates.
    """
    nb = P.shape[0]
    fl = floating(P)
    M[:, :] = 0.0
    for i in range(nb):
        if fl == 1 and i == 0:
            _free_transform(q, W)
        else:
            _transform(P, i, _joint(P, i, q, fl)[2], W)
        for k in range(13):
            W[i, 12 + k] = P[i, 17 + k]
    for i in range(nb - 1, -1, -1):
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:  # S = E: the composite inertia as a 6×6 [[I_O, [h]×], [−[h]×, m E]]
            m, hx, hy, hz = W[0, 12], W[0, 13], W[0, 14], W[0, 15]
            hxm = ((0.0, -hz, hy), (hz, 0.0, -hx), (-hy, hx, 0.0))
            for r in range(3):
                for c in range(3):
                    M[r, c] += W[0, 16 + 3 * r + c]
                    M[r, 3 + c] += hxm[r][c]
                    M[3 + r, c] -= hxm[r][c]
                M[3 + r, 3 + r] += m
            break
        F = _motion_subspace_force(W, i, P[i, 15] == REVOLUTE)
        ci, ki = int(P[i, COORDINATE]), P[i, MULTIPLIER]
        M[ci, ci] += ki * ki * _project(P, i, F)
        j = i
        while int(P[j, PARENT]) >= 0:
            F = _force_to_parent(W, j, 0, F[0], F[1], F[2], F[3], F[4], F[5])
            j = int(P[j, PARENT])
            if fl == 1 and j == 0:
                for r in range(6):
                    M[r, ci] += ki * F[r]
                    M[ci, r] += ki * F[r]
            else:
                cj = int(P[j, COORDINATE])
                x = ki * P[j, MULTIPLIER] * _project(P, j, F)
                M[ci, cj] += x
                M[cj, ci] += x
        if par >= 0:
            _add_composite_to_parent(W, i, par)


@njit(**_NO_REFCOUNT)
def crba(P, q, S, M):
    """One sample: ``M`` (nv, nv) from ``q`` (nq,), scratch ``S`` = :func:`workspace`. Returns False when a size
    does not fit (then ``M`` is left as it was) or an entry is not finite."""
    nv = M.shape[0]
    if not (_fits(P, S, q, nv) and M.shape[1] == nv):
        return False
    crba_one(P, _copy(q, S, _state_offset(P, nv)), _body_scratch(P, S), M)
    ok = True
    for r in range(nv):
        for c in range(nv):
            ok = ok and math.isfinite(M[r, c])
    return ok


@njit(**_NO_REFCOUNT)
def _crba_rows(P, Q, W, M, start, stop):
    """Samples ``start ≤ b < stop`` of :func:`crba_batch`, scratch ``W``."""
    for b in range(start, stop):
        crba_one(P, Q[b], W, M[b])


@njit(parallel=True, **_JIT)
def crba_batch(P, Q, M, nc):
    """A batch: ``M[b] = M(Q[b])``."""
    B = Q.shape[0]
    for c in prange(nc):
        _crba_rows(P, Q, scratch(P.shape[0]), M, c * B // nc, (c + 1) * B // nc)


# -- forward dynamics: ABA -------------------------------------------------------


@njit(**_NO_REFCOUNT)
def _add_articulated_to_parent(W, i, par, X, T):
    """``I^A_λ += X_iᵀ I^a X_i`` with I^a at ``W[i, 24:60]``; X, T are (6, 6) scratch."""
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
    for r in range(6):  # I^A_λ += Xᵀ T
        for c in range(6):
            acc = 0.0
            for k in range(6):
                acc += X[k, r] * T[k, c]
            W[par, 24 + 6 * r + c] += acc


@njit(**_NO_REFCOUNT)
def cholesky_solve(A, b):
    """Solve ``A x = b`` in place (``x`` into ``b``) for a symmetric positive-definite ``A`` (n, n), overwritten
    by its Cholesky factor L (``A = L Lᵀ``, lower triangle). A non-positive pivot gives NaN."""
    n = A.shape[0]
    for j in range(n):
        d = A[j, j]
        for k in range(j):
            d -= A[j, k] * A[j, k]
        d = math.sqrt(d) if d > 0.0 else math.nan
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= A[i, k] * b[k]
        b[i] = s / A[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= A[k, i] * b[k]
        b[i] = s / A[i, i]


@njit(**_NO_REFCOUNT)
def aba_one(P, q, qd, tau, g, fext, W, X, T, qdd):
    """``q̈ = FD(q, q̇, τ)`` into ``qdd``: the articulated-body algorithm on a tree, Featherstone (2008)
    Table 7.1; with a floating base, Table 9.6 (the base acceleration from ``I^A_0 a₀ = τ₀ − p^A_0``,
    gravity as a fictitious acceleration). No mimic joints. Returns False when an acceleration is not finite.
    """
    nb = P.shape[0]
    fl = floating(P)
    for i in range(nb):  # pass 1: velocities, bias accelerations c, rigid inertias, bias forces
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            _free_transform(q, W)
            wx, wy, wz, vx, vy, vz = qd[0], qd[1], qd[2], qd[3], qd[4], qd[5]
            c1 = c2 = (0.0, 0.0, 0.0)
        else:
            c, k, x = _joint(P, i, q, fl)
            _transform(P, i, x, W)
            if par < 0:
                wx = wy = wz = vx = vy = vz = 0.0
            else:
                wx, wy, wz, vx, vy, vz = _motion_to_child(W, i, W[par, 12], W[par, 13], W[par, 14],
                                                          W[par, 15], W[par, 16], W[par, 17])
            xd = qd[c]
            if P[i, 15] == REVOLUTE:  # v += S ẋ, c = v × S ẋ with S ẋ = (ẋ e_z, 0)
                wz += xd
                c1 = (wy * xd, -wx * xd, 0.0)
                c2 = (vy * xd, -vx * xd, 0.0)
            else:  # S ẋ = (0, ẋ e_z)
                vz += xd
                c1 = (0.0, 0.0, 0.0)
                c2 = (wy * xd, -wx * xd, 0.0)
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
        b = _bias_force(P, i, wx, wy, wz, vx, vy, vz)
        for k in range(6):
            W[i, 60 + k] = b[k]
    e = _external(P, fext)
    for k in range(6):
        W[nb - 1, 60 + k] -= e[k]
    for i in range(nb - 1, fl - 1, -1):  # pass 2: articulated inertias and bias forces
        c = int(P[i, COORDINATE])
        j = 2 if P[i, 15] == REVOLUTE else 5  # S = e_j, the 6-vector (e_z, 0) or (0, e_z)
        for r in range(6):  # U = I^A S, D = Sᵀ U, u = τ − Sᵀ p^A
            W[i, 66 + r] = W[i, 24 + 6 * r + j]
        D = W[i, 66 + j]
        u = tau[c] - W[i, 60 + j]
        W[i, 72], W[i, 73] = D, u
        par = int(P[i, PARENT])
        if par >= 0:
            # I^a = I^A − U Uᵀ/D (in place), p^a = p^A + I^a c + U u/D
            for r in range(6):
                for k in range(6):
                    W[i, 24 + 6 * r + k] -= W[i, 66 + r] * W[i, 66 + k] / D
            for r in range(6):
                acc = W[i, 60 + r] + W[i, 66 + r] * u / D
                for k in range(6):
                    acc += W[i, 24 + 6 * r + k] * W[i, 18 + k]
                W[i, 74 + r] = acc
            _add_articulated_to_parent(W, i, par, X, T)
            f = _force_to_parent(W, i, 0, W[i, 74], W[i, 75], W[i, 76], W[i, 77], W[i, 78], W[i, 79])
            for k in range(6):
                W[par, 60 + k] += f[k]
    ok = True
    for i in range(nb):  # pass 3: accelerations (a' = a − a_g, a_g = (0, g): gravity as a fictitious acceleration)
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            for r in range(6):
                for k in range(6):
                    X[r, k] = W[0, 24 + 6 * r + k]
                W[0, 80 + r] = tau[r] - W[0, 60 + r]
            cholesky_solve(X, W[0, 80:86])
            gx, gy, gz = _gravity_in_body0(W, g)
            qdd[0], qdd[1], qdd[2] = W[0, 80], W[0, 81], W[0, 82]
            qdd[3], qdd[4], qdd[5] = W[0, 83] + gx, W[0, 84] + gy, W[0, 85] + gz
            for r in range(6):
                ok = ok and math.isfinite(qdd[r])
            continue
        if par < 0:
            ax, ay, az, lx, ly, lz = _motion_to_child(W, i, 0.0, 0.0, 0.0, -g[0], -g[1], -g[2])
        else:
            ax, ay, az, lx, ly, lz = _motion_to_child(W, i, W[par, 80], W[par, 81], W[par, 82],
                                                      W[par, 83], W[par, 84], W[par, 85])
        ax, ay, az = ax + W[i, 18], ay + W[i, 19], az + W[i, 20]
        lx, ly, lz = lx + W[i, 21], ly + W[i, 22], lz + W[i, 23]
        Ua = (W[i, 66] * ax + W[i, 67] * ay + W[i, 68] * az + W[i, 69] * lx + W[i, 70] * ly + W[i, 71] * lz)
        c = int(P[i, COORDINATE])
        x = (W[i, 73] - Ua) / W[i, 72]
        qdd[c] = x
        ok = ok and math.isfinite(x)
        if P[i, 15] == REVOLUTE:  # a += S q̈
            az += x
        else:
            lz += x
        W[i, 80], W[i, 81], W[i, 82], W[i, 83], W[i, 84], W[i, 85] = ax, ay, az, lx, ly, lz
    return ok


@njit(**_JIT)
def mimic(P, nv):
    """True when some joints share a coordinate (mimic joints): then the ABA does not apply."""
    return nv < P.shape[0] + 5 * floating(P)


@njit(**_JIT)
def fd_scratch(nb, nv):
    """Scratch arrays of :func:`forward_one` for a tree of nb bodies and nv velocity coordinates."""
    return np.empty((nb, _WIDTH)), np.empty((6, 6)), np.empty((6, 6)), np.empty((nv, nv)), np.zeros(nv)


@njit(**_NO_REFCOUNT)
def forward_one(P, q, qd, tau, g, fext, W, X, T, M, zero, qdd):
    """``q̈ = FD(q, q̇, τ)``: the ABA (:func:`aba_one`), or with mimic joints ``M q̈ = τ − RNEA(q, q̇, 0)`` by CRBA
    and Cholesky (``zero``: nv zeros). Returns False when an acceleration is not finite."""
    if not mimic(P, qd.shape[0]):
        return aba_one(P, q, qd, tau, g, fext, W, X, T, qdd)
    rnea_one(P, q, qd, zero, g, fext, W, qdd)
    for k in range(qdd.shape[0]):
        qdd[k] = tau[k] - qdd[k]
    crba_one(P, q, W, M)
    cholesky_solve(M, qdd)
    ok = True
    for k in range(qdd.shape[0]):
        ok = ok and math.isfinite(qdd[k])
    return ok


@njit(**_NO_REFCOUNT)
def aba(P, q, qd, tau, g, fext, S, qdd):
    """One sample: ``qdd`` (nv,) from ``q`` (nq,), ``qd``, ``tau`` (nv,), ``g`` (3,), ``fext`` (6,), scratch
    ``S`` = :func:`workspace`.

    Returns False when a size does not fit (then ``qdd`` is left as it was) or an acceleration is not finite.
    """
    nq, nv = q.shape[0], qdd.shape[0]
    if not _state_fits(P, S, q, qd, tau, g, fext, nv):
        return False
    o = P.shape[0] * _WIDTH
    X, T = S[o:o + 36].reshape(6, 6), S[o + 36:o + 72].reshape(6, 6)
    M, zero = S[o + 72:o + 72 + nv * nv].reshape(nv, nv), S[o + 72 + nv * nv:o + 72 + nv * nv + nv]
    zero[:] = 0.0
    o = _state_offset(P, nv)
    return forward_one(P, _copy(q, S, o), _copy(qd, S, o + nq), _copy(tau, S, o + nq + nv), g, fext,
                       _body_scratch(P, S), X, T, M, zero, qdd)


@njit(**_NO_REFCOUNT)
def _forward_rows(P, Q, QD, TAU, g, F, W, X, T, M, zero, QDD, start, stop):
    """Samples ``start ≤ b < stop`` of :func:`aba_batch`, scratch ``W, X, T, M, zero``."""
    wide = F.shape[0] > 1
    for b in range(start, stop):
        forward_one(P, Q[b], QD[b], TAU[b], g, F[b * wide], W, X, T, M, zero, QDD[b])


@njit(parallel=True, **_JIT)
def aba_batch(P, Q, QD, TAU, g, F, QDD, nc):
    """A batch: ``QDD[b] = FD(Q[b], QD[b], TAU[b])``; ``F`` (1 or B, 6) the last body's wrenches."""
    B = Q.shape[0]
    for c in prange(nc):
        W, X, T, M, zero = fd_scratch(P.shape[0], QD.shape[1])
        _forward_rows(P, Q, QD, TAU, g, F, W, X, T, M, zero, QDD, c * B // nc, (c + 1) * B // nc)


# -- kinematics and energy -----------------------------------------------------


@njit(**_JIT)
def world_poses(P, q, W):
    """World poses of the canonical body frames into ``W[i, 12:24]`` (R row-major, then p), transforms at 0–11."""
    fl = floating(P)
    for i in range(P.shape[0]):
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            _free_transform(q, W)
        else:
            _transform(P, i, _joint(P, i, q, fl)[2], W)
        if par < 0:
            for k in range(12):
                W[i, 12 + k] = W[i, k]
            continue
        for r in range(3):
            x, y, z = W[par, 12 + 3 * r], W[par, 13 + 3 * r], W[par, 14 + 3 * r]
            W[i, 21 + r] = W[par, 21 + r] + x * W[i, 9] + y * W[i, 10] + z * W[i, 11]
            for c in range(3):
                W[i, 12 + 3 * r + c] = x * W[i, c] + y * W[i, 3 + c] + z * W[i, 6 + c]


@njit(**_JIT)
def poses_one(P, q, W, T):
    """World poses of the user's body frames into ``T`` (nb, 4, 4) (homogeneous, base/world frame)."""
    world_poses(P, q, W)
    for i in range(P.shape[0]):
        for r in range(3):  # user frame = canonical frame ∘ (R_f, p_f)
            x, y, z = W[i, 12 + 3 * r], W[i, 13 + 3 * r], W[i, 14 + 3 * r]
            T[i, r, 3] = W[i, 21 + r] + x * P[i, 39] + y * P[i, 40] + z * P[i, 41]
            for c in range(3):
                T[i, r, c] = x * P[i, 30 + c] + y * P[i, 33 + c] + z * P[i, 36 + c]
            T[i, 3, r] = 0.0
        T[i, 3, 3] = 1.0


@njit(**_JIT)
def energy_one(P, q, qd, g, W):
    """``(T, V)``: kinetic energy ``Σ ½ vᵢᵀ Iᵢ vᵢ`` and potential ``−Σ g · (mᵢ pᵢ + R_i hᵢ)`` (J).

    ``pᵢ``, ``R_i``: pose of body frame i in the world (base) frame, whose origin is the zero of V.
    """
    rnea_one(P, q, qd, np.zeros(qd.shape[0]), np.zeros(3), np.zeros(6), W, np.empty(qd.shape[0]))
    # the body velocities are now at W[:, 12:18]
    kinetic = 0.0
    for i in range(P.shape[0]):
        h = _inertia_times(P, i, W[i, 12], W[i, 13], W[i, 14], W[i, 15], W[i, 16], W[i, 17])
        for k in range(6):
            kinetic += 0.5 * W[i, 12 + k] * h[k]
    world_poses(P, q, W)
    potential = 0.0
    for i in range(P.shape[0]):
        for r in range(3):
            first = (P[i, 17] * W[i, 21 + r] + W[i, 12 + 3 * r] * P[i, 18] + W[i, 13 + 3 * r] * P[i, 19]
                     + W[i, 14 + 3 * r] * P[i, 20])
            potential -= g[r] * first
    return kinetic, potential


@njit(**_JIT)
def energy_batch(P, Q, QD, g, OUT):
    """``OUT[b] = (T, V)`` of sample b (serial: energies are for checks and plots, not hot loops)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        OUT[b, 0], OUT[b, 1] = energy_one(P, Q[b], QD[b], g, W)


@njit(**_JIT)
def centroidal_momentum_one(P, q, qd, W, out):
    """``out = (k_G, l)``: the angular momentum about the centre of mass and the linear momentum, world axes.

    Each body's spatial momentum about its origin, body axes, is ``(n, f) = I v = (I_O ω + h × v, m v −
    h × ω)``; in the world ``f_W = R f``, and about the world origin ``n_W = R n + p × f_W``. Summed: ``l = Σ
    f_W``, ``k_O = Σ n_W``, and with the centre of mass ``c = Σ (m p + R h) / Σ m``, ``k_G = k_O − c × l``
    (N·m·s, N·s; Orin, Goswami & Lee, Auton. Robots 35, 2013, eq. 1).
    """
    nb = P.shape[0]
    rnea_one(P, q, qd, np.zeros(qd.shape[0]), np.zeros(3), np.zeros(6), W, np.empty(qd.shape[0]))
    for i in range(nb):  # the body velocities are at W[:, 12:18]; their momenta go to W[:, 60:66]
        h = _inertia_times(P, i, W[i, 12], W[i, 13], W[i, 14], W[i, 15], W[i, 16], W[i, 17])
        for k in range(6):
            W[i, 60 + k] = h[k]
    world_poses(P, q, W)  # R at W[:, 12:21], p at W[:, 21:24]
    kx = ky = kz = lx = ly = lz = cx = cy = cz = mass = 0.0  # k_O, l, Σ (m p + R h)
    for i in range(nb):
        nx, ny, nz = _rot(W, i, 12, W[i, 60], W[i, 61], W[i, 62])
        fx, fy, fz = _rot(W, i, 12, W[i, 63], W[i, 64], W[i, 65])
        hx, hy, hz = _rot(W, i, 12, P[i, 18], P[i, 19], P[i, 20])
        ax, ay, az = cross(W[i, 21], W[i, 22], W[i, 23], fx, fy, fz)
        kx, ky, kz = kx + nx + ax, ky + ny + ay, kz + nz + az
        lx, ly, lz = lx + fx, ly + fy, lz + fz
        m = P[i, 17]
        cx, cy, cz = cx + m * W[i, 21] + hx, cy + m * W[i, 22] + hy, cz + m * W[i, 23] + hz
        mass += m
    bx, by, bz = cross(cx / mass, cy / mass, cz / mass, lx, ly, lz)
    out[0], out[1], out[2], out[3], out[4], out[5] = kx - bx, ky - by, kz - bz, lx, ly, lz


@njit(**_JIT)
def centroidal_momentum_batch(P, Q, QD, OUT):
    """``OUT[b] = (k_G, l)`` of sample b (serial: the output samples of a run)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        centroidal_momentum_one(P, Q[b], QD[b], W, OUT[b])


@njit(**_JIT)
def poses_batch(P, Q, T):
    """``T[b]`` = the body poses of sample b (serial)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        poses_one(P, Q[b], W, T[b])


@njit(**_JIT)
def body_poses_batch(P, Q, OUT):
    """``OUT[b, i] = (R, p)`` (12,) of canonical body frame i in the world, sample b (serial; for Jacobians)."""
    W = scratch(P.shape[0])
    for b in range(Q.shape[0]):
        world_poses(P, Q[b], W)
        OUT[b] = W[:, 12:24]
