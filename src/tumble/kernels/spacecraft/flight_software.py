"""The flight software: gyro, star tracker, Sun sensor and magnetometer sampled at the control period, the
MEKF, the estimate fed to the control law, the command held after a computation delay.

At each sample time ``t_k = t₀ + k T`` of the zero-order hold (``T`` the
control period) the part, in order:

1. **Reads the sensors** from the truth ``(q, ω)`` of the state, with noise from
   a counter-based generator: the normal variates of sample ``k`` are a hash of
   ``(seed, k, draw)`` (:func:`normal`), so a seed gives the same run on every
   machine, in any batch or chunk. Gyro (Crassidis & Junkins, *Optimal
   Estimation of Dynamic Systems*, 2nd ed., §7.2.3; the MEKF's model)::

       β_k = β_{k−1} + σ_u √T n_u
       ω̃_k = θ_k / T + ½ (β_k + β_{k−1}) + √(σ_v²/T + σ_u² T/12) n_v,   θ_k = log(q_{k−1}* ⊗ q_k)

   ``θ_k`` the rotation vector of the true attitude increment (body axes: a
   rate-integrating gyro with ideal coning compensation). The rate the control
   law reads is the gyro's rate at ``t_k``, ``ω(t_k) + β_k`` plus the same noise
   sample. Star tracker (every ``n_st``-th sample): ``q̃_k = q_k ⊗ exp(v/2)``,
   ``v ~ N(0, diag(σ_st²))``, body axes. Fine Sun sensor and magnetometer: the
   direction ``r`` (inertial: the Sun's, fixed; the field's ``R(q) B``, ``B`` the
   spacecraft's field in body axes) seen in body axes, ``b = R(q)ᵀ r``, turned by
   a rotation vector ``v ~ N(0, σ² I)``, so that its error ``v × b`` has the
   covariance ``σ² (I − b bᵀ)`` of the MEKF's vector model (Shuster's).
2. **Runs the MEKF step** (:mod:`tumble.estimation._mekf`'s compiled kernels):
   propagate ``(q̂, β̂, P)`` with ``ω̃_k`` over ``T``, then the updates of the
   sensors present (star tracker, Sun sensor, magnetometer).
3. **Gives the control law the estimate** ``q̂_k``, ``ω̂_k = ω̃(t_k) − β̂_k``; the
   command it computes acts after the computation delay, 0 or one period ``T``:
   with one, the command of ``t_k`` is held from ``t_{k+1}`` (the part keeps it
   pending meanwhile; none acts before the first is out).

With ``sensor_noise`` off the sensors read the truth exactly (bias ``β`` included,
constant) while the filter keeps its noise model, so that the loop fed a perfect
truth reproduces the truth-fed controller.

Parameters at ``p`` and the state slice at ``s``: the offsets below (a σ or an ``n_st`` of 0: no such
sensor). The derivatives of the whole slice are zero: it changes only at the samples.
"""

from __future__ import annotations

import math

import numpy as np

from tumble._quat import qexp, qlog, qmul, qrotate, qrotate_inv
from tumble.estimation._mekf import _propagate, _update_star_tracker, _update_vector
from tumble.kernels.spacecraft._base import Lane, Program, inline

# Parameters:
ARW = 0            # σ_v, rad/√s
RRW = 1            # σ_u, rad/s^1.5
ST_SIGMA = 2       # σ_st (3), rad, body axes
ST_EVERY = 5       # n_st: the star tracker reads every n_st-th sample (0: none)
DELAY = 6          # the computation delay in periods: 0 or 1
NOISE = 7          # 1: noisy sensors, 0: perfect ones
SUN_SIGMA = 8      # σ of the fine Sun sensor, rad (0: none)
SUN_DIRECTION = 9  # the Sun's direction (3), inertial axes, unit
MAG_SIGMA = 12     # σ of the magnetometer's direction, rad (0: none)
SIZE = 13
# State slice:
Q_EST = 0          # q̂ (4)
BIAS_EST = 4       # β̂ (3), rad/s
COVARIANCE = 7     # P (36), row-major, of [δθ, δβ]
OMEGA_EST = 43     # ω̂ (3), rad/s, the rate the law read
GYRO_BIAS = 46     # the gyro's true bias β (3), rad/s
Q_LAST = 49        # the true attitude at the last sample (4): the gyro's increment reference
PENDING = 53       # the command computed, not yet acting: u_c (3), m_c (3)
SEED = 59          # the noise seed (an integer < 2⁵³)
COUNT = 60         # samples taken so far
STATE = 61

