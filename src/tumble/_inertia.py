"""Validation of inertia tensors and rotations: the one place that checks an inertia tensor.

``principal_axes`` checks inertia tensors (kg·m², body axes) and returns their
principal moments and axes; :class:`tumble.RigidBody`, the torque models, the
robot links and the bodies whose inertia changes all validate through it. The
helpers for rotations and point masses live beside it.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
from numba import njit
from numba.extending import register_jitable
from numpy.typing import ArrayLike

from tumble import _quat
from tumble._quat import mdet
from tumble._validate import ValidationError, as_array, readonly

# Inertia symmetric when max |I − Iᵀ| ≤ _SYMMETRY_RTOL · max |I|.
_SYMMETRY_RTOL = 1e-12
# Largest |entry| (kg·m²): the eigen-decomposition squares entries, and past ~1e154 LAPACK's does not converge.
_LARGEST = 1e150
# Positive definite when the smallest principal moment > _DEFINITE_RTOL × the
# largest: below that a moment is indistinguishable from zero at the float64
# rounding of the eigen-decomposition (~1e-16 × the largest moment).
_DEFINITE_RTOL = 1e-14
# Principal moments closer than _DEGENERATE_RTOL × the largest are equal: the
# eigen-decomposition of a tensor with a double moment splits it by a few ulps
# (9 ulps measured for diag(1, 2, 2) in rotated axes), which would turn a
# symmetric top into an asymmetric body whose motion drifts from the
# symmetric one by ~(split) × (angle turned).
_DEGENERATE_RTOL = 16 * np.finfo(np.float64).eps
# Tensors per thread from which a batch's eigen-decompositions are shared between threads (16 ms of LAPACK each).
_THREADED = 1 << 14
# Triangle inequality I₁ + I₂ ≥ I₃ (1 − _TRIANGLE_RTOL) on the moments.
_TRIANGLE_RTOL = 1e-9
# A rotation matrix must satisfy max |RᵀR − E| ≤ _ROTATION_TOL; a quaternion
# must satisfy | |q| − 1 | ≤ _ROTATION_TOL.
_ROTATION_TOL = 1e-10


def frozen(arr: ArrayLike) -> np.ndarray:
    """A read-only float64 copy of ``arr``."""
    arr = np.array(arr, dtype=np.float64)
    arr.flags.writeable = False
    return arr


def as_shape(value, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a finite float64 array of exactly ``shape``."""
    arr = as_array(value, name, tail=shape)
    if arr.shape != shape:
        raise ValidationError(f"{name}: must have shape {shape}, got {arr.shape}")
    return arr


def check_inertia(value, name: str, *, definite: bool, check_triangle: bool):
    """Validate an inertia tensor of shape (3, 3); return it symmetrized, its moments (ascending) and axes.

    The rules are those of :func:`principal_axes`.
    """
    return principal_axes(as_shape(value, name, (3, 3)), name, definite=definite, check_triangle=check_triangle)


