"""Attitude representations: quaternions, rotation matrices, rotation vectors, Euler angles.

Conventions (the same everywhere in ``tumble``):

* An attitude is a Hamilton quaternion, **scalar first**, ``q = [w, x, y, z]``,
  mapping body axes to inertial axes:

      v_I = q ⊗ v_B ⊗ q*  =  R(q) v_B,

  where ``R(q)`` (:func:`to_matrix`) is the matching body → inertial rotation
  matrix. ``q`` and ``-q`` are the same rotation. Functions that interpret a
  quaternion as a rotation accept any non-zero ``q`` and use ``q / |q|``
  (as ``scipy.spatial.transform.Rotation`` does); :func:`multiply` and
  :func:`conjugate` are plain quaternion algebra.
* A rotation vector ``r`` (rad) is axis × angle: ``q = exp(r/2) =
  [cos(θ/2), sin(θ/2) r/θ]`` with ``θ = |r|``.
* Euler angles follow ``scipy.spatial.transform.Rotation.from_euler``: a
  sequence of three axes, lowercase ``"xyz"`` for *extrinsic* rotations about
  the fixed inertial axes, uppercase ``"XYZ"`` for *intrinsic* rotations about
  the moving body axes. Intrinsic ``"IJK"`` with angles ``(a, b, c)`` is
  ``q = q_I(a) ⊗ q_J(b) ⊗ q_K(c)``, i.e. ``R = R_I(a) R_J(b) R_K(c)``;
  extrinsic ``"ijk"`` is ``R = R_k(c) R_j(b) R_i(a)``. :func:`to_euler`
  returns the first and third angles in (-π, π] and the second in
  [-π/2, π/2] (Tait–Bryan, three different axes) or [0, π] (proper Euler,
  first axis = third axis).

All functions take array-likes with any leading batch axes (the last axis is
the quaternion (…, 4), the vector (…, 3) or the matrix (…, 3, 3)), broadcast
the batch axes of two arguments against each other, and return float64 NumPy
arrays. The conversion to and from scipy's scalar-last ``Rotation`` happens
only in :func:`to_scipy` and :func:`from_scipy`.

The module is one unit (about 550 lines), as scipy's ``Rotation`` is one
class: every representation converts to and from the quaternion through the
same input checks and batch shapes (the first section), and each public
function is a few lines over its compiled loop (the second), so that a
reader finds a conversion and the loop it runs side by side.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from ._quat import orthonormality, qexp, qfrom_matrix, qlog, qmul, qrotate, qrotate_inv, qto_matrix, qunit
from ._validate import ValidationError, as_array, readonly, require_positive
from ._vec import norm

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

__all__ = [
    "GIMBAL_LOCK_THRESHOLD",
    "GimbalLockWarning",
    "NonUnitQuaternionWarning",
    "angle",
    "conjugate",
    "from_euler",
    "from_matrix",
    "from_rotvec",
    "from_scipy",
    "identity",
    "multiply",
    "normalize",
    "relative_angle",
    "rotate",
    "rotate_inverse",
    "to_euler",
    "to_matrix",
    "to_rotvec",
    "to_scipy",
]

#: Distance (rad) of the second Euler angle from a singular value (0 or π for
#: proper Euler angles, ±π/2 for Tait–Bryan angles) below which
#: :func:`to_euler` treats the rotation as gimbal-locked (the value scipy uses).
GIMBAL_LOCK_THRESHOLD = 1e-7


class GimbalLockWarning(UserWarning):
    """Euler angles were requested for rotations at gimbal lock; the third angle was set to 0."""


class NonUnitQuaternionWarning(UserWarning):
    """An initial attitude given to :func:`tumble.simulate` was further than ``UNIT_Q0_TOL`` (1e-6) from unit
    length, and was normalised: ``q / |q|`` was used."""


# --------------------------------------------------------------------------
# Input checks and batch shapes (Python layer)
# --------------------------------------------------------------------------


def _where(bad: np.ndarray) -> str:
    """`` at index …`` for the first True entry of a boolean batch array ('' if 0-d)."""
    if bad.ndim == 0:
        return ""
    idx = tuple(int(i) for i in np.argwhere(bad)[0])
    return f" at index {idx[0] if len(idx) == 1 else idx}"


#: The largest rotation angle (rad) :func:`from_rotvec` takes: past it the spacing of float64 numbers is 2 rad.
_HUGE_ANGLE = 1e16


def _require_defined_angle(theta: np.ndarray, name: str, what: str) -> None:
    """Refuse angles (rad) past :data:`_HUGE_ANGLE` in magnitude, naming ``name`` and ``what`` they are."""
    huge = ~(np.abs(theta) <= _HUGE_ANGLE)
    if np.any(huge):
        raise ValidationError(f"{name}: {what} = {float(np.asarray(theta)[huge].flat[0]):.3g} rad{_where(huge)} "
                              f"is past {_HUGE_ANGLE:g} rad, where float64 angles are 2 rad apart and define no "
                              "rotation: reduce it modulo 2π first")


def _as_quat(q, name: str = "q", *, nonzero: bool = True) -> np.ndarray:
    """``q`` as a float64 (…, 4) array; with ``nonzero``, refuse q = 0 (it is no rotation)."""
    q = as_array(q, name, tail=(4,))
    if nonzero:
        zero = ~q.any(axis=-1)
        if zero.any():
            raise ValidationError(
                f"{name}: must be non-zero to represent a rotation (|{name}| = 0{_where(zero)})"
            )
    return q


def _scaled(q: np.ndarray) -> np.ndarray:
    """``q`` (non-zero) times the power of two that brings its largest |component| into [0.5, 1): the same
    rotation, scaled exactly (no rounding: formulas homogeneous in ``q`` give the same bits), with squares that
    neither underflow (``q = [1e-200, 1e-200, 0, 0]``) nor overflow (``[1e308, 1e308, 1e308, 1e308]``)."""
    return np.ldexp(q, -np.frexp(np.abs(q).max(axis=-1, keepdims=True))[1])


def _flat(arr: np.ndarray, batch: tuple[int, ...], tail: tuple[int, ...]) -> np.ndarray:
    """``arr`` broadcast to ``batch + tail`` and flattened to a C-contiguous, read-only (n, *tail) array
    (:func:`~tumble._validate.readonly`: the loops compile once)."""
    return readonly(np.broadcast_to(arr, batch + tail)).reshape((-1, *tail))


def _batch(*args: tuple[str, np.ndarray, int]) -> tuple[int, ...]:
    """Broadcast batch shape of arrays given as (name, array, number of trailing core axes)."""
    shapes = [a.shape[: a.ndim - core] for _, a, core in args]
    try:
        return np.broadcast_shapes(*shapes)
    except ValueError:
        names = ", ".join(name for name, _, _ in args)
        raise ValidationError(
            f"{names}: batch shapes must broadcast, got {' and '.join(map(str, shapes))}"
        ) from None


# --------------------------------------------------------------------------
# Compiled batch loops over flattened arrays; they call the _quat kernels.
# Inputs are validated (finite, non-zero where a rotation is meant) before.
# Results are stored component by component: assigning a tuple to a row
# (out[n] = ...) compiles Numba's shape-mismatch message formatter, 1.8 s of
# CPU in the first process that needs it (Numba 0.68).
# --------------------------------------------------------------------------


@njit(cache=True)
def _multiply_loop(p, q, out):
    for n in range(out.shape[0]):
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = qmul(p[n, 0], p[n, 1], p[n, 2], p[n, 3],
                                                          q[n, 0], q[n, 1], q[n, 2], q[n, 3])


@njit(cache=True)
def _normalize_loop(q, out):
    for n in range(out.shape[0]):
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = qunit(q[n, 0], q[n, 1], q[n, 2], q[n, 3])


@njit(cache=True)
def _rotate_loop(q, v, inverse, out):
    for n in range(out.shape[0]):
        w, x, y, z = qunit(q[n, 0], q[n, 1], q[n, 2], q[n, 3])
        if inverse:
            out[n, 0], out[n, 1], out[n, 2] = qrotate_inv(w, x, y, z, v[n, 0], v[n, 1], v[n, 2])
        else:
            out[n, 0], out[n, 1], out[n, 2] = qrotate(w, x, y, z, v[n, 0], v[n, 1], v[n, 2])


@njit(cache=True)
def _to_matrix_loop(q, out):
    for n in range(out.shape[0]):
        w, x, y, z = qunit(q[n, 0], q[n, 1], q[n, 2], q[n, 3])
        qto_matrix(w, x, y, z, out[n])


@njit(cache=True)
def _from_matrix_loop(m, tol, out, err, det):
    """``err[n], det[n]`` = max |mᵀm − 1| and det m of each matrix, and its quaternion into ``out[n]`` where
    ``err[n] ≤ tol`` and ``det[n] > 0`` (the caller refuses the others)."""
    for n in range(out.shape[0]):
        err[n], det[n] = orthonormality(m[n])
        if err[n] <= tol and det[n] > 0.0:
            out[n, 0], out[n, 1], out[n, 2], out[n, 3] = qfrom_matrix(m[n])


@njit(cache=True)
def _from_rotvec_loop(r, out):
    for n in range(out.shape[0]):
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = qexp(r[n, 0], r[n, 1], r[n, 2])


@njit(cache=True)
def _to_rotvec_loop(q, out):
    for n in range(out.shape[0]):
        out[n, 0], out[n, 1], out[n, 2] = qlog(q[n, 0], q[n, 1], q[n, 2], q[n, 3])


@njit(cache=True)
def _angle_loop(q, out):
    for n in range(out.shape[0]):
        rx, ry, rz = qlog(q[n, 0], q[n, 1], q[n, 2], q[n, 3])
        out[n] = math.sqrt(rx * rx + ry * ry + rz * rz)


@njit(cache=True)
def _axis_quat(axis, theta):
    """Quaternion of a rotation by ``theta`` (rad) about coordinate axis 0, 1 or 2."""
    return qexp(theta if axis == 0 else 0.0, theta if axis == 1 else 0.0, theta if axis == 2 else 0.0)


@njit(cache=True)
def _from_euler_loop(angles, i, j, k, out):
    for n in range(out.shape[0]):
        a = _axis_quat(i, angles[n, 0])
        b = _axis_quat(j, angles[n, 1])
        c = _axis_quat(k, angles[n, 2])
        ab = qmul(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3])
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = qmul(ab[0], ab[1], ab[2], ab[3], c[0], c[1], c[2], c[3])


@njit(cache=True)
def _wrap(angle):
    """Map an angle in [-2π, 2π] to (-π, π]."""
    if angle > math.pi:
        return angle - 2.0 * math.pi
    if angle <= -math.pi:
        return angle + 2.0 * math.pi
    return angle


@njit(cache=True)
def _to_euler_loop(q, i, j, k, zero_first, threshold, out):
    """Intrinsic Euler angles ``q ∝ q_i(a) ⊗ q_j(b) ⊗ q_k(c)``; returns the number of gimbal locks.

    Bernardes & Viollet (2022): with ``m`` the axis other than ``i, j`` and
    ``e = ±1`` the sign of the permutation ``(i, j, m)``, the four numbers

        proper Euler (k = i):  a, b, c, d = w, q_i, q_j, e q_m
        Tait–Bryan   (k = m):  a, b, c, d = w - q_j, q_i - e q_m, w + q_j, q_i + e q_m

    are ``(C cos θ₊, C sin θ₊, S cos θ₋, S sin θ₋)`` with ``C, S = cos, sin(b̃/2)``,
    ``θ± = (a ± c̃)/2``, ``b = b̃`` (proper) or ``b̃ - π/2``, and ``c = c̃``
    (proper) or ``-e c̃`` (Tait–Bryan). The formulas do not need ``|q| = 1``.
    At gimbal lock (``S`` or ``C`` ≈ 0) only ``θ₊`` or ``θ₋`` is defined; the
    third angle (or, with ``zero_first``, the first) is set to 0.
    """
    m = 3 - i - j
    e = 1.0 if (j - i) % 3 == 1 else -1.0
    proper = i == k
    sign = -1.0 if zero_first else 1.0
    locked = 0
    for n in range(out.shape[0]):
        w, qi, qj, qm = q[n, 0], q[n, 1 + i], q[n, 1 + j], e * q[n, 1 + m]
        if proper:
            a, b, c, d = w, qi, qj, qm
        else:
            a, b, c, d = w - qj, qi - qm, w + qj, qi + qm
        second = 2.0 * math.atan2(math.hypot(c, d), math.hypot(a, b))
        plus = math.atan2(b, a)
        minus = math.atan2(d, c)
        if second <= threshold:
            minus = sign * plus
            locked += 1
        elif second >= math.pi - threshold:
            plus = sign * minus
            locked += 1
        first, third = plus + minus, plus - minus
        if not proper:
            second -= 0.5 * math.pi
            third = 0.0 - e * third  # 0.0 - …: no -0.0 at gimbal lock
        out[n, 0] = _wrap(first)
        out[n, 1] = second
        out[n, 2] = _wrap(third)
    return locked


# --------------------------------------------------------------------------
# Quaternion algebra
# --------------------------------------------------------------------------


def identity(shape: int | tuple[int, ...] = ()) -> np.ndarray:
    """Identity quaternions ``[1, 0, 0, 0]`` of shape ``(*shape, 4)``."""
    shape = (shape,) if isinstance(shape, (int, np.integer)) else tuple(shape)
    q = np.zeros((*shape, 4))
    q[..., 0] = 1.0
    return q


def multiply(p: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` (…, 4), batch axes broadcast.

    For unit quaternions, ``R(p ⊗ q) = R(p) R(q)``: ``q`` is applied first.
    The inputs need not be unit quaternions and are not normalised.
    """
    p, q = _as_quat(p, "p", nonzero=False), _as_quat(q, "q", nonzero=False)
    batch = _batch(("p", p, 1), ("q", q, 1))
    out = np.empty((math.prod(batch), 4))
    _multiply_loop(_flat(p, batch, (4,)), _flat(q, batch, (4,)), out)
    return out.reshape((*batch, 4))