#: Draws per sample: n_u (3), n_v (3), then the star tracker's, the Sun sensor's and the magnetometer's v (3 each).
DRAWS = 15
_STAR, _SUN, _FIELD = 6, 9, 12

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
_TWO53 = 2.0 ** -53


def program(arw: float, rrw: float, star_tracker_sigma, star_tracker_every: int, delay: int, noise: bool,
            sun_sensor_sigma: float, sun_direction, magnetometer_sigma: float) -> Program:
    """The flight software's :class:`~tumble.kernels.spacecraft._base.Program` (parameters: the offsets above)."""
    params = np.concatenate([[arw, rrw], star_tracker_sigma, [star_tracker_every, delay, 1.0 if noise else 0.0],
                             [sun_sensor_sigma], sun_direction, [magnetometer_sigma]]).astype(np.float64)
    return Program("flight_software", params, state=STATE)


def state_slices(n: int, s: int) -> dict[str, slice]:
    return {"q_estimate": slice(s + Q_EST, s + Q_EST + 4), "bias_estimate": slice(s + BIAS_EST, s + BIAS_EST + 3),
            "covariance": slice(s + COVARIANCE, s + COVARIANCE + 36),
            "omega_estimate": slice(s + OMEGA_EST, s + OMEGA_EST + 3),
            "gyro_bias": slice(s + GYRO_BIAS, s + GYRO_BIAS + 3), "q_last": slice(s + Q_LAST, s + Q_LAST + 4),
            "seed": slice(s + SEED, s + SEED + 1)}


@inline
def _splitmix(z):
    """SplitMix64's output function (Steele, Lea & Flood, OOPSLA 2014) of the uint64 ``z``."""
    z = z + _GOLDEN
    z = (z ^ (z >> _S30)) * _MIX1
    z = (z ^ (z >> _S27)) * _MIX2
    return z ^ (z >> _S31)


@inline
def uniform(seed, counter):
    """A uniform variate in (0, 1) of ``(seed, counter)`` (two SplitMix64 rounds; 53 bits, never 0 or 1)."""
    z = _splitmix(_splitmix(np.uint64(seed)) ^ np.uint64(counter))
    return (float(z >> _S11) + 0.5) * _TWO53


@inline
def normal(seed, k, i):
    """The standard normal variate ``i`` (< :data:`DRAWS`) of sample ``k`` for ``seed``: Box–Muller of the
    uniforms of the counters ``2 (DRAWS k + i)`` and ``2 (DRAWS k + i) + 1``."""
    c = 2 * (DRAWS * k + i)
    u1, u2 = uniform(seed, c), uniform(seed, c + 1)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)


