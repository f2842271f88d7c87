"""Inverse dynamics (RNEA) and the joint-space inertia matrix (CRBA) of a kinematic tree.

Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008: Table 5.1
(RNEA) and Table 6.2 (CRBA) on a tree, §9.3 for a floating base; the columns
of ``P`` and ``W`` are those of :mod:`.layout`.
"""

from __future__ import annotations

from numba import njit, prange

from tumble.kernels.featherstone.layout import (ACCELERATION, COMPOSITE_INERTIA, COMPOSITE_MASS, COMPOSITE_MOMENT,
                                                COMPOSITE_PRODUCT, COORDINATE, FORCE, INLINE, JIT, JOINT_TYPE, MASS,
                                                MULTIPLIER, NO_REFCOUNT, ORIGIN, PARENT, PARENT_POSE, REVOLUTE,
                                                RIGID_INERTIA, VELOCITY, all_finite, body_scratch, fits, floating,
                                                scratch, state_copy, state_fits, state_offset)
from tumble.kernels.featherstone.spatial import (bias_force, external_wrench, force_to_parent, free_transform,
                                                 gravity_in_body0, inertia_times, joint, joint_transform,
                                                 motion_to_child, rotate, subspace)

# -- inverse dynamics: RNEA ----------------------------------------------------


@njit(**NO_REFCOUNT)
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
    for i in range(nb):  # forward: v_i, a_i, and f_i = I_i a_i + v_i ×* (I_i v_i)
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:
            free_transform(q, W)
            gx, gy, gz = gravity_in_body0(W, g)
            wx, wy, wz, vx, vy, vz = qd[0], qd[1], qd[2], qd[3], qd[4], qd[5]
            ax, ay, az, lx, ly, lz = qdd[0], qdd[1], qdd[2], qdd[3] - gx, qdd[4] - gy, qdd[5] - gz
        else:
            c, k, x = joint(P, i, q, fl)
            joint_transform(P, i, x, W)
            if par < 0:
                wx = wy = wz = vx = vy = vz = 0.0
                ax, ay, az, lx, ly, lz = motion_to_child(W, i, 0.0, 0.0, 0.0, -g[0], -g[1], -g[2])
            else:
                v, a = VELOCITY, ACCELERATION
                wx, wy, wz, vx, vy, vz = motion_to_child(W, i, W[par, v], W[par, v + 1], W[par, v + 2],
                                                         W[par, v + 3], W[par, v + 4], W[par, v + 5])
                ax, ay, az, lx, ly, lz = motion_to_child(W, i, W[par, a], W[par, a + 1], W[par, a + 2],
                                                         W[par, a + 3], W[par, a + 4], W[par, a + 5])
            xd, xdd = k * qd[c], k * qdd[c]
            if P[i, JOINT_TYPE] == REVOLUTE:  # v += S ẋ, a += S ẍ + v × S ẋ with S ẋ = (ẋ e_z, 0)
                wz += xd
                ax, ay, az = ax + wy * xd, ay - wx * xd, az + xdd
                lx, ly = lx + vy * xd, ly - vx * xd
            else:  # S ẋ = (0, ẋ e_z)
                vz += xd
                lx, ly, lz = lx + wy * xd, ly - wx * xd, lz + xdd
        W[i, VELOCITY], W[i, VELOCITY + 1], W[i, VELOCITY + 2] = wx, wy, wz
        W[i, VELOCITY + 3], W[i, VELOCITY + 4], W[i, VELOCITY + 5] = vx, vy, vz
        W[i, ACCELERATION], W[i, ACCELERATION + 1], W[i, ACCELERATION + 2] = ax, ay, az
        W[i, ACCELERATION + 3], W[i, ACCELERATION + 4], W[i, ACCELERATION + 5] = lx, ly, lz
        f = inertia_times(P, i, ax, ay, az, lx, ly, lz)
        b = bias_force(P, i, wx, wy, wz, vx, vy, vz)
        for k in range(6):
            W[i, FORCE + k] = f[k] + b[k]
    e = external_wrench(P, fext)
    for k in range(6):
        W[nb - 1, FORCE + k] -= e[k]
    for i in range(nb - 1, -1, -1):  # backward: τ_i = S_iᵀ f_i, f_λ(i) += X_iᵀ f_i
        if fl == 1 and i == 0:
            for k in range(6):
                tau[k] = W[0, FORCE + k]
            break
        c = int(P[i, COORDINATE])  # τ = Sᵀ f: n_z or f_z
        tau[c] += P[i, MULTIPLIER] * W[i, FORCE + subspace(P, i)]
        par = int(P[i, PARENT])
        if par >= 0:
            r = force_to_parent(W, i, PARENT_POSE, W[i, FORCE], W[i, FORCE + 1], W[i, FORCE + 2],
                                W[i, FORCE + 3], W[i, FORCE + 4], W[i, FORCE + 5])
            for k in range(6):
                W[par, FORCE + k] += r[k]
    return all_finite(tau)