def conjugate(q: ArrayLike) -> np.ndarray:
    """Conjugate ``q* = [w, -x, -y, -z]`` (…, 4); for a unit ``q`` it is the inverse rotation."""
    return _as_quat(q, nonzero=False) * np.array([1.0, -1.0, -1.0, -1.0])


def normalize(q: ArrayLike) -> np.ndarray:
    """Unit quaternion ``q / |q|`` (…, 4); a zero quaternion raises :class:`ValidationError`."""
    return _normalized(_as_quat(q))


def _normalized(q: np.ndarray) -> np.ndarray:
    """:func:`normalize` of a float64 (…, 4) array already checked (finite, non-zero; the front door's)."""
    out = np.empty((math.prod(q.shape[:-1]), 4))
    _normalize_loop(readonly(q).reshape((-1, 4)), out)
    return out.reshape(q.shape)


# --------------------------------------------------------------------------
# Rotating vectors, rotation matrices
# --------------------------------------------------------------------------


def _rotate(q, v, inverse: bool) -> np.ndarray:
    q, v = _as_quat(q), as_array(v, "v", tail=(3,))
    batch = _batch(("q", q, 1), ("v", v, 1))
    out = np.empty((math.prod(batch), 3))
    _rotate_loop(_flat(q, batch, (4,)), _flat(v, batch, (3,)), inverse, out)
    return out.reshape((*batch, 3))