def kernel(lane: Lane):
    """``(step, delayed)`` of the flight software for the state access ``lane``.

    ``step(model, p, s, period, y, j, B) -> (q̂, ω̂)``: the sensors and the MEKF at a sample time (in place;
    ``B`` the field, T, body axes); ``delayed(model, p, s, y, j, u, m) -> (u, m)``: the command that acts now,
    given the one just computed."""
    at, put, put3 = lane

    @inline
    def gather(y, j, offset, size):
        out = np.empty(size)
        for i in range(size):
            out[i] = at(y, offset + i, j)
        return out

    @inline
    def scatter(y, j, offset, values):
        for i in range(values.size):
            put(y, offset + i, j, values[i])

    @inline
    def observe(q_hat, beta_hat, P, qw, qx, qy, qz, r1, r2, r3, sigma, noise, seed, k, draw):
        """The MEKF's update with a direction sensor of noise ``sigma`` reading ``r`` (inertial axes)."""
        b1, b2, b3 = qrotate_inv(qw, qx, qy, qz, r1, r2, r3)
        nw, nx, ny, nz = qexp(noise * sigma * normal(seed, k, draw), noise * sigma * normal(seed, k, draw + 1),
                              noise * sigma * normal(seed, k, draw + 2))
        measured, reference = np.empty(3), np.empty(3)
        measured[0], measured[1], measured[2] = qrotate(nw, nx, ny, nz, b1, b2, b3)
        reference[0], reference[1], reference[2] = r1, r2, r3
        _update_vector(q_hat, beta_hat, P, measured, reference, sigma)

    @inline
    def step(model, p, s, period, y, j, f1, f2, f3):
        d = model.data
        k = int(at(y, s + COUNT, j))
        seed = int(at(y, s + SEED, j))
        noise = d[p + NOISE]
        arw, rrw = d[p + ARW], d[p + RRW]
        qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
        q_hat, beta_hat = gather(y, j, s + Q_EST, 4), gather(y, j, s + BIAS_EST, 3)
        P = gather(y, j, s + COVARIANCE, 36).reshape(6, 6)
        beta = gather(y, j, s + GYRO_BIAS, 3)
        rate_noise = np.empty(3)
        walk = math.sqrt(period) * rrw * noise
        white = math.sqrt(arw * arw / period + rrw * rrw * period / 12.0) * noise
        for i in range(3):
            rate_noise[i] = white * normal(seed, k, 3 + i)
        if k > 0:
            lw, lx, ly, lz = at(y, s + Q_LAST, j), at(y, s + Q_LAST + 1, j), at(y, s + Q_LAST + 2, j), \
                at(y, s + Q_LAST + 3, j)
            ew, ex, ey, ez = qmul(lw, -lx, -ly, -lz, qw, qx, qy, qz)
            theta = qlog(ew, ex, ey, ez)
            rate = np.empty(3)
            for i in range(3):
                previous = beta[i]
                beta[i] += walk * normal(seed, k, i)
                rate[i] = theta[i] / period + 0.5 * (beta[i] + previous) + rate_noise[i]
            _propagate(q_hat, beta_hat, P, rate, period, arw * arw, rrw * rrw, np.empty((6, 6)), np.empty((3, 3)))
        every = int(d[p + ST_EVERY])
        if every > 0 and k % every == 0:
            R = np.zeros((3, 3))
            v = np.empty(3)
            for i in range(3):
                sigma = d[p + ST_SIGMA + i]
                R[i, i] = sigma * sigma
                v[i] = noise * sigma * normal(seed, k, _STAR + i)
            dw, dx, dy, dz = qexp(v[0], v[1], v[2])
            q_meas = np.empty(4)
            q_meas[0], q_meas[1], q_meas[2], q_meas[3] = qmul(qw, qx, qy, qz, dw, dx, dy, dz)
            _update_star_tracker(q_hat, beta_hat, P, q_meas, R)
        if d[p + SUN_SIGMA] > 0.0:
            o = p + SUN_DIRECTION
            observe(q_hat, beta_hat, P, qw, qx, qy, qz, d[o], d[o + 1], d[o + 2], d[p + SUN_SIGMA], noise, seed, k,
                    _SUN)
        if d[p + MAG_SIGMA] > 0.0:
            r1, r2, r3 = qrotate(qw, qx, qy, qz, f1, f2, f3)
            observe(q_hat, beta_hat, P, qw, qx, qy, qz, r1, r2, r3, d[p + MAG_SIGMA], noise, seed, k, _FIELD)
        w1 = at(y, 4, j) + beta[0] + rate_noise[0] - beta_hat[0]
        w2 = at(y, 5, j) + beta[1] + rate_noise[1] - beta_hat[1]
        w3 = at(y, 6, j) + beta[2] + rate_noise[2] - beta_hat[2]
        scatter(y, j, s + Q_EST, q_hat)
        scatter(y, j, s + BIAS_EST, beta_hat)
        scatter(y, j, s + COVARIANCE, P.ravel())
        scatter(y, j, s + GYRO_BIAS, beta)
        put3(y, s + OMEGA_EST, j, w1, w2, w3)
        put(y, s + Q_LAST, j, qw)
        put3(y, s + Q_LAST + 1, j, qx, qy, qz)
        put(y, s + COUNT, j, k + 1.0)
        return q_hat[0], q_hat[1], q_hat[2], q_hat[3], w1, w2, w3

    @inline
    def delayed(model, p, s, y, j, u1, u2, u3, m1, m2, m3):
        if model.data[p + DELAY] == 0.0:
            return u1, u2, u3, m1, m2, m3
        o = s + PENDING
        acting = (at(y, o, j), at(y, o + 1, j), at(y, o + 2, j), at(y, o + 3, j), at(y, o + 4, j), at(y, o + 5, j))
        put3(y, o, j, u1, u2, u3)
        put3(y, o + 3, j, m1, m2, m3)
        return acting

    return step, delayed