def principal_axes(inertia, name: str = "inertia", *, definite: bool = True, check_triangle: bool = True,
                   member_note=None):
    """Validate inertia tensors (…, 3, 3) (kg·m², body axes); return them symmetrized, moments, axes.

    Rules: finite; symmetric to ``_SYMMETRY_RTOL`` relative to the largest
    |entry| (then symmetrized exactly, ``(I + Iᵀ)/2``); positive definite
    (``definite``) or semi-definite (parts: a thin rod, a point mass); with
    ``check_triangle``, ``I₁ + I₂ ≥ I₃ (1 − _TRIANGLE_RTOL)``. A broken rule
    raises :class:`ValidationError` naming ``name`` (and the batch index);
    ``member_note(k)``, if given, adds a word on member ``k`` (an index tuple),
    e.g. its sample time.
    ``moments`` (…, 3) ascend, and neighbours that differ by at most
    ``_DEGENERATE_RTOL`` (16 ε) × the largest — the rounding of the
    eigen-decomposition — are replaced by the mean of their group (two, or all
    three), so a symmetric body or a sphere described in rotated axes stays
    one; ``axes`` (…, 3, 3) = R_BP, columns the principal
    axes in body axes, made deterministic: each eigenvector's largest-magnitude
    component is positive, then the third is flipped if needed for det +1.
    Batched, so that a batch of N bodies is validated in one call.
    """
    inertia = as_array(inertia, name, tail=(3, 3))

    def where(bad):
        k = np.argwhere(bad)[0] if inertia.ndim > 2 else ()
        return name + "".join(f"[{int(i)}]" for i in k), tuple(int(i) for i in k)

    def note(k):
        return f" ({member_note(k)})" if member_note is not None and k else ""

    batch = inertia.shape[:-2]
    symmetric, scale, asym = np.empty(inertia.shape), np.empty(batch), np.empty(batch)
    _symmetrized(readonly(np.ascontiguousarray(inertia)).reshape(-1, 3, 3), symmetric.reshape(-1, 3, 3),
                 scale.reshape(-1), asym.reshape(-1))
    bad = scale > _LARGEST
    if bad.any():
        field, k = where(bad)
        raise ValidationError(f"{field}: entries must be at most {_LARGEST:g} kg m^2 in magnitude (the "
                              f"eigen-decomposition squares them), got {scale[k]:.3g}{note(k)}")
    bad = asym > _SYMMETRY_RTOL * scale
    if bad.any():
        field, k = where(bad)
        raise ValidationError(
            f"{field}: must be symmetric (max |I - I^T| = {asym[k]:.3g} > "
            f"{_SYMMETRY_RTOL:g} x max |I| = {_SYMMETRY_RTOL * scale[k]:.3g}){note(k)}"
        )
    inertia = symmetric
    moments, axes, diagonal = np.empty(batch + (3,)), np.empty(batch + (3, 3)), np.empty(batch, dtype=np.bool_)
    flat_moments, flat_axes = moments.reshape(-1, 3), axes.reshape(-1, 3, 3)
    _diagonal_decomposition(readonly(inertia).reshape(-1, 3, 3), flat_moments, flat_axes, diagonal.reshape(-1))
    rest = np.flatnonzero(~diagonal)
    if rest.size:
        flat_moments[rest], flat_axes[rest] = _eigh(inertia.reshape(-1, 3, 3)[rest])
    _canonical(flat_moments, flat_axes)
    m1, m2, m3 = moments[..., 0], moments[..., 1], moments[..., 2]
    bad = ~(m1 > _DEFINITE_RTOL * m3) if definite else m1 < -_DEFINITE_RTOL * m3
    if bad.any():
        field, k = where(bad)
        rule = (f"must be positive definite (principal moments {moments[k].tolist()} kg m^2; "
                f"the smallest must exceed {_DEFINITE_RTOL:g} x the largest)") if definite else (
                f"must be positive semi-definite (principal moments {moments[k].tolist()} kg m^2)")
        raise ValidationError(f"{field}: {rule}{note(k)}")
    bad = m1 + m2 < m3 * (1.0 - _TRIANGLE_RTOL)
    if check_triangle and bad.any():
        field, k = where(bad)
        raise ValidationError(
            f"{field}: principal moments break the triangle inequality "
            f"I1 + I2 >= I3 (1 - {_TRIANGLE_RTOL:g}): {m1[k]:.6g} + {m2[k]:.6g} "
            f"< {m3[k]:.6g}; pass check_triangle=False to accept such data{note(k)}"
        )
    return inertia, moments, axes