def rotate(q: ArrayLike, v: ArrayLike) -> np.ndarray:
    """Rotate body-axis vectors into inertial axes: ``v_I = q ⊗ v_B ⊗ q* = R(q) v_B``.

    ``q`` (…, 4) is used as ``q / |q|``; ``v`` (…, 3) in any unit; batch axes broadcast.
    """
    return _rotate(q, v, False)


def rotate_inverse(q: ArrayLike, v: ArrayLike) -> np.ndarray:
    """Rotate inertial-axis vectors into body axes: ``v_B = q* ⊗ v_I ⊗ q = R(q)ᵀ v_I``.

    ``q`` (…, 4) is used as ``q / |q|``; ``v`` (…, 3) in any unit; batch axes broadcast.
    """
    return _rotate(q, v, True)


def to_matrix(q: ArrayLike) -> np.ndarray:
    """Rotation matrix ``R(q)`` (…, 3, 3), body → inertial (``v_I = R v_B``), of ``q / |q|``.

    ``R = (w² - |u|²) 1 + 2 u uᵀ + 2 w [u]×`` with ``q = [w, u]``.
    """
    q = _as_quat(q)
    out = np.empty((math.prod(q.shape[:-1]), 3, 3))
    _to_matrix_loop(_flat(q, q.shape[:-1], (4,)), out)
    return out.reshape((*q.shape[:-1], 3, 3))


