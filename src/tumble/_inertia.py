"""Validation of inertia tensors and rotations: the one place that checks an inertia tensor.

``principal_axes`` checks inertia tensors (kg·m², body axes) and returns their
principal moments and axes; :class:`tumble.RigidBody`, the torque models, the
robot links and the bodies whose inertia changes all validate through it. The
helpers for rotations and point masses live beside it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from tumble import _quat
from tumble._validate import ValidationError, as_array

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
    ``moments`` (…, 3) ascend, and two that differ by less than
    ``_DEGENERATE_RTOL`` (16 ε) × the largest — the rounding of the
    eigen-decomposition — are replaced by their mean, so a symmetric body
    described in rotated axes stays symmetric; ``axes`` (…, 3, 3) = R_BP, columns the principal
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

    scale = np.abs(inertia).max(axis=(-2, -1))
    bad = scale > _LARGEST
    if bad.any():
        field, k = where(bad)
        raise ValidationError(f"{field}: entries must be at most {_LARGEST:g} kg m^2 in magnitude (the "
                              f"eigen-decomposition squares them), got {scale[k]:.3g}{note(k)}")
    asym = np.abs(inertia - np.swapaxes(inertia, -1, -2)).max(axis=(-2, -1))
    bad = asym > _SYMMETRY_RTOL * scale
    if bad.any():
        field, k = where(bad)
        raise ValidationError(
            f"{field}: must be symmetric (max |I - I^T| = {asym[k]:.3g} > "
            f"{_SYMMETRY_RTOL:g} x max |I| = {_SYMMETRY_RTOL * scale[k]:.3g}){note(k)}"
        )
    inertia = 0.5 * (inertia + np.swapaxes(inertia, -1, -2))
    moments, axes = np.linalg.eigh(inertia)
    for i in (0, 1):  # a double (or triple) moment split by rounding: made equal again
        close = moments[..., i + 1] - moments[..., i] <= _DEGENERATE_RTOL * np.abs(moments[..., 2])
        mean = 0.5 * (moments[..., i] + moments[..., i + 1])
        moments[..., i] = np.where(close, mean, moments[..., i])
        moments[..., i + 1] = np.where(close, mean, moments[..., i + 1])
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
    largest = np.abs(axes).argmax(axis=-2)[..., None, :]
    axes = axes * np.sign(np.take_along_axis(axes, largest, axis=-2))
    axes[..., :, 2] *= np.sign(np.linalg.det(axes))[..., None]
    return inertia, moments, axes


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