@njit(**NO_REFCOUNT)
def rnea(P, q, qd, qdd, g, fext, S, tau):
    """One sample: ``tau`` (nv,) from ``q`` (nq,), ``qd``, ``qdd`` (nv,), ``g`` (3,), ``fext`` (6,), scratch
    ``S`` = :func:`~.layout.workspace`.

    Returns False when a size does not fit (then ``tau`` is left as it was) or a torque is not finite.
    """
    nq, nv = q.shape[0], tau.shape[0]
    if not state_fits(P, S, q, qd, qdd, g, fext, nv):
        return False
    o = state_offset(P, nv)
    return rnea_one(P, state_copy(q, S, o), state_copy(qd, S, o + nq), state_copy(qdd, S, o + nq + nv), g, fext,
                    body_scratch(P, S), tau)


@njit(**NO_REFCOUNT)
def _rnea_rows(P, Q, QD, QDD, g, F, W, TAU, start, stop):
    """Samples ``start ≤ b < stop`` of :func:`rnea_batch`, scratch ``W``."""
    wide = F.shape[0] > 1
    for b in range(start, stop):
        rnea_one(P, Q[b], QD[b], QDD[b], g, F[b * wide], W, TAU[b])


@njit(parallel=True, **JIT)
def rnea_batch(P, Q, QD, QDD, g, F, TAU, nc):
    """A batch: ``TAU[b] = ID(Q[b], QD[b], QDD[b])``; ``F`` (1 or B, 6) the last body's wrenches."""
    B = Q.shape[0]
    for c in prange(nc):
        _rnea_rows(P, Q, QD, QDD, g, F, scratch(P.shape[0]), TAU, c * B // nc, (c + 1) * B // nc)


# -- joint-space inertia: CRBA -------------------------------------------------


@njit(**INLINE)
def _motion_subspace_force(W, i, revolute):
    """``F = I S`` for the composite rigid inertia (m, h, I_O) of body i: S = (e_z, 0) gives
    ``(I_O e_z, e_z × h)``, S = (0, e_z) gives ``(h × e_z, m e_z)``."""
    I, h = COMPOSITE_INERTIA, COMPOSITE_MOMENT
    if revolute:
        return W[i, I + 2], W[i, I + 5], W[i, I + 8], -W[i, h + 1], W[i, h], 0.0
    return W[i, h + 1], -W[i, h], 0.0, 0.0, 0.0, W[i, COMPOSITE_MASS]


@njit(**INLINE)
def _project(P, j, F):
    """``S_jᵀ F`` for a force vector F = (n, f): n_z or f_z."""
    return F[2] if P[j, JOINT_TYPE] == REVOLUTE else F[5]


@njit(**NO_REFCOUNT)
def _add_composite_to_parent(W, i, par):
    """``I^c_λ += X_iᵀ I^c_i X_i`` for rigid inertias (m, h, I_O): ``h' = R h + m p``,
    ``I_O' = R I_O Rᵀ + (2 h'' · p + m|p|²) E − (h'' pᵀ + p h''ᵀ + m p pᵀ)``, ``h'' = R h``.

    ``R I_O Rᵀ`` as ``R (I_O Rᵀ)``, the product kept at ``W[i, COMPOSITE_PRODUCT]``; symmetric, so its upper
    triangle is computed and mirrored."""
    R, I, IR = PARENT_POSE, COMPOSITE_INERTIA, COMPOSITE_PRODUCT
    m = W[i, COMPOSITE_MASS]
    hx, hy, hz = rotate(W, i, R, W[i, COMPOSITE_MOMENT], W[i, COMPOSITE_MOMENT + 1], W[i, COMPOSITE_MOMENT + 2])
    px, py, pz = W[i, R + ORIGIN], W[i, R + ORIGIN + 1], W[i, R + ORIGIN + 2]
    W[par, COMPOSITE_MASS] += m
    W[par, COMPOSITE_MOMENT] += hx + m * px
    W[par, COMPOSITE_MOMENT + 1] += hy + m * py
    W[par, COMPOSITE_MOMENT + 2] += hz + m * pz
    for a in range(3):  # I_O Rᵀ: row a of I_O against row c of R
        for c in range(3):
            W[i, IR + 3 * a + c] = (W[i, I + 3 * a] * W[i, R + 3 * c] + W[i, I + 3 * a + 1] * W[i, R + 3 * c + 1]
                                    + W[i, I + 3 * a + 2] * W[i, R + 3 * c + 2])
    diag = 2.0 * (hx * px + hy * py + hz * pz) + m * (px * px + py * py + pz * pz)
    h = (hx, hy, hz)
    p = (px, py, pz)
    for r in range(3):
        for c in range(r, 3):
            x = (W[i, R + 3 * r] * W[i, IR + c] + W[i, R + 3 * r + 1] * W[i, IR + 3 + c]
                 + W[i, R + 3 * r + 2] * W[i, IR + 6 + c] - (h[r] * p[c] + p[r] * h[c] + m * p[r] * p[c]))
            if r == c:
                W[par, I + 4 * r] += x + diag  # (r, r)
            else:
                W[par, I + 3 * r + c] += x
                W[par, I + 3 * c + r] += x


@njit(**NO_REFCOUNT)
def crba_one(P, q, W, M):
    """Joint-space inertia matrix ``M(q)`` into ``M`` (nv, nv): Featherstone (2008) Table 6.2 on a tree.

    With a floating base, ``M[0:6, 0:6]`` is the composite inertia of the
    whole robot in body 0 axes (Featherstone 2008, §9.3); with mimic joints
    the result is ``Gᵀ M G`` in the independent coordinates.
    """
    nb = P.shape[0]
    fl = floating(P)
    M[:, :] = 0.0
    for i in range(nb):  # poses, and each body's rigid inertia as the start of its composite inertia
        if fl == 1 and i == 0:
            free_transform(q, W)
        else:
            joint_transform(P, i, joint(P, i, q, fl)[2], W)
        for k in range(RIGID_INERTIA):
            W[i, COMPOSITE_MASS + k] = P[i, MASS + k]
    for i in range(nb - 1, -1, -1):
        par = int(P[i, PARENT])
        if fl == 1 and i == 0:  # S = E: the composite inertia as a 6×6 [[I_O, [h]×], [−[h]×, m E]]
            m = W[0, COMPOSITE_MASS]
            hx, hy, hz = W[0, COMPOSITE_MOMENT], W[0, COMPOSITE_MOMENT + 1], W[0, COMPOSITE_MOMENT + 2]
            hxm = ((0.0, -hz, hy), (hz, 0.0, -hx), (-hy, hx, 0.0))
            for r in range(3):
                for c in range(3):
                    M[r, c] += W[0, COMPOSITE_INERTIA + 3 * r + c]
                    M[r, 3 + c] += hxm[r][c]
                    M[3 + r, c] -= hxm[r][c]
                M[3 + r, 3 + r] += m
            break
        F = _motion_subspace_force(W, i, P[i, JOINT_TYPE] == REVOLUTE)
        ci, ki = int(P[i, COORDINATE]), P[i, MULTIPLIER]
        M[ci, ci] += ki * ki * _project(P, i, F)
        j = i
        while int(P[j, PARENT]) >= 0:
            F = force_to_parent(W, j, PARENT_POSE, F[0], F[1], F[2], F[3], F[4], F[5])
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


@njit(**NO_REFCOUNT)
def crba(P, q, S, M):
    """One sample: ``M`` (nv, nv) from ``q`` (nq,), scratch ``S`` = :func:`~.layout.workspace`. Returns False
    when a size does not fit (then ``M`` is left as it was) or an entry is not finite."""
    nv = M.shape[0]
    if not (fits(P, S, q, nv) and M.shape[1] == nv):
        return False
    crba_one(P, state_copy(q, S, state_offset(P, nv)), body_scratch(P, S), M)
    return all_finite(M)


@njit(**NO_REFCOUNT)
def _crba_rows(P, Q, W, M, start, stop):
    """Samples ``start ≤ b < stop`` of :func:`crba_batch`, scratch ``W``."""
    for b in range(start, stop):
        crba_one(P, Q[b], W, M[b])


@njit(parallel=True, **JIT)
def crba_batch(P, Q, M, nc):
    """A batch: ``M[b] = M(Q[b])``."""
    B = Q.shape[0]
    for c in prange(nc):
        _crba_rows(P, Q, scratch(P.shape[0]), M, c * B // nc, (c + 1) * B // nc)