def from_matrix(R: ArrayLike, *, tol: float = 1e-6) -> np.ndarray:
    """Unit quaternion (…, 4), with ``w ≥ 0``, of body → inertial rotation matrices ``R`` (…, 3, 3).

    ``R`` must be orthonormal, ``max |RᵀR - 1| ≤ tol``, and proper,
    ``det R > 0`` (so ``det R = +1`` to within ``tol``); otherwise
    :class:`ValidationError` is raised. A matrix within ``tol`` of a rotation
    is accepted as it is, without a separate orthonormalisation: Shepperd's
    method (S. W. Shepperd, J. Guidance Control 1(3), 1978) followed by
    normalisation returns a rotation within O(tol) of it, and the exact one
    for an orthonormal ``R``.
    """
    tol = require_positive(tol, "tol")
    R = as_array(R, "R", tail=(3, 3))
    batch = R.shape[:-2]
    out, err, det = np.empty((math.prod(batch), 4)), np.empty(batch), np.empty(batch)
    _from_matrix_loop(_flat(R, batch, (3, 3)), tol, out, err.reshape(-1), det.reshape(-1))
    bad = err > tol
    if bad.any():
        raise ValidationError(
            f"R: must be orthonormal (max |RᵀR - 1| = {err[bad].flat[0]:.3g} > tol = {tol:g}{_where(bad)})"
        )
    bad = det <= 0.0
    if bad.any():
        raise ValidationError(
            f"R: must have det = +1, a proper rotation (found det = {det[bad].flat[0]:.3g}{_where(bad)})"
        )
    return out.reshape((*R.shape[:-2], 4))


