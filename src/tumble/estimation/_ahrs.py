"""AHRS filters for a gyro, an accelerometer and a magnetometer: Madgwick, Mahony and a quaternion EKF.

**Frame.** These filters estimate the attitude ``q`` (scalar first, body →
level frame ``L``) relative to the local level frame ``L`` fixed by the
two reference directions they see:

* ``z_L`` is *up*: the direction of the specific force of a body at rest,
  which an accelerometer reads as ``R(q)ᵀ [0, 0, 1]`` (normalised);
* ``x_L`` is *magnetic north*: the horizontal component of the magnetic
  field, so that the field is ``[cos δ, 0, −sin δ]`` (normalised) in ``L``,
  ``δ`` the magnetic inclination (positive when the field points down);
* ``y_L = z_L × x_L`` is west (``L`` is north–west–up).

**Samples.** ``K`` samples at interval ``dt`` (s): ``rate[k]`` (rad/s, body
axes) is the gyro's mean rate over ``(t_{k−1}, t_k]``, ``accel[k]`` and
``mag[k]`` (any units: only their directions are used) are read at ``t_k``.
``q[0] = q0`` and each later ``q[k]`` is one step of the filter from
``q[k − 1]`` with sample ``k``; ``rate[0]`` is not used. Batches (…, K, 3)
run in parallel.

* Madgwick (S. O. H. Madgwick, *An efficient orientation filter for inertial
  and inertial/magnetic sensor arrays*, 2010, eqs. 31–34, 45–46): one
  normalised gradient-descent step on ``f(q) = [R(q)ᵀ ẑ − â; R(q)ᵀ b − m̂]``
  per sample, ``q̇ = ½ q ⊗ [0, ω] − β ∇f/|∇f|``, with the earth field
  ``b = [|h_xy|, 0, h_z]`` of ``h = R(q) m̂``; ``f`` in the paper's
  unit-norm polynomial form.
* Mahony (R. Mahony, T. Hamel, J.-M. Pflimlin, *Nonlinear complementary
  filters on the special orthogonal group*, IEEE TAC 53(5), 2008, eq. 48,
  explicit complementary filter with bias): ``ω_mes = â × R(q)ᵀẑ + m̂ × v̂_m``,
  ``b ← b − k_I ω_mes dt``, ``q̇ = ½ q ⊗ [0, ω − b + k_P ω_mes]``.
* EKF: the four quaternion components as state, ``q ← (I + ½dt Ω(ω)) q``
  with process noise ``σ_ω² W Wᵀ``, ``W = ½dt [−q_vᵀ; q_w I + [q_v×]]``,
  measurement ``h(q) = [R(q)ᵀ ẑ; R(q)ᵀ m_L]`` of the normalised
  accelerometer and magnetometer with noise ``diag(σ_a² I, σ_m² I)`` and its
  exact Jacobian (R. G. Valenti et al.'s and the *ahrs* package's
  formulation; J. L. Crassidis, F. L. Markley & Y. Cheng, JGCD 30(1), 2007).
  The predicted quaternion is normalised before the update.

All three integrate ``q̇`` by one Euler step and renormalise, as published.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from tumble._quat import qmul_vector, qnorm, qrotate, qrotate_inv
from tumble._validate import ValidationError, as_array, readonly, require_non_negative, require_positive
from tumble.attitude import _as_quat
from tumble.estimation._mekf import covariance_matrix

__all__ = ["ahrs_ekf", "madgwick", "mahony"]


@njit(cache=True)
def _unit3(v):
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return v[0] / n, v[1] / n, v[2] / n


@njit(cache=True)
def _euler_step(q, wx, wy, wz, dt, cw, cx, cy, cz):
    """``q ← (q + (½ q ⊗ [0, ω] − c) dt) / |·|``: the published filters' integration step."""
    dw, dx, dy, dz = qmul_vector(q[0], q[1], q[2], q[3], wx, wy, wz)
    nw = q[0] + (0.5 * dw - cw) * dt
    nx = q[1] + (0.5 * dx - cx) * dt
    ny = q[2] + (0.5 * dy - cy) * dt
    nz = q[3] + (0.5 * dz - cz) * dt
    n = qnorm(nw, nx, ny, nz)
    q[0], q[1], q[2], q[3] = nw / n, nx / n, ny / n, nz / n


