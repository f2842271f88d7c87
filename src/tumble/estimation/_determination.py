"""Attitude determination from vector observations: TRIAD, Davenport's q-method and QUEST.

Wahba's problem: given unit vectors ``b_i`` measured in body axes and the same
directions ``r_i`` known in inertial axes, find the rotation ``R`` (body →
inertial, tumble's convention) that minimises

    L(R) = ½ Σ a_i |r_i − R b_i|²,        a_i = 1 / σ_i²  (weights, rad⁻²).

With the attitude profile matrix ``B = Σ a_i b_i r_iᵀ``, ``S = B + Bᵀ``,
``σ = tr B`` and ``z = Σ a_i b_i × r_i``, Davenport's matrix

    K = [[S − σ I,  z],
         [zᵀ,       σ]]

has the optimal quaternion, in Markley's vector-first order ``(q_v, q_4)``, as
the eigenvector of its largest eigenvalue ``λ_max`` (Davenport 1968).
Markley's attitude matrix ``A(q)`` maps inertial to body axes and equals
``R(q)ᵀ`` of the Hamilton quaternion with the same components, so the
scalar-first ``[q_4, q_v]`` *is* tumble's body → inertial quaternion: no sign
flips anywhere.

* :func:`triad` (Black 1964; Markley & Crassidis 2014, §5.2.1) uses exactly two
  vectors, trusting the first fully.
* :func:`davenport` solves the 4×4 symmetric eigenproblem.
* :func:`quest` (Shuster & Oh 1981) finds ``λ_max`` by Newton's method on the
  characteristic polynomial of ``K`` from ``λ₀ = Σ a_i`` and the quaternion from
  ``q ∝ [γ, (α I + β S + S²) z]``; when the rotation is near π (small ``γ``) it
  solves in the reference frame turned by π about an inertial axis (the method of
  sequential rotations) and turns the result back. It also returns the
  covariance of the attitude error, the Cramér–Rao bound of the QUEST
  measurement model ``b̃_i = b_i + v_i``, ``v_i ⊥ b_i``, ``E[v_i v_iᵀ] = σ_i² (I − b_i b_iᵀ)``:

      P_θθ = [Σ a_i (I − b_i b_iᵀ)]⁻¹   (rad², body axes),

  of the rotation vector ``δθ`` with ``q_true = q̂ ⊗ exp(δθ/2)`` (Shuster 1989).

Every function takes batches: ``b`` of shape (…, n, 3), ``r`` (…, n, 3)
broadcast against it, and returns (…, 4) quaternions. Vectors need not be unit
length; they are normalised.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from tumble._quat import qfrom_matrix, qmul
from tumble._validate import ValidationError, as_array, readonly
from tumble.attitude import _batch, _flat, _where

__all__ = ["AttitudeEstimate", "davenport", "quest", "triad"]

#: |b₁ × b₂| (unit vectors) below which TRIAD refuses the pair as parallel: the
#: second axis of its frame would be set by rounding.
PARALLEL_SINE = 1e-8

#: Newton iterations of QUEST's characteristic equation stop when the step is below this (relative to λ₀).
_NEWTON_TOL = 1e-15


@dataclass(frozen=True)
class AttitudeEstimate:
    """An attitude from vector observations.

    q : (…, 4)            unit quaternion, scalar first, body → inertial
    covariance : (…, 3, 3)  covariance of the attitude error ``δθ`` (rad², body axes), ``q_true = q ⊗ exp(δθ/2)``
    loss : (…,)           Wahba's loss at the optimum, ``Σ a_i − λ_max`` (dimensionless for weights in rad⁻²)
    """

    q: np.ndarray
    covariance: np.ndarray
    loss: np.ndarray


# --------------------------------------------------------------------------
# Compiled kernels (one observation set each; the batch loops are below)
# --------------------------------------------------------------------------


@njit(cache=True)
def _unit(v):
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return v[0] / n, v[1] / n, v[2] / n


@njit(cache=True)
def _profile(b, r, a, B, z):
    """Attitude profile ``B = Σ a_i b_i r_iᵀ`` and ``z = Σ a_i b_i × r_i`` of unit-normalised vectors."""
    B[:] = 0.0
    z[:] = 0.0
    for i in range(b.shape[0]):
        b0, b1, b2 = _unit(b[i])
        r0, r1, r2 = _unit(r[i])
        bv = (b0, b1, b2)
        rv = (r0, r1, r2)
        for j in range(3):
            for k in range(3):
                B[j, k] += a[i] * bv[j] * rv[k]
        z[0] += a[i] * (b1 * r2 - b2 * r1)
        z[1] += a[i] * (b2 * r0 - b0 * r2)
        z[2] += a[i] * (b0 * r1 - b1 * r0)


@njit(cache=True)
def _triad_frame(v, t):
    """Columns of ``t``: the TRIAD frame ``t₁ = v̂₁``, ``t₂ = (v₁ × v₂)/|v₁ × v₂|``, ``t₃ = t₁ × t₂``."""
    x0, x1, x2 = _unit(v[0])
    c0, c1, c2 = x1 * v[1, 2] - x2 * v[1, 1], x2 * v[1, 0] - x0 * v[1, 2], x0 * v[1, 1] - x1 * v[1, 0]
    y0, y1, y2 = _unit((c0, c1, c2))
    t[0, 0], t[1, 0], t[2, 0] = x0, x1, x2
    t[0, 1], t[1, 1], t[2, 1] = y0, y1, y2
    t[0, 2], t[1, 2], t[2, 2] = x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0


@njit(cache=True)
def _triad_one(b, r, out):
    """TRIAD: ``R = [t^r] [t^b]ᵀ`` from the frames of (r₁, r₂) and (b₁, b₂); ``R b₁ = r̂₁`` exactly."""
    tb = np.empty((3, 3))
    tr = np.empty((3, 3))
    _triad_frame(b, tb)
    _triad_frame(r, tr)
    w, x, y, z = qfrom_matrix(tr @ tb.T)
    out[0], out[1], out[2], out[3] = w, x, y, z


@njit(cache=True)
def _davenport_one(b, r, a, out):
    B = np.empty((3, 3))
    z = np.empty(3)
    _profile(b, r, a, B, z)
    sigma = B[0, 0] + B[1, 1] + B[2, 2]
    K = np.empty((4, 4))
    for j in range(3):
        for k in range(3):
            K[j, k] = B[j, k] + B[k, j] - (sigma if j == k else 0.0)
        K[j, 3] = z[j]
        K[3, j] = z[j]
    K[3, 3] = sigma
    _, vectors = np.linalg.eigh(K)
    s = 1.0 if vectors[3, 3] >= 0.0 else -1.0
    out[0], out[1], out[2], out[3] = s * vectors[3, 3], s * vectors[0, 3], s * vectors[1, 3], s * vectors[2, 3]


@njit(cache=True)
def _quest_solve(B, z, a_sum, out):
    """QUEST on a profile (B, z): ``λ_max`` by Newton, the quaternion ``[γ, x]/|·|`` into ``out``; returns
    ``(λ_max, |γ|)``. ``[γ, x]`` is the last column of ``adj(λ_max I − K) = Π_j(λ_max − λ_j) q qᵀ``, so
    ``γ = Π_j(λ_max − λ_j) q₄²``: small near a rotation by π, and comparable between frames (the
    eigenvalue gaps do not depend on the frame)."""
    S = B + B.T
    sigma = B[0, 0] + B[1, 1] + B[2, 2]
    kappa = (S[1, 1] * S[2, 2] - S[1, 2] * S[2, 1] + S[0, 0] * S[2, 2] - S[0, 2] * S[2, 0]
             + S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0])
    delta = np.linalg.det(S)
    Sz = S @ z
    SSz = S @ Sz
    zz, zSz, zSSz = z @ z, z @ Sz, z @ SSz
    ca = sigma * sigma - kappa
    cb = sigma * sigma + zz
    cc = delta + zSz
    cd = zSSz
    lam = a_sum
    for _ in range(50):
        f = lam**4 - (ca + cb) * lam**2 - cc * lam + (ca * cb + cc * sigma - cd)
        df = 4.0 * lam**3 - 2.0 * (ca + cb) * lam - cc
        step = f / df
        lam -= step
        if abs(step) <= _NEWTON_TOL * a_sum:
            break
    alpha = lam * lam - sigma * sigma + kappa
    beta = lam - sigma
    gamma = (lam + sigma) * alpha - delta
    x = alpha * z + beta * Sz + SSz
    n = math.sqrt(gamma * gamma + x @ x)
    out[0], out[1], out[2], out[3] = gamma / n, x[0] / n, x[1] / n, x[2] / n
    return lam, abs(gamma)


@njit(cache=True)
def _quest_one(b, r, a, q_out, cov_out):
    """QUEST with sequential rotations; returns Wahba's loss ``Σ a_i − λ_max``; writes q and P_θθ.

    Solves in the reference frame as given and turned by π about x, y and z, and keeps the solution of the
    largest ``|γ|`` (``∝ q_k²``: the largest component of the true quaternion, at least ½)."""
    a_sum = a.sum()
    B = np.empty((3, 3))
    z = np.empty(3)
    r_turned = np.empty_like(r)
    best = -1.0
    lam_best = a_sum
    trial = np.empty(4)
    for axis in range(4):  # 3 = no turn; 0, 1, 2 = the reference frame turned by π about x, y, z
        for i in range(r.shape[0]):
            for j in range(3):
                r_turned[i, j] = r[i, j] if axis == 3 or j == axis else -r[i, j]
        _profile(b, r_turned, a, B, z)
        lam, g = _quest_solve(B, z, a_sum, trial)
        if g > best:
            best, lam_best = g, lam
            if axis == 3:
                q_out[:] = trial
            else:  # R = R_axis R': q = e_axis ⊗ q'
                e = np.zeros(4)
                e[axis + 1] = 1.0
                w, x, y, zz = qmul(e[0], e[1], e[2], e[3], trial[0], trial[1], trial[2], trial[3])
                s = 1.0 if w >= 0.0 else -1.0
                q_out[0], q_out[1], q_out[2], q_out[3] = s * w, s * x, s * y, s * zz
    info = np.zeros((3, 3))
    for i in range(b.shape[0]):
        u = _unit(b[i])
        for j in range(3):
            for k in range(3):
                info[j, k] += a[i] * ((1.0 if j == k else 0.0) - u[j] * u[k])
    cov_out[:, :] = np.linalg.inv(info)
    return a_sum - lam_best


@njit(cache=True, parallel=True)
def _triad_batch(b, r, out):
    for n in prange(out.shape[0]):
        _triad_one(b[n], r[n], out[n])


@njit(cache=True, parallel=True)
def _davenport_batch(b, r, a, out):
    for n in prange(out.shape[0]):
        _davenport_one(b[n], r[n], a, out[n])


@njit(cache=True, parallel=True)
def _quest_batch(b, r, a, q, cov, loss):
    for n in prange(q.shape[0]):
        loss[n] = _quest_one(b[n], r[n], a, q[n], cov[n])


# --------------------------------------------------------------------------
# Python layer: checks, batch shapes
# --------------------------------------------------------------------------


def _observations(b, r, *, count: int | None = None) -> tuple[tuple[int, ...], np.ndarray, np.ndarray]:
    """``b`` and ``r`` checked (finite, non-zero, same number of vectors) and flattened to (N, n, 3)."""
    b = as_array(b, "b", tail=(3,))
    r = as_array(r, "r", tail=(3,))
    for name, v in (("b", b), ("r", r)):
        if v.ndim < 2:
            raise ValidationError(f"{name}: must have shape (…, n, 3), got {v.shape}")
        zero = ~v.any(axis=-1)
        if zero.any():
            raise ValidationError(f"{name}: vectors must be non-zero (|{name}| = 0{_where(zero)})")
    if b.shape[-2] != r.shape[-2]:
        raise ValidationError(f"r: must hold as many vectors as b ({b.shape[-2]}), got {r.shape[-2]}")
    n = b.shape[-2]
    if count is not None and n != count:
        raise ValidationError(f"b: must hold exactly {count} vectors, got {n}")
    batch = _batch(("b", b, 2), ("r", r, 2))
    return batch, _flat(b, batch, (n, 3)), _flat(r, batch, (n, 3))


def _weights(sigma, n: int) -> np.ndarray:
    """Weights ``a_i = 1/σ_i²`` (rad⁻²) of ``sigma`` (rad, a number or one per vector)."""
    s = as_array(sigma, "sigma")
    if s.ndim > 1 or (s.ndim == 1 and s.shape[0] != n):
        raise ValidationError(f"sigma: must be a number or have shape ({n},), got {s.shape}")
    if np.any(s <= 0.0):
        raise ValidationError(f"sigma: must be > 0 (rad), got {s}")
    return readonly(np.broadcast_to(1.0 / s**2, (n,)))


def triad(b: ArrayLike, r: ArrayLike) -> np.ndarray:
    """Attitude (…, 4) from two vector observations by TRIAD: ``r₁ = R b₁`` exactly, ``r₂`` in the plane.

    b : (…, 2, 3)  directions measured in body axes (any length > 0)
    r : (…, 2, 3)  the same directions in inertial axes
    Returns the unit quaternion, scalar first, body → inertial. Refuses parallel ``b₁, b₂`` (or ``r₁, r₂``):
    ``|b̂₁ × b̂₂| < 1e-8``.
    """
    batch, bf, rf = _observations(b, r, count=2)
    for name, v in (("b", bf), ("r", rf)):
        u = v / np.linalg.norm(v, axis=-1, keepdims=True)
        sine = np.linalg.norm(np.cross(u[:, 0], u[:, 1]), axis=-1)
        bad = sine < PARALLEL_SINE
        if bad.any():
            raise ValidationError(f"{name}: the two vectors must not be parallel "
                                  f"(|{name}₁ × {name}₂| = {sine[bad][0]:.3g} < {PARALLEL_SINE:g}"
                                  f"{_where(bad.reshape(batch))})")
    out = np.empty((bf.shape[0], 4))
    _triad_batch(bf, rf, out)
    return out.reshape((*batch, 4))


def davenport(b: ArrayLike, r: ArrayLike, sigma: ArrayLike = 1.0) -> np.ndarray:
    """Attitude (…, 4) from n ≥ 2 vector observations by Davenport's q-method (module docstring).

    b : (…, n, 3) body-axis directions; r : (…, n, 3) inertial directions;
    sigma : number or (n,), rad, the noise of each observation (weights ``1/σ²``).
    """
    batch, bf, rf = _observations(b, r)
    out = np.empty((bf.shape[0], 4))
    _davenport_batch(bf, rf, _weights(sigma, bf.shape[1]), out)
    return out.reshape((*batch, 4))


def quest(b: ArrayLike, r: ArrayLike, sigma: ArrayLike = 1.0) -> AttitudeEstimate:
    """Attitude and its covariance from n ≥ 2 vector observations by QUEST (module docstring).

    b : (…, n, 3) body-axis directions; r : (…, n, 3) inertial directions;
    sigma : number or (n,), rad, the noise of each observation (weights ``1/σ²``; the covariance is in rad²).
    """
    batch, bf, rf = _observations(b, r)
    N = bf.shape[0]
    q, cov, loss = np.empty((N, 4)), np.empty((N, 3, 3)), np.empty(N)
    _quest_batch(bf, rf, _weights(sigma, bf.shape[1]), q, cov, loss)
    return AttitudeEstimate(q=q.reshape((*batch, 4)), covariance=cov.reshape((*batch, 3, 3)),
                            loss=loss.reshape(batch))