# --------------------------------------------------------------------------
# Rotation vectors and angles
# --------------------------------------------------------------------------


def from_rotvec(r: ArrayLike) -> np.ndarray:
    """Unit quaternion (…, 4) of rotation vectors ``r`` (…, 3, rad).

    ``q = exp(r/2) = [cos(θ/2), sin(θ/2) r/θ]`` with ``θ = |r|`` (a Taylor
    series for ``θ < 1e-4``). An angle past :data:`_HUGE_ANGLE` (1e16 rad) is
    refused: float64 angles there are 2 rad apart, so they define no rotation
    (and ``θ²`` overflows past 1.3e154, which gave NaN).
    """
    r = as_array(r, "r", tail=(3,))
    _require_defined_angle(norm(r), "r", "rotation angle |r|")
    out = np.empty((math.prod(r.shape[:-1]), 4))
    _from_rotvec_loop(_flat(r, r.shape[:-1], (3,)), out)
    return out.reshape((*r.shape[:-1], 4))


def to_rotvec(q: ArrayLike) -> np.ndarray:
    """Rotation vector (…, 3, rad) of ``q / |q|``, angle ``θ = 2 atan2(|u|, |w|)`` in [0, π]."""
    q = _scaled(_as_quat(q))
    out = np.empty((math.prod(q.shape[:-1]), 3))
    _to_rotvec_loop(_flat(q, q.shape[:-1], (4,)), out)
    return out.reshape((*q.shape[:-1], 3))


def angle(q: ArrayLike) -> np.ndarray:
    """Rotation angle θ ∈ [0, π] (rad, shape (…)) of ``q / |q|``.

    ``θ = 2 atan2(|u|, |w|)`` with ``q = [w, u]``: accurate near 0 and near π.
    """
    q = _scaled(_as_quat(q))
    out = np.empty(math.prod(q.shape[:-1]))
    _angle_loop(_flat(q, q.shape[:-1], (4,)), out)
    return out.reshape(q.shape[:-1])


