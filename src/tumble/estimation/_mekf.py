"""Multiplicative extended Kalman filter (MEKF): attitude error and gyro bias from a gyro, a star tracker and
vector observations.

State: the attitude ``q̂`` (unit quaternion, scalar first, body → inertial) and
the gyro bias ``β̂`` (rad/s, body axes). The filter's covariance ``P`` (6×6) is
that of the error ``δx = [δθ, δβ]`` with

    q_true = q̂ ⊗ exp(δθ/2),   β_true = β̂ + δβ        (δθ: rotation vector, rad, body axes)

(Lefferts, Markley & Shuster, J. Guid. Control Dyn. 5(5), 1982; Markley &
Crassidis, *Fundamentals of Spacecraft Attitude Determination and Control*,
2014, §6.2, in tumble's body → inertial convention).

Gyro model: ``ω̃ = ω + β + η_v``, ``β̇ = η_u`` with white noises of spectral
densities ``σ_v²`` (angle random walk, rad²/s) and ``σ_u²`` (rate random walk,
rad²/s³). Over a step ``Δt`` with the mean measured rate ``ω̃_k``:

    ω̂ = ω̃_k − β̂,   q̂ ← q̂ ⊗ exp(ω̂ Δt / 2),   P ← Φ P Φᵀ + Q,
    Φ = [[e^{−[ω̂×]Δt},  −∫₀^Δt e^{−[ω̂×]s} ds], [0, I]]             (closed form, Markley & Crassidis eq. 6.84)
    Q = [[(σ_v² Δt + σ_u² Δt³/3) I,  −σ_u² Δt²/2 I], [−σ_u² Δt²/2 I,  σ_u² Δt I]]   (eq. 6.93)

Updates (Joseph form, then the reset ``q̂ ← q̂ ⊗ exp(δθ̂/2)``, ``β̂ ← β̂ + δβ̂``):

* star tracker quaternion ``q̃ = q_true ⊗ exp(v/2)``, ``v ~ N(0, R_st)`` in body axes:
  innovation ``y = log(q̂* ⊗ q̃)`` (rad), ``H = [I 0]``; 3 degrees of freedom;
* unit vector ``b̃ ≈ R(q_true)ᵀ r`` of a known inertial direction ``r``:
  ``y = b̃ − R(q̂)ᵀ r``, ``H = [[R(q̂)ᵀ r ×], 0]``, noise ``σ² I`` (Shuster's model; the innovation
  has 2 degrees of freedom, across ``b̂``).

Each update adds ``yᵀ S⁻¹ y`` (the normalised innovation squared, NIS) to its
step's total and its degrees of freedom to the step's count, so that the NIS
of a consistent filter is χ²-distributed with that count.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._quat import qexp, qlog, qmul, qnorm, qrotate_inv
from tumble._validate import ValidationError, as_array, increasing_times, readonly, require_non_negative
from tumble.attitude import _as_quat

__all__ = ["FilterResult", "covariance_matrix", "mekf"]

#: Below this rotation per step (rad), Φ's coefficients are taken from their Taylor series (error < θ⁴/120).
_SMALL_TURN = 1e-3


@dataclass(frozen=True)
class FilterResult:
    """Estimates of a filter at its times, a posteriori (after the measurements at each time).

    t : (K,)               times, s
    q : (…, K, 4)          attitude, unit quaternion, scalar first, body → inertial
    bias : (…, K, 3)       gyro bias, rad/s, body axes
    covariance : (…, K, 6, 6)  covariance of ``[δθ, δβ]`` (rad², rad²/s, rad²/s²)
    nis : (…, K)           normalised innovation squared, summed over the updates at each time
    nis_dof : (…, K)       degrees of freedom of ``nis`` (0 where nothing was measured)
    """

    t: np.ndarray
    q: np.ndarray
    bias: np.ndarray
    covariance: np.ndarray
    nis: np.ndarray
    nis_dof: np.ndarray

    def error(self, q_true: ArrayLike, bias_true: ArrayLike) -> np.ndarray:
        """Estimation error ``[δθ, δβ]`` (…, K, 6) against the truth: ``q_true = q̂ ⊗ exp(δθ/2)``, ``δβ = β − β̂``."""
        dtheta = attitude.to_rotvec(attitude.multiply(attitude.conjugate(self.q), q_true))
        return np.concatenate([dtheta, np.asarray(bias_true) - self.bias], axis=-1)

    def nees(self, q_true: ArrayLike, bias_true: ArrayLike) -> np.ndarray:
        """Normalised estimation error squared ``δxᵀ P⁻¹ δx`` (…, K); χ²(6) for a consistent filter."""
        e = self.error(q_true, bias_true)
        return np.einsum("...i,...i->...", e, np.linalg.solve(self.covariance, e[..., None])[..., 0])


# --------------------------------------------------------------------------
# Compiled kernels
# --------------------------------------------------------------------------


@njit(cache=True)
def _skew(x, y, z, out):
    out[0, 0], out[0, 1], out[0, 2] = 0.0, -z, y
    out[1, 0], out[1, 1], out[1, 2] = z, 0.0, -x
    out[2, 0], out[2, 1], out[2, 2] = -y, x, 0.0


@njit(cache=True)
def _propagate(q, beta, P, rate, dt, arw2, rrw2, Phi, W):
    """One step of the gyro model: q ← q ⊗ exp(ω̂Δt/2), P ← ΦPΦᵀ + Q (module docstring)."""
    wx, wy, wz = rate[0] - beta[0], rate[1] - beta[1], rate[2] - beta[2]
    w2 = wx * wx + wy * wy + wz * wz
    theta = math.sqrt(w2) * dt
    if theta < _SMALL_TURN:
        t2 = theta * theta
        c1 = dt * (1.0 - t2 / 6.0)                  # sin θ / |ω|
        c2 = dt * dt * (0.5 - t2 / 24.0)            # (1 − cos θ) / |ω|²
        c3 = dt * dt * dt * (1.0 / 6.0 - t2 / 120.0)  # (θ − sin θ) / |ω|³
    else:
        w = math.sqrt(w2)
        c1 = math.sin(theta) / w
        c2 = (1.0 - math.cos(theta)) / w2
        c3 = (theta - math.sin(theta)) / (w2 * w)
    _skew(wx, wy, wz, W)
    W2 = W @ W
    Phi[:, :] = 0.0
    for i in range(3):
        for j in range(3):
            eye = 1.0 if i == j else 0.0
            Phi[i, j] = eye - c1 * W[i, j] + c2 * W2[i, j]
            Phi[i, 3 + j] = -dt * eye + c2 * W[i, j] - c3 * W2[i, j]
        Phi[3 + i, 3 + i] = 1.0
    P[:, :] = Phi @ P @ Phi.T
    for i in range(3):
        P[i, i] += arw2 * dt + rrw2 * dt**3 / 3.0
        P[i, 3 + i] -= 0.5 * rrw2 * dt * dt
        P[3 + i, i] -= 0.5 * rrw2 * dt * dt
        P[3 + i, 3 + i] += rrw2 * dt
    dq = qexp(wx * dt, wy * dt, wz * dt)
    nw, nx, ny, nz = qmul(q[0], q[1], q[2], q[3], dq[0], dq[1], dq[2], dq[3])
    n = qnorm(nw, nx, ny, nz)
    q[0], q[1], q[2], q[3] = nw / n, nx / n, ny / n, nz / n


@njit(cache=True)
def _update(q, beta, P, y, H, R):
    """Kalman update with innovation y (m,), H (m, 6), noise R (m, m); Joseph form; reset. Returns yᵀS⁻¹y."""
    S = H @ P @ H.T + R
    S_inv = np.linalg.inv(S)
    K = P @ H.T @ S_inv
    dx = K @ y
    IKH = np.eye(6) - K @ H
    P[:, :] = IKH @ P @ IKH.T + K @ R @ K.T
    dq = qexp(dx[0], dx[1], dx[2])
    nw, nx, ny, nz = qmul(q[0], q[1], q[2], q[3], dq[0], dq[1], dq[2], dq[3])
    n = qnorm(nw, nx, ny, nz)
    q[0], q[1], q[2], q[3] = nw / n, nx / n, ny / n, nz / n
    for i in range(3):
        beta[i] += dx[3 + i]
    return y @ (S_inv @ y)


@njit(cache=True)
def _update_star_tracker(q, beta, P, q_meas, R):
    """Star tracker update: y = log(q̂* ⊗ q̃), H = [I 0]."""
    ew, ex, ey, ez = qmul(q[0], -q[1], -q[2], -q[3], q_meas[0], q_meas[1], q_meas[2], q_meas[3])
    n = qnorm(ew, ex, ey, ez)
    y = np.empty(3)
    y[0], y[1], y[2] = qlog(ew / n, ex / n, ey / n, ez / n)
    H = np.zeros((3, 6))
    for i in range(3):
        H[i, i] = 1.0
    return _update(q, beta, P, y, H, R)


@njit(cache=True)
def _update_vector(q, beta, P, b_meas, r, sigma):
    """Unit-vector update: y = b̃/|b̃| − R(q̂)ᵀ r̂, H = [[b̂×], 0], noise σ² I."""
    nr = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    bx, by, bz = qrotate_inv(q[0], q[1], q[2], q[3], r[0] / nr, r[1] / nr, r[2] / nr)
    nb = math.sqrt(b_meas[0] ** 2 + b_meas[1] ** 2 + b_meas[2] ** 2)
    y = np.empty(3)
    y[0], y[1], y[2] = b_meas[0] / nb - bx, b_meas[1] / nb - by, b_meas[2] / nb - bz
    H = np.zeros((3, 6))
    _skew(bx, by, bz, H[:, :3])
    return _update(q, beta, P, y, H, sigma * sigma * np.eye(3))


@njit(cache=True)
def _mekf_run(t, rate, q0, beta0, P0, arw2, rrw2, q_st, R_st, vec, ref, vec_sigma, q_out, beta_out, P_out, nis,
              dof):
    """One run: at each time, update with the measurements there (NaN = none), store, then propagate."""
    q = q0.copy()
    beta = beta0.copy()
    P = P0.copy()
    Phi = np.empty((6, 6))
    W = np.empty((3, 3))
    for k in range(t.shape[0]):
        if k > 0:
            _propagate(q, beta, P, rate[k - 1], t[k] - t[k - 1], arw2, rrw2, Phi, W)
        nis[k] = 0.0
        dof[k] = 0
        if not np.isnan(q_st[k, 0]):
            nis[k] += _update_star_tracker(q, beta, P, q_st[k], R_st)
            dof[k] += 3
        for j in range(vec.shape[1]):
            if not np.isnan(vec[k, j, 0]):
                nis[k] += _update_vector(q, beta, P, vec[k, j], ref[k, j], vec_sigma[j])
                dof[k] += 2
        q_out[k] = q
        beta_out[k] = beta
        P_out[k] = P


@njit(cache=True, parallel=True)
def _mekf_batch(t, rate, q0, beta0, P0, arw2, rrw2, q_st, R_st, vec, ref, vec_sigma, q_out, beta_out, P_out, nis,
                dof):
    for n in prange(q_out.shape[0]):
        _mekf_run(t, rate[n], q0[n], beta0[n], P0, arw2, rrw2, q_st[n], R_st, vec[n], ref, vec_sigma, q_out[n],
                  beta_out[n], P_out[n], nis[n], dof[n])


# --------------------------------------------------------------------------
# Python layer
# --------------------------------------------------------------------------


def covariance_matrix(value, name: str, size: int) -> np.ndarray:
    """``value`` as a symmetric positive-definite (size, size) matrix, else a ValidationError naming ``name``.

    Symmetric means ``|C − Cᵀ| ≤ 1e-12 max|C|``; positive definite means its Cholesky factorisation exists.
    """
    c = as_array(value, name)
    if c.shape != (size, size):
        raise ValidationError(f"{name}: must have shape ({size}, {size}), got {c.shape}")
    if np.abs(c - c.T).max() > 1e-12 * np.abs(c).max():
        raise ValidationError(f"{name}: must be symmetric (max |C − Cᵀ| = {np.abs(c - c.T).max():.3g})")
    try:
        np.linalg.cholesky(c)
    except np.linalg.LinAlgError:
        raise ValidationError(f"{name}: must be positive definite "
                              f"(smallest eigenvalue {np.linalg.eigvalsh(c).min():.3g})") from None
    return readonly(0.5 * (c + c.T))


def _runs(value, name: str, tail: tuple[int, ...], runs: int, *, measured: bool = False) -> np.ndarray:
    """``value`` (tail) or (runs, *tail) broadcast to (runs, *tail), read-only and contiguous; with ``measured``,
    rows of measurements: NaN where there is none, else non-zero."""
    arr = as_array(value, name, tail=tail, finite=not measured)
    if arr.shape not in (tail, (runs, *tail)):
        raise ValidationError(f"{name}: must have shape {tail} or {(runs, *tail)}, got {arr.shape}")
    if measured and np.isinf(arr).any():
        raise ValidationError(f"{name}: must be finite or NaN (no measurement), found inf")
    if measured and np.any(~arr.any(axis=-1)):
        raise ValidationError(f"{name}: a measurement must be non-zero (NaN where there is none)")
    return readonly(np.broadcast_to(arr, (runs, *tail)))


def mekf(t: ArrayLike, rate: ArrayLike, *, q0: ArrayLike, P0: ArrayLike, arw: float, rrw: float,
         bias0: ArrayLike = (0.0, 0.0, 0.0), star_tracker: ArrayLike | None = None,
         star_tracker_covariance: ArrayLike | None = None, vectors: ArrayLike | None = None,
         references: ArrayLike | None = None, vector_sigma: ArrayLike | None = None) -> FilterResult:
    """Run the MEKF (module docstring) over K times, for one run or a batch of R runs at once (compiled, in
    parallel over runs).

    t : (K,)                     times, s, increasing
    rate : ([R,] K−1, 3)         mean measured body rate over each interval [t_k, t_k+1], rad/s
                                 (``Increments.rate``)
    q0 : ([R,] 4)                initial attitude estimate (scalar first, body → inertial; normalised)
    P0 : (6, 6)                  initial covariance of ``[δθ, δβ]``, symmetric positive definite
    arw, rrw                     gyro angle random walk σ_v (rad/√s) and rate random walk σ_u (rad/s^1.5)
    bias0 : ([R,] 3)             initial bias estimate, rad/s
    star_tracker : ([R,] K, 4)   measured attitude at each time (NaN rows where none), with
    star_tracker_covariance      (3, 3) its noise covariance, rad², body axes
    vectors : ([R,] K, m, 3)     measured directions in body axes (NaN rows where none), with
    references : ([K,] m, 3)     the same directions in inertial axes and
    vector_sigma : (m,) or number  their noise, rad
    """
    t = increasing_times(t, "t", what="filter times", at_least=2)
    K = t.shape[0]
    r = as_array(rate, "rate", tail=(3,))
    if r.shape[-2:-1] != (K - 1,) or r.ndim > 3:
        raise ValidationError(f"rate: must have shape ([R,] {K - 1}, 3), one rate per interval of t, got {r.shape}")
    q0 = _as_quat(q0, "q0")
    batched = [a.shape[0] for a, core in ((r, 2), (q0, 1), (np.asarray(star_tracker), 2), (np.asarray(vectors), 3),
                                          (np.asarray(bias0), 1)) if a.ndim == core + 1]
    runs = max(batched, default=1)
    rate_runs = _runs(r, "rate", (K - 1, 3), runs)
    q0 = _runs(q0 / np.linalg.norm(q0, axis=-1, keepdims=True), "q0", (4,), runs)
    bias0 = _runs(bias0, "bias0", (3,), runs)
    P0 = covariance_matrix(P0, "P0", 6)
    arw2 = require_non_negative(arw, "arw") ** 2
    rrw2 = require_non_negative(rrw, "rrw") ** 2
    if star_tracker is None:
        q_st = np.full((runs, K, 4), np.nan)
        R_st = np.eye(3)
    else:
        if star_tracker_covariance is None:
            raise ValidationError("star_tracker_covariance: must be given with star_tracker")
        q_st = _runs(star_tracker, "star_tracker", (K, 4), runs, measured=True)
        R_st = covariance_matrix(star_tracker_covariance, "star_tracker_covariance", 3)
    if vectors is None:
        vec, ref, sig = np.full((runs, K, 0, 3), np.nan), np.zeros((K, 0, 3)), np.zeros(0)
    else:
        v = as_array(vectors, "vectors", tail=(3,), finite=False)
        m = v.shape[-2] if v.ndim >= 3 else 0
        vec = _runs(v, "vectors", (K, m, 3), runs, measured=True)
        if references is None or vector_sigma is None:
            raise ValidationError("references: must be given with vectors (and vector_sigma)")
        ref_arr = as_array(references, "references", tail=(m, 3))
        if ref_arr.shape not in ((m, 3), (K, m, 3)):
            raise ValidationError(f"references: must have shape ({m}, 3) or ({K}, {m}, 3), got {ref_arr.shape}")
        ref = readonly(np.broadcast_to(ref_arr, (K, m, 3)))
        sig = readonly(np.broadcast_to(as_array(vector_sigma, "vector_sigma"), (m,)))
        if np.any(sig <= 0.0):
            raise ValidationError(f"vector_sigma: must be > 0 (rad), got {sig}")
    q_out, beta_out = np.empty((runs, K, 4)), np.empty((runs, K, 3))
    P_out, nis, dof = np.empty((runs, K, 6, 6)), np.empty((runs, K)), np.empty((runs, K), dtype=np.int64)
    # every input read-only (the one form of readonly()), with or without star tracker and vectors: one compiled
    # copy of the filter (about 20 CPU s), not one per combination of the measurements given
    _mekf_batch(readonly(t), rate_runs, q0, bias0, readonly(P0), arw2, rrw2, readonly(q_st), readonly(R_st),
                readonly(vec), readonly(ref), readonly(sig), q_out, beta_out, P_out, nis, dof)
    lead = (runs,) if batched else ()
    return FilterResult(t=t, q=q_out.reshape((*lead, K, 4)), bias=beta_out.reshape((*lead, K, 3)),
                        covariance=P_out.reshape((*lead, K, 6, 6)), nis=nis.reshape((*lead, K)),
                        nis_dof=dof.reshape((*lead, K)))
