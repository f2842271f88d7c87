"""Inverse and forward dynamics of serial chains, batched and compiled.

The equations of motion of a chain with joint coordinates ``q`` (n,)::

    M(q) q̈ + C(q, q̇) q̇ + g(q) = τ + J(q)ᵀ w_ext

``τ`` (N·m for revolute, N for prismatic joints), ``M`` the joint-space
inertia matrix, ``C(q, q̇) q̇`` the Coriolis and centrifugal torques, ``g(q)``
the gravity torques, ``w_ext`` the external wrench on the end link.

Every function takes joint arrays of shape (n,) (one state, the fastest
path for a single call) or (B, n) (a batch, run in parallel over the cores),
and returns arrays of the same leading shape. ``gravity`` (m/s², base frame)
defaults to the chain's. ``f_ext`` is the wrench ``[f_x, f_y, f_z, n_x, n_y,
n_z]`` (N, N·m) exerted *on* the end link by its surroundings, in the axes of
the end link's frame (DH frame n, or the URDF link of the last moving joint),
the moment taken about that frame's origin; shape (6,) or (B, 6).

Algorithms: Featherstone, *Rigid Body Dynamics Algorithms* (Springer 2008):
RNEA (Table 5.1), CRBA (Table 6.2), ABA (Table 7.1); see
:mod:`tumble.kernels.featherstone`. Inputs are checked cheaply: shapes here, and
finiteness inside the compiled code (a non-finite result makes this layer
find and name the non-finite input).
"""

from __future__ import annotations

import numba
import numpy as np

from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _kernels
from tumble.robot.chain import SerialChain

__all__ = ["rnea", "gravity_torques", "coriolis", "mass_matrix", "forward_dynamics",
           "link_poses", "kinetic_energy", "potential_energy"]


# A batch is split into this many chunks per thread (load balance vs one scratch allocation per chunk).
_CHUNKS_PER_THREAD = 4


def _chunks(batch: int) -> int:
    return max(1, min(batch, _CHUNKS_PER_THREAD * numba.get_num_threads()))


_F64 = np.dtype(np.float64)
_NDARRAY = np.ndarray  # a module global: one lookup fewer per check on the fast path (measured 0.43 → 0.29 µs)


def _three(chain: SerialChain, a, b, c, names: tuple[str, str, str]):
    """Three joint arrays of one shape, (n,) or (B, n); a fast path for one state given as float64 arrays."""
    one = chain._one_state
    if (type(a) is _NDARRAY and type(b) is _NDARRAY and type(c) is _NDARRAY
            and a.dtype is _F64 and b.dtype is _F64 and c.dtype is _F64
            and a.shape == one and b.shape == one and c.shape == one):
        return a, b, c
    a = _joints(chain, a, names[0])
    return a, _like(chain, a, b, names[1]), _like(chain, a, c, names[2])


def _joints(chain: SerialChain, x, name: str) -> np.ndarray:
    """``x`` as a float64 array (n,) or a C-contiguous (B, n) batch."""
    a = np.asarray(x, dtype=np.float64)
    n = len(chain._links)
    if a.ndim == 1 and a.shape[0] == n:
        return a  # one state: a 1-D float64 array is contiguous unless strided (then Numba adapts)
    if a.ndim == 2 and a.shape[1] == n:
        return np.ascontiguousarray(a)
    raise ValidationError(f"{name}: must have shape ({n},) or (B, {n}) for this {n}-joint chain, got {a.shape}")


def _like(chain: SerialChain, q: np.ndarray, x, name: str) -> np.ndarray:
    """``x`` as a joint array of the shape of ``q``."""
    a = _joints(chain, x, name)
    if a.shape != q.shape:
        raise ValidationError(f"{name}: must have the shape of q {q.shape}, got {a.shape}")
    return a


def _gravity(gravity) -> np.ndarray:
    g = np.ascontiguousarray(gravity, dtype=np.float64)
    if g.shape != (3,):
        raise ValidationError(f"gravity: must have shape (3,), got {g.shape}")
    return g


def _wrench(chain: SerialChain, f_ext, q: np.ndarray) -> np.ndarray:
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


def _loads(chain: SerialChain, q, gravity, f_ext):
    """The gravity vector (m/s²) and the end-link wrench array of a call (the chain's defaults when None)."""
    g = chain._gravity if gravity is None else _gravity(gravity)
    if f_ext is None:
        return g, (chain._no_wrench if q.ndim == 1 else chain._no_wrenches)
    return g, _wrench(chain, f_ext, q)


