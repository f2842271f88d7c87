"""The columns of a kinematic tree's table ``P`` and of the algorithms' scratch ``W``, by name.

A tree is one float64 array ``P`` of shape (nb, :data:`PARAMS`), built once
by :class:`tumble.robot.RobotTree`; row ``i`` describes joint ``i`` and the
body ``i`` it moves, in *canonical* frames whose origin lies on the joint axis
and whose z axis is that axis. A *pose* is 12 columns: the rotation ``R``
row-major (9), then the origin ``p`` (3) at ``+ORIGIN``.

=======================  =====  ==========================================================
column                   width  meaning
=======================  =====  ==========================================================
:data:`JOINT_FRAME`      12     pose of joint frame i (before motion) in body frame λ(i):
                                ``R_o`` (its axes in λ(i)'s), ``p_o`` (m)
:data:`AXIS`             3      ``s = e_z = (0, 0, 1)``: the joint axis in the canonical
                                frames (always z: the algorithms turn about and slide
                                along z only)
:data:`JOINT_TYPE`       1      :data:`REVOLUTE`, :data:`PRISMATIC` or :data:`FREE` (the
                                floating base)
:data:`OFFSET`           1      the joint variable is ``θ = k q[c] + offset`` (rad or m)
:data:`MASS`             1      ``m``: body mass (kg)
:data:`FIRST_MOMENT`     3      ``h = m c``: first mass moment about the body origin (kg·m)
:data:`INERTIA`          9      ``I_O``: rotational inertia about the body origin,
                                row-major (kg·m²)
:data:`USER_FRAME`       12     pose of the user's body frame in the canonical frame:
                                ``R_f``, ``p_f`` (m)
:data:`PARENT`           1      ``λ(i)``: the parent body, −1 for the fixed base (or the
                                world, for the free body)
:data:`COORDINATE`       1      ``c``: index of the joint's velocity coordinate in ``q̇``
:data:`MULTIPLIER`       1      ``k``: a mimic joint shares the coordinate ``c`` of the joint
                                it copies
=======================  =====  ==========================================================

``(m, h, I_O)`` is the body's rigid inertia, :data:`RIGID_INERTIA` columns
from :data:`MASS`.

The single-sample algorithms keep per-body quantities in a scratch ``W`` of
shape (nb, :data:`WIDTH`); an algorithm uses the columns it needs, so that
columns are shared between algorithms (body i's motion and force vectors are
in body i axes, ``(ω, v)`` and ``(n, f)``):

==============================  =====  =====================================================
column                          width  meaning (algorithm)
==============================  =====  =====================================================
:data:`PARENT_POSE`             12     ``(R, p)``: pose of body frame i in body frame λ(i) at
                                       the joint's variable, the transform ``X_i`` (all)
:data:`VELOCITY`                6      ``v_i`` (RNEA, ABA, energies, momentum)
:data:`ACCELERATION`            6      ``a_i`` (RNEA)
:data:`BIAS_ACCELERATION`       6      ``c_i = v_i × S_i q̇_i`` (ABA, in RNEA's ``a_i``)
:data:`FORCE`                   6      ``f_i``: the force across joint i (RNEA)
:data:`ARTICULATED_INERTIA`     36     ``I^A_i`` (6×6 row-major), then ``I^a_i`` in place (ABA)
:data:`BIAS_FORCE`              6      ``p^A_i`` (ABA)
:data:`MOMENTUM`                6      ``I_i v_i``: the body's spatial momentum (momentum)
:data:`AXIS_INERTIA`            6      ``U_i = I^A_i S_i`` (ABA)
:data:`JOINT_INERTIA`           1      ``D_i = S_iᵀ U_i`` (ABA)
:data:`JOINT_FORCE`             1      ``u_i = τ_i − S_iᵀ p^A_i`` (ABA)
:data:`TRANSMITTED_BIAS`        6      ``p^a_i = p^A_i + I^a_i c_i + U_i u_i / D_i`` (ABA)
:data:`ABA_ACCELERATION`        6      ``a_i`` (ABA, whose pass 3 still reads ``c_i``)
:data:`COMPOSITE_MASS`          13     the composite rigid inertia of the subtree at i: ``m``,
                                       ``h`` at :data:`COMPOSITE_MOMENT`, ``I_O`` at
                                       :data:`COMPOSITE_INERTIA`, as in ``P`` (CRBA)
:data:`COMPOSITE_PRODUCT`       9      ``I_O Rᵀ`` row-major (CRBA)
:data:`WORLD_POSE`              12     pose of body frame i in the world (base) frame (poses)
==============================  =====  =====================================================

(Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008: RNEA Table
5.1, CRBA Table 6.2, ABA Table 7.1.) The single-state entries take one flat
:func:`workspace` instead: ``W``, then two 6×6 matrices, the mimic joints'
``M`` (nv, nv) and nv zeros, then a contiguous copy of the state.

The compiler options that the algorithms' modules share are defined here
too (:data:`JIT`, :data:`INLINE`, :data:`NO_REFCOUNT`), below them all.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Compiler options: a division by zero gives inf or NaN (found by the finiteness checks)
# rather than an exception; the small vector helpers are inlined in Numba's IR (measured
# 0.9 → 0.5 µs per 7-DOF RNEA). No fast-math flags, not even contraction into fused
# multiply-adds (docs/integrators.md): whether LLVM fuses ``a·b + c`` depends on what it
# has inlined around it, so each copy of a function (its own compiled module, and every
# caller's module it is linked into and optimised again) would round differently, and
# which copy runs depends on which module the JIT linked first, i.e. on what came from
# Numba's cache (docs/reliability.md, "Cached and fresh code agree").
JIT = {"cache": True, "error_model": "numpy"}
INLINE = {**JIT, "inline": "always"}
# The sweeps and the single-state entries allocate nothing, so they are compiled without
# Numba's reference counting (``_nrt=False``): else every array argument, every array handed
# to an inlined helper and every row view of a batch costs an atomic increment and decrement
# of a shared counter, 16 per call and 4 per body in RNEA (measured: 7-DOF RNEA sweep 413 →
# 341 ns), and a call from Python wraps each array in a counted record (measured: the entry
# of a one-link RNEA called from Python 0.43 → 0.22 µs).
NO_REFCOUNT = {**JIT, "_nrt": False}

#: Joint types (column :data:`JOINT_TYPE`).
REVOLUTE, PRISMATIC, FREE = 0, 1, 2

#: In a pose (12 columns), where the origin ``p`` follows the row-major rotation ``R``.
ORIGIN = 9

# -- the tree P (nb, PARAMS) ---------------------------------------------------
JOINT_FRAME = 0
AXIS = 12
JOINT_TYPE = 15
OFFSET = 16
MASS = 17
FIRST_MOMENT = 18
INERTIA = 21
#: Columns of the rigid inertia ``(m, h, I_O)`` from :data:`MASS`.
RIGID_INERTIA = 13
USER_FRAME = 30
PARENT = 42
COORDINATE = 43
MULTIPLIER = 44
PARAMS = 45

# -- the per-body scratch W (nb, WIDTH) ------------------------------------------
PARENT_POSE = 0
VELOCITY = 12
ACCELERATION = 18
BIAS_ACCELERATION = 18  # ABA's c_i, where RNEA keeps a_i
FORCE = 24
ARTICULATED_INERTIA = 24  # ABA's I^A_i, where RNEA keeps f_i
BIAS_FORCE = 60
MOMENTUM = 60  # the centroidal momentum's I_i v_i, where ABA keeps p^A_i
AXIS_INERTIA = 66
JOINT_INERTIA = 72
JOINT_FORCE = 73
TRANSMITTED_BIAS = 74
ABA_ACCELERATION = 80
WIDTH = 86
# CRBA: the composite inertia (m, h, I_O), the 13 columns of P's MASS, FIRST_MOMENT, INERTIA; and I_O Rᵀ
COMPOSITE_MASS, COMPOSITE_MOMENT, COMPOSITE_INERTIA = 12, 13, 16
COMPOSITE_PRODUCT = 25
# poses: the world pose beside the parent pose
WORLD_POSE = 12

#: Entries of the two 6×6 matrices (``X``, ``T``) that follow ``W`` in a :func:`workspace`.
SPATIAL_PAIR = 72


@njit(**JIT)
def floating(P):
    """1 when body 0 is a floating base (free joint), else 0 (also the configuration index shift)."""
    return 1 if P[0, JOINT_TYPE] == FREE else 0


@njit(**JIT)
def scratch(nb):
    """The scratch ``W`` of the ``*_one`` functions for a tree of nb bodies."""
    return np.empty((nb, WIDTH))


@njit(**INLINE)
def workspace_size(nb, nv):
    """The length of a :func:`workspace` for a tree of nb bodies and nv velocity coordinates."""
    return nb * WIDTH + SPATIAL_PAIR + nv * nv + 4 * nv + 1


def workspace(nb: int, nv: int) -> np.ndarray:
    """The flat scratch of the single-state entries for a tree of nb bodies and nv velocity coordinates, in
    order: the per-body scratch (nb, WIDTH); ABA's two 6×6 blocks; for mimic joints M (nv, nv) and nv zeros;
    a contiguous copy of the state (q, nq ≤ nv + 1, and two nv-vectors)."""
    return np.empty(workspace_size(nb, nv))


@njit(**INLINE)
def fits(P, S, q, nv):
    """True when ``q`` has the tree's nq = nv + (1 with a floating base) entries and ``S`` is its workspace."""
    return q.shape[0] == nv + floating(P) and S.shape[0] == workspace_size(P.shape[0], nv)


