"""Forward dynamics of a kinematic tree: the articulated-body algorithm, or CRBA and Cholesky for mimic joints.

Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008: Table 7.1
(ABA), Table 9.6 for a floating base; the columns of ``P`` and ``W`` are
those of :mod:`.layout`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tumble._vec import cross
from tumble.kernels.featherstone.inverse import crba_one, rnea_one
from tumble.kernels.featherstone.layout import (ABA_ACCELERATION, ARTICULATED_INERTIA, AXIS_INERTIA,
                                                BIAS_ACCELERATION, BIAS_FORCE, COORDINATE, FIRST_MOMENT, INERTIA,
                                                INLINE, JIT, JOINT_FORCE, JOINT_INERTIA, JOINT_TYPE, MASS, NO_REFCOUNT,
                                                ORIGIN, PARENT, PARENT_POSE, REVOLUTE, SPATIAL_PAIR,
                                                TRANSMITTED_BIAS, VELOCITY, WIDTH, all_finite, body_scratch,
                                                floating, state_copy, state_fits, state_offset)
from tumble.kernels.featherstone.spatial import (bias_force, external_wrench, force_to_parent, free_transform,
                                                 gravity_in_body0, joint, joint_transform, motion_to_child,
                                                 subspace)


@njit(**NO_REFCOUNT)
def _add_articulated_to_parent(W, i, par, X, T):
    """``I^A_λ += X_iᵀ I^a X_i`` with I^a at ``W[i, ARTICULATED_INERTIA]``; X, T are (6, 6) scratch."""
    # X = [[E, 0], [−E [p]×, E]], E = Rᵀ
    R, p, I = PARENT_POSE, PARENT_POSE + ORIGIN, ARTICULATED_INERTIA
    for r in range(3):
        for c in range(3):
            e = W[i, R + 3 * c + r]
            X[r, c] = e
            X[3 + r, 3 + c] = e
            X[r, 3 + c] = 0.0
    for r in range(3):
        # row r of −E [p]× is −(eᵣᵀ [p]×) = −(eᵣ × p)ᵀ = (p × eᵣ)ᵀ,
        # eᵣ = row r of E = column r of R
        c = cross(W[i, p], W[i, p + 1], W[i, p + 2], W[i, R + r], W[i, R + 3 + r], W[i, R + 6 + r])
        X[3 + r, 0], X[3 + r, 1], X[3 + r, 2] = c[0], c[1], c[2]
    for r in range(6):  # T = I^a X
        for c in range(6):
            acc = 0.0
            for k in range(6):
                acc += W[i, I + 6 * r + k] * X[k, c]
            T[r, c] = acc
    for r in range(6):  # I^A_λ += Xᵀ T
        for c in range(6):
            acc = 0.0
            for k in range(6):
                acc += X[k, r] * T[k, c]
            W[par, I + 6 * r + c] += acc


@njit(**NO_REFCOUNT)
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


@njit(**NO_REFCOUNT)
def aba_one(P, q, qd, tau, g, fext, W, X, T, qdd):
    """``q̈ = FD(q, q̇, τ)`` into ``qdd``: the articulated-body algorithm on a tree, Featherstone (2008)
    Table 7.1; with a floating base, Table 9.6 (the base acceleration from ``I^A_0 a₀ = τ₀ − p^A_0``,
    gravity as a fictitious acceleration). No mimic joints. Returns False when an acceleration is not finite.
    """
    nb = P.shape[0]
    fl = floating(P)
    IA, pA, U = ARTICULATED_INERTIA, BIAS_FORCE, AXIS_INERTIA  # the columns of I^A, p^A and U
    for i in range(nb):  # pass 1: velocities, bias accelerations c, rigid inertias, bias forces
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            free_transform(q, W)
            wx, wy, wz, vx, vy, vz = qd[0], qd[1], qd[2], qd[3], qd[4], qd[5]
            c1 = c2 = (0.0, 0.0, 0.0)
        else:
            c, k, x = joint(P, i, q, fl)
            joint_transform(P, i, x, W)
            if par < 0:
                wx = wy = wz = vx = vy = vz = 0.0
            else:
                v = VELOCITY
                wx, wy, wz, vx, vy, vz = motion_to_child(W, i, W[par, v], W[par, v + 1], W[par, v + 2],
                                                         W[par, v + 3], W[par, v + 4], W[par, v + 5])
            xd = qd[c]
            if P[i, JOINT_TYPE] == REVOLUTE:  # v += S ẋ, c = v × S ẋ with S ẋ = (ẋ e_z, 0)
                wz += xd
                c1 = (wy * xd, -wx * xd, 0.0)
                c2 = (vy * xd, -vx * xd, 0.0)
            else:  # S ẋ = (0, ẋ e_z)
                vz += xd
                c1 = (0.0, 0.0, 0.0)
                c2 = (wy * xd, -wx * xd, 0.0)
        W[i, VELOCITY], W[i, VELOCITY + 1], W[i, VELOCITY + 2] = wx, wy, wz
        W[i, VELOCITY + 3], W[i, VELOCITY + 4], W[i, VELOCITY + 5] = vx, vy, vz
        W[i, BIAS_ACCELERATION], W[i, BIAS_ACCELERATION + 1], W[i, BIAS_ACCELERATION + 2] = c1[0], c1[1], c1[2]
        W[i, BIAS_ACCELERATION + 3], W[i, BIAS_ACCELERATION + 4], W[i, BIAS_ACCELERATION + 5] = c2[0], c2[1], c2[2]
        # I^A = [[I_O, [h]×], [−[h]×, m E]]
        m, hx, hy, hz = P[i, MASS], P[i, FIRST_MOMENT], P[i, FIRST_MOMENT + 1], P[i, FIRST_MOMENT + 2]
        for r in range(3):
            for c in range(3):
                W[i, IA + 6 * r + c] = P[i, INERTIA + 3 * r + c]
                W[i, IA + 6 * (3 + r) + 3 + c] = m if r == c else 0.0
        hxm = ((0.0, -hz, hy), (hz, 0.0, -hx), (-hy, hx, 0.0))
        for r in range(3):
            for c in range(3):
                W[i, IA + 6 * r + 3 + c] = hxm[r][c]
                W[i, IA + 6 * (3 + r) + c] = -hxm[r][c]
        b = bias_force(P, i, wx, wy, wz, vx, vy, vz)
        for k in range(6):
            W[i, pA + k] = b[k]
    e = external_wrench(P, fext)
    for k in range(6):
        W[nb - 1, pA + k] -= e[k]
    for i in range(nb - 1, fl - 1, -1):  # pass 2: articulated inertias and bias forces
        c = int(P[i, COORDINATE])
        j = subspace(P, i)
        for r in range(6):  # U = I^A S, D = Sᵀ U, u = τ − Sᵀ p^A
            W[i, U + r] = W[i, IA + 6 * r + j]
        D = W[i, U + j]
        u = tau[c] - W[i, pA + j]
        W[i, JOINT_INERTIA], W[i, JOINT_FORCE] = D, u
        par = int(P[i, PARENT])
        if par >= 0:
            # I^a = I^A − U Uᵀ/D (in place), p^a = p^A + I^a c + U u/D
            for r in range(6):
                for k in range(6):
                    W[i, IA + 6 * r + k] -= W[i, U + r] * W[i, U + k] / D
            for r in range(6):
                acc = W[i, pA + r] + W[i, U + r] * u / D
                for k in range(6):
                    acc += W[i, IA + 6 * r + k] * W[i, BIAS_ACCELERATION + k]
                W[i, TRANSMITTED_BIAS + r] = acc
            _add_articulated_to_parent(W, i, par, X, T)
            pa = TRANSMITTED_BIAS
            f = force_to_parent(W, i, PARENT_POSE, W[i, pa], W[i, pa + 1], W[i, pa + 2], W[i, pa + 3],
                                W[i, pa + 4], W[i, pa + 5])
            for k in range(6):
                W[par, pA + k] += f[k]
    a = ABA_ACCELERATION
    for i in range(nb):  # pass 3: accelerations (a' = a − a_g, a_g = (0, g): gravity as a fictitious acceleration)
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            for r in range(6):
                for k in range(6):
                    X[r, k] = W[0, IA + 6 * r + k]
                W[0, a + r] = tau[r] - W[0, pA + r]
            cholesky_solve(X, W[0, a:a + 6])
            gx, gy, gz = gravity_in_body0(W, g)
            qdd[0], qdd[1], qdd[2] = W[0, a], W[0, a + 1], W[0, a + 2]
            qdd[3], qdd[4], qdd[5] = W[0, a + 3] + gx, W[0, a + 4] + gy, W[0, a + 5] + gz
            continue
        if par < 0:
            ax, ay, az, lx, ly, lz = motion_to_child(W, i, 0.0, 0.0, 0.0, -g[0], -g[1], -g[2])
        else:
            ax, ay, az, lx, ly, lz = motion_to_child(W, i, W[par, a], W[par, a + 1], W[par, a + 2],
                                                     W[par, a + 3], W[par, a + 4], W[par, a + 5])
        ax, ay, az = (ax + W[i, BIAS_ACCELERATION], ay + W[i, BIAS_ACCELERATION + 1],
                      az + W[i, BIAS_ACCELERATION + 2])
        lx, ly, lz = (lx + W[i, BIAS_ACCELERATION + 3], ly + W[i, BIAS_ACCELERATION + 4],
                      lz + W[i, BIAS_ACCELERATION + 5])
        Ua = (W[i, U] * ax + W[i, U + 1] * ay + W[i, U + 2] * az + W[i, U + 3] * lx + W[i, U + 4] * ly
              + W[i, U + 5] * lz)
        c = int(P[i, COORDINATE])
        x = (W[i, JOINT_FORCE] - Ua) / W[i, JOINT_INERTIA]
        qdd[c] = x
        if P[i, JOINT_TYPE] == REVOLUTE:  # a += S q̈
            az += x
        else:
            lz += x
        W[i, a], W[i, a + 1], W[i, a + 2], W[i, a + 3], W[i, a + 4], W[i, a + 5] = ax, ay, az, lx, ly, lz
    return all_finite(qdd)


@njit(**JIT)
def mimic(P, nv):
    """True when some joints share a coordinate (mimic joints): then the ABA does not apply."""
    return nv < P.shape[0] + 5 * floating(P)


@njit(**JIT)
def fd_scratch(nb, nv):
    """Scratch arrays of :func:`forward_one` for a tree of nb bodies and nv velocity coordinates."""
    return np.empty((nb, WIDTH)), np.empty((6, 6)), np.empty((6, 6)), np.empty((nv, nv)), np.zeros(nv)


@njit(**INLINE)
def fd_views(P, S, nv):
    """The scratch arrays of :func:`forward_one`, ``(W, X, T, M, zero)``, as views of a workspace ``S``
    (:func:`~.layout.workspace`: ``W``, then the two 6×6 matrices, ``M`` and the zeros), the zeros set. They
    allocate nothing: code compiled for a GPU takes its scratch so."""
    o = P.shape[0] * WIDTH
    X, T = S[o:o + 36].reshape((6, 6)), S[o + 36:o + SPATIAL_PAIR].reshape((6, 6))
    o += SPATIAL_PAIR
    M, zero = S[o:o + nv * nv].reshape((nv, nv)), S[o + nv * nv:o + nv * nv + nv]
    for k in range(nv):
        zero[k] = 0.0
    return body_scratch(P, S), X, T, M, zero


@njit(**NO_REFCOUNT)
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
    return all_finite(qdd)


@njit(**NO_REFCOUNT)
def aba(P, q, qd, tau, g, fext, S, qdd):
    """One sample: ``qdd`` (nv,) from ``q`` (nq,), ``qd``, ``tau`` (nv,), ``g`` (3,), ``fext`` (6,), scratch
    ``S`` = :func:`~.layout.workspace`.

    Returns False when a size does not fit (then ``qdd`` is left as it was) or an acceleration is not finite.
    """
    nq, nv = q.shape[0], qdd.shape[0]
    if not state_fits(P, S, q, qd, tau, g, fext, nv):
        return False
    W, X, T, M, zero = fd_views(P, S, nv)
    o = state_offset(P, nv)
    return forward_one(P, state_copy(q, S, o), state_copy(qd, S, o + nq), state_copy(tau, S, o + nq + nv), g, fext,
                       W, X, T, M, zero, qdd)


@njit(**NO_REFCOUNT)
def _forward_rows(P, Q, QD, TAU, g, F, W, X, T, M, zero, QDD, start, stop):
    """Samples ``start ≤ b < stop`` of :func:`aba_batch`, scratch ``W, X, T, M, zero``."""
    wide = F.shape[0] > 1
    for b in range(start, stop):
        forward_one(P, Q[b], QD[b], TAU[b], g, F[b * wide], W, X, T, M, zero, QDD[b])


@njit(parallel=True, **JIT)
def aba_batch(P, Q, QD, TAU, g, F, QDD, nc):
    """A batch: ``QDD[b] = FD(Q[b], QD[b], TAU[b])``; ``F`` (1 or B, 6) the last body's wrenches."""
    B = Q.shape[0]
    for c in prange(nc):
        W, X, T, M, zero = fd_scratch(P.shape[0], QD.shape[1])
        _forward_rows(P, Q, QD, TAU, g, F, W, X, T, M, zero, QDD, c * B // nc, (c + 1) * B // nc)