def relative_angle(p: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Angle θ ∈ [0, π] (rad, shape (…)) of ``p* ⊗ q``, the rotation from attitude ``p`` to ``q``.

    It is the geodesic distance between the two attitudes on SO(3), the usual
    attitude-error measure; batch axes broadcast.
    """
    p, q = _as_quat(p, "p"), _as_quat(q, "q")
    return angle(multiply(conjugate(p), q))


# --------------------------------------------------------------------------
# Euler angles
# --------------------------------------------------------------------------


def _parse_seq(seq) -> tuple[tuple[int, int, int], bool]:
    """Axes (0, 1, 2 for x, y, z) of an Euler sequence and whether it is intrinsic (uppercase)."""
    if not isinstance(seq, str) or len(seq) != 3 or not set(seq.lower()) <= set("xyz"):
        raise ValidationError(
            f"seq: must be three axes from 'xyz' (extrinsic) or 'XYZ' (intrinsic), got {seq!r}"
        )
    if not (seq.islower() or seq.isupper()):
        raise ValidationError(
            f"seq: must be all lowercase (extrinsic) or all uppercase (intrinsic), got {seq!r}"
        )
    if seq[0] == seq[1] or seq[1] == seq[2]:
        raise ValidationError(f"seq: consecutive axes must differ, got {seq!r}")
    i, j, k = ("xyz".index(c) for c in seq.lower())
    return (i, j, k), seq.isupper()


def from_euler(seq: str, angles: ArrayLike, *, degrees: bool = False) -> np.ndarray:
    """Unit quaternion (…, 4) of Euler angles (…, 3) about the axes ``seq``.

    Intrinsic ``"IJK"`` (body axes): ``q = q_I(a) ⊗ q_J(b) ⊗ q_K(c)``;
    extrinsic ``"ijk"`` (inertial axes): ``q = q_k(c) ⊗ q_j(b) ⊗ q_i(a)``,
    the meaning of ``scipy.spatial.transform.Rotation.from_euler``.
    Angles in rad, or degrees with ``degrees=True``; an angle past
    :data:`_HUGE_ANGLE` (1e16 rad) is refused, as in :func:`from_rotvec`.
    """
    axes, intrinsic = _parse_seq(seq)
    rad: np.ndarray = as_array(angles, "angles", tail=(3,))
    if degrees:
        rad = np.deg2rad(rad)
    _require_defined_angle(rad, "angles", "Euler angle")
    if not intrinsic:  # extrinsic ijk (a, b, c) = intrinsic KJI (c, b, a)
        axes, rad = axes[::-1], rad[..., ::-1]
    out = np.empty((math.prod(rad.shape[:-1]), 4))
    _from_euler_loop(_flat(rad, rad.shape[:-1], (3,)), *axes, out)
    return out.reshape((*rad.shape[:-1], 4))


def to_euler(q: ArrayLike, seq: str, *, degrees: bool = False) -> np.ndarray:
    """Euler angles (…, 3) about the axes ``seq`` of the rotations ``q / |q|``; inverts :func:`from_euler`.

    First and third angles in (-π, π]; second in [-π/2, π/2] for Tait–Bryan
    sequences and [0, π] for proper Euler sequences (rad, or degrees with
    ``degrees=True``). Computed directly from the quaternion by the method of
    E. Bernardes and S. Viollet, "Quaternion to Euler angles conversion: a
    direct, general and computationally efficient method", PLoS ONE 17(11),
    e0276302 (2022).

    Within :data:`GIMBAL_LOCK_THRESHOLD` rad of gimbal lock (second angle at
    0 or π for proper Euler, ±π/2 for Tait–Bryan) the first and third angles
    are not separately defined: the third is set to 0, the first carries the
    whole rotation about the locked axis (the rotation is then reproduced to
    within the threshold), and one :class:`GimbalLockWarning` reports how many
    rotations were affected.
    """
    axes, intrinsic = _parse_seq(seq)
    q = _scaled(_as_quat(q))
    if not intrinsic:  # extrinsic ijk (a, b, c) = intrinsic KJI (c, b, a)
        axes = axes[::-1]
    out = np.empty((math.prod(q.shape[:-1]), 3))
    flat = _flat(q, q.shape[:-1], (4,))
    locked = _to_euler_loop(flat, *axes, not intrinsic, GIMBAL_LOCK_THRESHOLD, out)
    if not intrinsic:
        out = out[:, ::-1]
    if locked:
        warnings.warn(
            f"to_euler: {locked} of {out.shape[0]} rotations are at gimbal lock for {seq!r} "
            f"(second angle within {GIMBAL_LOCK_THRESHOLD:g} rad of a singular value); "
            "their third angle was set to 0",
            GimbalLockWarning,
            stacklevel=2,
        )
    if degrees:
        out = np.rad2deg(out)
    return np.ascontiguousarray(out).reshape((*q.shape[:-1], 3))


# --------------------------------------------------------------------------
# scipy interop: the one place where the scalar-last convention appears
# --------------------------------------------------------------------------


def to_scipy(q: ArrayLike) -> Rotation:
    """``scipy.spatial.transform.Rotation`` of the (batch of) quaternions ``q`` (…, 4), scalar first."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(_scaled(_as_quat(q)), scalar_first=True)


def from_scipy(rot: Rotation) -> np.ndarray:
    """Scalar-first unit quaternion(s) (…, 4) of a ``scipy.spatial.transform.Rotation``."""
    from scipy.spatial.transform import Rotation

    if not isinstance(rot, Rotation):
        raise ValidationError(f"rot: must be a scipy.spatial.transform.Rotation, got {type(rot).__name__}")
    return np.asarray(rot.as_quat(scalar_first=True), dtype=np.float64)