@njit(cache=True)
def _earth_field(q, mx, my, mz):
    """Madgwick's / Mahony's level-frame field ``[|h_xy|, 0, h_z]`` of ``h = R(q) m̂`` (eqs. 45–46)."""
    hx, hy, hz = qrotate(q[0], q[1], q[2], q[3], mx, my, mz)
    return math.sqrt(hx * hx + hy * hy), hz


@njit(cache=True)
def _madgwick_step(q, omega, a, m, dt, beta):
    ax, ay, az = _unit3(a)
    mx, my, mz = _unit3(m)
    bx, bz = _earth_field(q, mx, my, mz)
    w, x, y, z = q[0], q[1], q[2], q[3]
    # f (eq. 31 with d = ẑ, b = [b_x, 0, b_z]) and the gradient Jᵀf of eq. 34, J of eq. 32, by components
    f1 = 2.0 * (x * z - w * y) - ax
    f2 = 2.0 * (w * x + y * z) - ay
    f3 = 2.0 * (0.5 - x * x - y * y) - az
    f4 = 2.0 * bx * (0.5 - y * y - z * z) + 2.0 * bz * (x * z - w * y) - mx
    f5 = 2.0 * bx * (x * y - w * z) + 2.0 * bz * (w * x + y * z) - my
    f6 = 2.0 * bx * (w * y + x * z) + 2.0 * bz * (0.5 - x * x - y * y) - mz
    gw = -2.0 * y * f1 + 2.0 * x * f2 - 2.0 * bz * y * f4 + (-2.0 * bx * z + 2.0 * bz * x) * f5 + 2.0 * bx * y * f6
    gx = (2.0 * z * f1 + 2.0 * w * f2 - 4.0 * x * f3 + 2.0 * bz * z * f4 + (2.0 * bx * y + 2.0 * bz * w) * f5
          + (2.0 * bx * z - 4.0 * bz * x) * f6)
    gy = (-2.0 * w * f1 + 2.0 * z * f2 - 4.0 * y * f3 + (-4.0 * bx * y - 2.0 * bz * w) * f4
          + (2.0 * bx * x + 2.0 * bz * z) * f5 + (2.0 * bx * w - 4.0 * bz * y) * f6)
    gz = (2.0 * x * f1 + 2.0 * y * f2 + (-4.0 * bx * z + 2.0 * bz * x) * f4 + (-2.0 * bx * w + 2.0 * bz * y) * f5
          + 2.0 * bx * x * f6)
    n = qnorm(gw, gx, gy, gz)
    s = beta / n if n > 0.0 else 0.0
    _euler_step(q, omega[0], omega[1], omega[2], dt, s * gw, s * gx, s * gy, s * gz)


@njit(cache=True)
def _mahony_step(q, bias, w, a, m, dt, k_p, k_i):
    ax, ay, az = _unit3(a)
    mx, my, mz = _unit3(m)
    bx, bz = _earth_field(q, mx, my, mz)
    vax, vay, vaz = qrotate_inv(q[0], q[1], q[2], q[3], 0.0, 0.0, 1.0)
    vmx, vmy, vmz = _unit3(qrotate_inv(q[0], q[1], q[2], q[3], bx, 0.0, bz))
    ex = ay * vaz - az * vay + my * vmz - mz * vmy
    ey = az * vax - ax * vaz + mz * vmx - mx * vmz
    ez = ax * vay - ay * vax + mx * vmy - my * vmx
    bias[0] -= k_i * ex * dt
    bias[1] -= k_i * ey * dt
    bias[2] -= k_i * ez * dt
    _euler_step(q, w[0] - bias[0] + k_p * ex, w[1] - bias[1] + k_p * ey, w[2] - bias[2] + k_p * ez, dt,
                0.0, 0.0, 0.0, 0.0)


