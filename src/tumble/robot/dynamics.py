"""Inverse and forward dynamics of kinematic trees (serial chains included), batched and compiled.

The equations of motion of a robot with configuration ``q`` (nq,) and
velocity ``q̇`` (nv,) (:mod:`tumble.robot.tree`: for a fixed base these are
the joint coordinates and rates; a floating base adds ``[r, quat]`` and
``[ω, v]`` in front)::

    M(q) q̈ + C(q, q̇) q̇ + g(q) = τ + J(q)ᵀ w_ext

``τ`` (N·m for revolute, N for prismatic joints; the wrench (n, f) on a
floating base, base axes), ``M`` the joint-space inertia matrix, ``C(q, q̇)
q̇`` the Coriolis and centrifugal torques, ``g(q)`` the gravity torques,
``w_ext`` the external wrench on the last link. With mimic joints the
coordinates are the independent ones and ``τ``, ``M`` are ``Gᵀ τ``, ``Gᵀ M G``.

Every function takes arrays of shape (nq,) / (nv,) (one state, the fastest
path for a single call) or (B, nq) / (B, nv) (a batch, run in parallel over
the cores), and returns arrays of the same leading shape. ``gravity`` (m/s²,
world/base frame) defaults to the robot's. ``f_ext`` is the wrench ``[f_x,
f_y, f_z, n_x, n_y, n_z]`` (N, N·m) exerted *on* the last link by its
surroundings, in the axes of that link's frame (DH frame n, or the URDF link
of the last moving joint), the moment taken about that frame's origin; shape
(6,) or (B, 6).

Algorithms: Featherstone, *Rigid Body Dynamics Algorithms* (Springer 2008):
RNEA (Table 5.1), CRBA (Table 6.2), ABA (Table 7.1), floating base (§9.3,
Table 9.6); see :mod:`tumble.kernels.featherstone`. Inputs are checked
cheaply: one state given as 1-D float64 arrays goes straight to the compiled
code, which checks the sizes and the finiteness of the result; anything else,
or a failure there, takes the checked path here, which converts, checks the
shapes and, after a non-finite result, finds and names the non-finite input.
"""

from __future__ import annotations

from functools import cached_property

import numba
import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _kernels
from tumble.robot.tree import RobotTree

__all__ = ["rnea", "gravity_torques", "coriolis", "mass_matrix", "forward_dynamics",
           "link_poses", "kinetic_energy", "potential_energy"]


# A batch is split into this many chunks per thread (load balance vs one scratch allocation per chunk).
_CHUNKS_PER_THREAD = 4


def _chunks(batch: int) -> int:
    return max(1, min(batch, _CHUNKS_PER_THREAD * numba.get_num_threads()))


_F64 = np.dtype(np.float64)
_NDARRAY = np.ndarray  # a module global: one lookup fewer per check on the fast path (measured 0.43 → 0.29 µs)
_empty = np.empty  # likewise per result (measured 0.03 µs)


def _vectors(a, b, c) -> bool:
    """True when ``a``, ``b``, ``c`` are 1-D float64 ndarrays: one state that the compiled entries take as given
    (their sizes are checked in the compiled code)."""
    return (type(a) is _NDARRAY and type(b) is _NDARRAY and type(c) is _NDARRAY
            and a.dtype is _F64 and b.dtype is _F64 and c.dtype is _F64 and a.ndim == 1 and b.ndim == 1
            and c.ndim == 1)


_VECTOR = numba.types.Array(numba.float64, 1, "A")  # (n,), any stride: q, qd, qdd, tau as given
_FLAT = numba.types.Array(numba.float64, 1, "C")  # (n,), contiguous: gravity, wrench, the workspace, a result
_TABLE = numba.types.Array(numba.float64, 2, "C")  # (rows, columns), C order: the tree's P, a result M


class _SingleState:
    """The single-state kernels of :mod:`tumble.kernels.featherstone`, each as the compiled entry of one
    signature (compiled, or loaded from Numba's cache, on first use, then a plain attribute), so that a call
    skips Numba's type resolution of its arguments (measured 0.35 → 0.21 µs for seven arrays). An entry does
    not check types: callers pass float64 ndarrays of these dimensions only (sizes are checked by the
    kernels)."""

    @cached_property
    def rnea(self):
        return _kernels.rnea.compile((_TABLE,) + (_VECTOR,) * 3 + (_FLAT,) * 4)

    @cached_property
    def crba(self):
        return _kernels.crba.compile((_TABLE, _VECTOR, _FLAT, _TABLE))

    @cached_property
    def aba(self):
        return _kernels.aba.compile((_TABLE,) + (_VECTOR,) * 3 + (_FLAT,) * 4)


_one = _SingleState()