def _eigh(tensors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """NumPy's (LAPACK's) ``eigh`` of symmetric tensors (n, 3, 3): a batch of ``_THREADED`` or more per
    thread in one share per Numba thread (NumPy releases the GIL inside it: 1e6 rotated tensors take 1 s on
    one core), each tensor decomposed as alone, so the result is the same bit for bit."""
    shares = min(numba.get_num_threads(), len(tensors) // _THREADED)
    if shares < 2:
        return np.linalg.eigh(tensors)
    with ThreadPoolExecutor(shares) as pool:
        parts = list(pool.map(np.linalg.eigh, np.array_split(tensors, shares)))
    return np.concatenate([m for m, _ in parts]), np.concatenate([v for _, v in parts])


@register_jitable
def symmetrize(tensor, out):
    """``out = (I + Iᵀ)/2`` of one tensor ``I`` (3, 3); returns ``(max |Iᵢⱼ|, max |Iᵢⱼ − Iⱼᵢ|)``. Plain
    Python until compiled: the GPU's set-up (:mod:`tumble._rigid_cuda`) calls it too."""
    s = a = 0.0
    for i in range(3):
        for j in range(3):
            s = max(s, abs(tensor[i, j]))
            a = max(a, abs(tensor[i, j] - tensor[j, i]))
            out[i, j] = 0.5 * (tensor[i, j] + tensor[j, i])
    return s, a


@njit(cache=True)
def _symmetrized(inertia, out, scale, asym):
    """Per tensor ``n`` of ``inertia`` (n, 3, 3): ``out[n] = (I + Iᵀ)/2``, ``scale[n] = max |Iᵢⱼ|`` and
    ``asym[n] = max |Iᵢⱼ − Iⱼᵢ|`` (:func:`symmetrize`)."""
    for n in range(out.shape[0]):
        scale[n], asym[n] = symmetrize(inertia[n], out[n])


@njit(cache=True)
def _diagonal_decomposition(inertia, moments, axes, diagonal):
    """Per tensor ``n`` of ``inertia`` (n, 3, 3), symmetric: ``diagonal[n]``, whether its products of inertia
    are all zero, and for those the eigen-decomposition LAPACK's ``eigh`` returns, without its cost (0.3 µs
    a tensor): the diagonal into ``moments[n]`` and the body axes into the columns of ``axes[n]``, sorted
    ascending by selection (the smallest of the rest swapped into place, the first of equals), as LAPACK
    sorts. Other tensors are left to ``eigh``."""
    for n in range(inertia.shape[0]):
        a = inertia[n]
        diagonal[n] = a[0, 1] == 0.0 and a[0, 2] == 0.0 and a[1, 2] == 0.0
        if not diagonal[n]:
            continue
        m, v = moments[n], axes[n]
        for i in range(3):
            m[i] = a[i, i]
            for j in range(3):
                v[i, j] = 1.0 if i == j else 0.0
        sort_ascending(m, v)


@register_jitable
def sort_ascending(m, v):
    """In place: the moments ``m`` (3,) sorted ascending by selection (the smallest of the rest swapped into
    place, the first of equals), as LAPACK sorts, with the columns of ``v`` (3, 3) (their axes)."""
    for i in range(2):
        k = i
        for j in range(i + 1, 3):
            if m[j] < m[k]:
                k = j
        if k != i:
            m[i], m[k] = m[k], m[i]
            for r in range(3):
                v[r, i], v[r, k] = v[r, k], v[r, i]


@njit(cache=True)
def _canonical(moments, axes):
    """In place, per body ``n``: :func:`canonical` of ``moments[n]`` and ``axes[n]``."""
    for n in range(moments.shape[0]):
        canonical(moments[n], axes[n])


@register_jitable
def canonical(m, a):
    """In place, for one body: ascending moments ``m`` (3,) within ``_DEGENERATE_RTOL`` × the largest of a
    neighbour replaced by the mean of their group (a pair, or all three); each column of ``a`` (3, 3) (the
    eigenvectors) signed so that its largest-magnitude component (the first of equals) is positive, then
    the third negated where ``det < 0``, for a right-handed frame."""
    tol = _DEGENERATE_RTOL * abs(m[2])
    lower, upper = m[1] - m[0] <= tol, m[2] - m[1] <= tol
    if lower and upper:
        m[0] = m[1] = m[2] = (m[0] + m[1] + m[2]) / 3.0
    elif lower:
        m[0] = m[1] = 0.5 * (m[0] + m[1])
    elif upper:
        m[1] = m[2] = 0.5 * (m[1] + m[2])
    for j in range(3):
        largest = 0
        for i in range(1, 3):
            if abs(a[i, j]) > abs(a[largest, j]):
                largest = i
        if a[largest, j] < 0.0:
            a[0, j], a[1, j], a[2, j] = -a[0, j], -a[1, j], -a[2, j]
    if mdet(a) < 0.0:
        a[0, 2], a[1, 2], a[2, 2] = -a[0, 2], -a[1, 2], -a[2, 2]


def as_rotation(rotation, name: str) -> np.ndarray:
    """A 3×3 proper rotation from ``None`` (identity), a matrix or a unit quaternion [w, x, y, z]."""
    if rotation is None:
        return np.eye(3)
    r = as_array(rotation, name)
    if r.shape == (4,):
        norm = float(np.linalg.norm(r))
        if abs(norm - 1.0) > _ROTATION_TOL:
            raise ValidationError(
                f"{name}: a quaternion [w, x, y, z] must have unit norm "
                f"(|q| = {norm!r}, tolerance {_ROTATION_TOL:g})"
            )
        matrix = np.empty((3, 3))
        _quat.qto_matrix(*r.tolist(), matrix)
        return matrix
    if r.shape == (3, 3):
        err = np.abs(r.T @ r - np.eye(3)).max()
        if err > _ROTATION_TOL:
            raise ValidationError(
                f"{name}: must be orthonormal (max |R^T R - E| = {err:.3g} > {_ROTATION_TOL:g})"
            )
        if np.linalg.det(r) < 0.0:
            raise ValidationError(f"{name}: must be a proper rotation (det R = -1 is a reflection)")
        return r
    raise ValidationError(
        f"{name}: must be a 3x3 rotation matrix or a unit quaternion [w, x, y, z], got shape {r.shape}"
    )


def parallel_axis(masses, offsets) -> np.ndarray:
    """Inertia of point masses about the origin: ``Σₖ mₖ (|dₖ|² E − dₖ dₖᵀ)`` (kg·m²).

    ``masses`` (kg) of shape () or (n,), ``offsets`` ``dₖ`` (m) of shape (3,) or (n, 3).
    """
    masses = np.atleast_1d(masses)
    offsets = np.atleast_2d(offsets)
    return (masses @ (offsets * offsets).sum(axis=1)) * np.eye(3) - (masses[:, None] * offsets).T @ offsets