@njit(cache=True)
def _rotate_inv_jacobian(q, r, H, row):
    """Rows ``row:row+3`` of ``H`` ← ∂(R(q)ᵀ r)/∂q of ``R(q)ᵀ r = (w² − |v|²) r + 2(v·r) v − 2w v × r``."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    r0, r1, r2 = r[0], r[1], r[2]
    H[row, 0] = 2.0 * (r0 * w + r1 * z - r2 * y)
    H[row, 1] = 2.0 * (r0 * x + r1 * y + r2 * z)
    H[row, 2] = 2.0 * (-r0 * y + r1 * x - r2 * w)
    H[row, 3] = 2.0 * (-r0 * z + r1 * w + r2 * x)
    H[row + 1, 0] = 2.0 * (-r0 * z + r1 * w + r2 * x)
    H[row + 1, 1] = 2.0 * (r0 * y - r1 * x + r2 * w)
    H[row + 1, 2] = 2.0 * (r0 * x + r1 * y + r2 * z)
    H[row + 1, 3] = 2.0 * (-r0 * w - r1 * z + r2 * y)
    H[row + 2, 0] = 2.0 * (r0 * y - r1 * x + r2 * w)
    H[row + 2, 1] = 2.0 * (r0 * z - r1 * w - r2 * x)
    H[row + 2, 2] = 2.0 * (r0 * w + r1 * z - r2 * y)
    H[row + 2, 3] = 2.0 * (r0 * x + r1 * y + r2 * z)


@njit(cache=True)
def _ekf_step(q, P, w, a, m, dt, m_ref, var_gyro, R):
    """One EKF step (module docstring): predict with the gyro, correct with â and m̂."""
    h = 0.5 * dt
    F = np.eye(4)
    F[0, 1], F[0, 2], F[0, 3] = -h * w[0], -h * w[1], -h * w[2]
    F[1, 0], F[1, 2], F[1, 3] = h * w[0], h * w[2], -h * w[1]
    F[2, 0], F[2, 1], F[2, 3] = h * w[1], -h * w[2], h * w[0]
    F[3, 0], F[3, 1], F[3, 2] = h * w[2], h * w[1], -h * w[0]
    W = np.empty((4, 3))
    W[0, 0], W[0, 1], W[0, 2] = -q[1], -q[2], -q[3]
    W[1, 0], W[1, 1], W[1, 2] = q[0], -q[3], q[2]
    W[2, 0], W[2, 1], W[2, 2] = q[3], q[0], -q[1]
    W[3, 0], W[3, 1], W[3, 2] = -q[2], q[1], q[0]
    W *= h
    qp = F @ q
    qp /= math.sqrt(qp @ qp)
    P[:, :] = F @ P @ F.T + var_gyro * (W @ W.T)
    z = np.empty(6)
    z[0], z[1], z[2] = _unit3(a)
    z[3], z[4], z[5] = _unit3(m)
    y = np.empty(6)
    y[0], y[1], y[2] = qrotate_inv(qp[0], qp[1], qp[2], qp[3], 0.0, 0.0, 1.0)
    y[3], y[4], y[5] = qrotate_inv(qp[0], qp[1], qp[2], qp[3], m_ref[0], m_ref[1], m_ref[2])
    H = np.empty((6, 4))
    _rotate_inv_jacobian(qp, np.array([0.0, 0.0, 1.0]), H, 0)
    _rotate_inv_jacobian(qp, m_ref, H, 3)
    S = H @ P @ H.T + R
    K = P @ H.T @ np.linalg.inv(S)
    P[:, :] = (np.eye(4) - K @ H) @ P
    qn = qp + K @ (z - y)
    qn /= math.sqrt(qn @ qn)
    q[:] = qn


@njit(cache=True, parallel=True)
def _madgwick_batch(rate, accel, mag, dt, q0, beta, out):
    for n in prange(out.shape[0]):
        q = q0[n].copy()
        out[n, 0] = q
        for k in range(1, out.shape[1]):
            _madgwick_step(q, rate[n, k], accel[n, k], mag[n, k], dt, beta)
            out[n, k] = q


@njit(cache=True, parallel=True)
def _mahony_batch(rate, accel, mag, dt, q0, k_p, k_i, out):
    for n in prange(out.shape[0]):
        q = q0[n].copy()
        bias = np.zeros(3)
        out[n, 0] = q
        for k in range(1, out.shape[1]):
            _mahony_step(q, bias, rate[n, k], accel[n, k], mag[n, k], dt, k_p, k_i)
            out[n, k] = q


@njit(cache=True, parallel=True)
def _ekf_batch(rate, accel, mag, dt, q0, P0, m_ref, var_gyro, R, out):
    for n in prange(out.shape[0]):
        q = q0[n].copy()
        P = P0.copy()
        out[n, 0] = q
        for k in range(1, out.shape[1]):
            _ekf_step(q, P, rate[n, k], accel[n, k], mag[n, k], dt, m_ref, var_gyro, R)
            out[n, k] = q


def _samples(rate, accel, mag, q0) -> tuple[tuple[int, ...], np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The three sample arrays (…, K, 3) of one shape, flattened to (N, K, 3); q0 normalised and broadcast."""
    rate = as_array(rate, "rate", tail=(3,))
    if rate.ndim < 2:
        raise ValidationError(f"rate: must have shape (…, K, 3), got {rate.shape}")
    arrays = [rate]
    for name, v in (("accel", accel), ("mag", mag)):
        arr = as_array(v, name, tail=(3,))
        if arr.shape != rate.shape:
            raise ValidationError(f"{name}: must have the shape of rate {rate.shape}, got {arr.shape}")
        if not np.linalg.norm(arr, axis=-1).all():
            raise ValidationError(f"{name}: every sample must be non-zero (its direction is measured)")
        arrays.append(arr)
    lead = rate.shape[:-2]
    q0 = _as_quat(q0, "q0")
    if q0.shape not in ((4,), (*lead, 4)):
        raise ValidationError(f"q0: must have shape (4,) or {(*lead, 4)}, got {q0.shape}")
    q0 = np.broadcast_to(q0 / np.linalg.norm(q0, axis=-1, keepdims=True), (*lead, 4)).reshape(-1, 4)
    flat = [readonly(a).reshape(-1, *rate.shape[-2:]) for a in arrays]
    return lead, flat[0], flat[1], flat[2], readonly(q0)