def rnea(chain: SerialChain, q, qd, qdd, *, gravity=None, f_ext=None) -> np.ndarray:
    """Inverse dynamics ``τ = M(q) q̈ + C(q, q̇) q̇ + g(q) − J(q)ᵀ w_ext`` (recursive Newton–Euler).

    ``q`` (rad or m), ``qd`` (rad/s or m/s), ``qdd`` (rad/s² or m/s²) of shape
    (n,) or (B, n); returns ``τ`` of the same shape (N·m or N). Featherstone
    (2008) Table 5.1, with gravity as a base acceleration ``a₀ = −g``.
    """
    q, qd, qdd = _three(chain, q, qd, qdd, ("q", "qd", "qdd"))
    g, f = _loads(chain, q, gravity, f_ext)
    tau = np.empty(q.shape)
    if q.ndim == 1:
        ok = _kernels.rnea(chain._params, q, qd, qdd, g, f, tau)
    else:
        _kernels.rnea_batch(chain._params, q, qd, qdd, g, f, tau, _chunks(len(q)))
        ok = bool(np.isfinite(tau).all())
    if not ok:
        _explain("rnea", _OVERFLOW, q=q, qd=qd, qdd=qdd, gravity=g, f_ext=f)
    return tau


def gravity_torques(chain: SerialChain, q, *, gravity=None) -> np.ndarray:
    """``g(q)``: the joint torques that hold the chain still against gravity, ``rnea(q, 0, 0)``."""
    q = _joints(chain, q, "q")
    zero = np.zeros_like(q)
    return rnea(chain, q, zero, zero, gravity=gravity)


def coriolis(chain: SerialChain, q, qd) -> np.ndarray:
    """``C(q, q̇) q̇``: Coriolis and centrifugal torques, ``rnea(q, q̇, 0)`` without gravity."""
    q = _joints(chain, q, "q")
    zero = np.zeros_like(q)
    return rnea(chain, q, qd, zero, gravity=np.zeros(3))


def mass_matrix(chain: SerialChain, q) -> np.ndarray:
    """Joint-space inertia matrix ``M(q)``, (n, n) or (B, n, n), symmetric positive definite.

    The composite-rigid-body algorithm, Featherstone (2008) Table 6.2. Units
    kg·m² (revolute–revolute), kg·m (mixed), kg (prismatic–prismatic).
    """
    q = _joints(chain, q, "q")
    M = np.empty((*q.shape, chain.dof))
    if q.ndim == 1:
        _kernels.crba(chain._params, q, M)
    else:
        _kernels.crba_batch(chain._params, q, M, _chunks(len(q)))
    if not np.isfinite(M).all():
        _explain("mass_matrix", _OVERFLOW, q=q)
    return M


def forward_dynamics(chain: SerialChain, q, qd, tau, *, gravity=None, f_ext=None) -> np.ndarray:
    """Forward dynamics ``q̈ = M(q)⁻¹ (τ + J(q)ᵀ w_ext − C(q, q̇) q̇ − g(q))``, articulated-body algorithm.

    O(n) in the number of joints: Featherstone (2008) Table 7.1. Shapes and
    units as :func:`rnea`; returns ``q̈``.
    """
    q, qd, tau = _three(chain, q, qd, tau, ("q", "qd", "tau"))
    g, f = _loads(chain, q, gravity, f_ext)
    qdd = np.empty(q.shape)
    if q.ndim == 1:
        ok = _kernels.aba(chain._params, q, qd, tau, g, f, qdd)
    else:
        _kernels.aba_batch(chain._params, q, qd, tau, g, f, qdd, _chunks(len(q)))
        ok = bool(np.isfinite(qdd).all())
    if not ok:
        _explain("forward_dynamics", _SINGULAR, q=q, qd=qd, tau=tau, gravity=g, f_ext=f)
    return qdd


def link_poses(chain: SerialChain, q) -> np.ndarray:
    """Poses of the link frames in the base frame: (n, 4, 4) or (B, n, 4, 4) homogeneous transforms.

    ``T[i] = [[R, p], [0, 1]]``: ``R`` maps link-i axes to base axes, ``p`` is
    the origin of link frame i (m). These are the user's frames (DH frame i, or
    the URDF link of joint i).
    """
    q = _joints(chain, q, "q")
    T = np.empty((*q.shape, 4, 4))
    flat = q.reshape(-1, chain.dof)
    _kernels.poses_batch(chain._params, flat, T.reshape(-1, chain.dof, 4, 4))
    return T


def _energies(chain, q, qd, gravity):
    q = _joints(chain, q, "q")
    qd = _like(chain, q, qd, "qd")
    out = np.empty((*q.shape[:-1], 2))
    flat = q.reshape(-1, chain.dof)
    g = chain._gravity if gravity is None else _gravity(gravity)
    _kernels.energy_batch(chain._params, flat, qd.reshape(-1, chain.dof), g,
                          out.reshape(-1, 2))
    return out


def kinetic_energy(chain: SerialChain, q, qd) -> np.ndarray | float:
    """Kinetic energy ``T = ½ q̇ᵀ M(q) q̇ = Σᵢ ½ vᵢᵀ Iᵢ vᵢ`` (J), shape () or (B,)."""
    return _energies(chain, q, qd, None)[..., 0]


def potential_energy(chain: SerialChain, q, *, gravity=None) -> np.ndarray | float:
    """Gravitational potential energy ``V = −Σᵢ mᵢ g · cᵢ`` (J), zero at the base origin; shape () or (B,).

    ``cᵢ``: centre of mass of link i in the base frame.
    """
    q = _joints(chain, q, "q")
    return _energies(chain, q, np.zeros_like(q), gravity)[..., 1]