def _three(model: RobotTree, a: ArrayLike, b: ArrayLike, c: ArrayLike, names: tuple[str, str, str]
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A configuration (nq,) or (B, nq) and two velocity-like arrays (nv,) or (B, nv), checked and named."""
    a = _joints(model, a, names[0], model._nq)
    return a, _like(model, a, b, names[1]), _like(model, a, c, names[2])


def _joints(model: RobotTree, x, name: str, size: int | None = None) -> np.ndarray:
    """``x`` as a C-contiguous, writeable float64 array (n,) or batch (B, n), n = ``size`` (default nq).

    Writeable (a read-only input, such as a Trajectory's, is copied): the kernels then compile once, with the
    arrays that the compiled robot model passes them.
    """
    a = np.asarray(x, dtype=np.float64)
    n = model._nq if size is None else size
    if (a.ndim == 1 and a.shape[0] == n) or (a.ndim == 2 and a.shape[1] == n):
        return a if a.flags.c_contiguous and a.flags.writeable else np.array(a)
    what = "configuration coordinates" if size is None or size == model._nq else "velocity coordinates"
    raise ValidationError(f"{name}: must have shape ({n},) or (B, {n}) for the {n} {what} of this robot, "
                          f"got {a.shape}")


def _like(model: RobotTree, q: np.ndarray, x, name: str) -> np.ndarray:
    """``x`` as a velocity-like array (nv,) or (B, nv) with the leading shape of ``q``."""
    a = _joints(model, x, name, model._nv)
    if a.shape[:-1] != q.shape[:-1]:
        raise ValidationError(f"{name}: must have the batch shape of q {q.shape[:-1]}, got {a.shape[:-1]}")
    return a


def _gravity(gravity) -> np.ndarray:
    g = np.ascontiguousarray(gravity, dtype=np.float64)
    if g.shape != (3,):
        raise ValidationError(f"gravity: must have shape (3,), got {g.shape}")
    return g


def _wrench(model: RobotTree, f_ext, q: np.ndarray) -> np.ndarray:
    f = np.ascontiguousarray(f_ext, dtype=np.float64)
    if q.ndim == 1 and f.shape == (6,):
        return f
    if q.ndim == 2 and (f.shape == (6,) or f.shape in ((1, 6), (q.shape[0], 6))):
        return f.reshape(-1, 6)
    raise ValidationError(f"f_ext: must have shape (6,) or ({len(q)}, 6) for q of shape {q.shape}, got {f.shape}")


_OVERFLOW = "a value overflowed"
_SINGULAR = "the joint-space inertia is singular (a joint moves no mass or inertia) or a value overflowed"


def _explain(what: str, cause: str, **inputs) -> None:
    """After a non-finite result of ``what``: raise naming the input that is not finite, else the ``cause``."""
    for name, value in inputs.items():
        as_array(value, name)  # raises, naming the field and the index
    raise ValidationError(f"{what}: the result is not finite although the inputs are: {cause}")


def _loads(model: RobotTree, q: np.ndarray, gravity: ArrayLike | None, f_ext: ArrayLike | None
           ) -> tuple[np.ndarray, np.ndarray]:
    """The gravity vector (m/s²) and the end-link wrench array of a call (the chain's defaults when None)."""
    g = model._gravity if gravity is None else _gravity(gravity)
    if f_ext is None:
        return g, (model._no_wrench if q.ndim == 1 else model._no_wrenches)
    return g, _wrench(model, f_ext, q)


def rnea(model: RobotTree, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, *, gravity: ArrayLike | None = None,
         f_ext: ArrayLike | None = None) -> np.ndarray:
    """Inverse dynamics ``τ = M(q) q̈ + C(q, q̇) q̇ + g(q) − J(q)ᵀ w_ext`` (recursive Newton–Euler).

    ``q`` (rad or m), ``qd`` (rad/s or m/s), ``qdd`` (rad/s² or m/s²) of shape
    (nq,)/(nv,) or (B, ·); returns ``τ`` (nv,) or (B, nv) (N·m or N). Featherstone
    (2008) Table 5.1, with gravity as a base acceleration ``a₀ = −g``.
    """
    if gravity is None and f_ext is None and _vectors(q, qd, qdd):  # one state: the checks are the kernel's
        tau = _empty(model._nv)
        if _one.rnea(model._params, q, qd, qdd, model._gravity, model._no_wrench, model._workspace, tau):
            return tau
    q, qd, qdd = _three(model, q, qd, qdd, ("q", "qd", "qdd"))  # else (or on failure) checked, errors named
    g, f = _loads(model, q, gravity, f_ext)
    tau = np.empty(qd.shape)
    if q.ndim == 1:
        ok = _one.rnea(model._params, q, qd, qdd, g, f, model._workspace, tau)
    else:
        _kernels.rnea_batch(model._params, q, qd, qdd, g, f, tau, _chunks(len(q)))
        ok = bool(np.isfinite(tau).all())
    if not ok:
        _explain("rnea", _OVERFLOW, q=q, qd=qd, qdd=qdd, gravity=g, f_ext=f)
    return tau


def gravity_torques(model: RobotTree, q: ArrayLike, *, gravity: ArrayLike | None = None) -> np.ndarray:
    """``g(q)``: the joint torques that hold the chain still against gravity, ``rnea(q, 0, 0)``."""
    q = _joints(model, q, "q")
    zero = np.zeros((*q.shape[:-1], model._nv))
    return rnea(model, q, zero, zero, gravity=gravity)


def coriolis(model: RobotTree, q: ArrayLike, qd: ArrayLike) -> np.ndarray:
    """``C(q, q̇) q̇``: Coriolis and centrifugal torques, ``rnea(q, q̇, 0)`` without gravity."""
    q = _joints(model, q, "q")
    zero = np.zeros((*q.shape[:-1], model._nv))
    return rnea(model, q, qd, zero, gravity=np.zeros(3))


def mass_matrix(model: RobotTree, q: ArrayLike) -> np.ndarray:
    """Joint-space inertia matrix ``M(q)``, (n, n) or (B, n, n), symmetric positive definite.

    The composite-rigid-body algorithm, Featherstone (2008) Table 6.2. Units
    kg·m² (revolute–revolute), kg·m (mixed), kg (prismatic–prismatic).
    """
    nv = model._nv
    if type(q) is _NDARRAY and q.dtype is _F64 and q.ndim == 1:  # one state: the size check is the kernel's
        M = _empty((nv, nv))
        if _one.crba(model._params, q, model._workspace, M):
            return M
    q = _joints(model, q, "q")  # else (or on failure) checked, errors named
    M = np.empty((*q.shape[:-1], nv, nv))
    if q.ndim == 1:
        ok = _one.crba(model._params, q, model._workspace, M)
    else:
        _kernels.crba_batch(model._params, q, M, _chunks(len(q)))
        ok = bool(np.isfinite(M).all())
    if not ok:
        _explain("mass_matrix", _OVERFLOW, q=q)
    return M


def forward_dynamics(model: RobotTree, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, *, gravity: ArrayLike | None = None,
                     f_ext: ArrayLike | None = None) -> np.ndarray:
    """Forward dynamics ``q̈ = M(q)⁻¹ (τ + J(q)ᵀ w_ext − C(q, q̇) q̇ − g(q))``, articulated-body algorithm.

    O(n) in the number of joints: Featherstone (2008) Table 7.1. Shapes and
    units as :func:`rnea`; returns ``q̈``.
    """
    if gravity is None and f_ext is None and _vectors(q, qd, tau):  # one state: the checks are the kernel's
        qdd = _empty(model._nv)
        if _one.aba(model._params, q, qd, tau, model._gravity, model._no_wrench, model._workspace, qdd):
            return qdd
    q, qd, tau = _three(model, q, qd, tau, ("q", "qd", "tau"))  # else (or on failure) checked, errors named
    g, f = _loads(model, q, gravity, f_ext)
    qdd = np.empty(qd.shape)
    if q.ndim == 1:
        ok = _one.aba(model._params, q, qd, tau, g, f, model._workspace, qdd)
    else:
        _kernels.aba_batch(model._params, q, qd, tau, g, f, qdd, _chunks(len(q)))
        ok = bool(np.isfinite(qdd).all())
    if not ok:
        cause = f"joint(s) {list(model.massless_joints)} move no mass or inertia: M(q) is singular" \
            if model.massless_joints else _SINGULAR
        _explain("forward_dynamics", cause, q=q, qd=qd, tau=tau, gravity=g, f_ext=f)
    return qdd


def link_poses(model: RobotTree, q: ArrayLike) -> np.ndarray:
    """Poses of the link frames in the base frame: (n, 4, 4) or (B, n, 4, 4) homogeneous transforms.

    ``T[i] = [[R, p], [0, 1]]``: ``R`` maps link-i axes to base axes, ``p`` is
    the origin of link frame i (m). These are the user's frames (DH frame i, or
    the URDF link of joint i).
    """
    q = _joints(model, q, "q")
    nb = len(model._links)
    T = np.empty((*q.shape[:-1], nb, 4, 4))
    _kernels.poses_batch(model._params, q.reshape(-1, model._nq), T.reshape(-1, nb, 4, 4))
    return T


def _energies(model, q, qd, gravity):
    q = _joints(model, q, "q")
    qd = _like(model, q, qd, "qd")
    out = np.empty((*q.shape[:-1], 2))
    g = model._gravity if gravity is None else _gravity(gravity)
    _kernels.energy_batch(model._params, q.reshape(-1, model._nq), qd.reshape(-1, model._nv), g,
                          out.reshape(-1, 2))
    return out


def kinetic_energy(model: RobotTree, q: ArrayLike, qd: ArrayLike) -> np.ndarray | float:
    """Kinetic energy ``T = ½ q̇ᵀ M(q) q̇ = Σᵢ ½ vᵢᵀ Iᵢ vᵢ`` (J), shape () or (B,)."""
    return _energies(model, q, qd, None)[..., 0]


def potential_energy(model: RobotTree, q: ArrayLike, *, gravity: ArrayLike | None = None) -> np.ndarray | float:
    """Gravitational potential energy ``V = −Σᵢ mᵢ g · cᵢ`` (J), zero at the base origin; shape () or (B,).

    ``cᵢ``: centre of mass of link i in the base frame.
    """
    q = _joints(model, q, "q")
    return _energies(model, q, np.zeros((*q.shape[:-1], model._nv)), gravity)[..., 1]