def madgwick(rate: ArrayLike, accel: ArrayLike, mag: ArrayLike, dt: float, *, q0: ArrayLike,
             gain: float = 0.041) -> np.ndarray:
    """Madgwick's MARG filter (module docstring): attitudes (…, K, 4), body → level frame ``L``.

    ``gain`` is β (rad/s), the gradient step; 0.041 is the default of the paper's MARG results (and *ahrs*).
    """
    lead, r, a, m, q0 = _samples(rate, accel, mag, q0)
    out = np.empty((r.shape[0], r.shape[1], 4))
    _madgwick_batch(r, a, m, require_positive(dt, "dt"), q0, require_non_negative(gain, "gain"), out)
    return out.reshape((*lead, r.shape[1], 4))


def mahony(rate: ArrayLike, accel: ArrayLike, mag: ArrayLike, dt: float, *, q0: ArrayLike, k_p: float = 1.0,
           k_i: float = 0.3) -> np.ndarray:
    """Mahony's explicit complementary filter with gyro-bias estimate (module docstring): attitudes (…, K, 4).

    ``k_p`` (rad/s) and ``k_i`` (rad/s²) are the proportional and integral gains; the bias starts at zero.
    """
    lead, r, a, m, q0 = _samples(rate, accel, mag, q0)
    out = np.empty((r.shape[0], r.shape[1], 4))
    _mahony_batch(r, a, m, require_positive(dt, "dt"), q0, require_non_negative(k_p, "k_p"),
                  require_non_negative(k_i, "k_i"), out)
    return out.reshape((*lead, r.shape[1], 4))


def ahrs_ekf(rate: ArrayLike, accel: ArrayLike, mag: ArrayLike, dt: float, *, q0: ArrayLike, inclination: float,
             var_gyro: float = 0.3**2, var_accel: float = 0.5**2, var_mag: float = 0.8**2,
             P0: ArrayLike | None = None) -> np.ndarray:
    """Quaternion EKF (module docstring): attitudes (…, K, 4), body → level frame ``L``.

    inclination : rad, ``δ`` of the reference field ``m_L = [cos δ, 0, −sin δ]`` (positive pointing down)
    var_gyro : (rad/s)², gyro noise variance; var_accel, var_mag : variances of the normalised directions
    P0 : (4, 4) initial covariance of the quaternion components, symmetric positive definite (default I)
    """
    lead, r, a, m, q0 = _samples(rate, accel, mag, q0)
    delta = float(as_array(inclination, "inclination"))
    if abs(delta) > math.pi / 2:
        raise ValidationError(f"inclination: must be in [−π/2, π/2] rad, got {delta}")
    m_ref = np.array([math.cos(delta), 0.0, -math.sin(delta)])
    P0 = covariance_matrix(np.eye(4) if P0 is None else P0, "P0", 4)
    R = np.diag([require_positive(var_accel, "var_accel")] * 3 + [require_positive(var_mag, "var_mag")] * 3)
    out = np.empty((r.shape[0], r.shape[1], 4))
    _ekf_batch(r, a, m, require_positive(dt, "dt"), q0, P0, m_ref, require_non_negative(var_gyro, "var_gyro"), R,
               out)
    return out.reshape((*lead, r.shape[1], 4))