@njit(**INLINE)
def state_fits(P, S, q, qd, other, g, fext, nv):
    """:func:`fits`, and ``qd`` and ``other`` of nv entries, ``g`` of 3 and ``fext`` of 6."""
    return (fits(P, S, q, nv) and qd.shape[0] == nv and other.shape[0] == nv and g.shape[0] == 3
            and fext.shape[0] == 6)


@njit(**INLINE)
def body_scratch(P, S):
    """The per-body scratch ``W`` (nb, WIDTH) at the start of a :func:`workspace` ``S``."""
    return S[:P.shape[0] * WIDTH].reshape(P.shape[0], WIDTH)


@njit(**INLINE)
def state_offset(P, nv):
    """Where the copy of the state starts in a :func:`workspace`."""
    return P.shape[0] * WIDTH + SPATIAL_PAIR + nv * nv + nv


@njit(**INLINE)
def state_copy(x, S, o):
    """``x`` (n,) copied into ``S[o:o + n]``, returned as that contiguous view: the array type of a batch's
    rows, so that one compiled version of each sweep serves single states and batches."""
    for k in range(x.shape[0]):
        S[o + k] = x[k]
    return S[o:o + x.shape[0]]


@njit(**INLINE)
def all_finite(x):
    """True when every entry of ``x`` (any shape: torques, accelerations, a mass matrix) is finite: the check of
    every result of the single-state entries and sweeps (a NaN or inf means an input they could not use)."""
    for value in x.flat:
        if not math.isfinite(value):
            return False
    return True
