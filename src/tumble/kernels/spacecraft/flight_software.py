"""The flight software: a gyro, a star tracker, fine and coarse Sun sensors and a magnetometer, each sampled at its own
rate with its own latency, the MEKF fed the time-stamped readings, the estimate fed to the control law, the
command held after a computation delay.

**The sensors** (:func:`kernel`'s ``sense``, at every step end ``t``). Sensor
``i`` reads the truth ``(q, ω)`` of the state at its sample times
``τ_m = t₀ + m P_i`` (``P_i`` its period; the steps land on them) and its
reading is out ``L_i`` (its latency) later. Its noise comes from a
counter-based generator keyed by the run's seed and the sensor's own stream
number: the normal variates of its sample ``m`` are a hash of
``(seed, stream, m, draw)`` (:func:`normal`), so that a seed gives the same run
on every machine, in any batch or chunk, and no sensor's rate or stream moves
another's noise. Gyro (Crassidis & Junkins, *Optimal Estimation of Dynamic
Systems*, 2nd ed., §7.2.3; the MEKF's model), a rate-integrating gyro with
ideal coning compensation whose reading at ``τ_m`` is the true attitude and
the accumulated angle error ``E``::

    β_m = β_{m−1} + σ_u √P n_u,      E_m = E_{m−1} + P (½ (β_m + β_{m−1}) + w_m),
    w_m = √(σ_v²/P + σ_u² P/12) n_v

so the rate over ``[τ_a, τ_b]`` it gives is ``(log(q_a* ⊗ q_b) + E_b − E_a) / (τ_b − τ_a)``
(body axes), and its rate sample ``ω(τ_m) + β_m + w_m``. Star tracker:
``q̃ = q ⊗ exp(v/2)``, ``v ~ N(0, diag(σ_st²))``, body axes. Fine Sun sensor and
magnetometer: the direction ``r`` (inertial: the Sun's, fixed; the field's
``R(q) B``, ``B`` the spacecraft's field in body axes) seen in body axes,
``b = R(q)ᵀ r``, turned by a rotation vector ``v ~ N(0, σ² I)``, so that its
error ``v × b`` has the covariance ``σ² (I − b bᵀ)`` of the MEKF's vector model
(Shuster's). Coarse Sun sensor: six cosine heads on the body's faces ±x, ±y,
±z, each reading ``I = ν max(0, n · ŝ_B) + σ w`` (full scale 1, ``ν`` the
fraction of the Sun seen, :mod:`tumble.spacecraft.eclipse`); the flight
software's Sun vector is ``v_i = I₊ᵢ − I₋ᵢ`` (``= ν ŝ_B`` without noise), a
direction ``v/|v|`` of noise ``√2 σ/|v|`` across it. The Sun is the
spacecraft's environment table's (its direction and ``ν`` at ``t``) or the
fixed ``sun_direction`` (``ν = 1``); a Sun sensor gives no reading while
``ν`` (coarse: ``|v|``) is below :data:`DARK`: no Sun, no measurement. Each sensor keeps its two newest readings with their times
(with a latency below the period, one of them is out).

**The flight software** (``step``, at each sample ``t_k = t₀ + k T`` of the
zero-order hold) uses the newest reading of each sensor that is out by
``t_k`` and not used before:

1. the filter ``(q̂, β̂, P)``, kept at the time ``t_f`` of its last update, takes
   the direction readings (star tracker, Sun sensor, magnetometer) in the order
   of their times ``τ ≥ t_f``: it propagates to ``τ`` with the gyro's rate over
   ``[t_f, τ]`` (:func:`tumble.estimation._mekf._propagate`; ``τ`` is a gyro
   sample time, and the gyro's reading of ``τ`` must be out too) and updates. A
   reading older than ``t_f`` (overtaken by another sensor's of shorter
   latency) is not used;
2. it predicts, without keeping it, to the newest gyro reading ``τ_g`` and on
   to ``t_k`` with that reading's rate: the estimate ``q̂_k`` and its covariance;
3. gives the control law ``q̂_k`` and ``ω̂_k = ω̃(τ_g) − β̂`` (0 before the gyro's first
   reading is out); the command it computes acts after the computation delay
   ``δ = delay·T`` (``delay`` in [0, 1]): the part keeps it pending and, at the
   step that ends at ``t_k + δ`` (:meth:`tumble.spacecraft.Spacecraft.step_ends`
   makes the steps end there), hands it to the zero-order hold; the one held
   acts until then (none acts before the first is out).

With ``sensor_noise`` off the sensors read the truth exactly (bias ``β`` included,
constant) while the filter keeps its noise model, so that the loop fed a perfect
truth reproduces the truth-fed controller.

Parameters at ``p`` and the state slice at ``s``: the offsets below (a σ of 0 or a period of 0: no such
sensor). The derivatives of the whole slice are zero: it changes only at the samples.
"""

from __future__ import annotations

import math

import numpy as np

from tumble._quat import qexp, qlog, qmul, qrotate, qrotate_inv
from tumble.estimation._mekf import _propagate, _update_star_tracker, _update_vector
from tumble.kernels.spacecraft._base import SAMPLE_TOLERANCE, Lane, Program, inline
from tumble.kernels.spacecraft._layout import PERIOD, START

#: The sensors, in the order of their clocks and readings (the gyro first: the others read its state).
SENSORS = ("gyro", "star_tracker", "sun_sensor", "magnetometer", "coarse_sun_sensor")
GYRO, STAR_TRACKER, SUN_SENSOR, MAGNETOMETER, COARSE_SUN_SENSOR = range(5)

#: A Sun sensor gives no reading when less than this fraction of the Sun is seen (coarse: when its Sun vector
#: is shorter than this, of full scale 1): no Sun, no measurement.
DARK = 0.5

# Parameters:
ARW = 0            # σ_v, rad/√s
RRW = 1            # σ_u, rad/s^1.5
ST_SIGMA = 2       # σ_st (3), rad, body axes
DELAY = 5          # the computation delay in periods, in [0, 1]
NOISE = 6          # 1: noisy sensors, 0: perfect ones
SUN_SIGMA = 7      # σ of the fine Sun sensor, rad (0: none)
SUN_DIRECTION = 8  # the Sun's direction (3), inertial axes, unit
MAG_SIGMA = 11     # σ of the magnetometer's direction, rad (0: none)
CSS_SIGMA = 12     # σ of each coarse Sun sensor head's current, of full scale 1 (0: none)
CLOCKS = 13        # per sensor of SENSORS: period P (s; 0: none), latency L (s), stream number
CLOCK = 3
SIZE = CLOCKS + CLOCK * len(SENSORS)
# State slice:
Q_EST = 0          # q̂ (4) at the last sample (predicted to it)
BIAS_EST = 4       # β̂ (3), rad/s
COVARIANCE = 7     # P (36), row-major, of [δθ, δβ], predicted to the last sample
OMEGA_EST = 43     # ω̂ (3), rad/s, the rate the law read
GYRO_BIAS = 46     # the gyro's true bias β (3), rad/s
PENDING = 49       # the command computed, not yet acting: u_c (3), m_c (3)
SEED = 55          # the noise seed (an integer < 2⁵³)
FILTER_Q = 56      # the filter's q̂ (4) at t_f
FILTER_P = 60      # its P (36) at t_f
FILTER_TIME = 96   # t_f, s: the time of its last update
FILTER_GYRO = 97   # the gyro's reading at t_f: q (4), E (3)
GYRO_ERROR = 104   # the gyro's accumulated angle error E (3), rad
NEXT = 107         # per sensor: the index m of its next sample
USED = NEXT + len(SENSORS)      # per sensor: the time of its newest reading the flight software used, s (NEVER: none)
READINGS = USED + len(SENSORS)  # per sensor: its two newest readings, the newest first, each of READING values:
READING = 15       # τ (s; NEVER: none), value (4: q̃; b̃ (3) [and the coarse Sun sensor's σ]; the gyro's rate (3)),
                   # reference r (3), gyro q (4), E (3)
TAU, VALUE, REFERENCE, READ_Q, READ_E = 0, 1, 5, 8, 12
STATE = READINGS + 2 * READING * len(SENSORS)

#: The time of a reading not taken (finite: the integrators take a state that is not finite for divergence).
NEVER = -1.0e300

#: Normal draws per sample of a sensor: the gyro's n_u (3), n_v (3); the others' v (3).
DRAWS = 6

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
_TWO53 = 2.0 ** -53


def program(arw: float, rrw: float, star_tracker_sigma, delay: float, noise: bool, sun_sensor_sigma: float,
            sun_direction, magnetometer_sigma: float, coarse_sun_sensor_sigma: float, clocks) -> Program:
    """The flight software's :class:`~tumble.kernels.spacecraft._base.Program` (parameters: the offsets above;
    ``clocks`` (5, 3): period, latency and stream number of each of :data:`SENSORS`)."""
    params = np.concatenate([[arw, rrw], star_tracker_sigma, [delay, 1.0 if noise else 0.0, sun_sensor_sigma],
                             sun_direction, [magnetometer_sigma, coarse_sun_sensor_sigma],
                             np.ravel(clocks)]).astype(np.float64)
    return Program("flight_software", params, state=STATE)


def initial_state(y0: np.ndarray, s: int, t0: float, q0: np.ndarray, covariance0: np.ndarray) -> None:
    """Write the filter's and the sensors' initial state into the rows of ``y0`` (N, size) at the offset ``s``,
    the estimate, bias and seed being written already: the filter at ``t0`` (s) with ``covariance0`` (6, 6),
    the gyro's reference the true ``q0`` (N, 4) with no error yet, no reading taken or used."""
    y0[:, s + COVARIANCE:s + COVARIANCE + 36] = covariance0.ravel()
    y0[:, s + FILTER_Q:s + FILTER_Q + 4] = y0[:, s + Q_EST:s + Q_EST + 4]
    y0[:, s + FILTER_P:s + FILTER_P + 36] = covariance0.ravel()
    y0[:, s + FILTER_TIME] = t0
    y0[:, s + FILTER_GYRO:s + FILTER_GYRO + 4] = q0
    y0[:, s + USED:s + USED + len(SENSORS)] = NEVER
    for k in range(2 * len(SENSORS)):
        y0[:, s + READINGS + k * READING + TAU] = NEVER


@inline
def _splitmix(z):
    """SplitMix64's output function (Steele, Lea & Flood, OOPSLA 2014) of the uint64 ``z``."""
    z = z + _GOLDEN
    z = (z ^ (z >> _S30)) * _MIX1
    z = (z ^ (z >> _S27)) * _MIX2
    return z ^ (z >> _S31)


@inline
def stream_key(seed, stream):
    """The key of a sensor's noise: the run's ``seed`` mixed with the sensor's ``stream`` number (uint64)."""
    return _splitmix(np.uint64(seed)) ^ _splitmix(_splitmix(np.uint64(stream)))


@inline
def uniform(key, counter):
    """A uniform variate in (0, 1) of ``(key, counter)`` (a SplitMix64 round; 53 bits, never 0 or 1)."""
    z = _splitmix(key ^ np.uint64(counter))
    return (float(z >> _S11) + 0.5) * _TWO53


@inline
def normal(key, m, i):
    """The standard normal variate ``i`` (< :data:`DRAWS`) of a sensor's sample ``m`` for its ``key``
    (:func:`stream_key`): Box–Muller of the uniforms of the counters ``2 (DRAWS m + i)`` and ``2 (DRAWS m + i) + 1``."""
    c = 2 * (DRAWS * m + i)
    u1, u2 = uniform(key, c), uniform(key, c + 1)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)


def kernel(lane: Lane):
    """``(sense, step, pend, due)`` of the flight software for the state access ``lane``.

    ``sense(model, p, s, t, y, j, B, ŝ, ν)``: the sensors whose sample time is ``t`` (s) read the truth (in
    place; ``B`` the field, T, body axes; ``ŝ`` the Sun's direction, inertial, and ``ν`` the fraction of it
    seen); ``step(model, p, s, period, t, y, j) -> (q̂, ω̂)``: the MEKF at the
    flight software's sample time ``t`` (in place); ``pend(model, p, s, y, j, u, m) -> bool``: keeps the
    command just computed pending when it acts after a delay; ``due(model, p, t) -> bool``: whether a pending
    command starts acting at ``t`` (the pending command is at ``PENDING``: u_c (3), m_c (3))."""
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
    def reading(s, sensor, newest):
        """The offset of a sensor's newest (or older) reading."""
        return s + READINGS + (2 * sensor + (0 if newest else 1)) * READING

    @inline
    def record(y, j, s, sensor, tau, v1, v2, v3, v4, r1, r2, r3):
        """Keep a new reading of ``sensor`` taken at ``tau``: the newest moves to the older place; the gyro's
        reading of now (its true ``q`` and error ``E``) goes with it."""
        new, old = reading(s, sensor, True), reading(s, sensor, False)
        for i in range(READING):
            put(y, old + i, j, at(y, new + i, j))
        put(y, new + TAU, j, tau)
        put(y, new + VALUE, j, v1)
        put3(y, new + VALUE + 1, j, v2, v3, v4)
        put3(y, new + REFERENCE, j, r1, r2, r3)
        for i in range(4):
            put(y, new + READ_Q + i, j, at(y, i, j))
        for i in range(3):
            put(y, new + READ_E + i, j, at(y, s + GYRO_ERROR + i, j))

    @inline
    def turned(key, m, sigma, noise, b1, b2, b3):
        """``b`` turned by the rotation vector ``v ~ N(0, σ² I)`` of the sample ``m``."""
        nw, nx, ny, nz = qexp(noise * sigma * normal(key, m, 0), noise * sigma * normal(key, m, 1),
                              noise * sigma * normal(key, m, 2))
        return qrotate(nw, nx, ny, nz, b1, b2, b3)

    @inline
    def sense(model, p, s, t, y, j, f1, f2, f3, s1, s2, s3, light):
        d = model.data
        t0, noise, seed = d[START], d[p + NOISE], int(at(y, s + SEED, j))
        qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
        present = (True, d[p + CLOCKS + CLOCK * STAR_TRACKER] > 0.0, d[p + SUN_SIGMA] > 0.0, d[p + MAG_SIGMA] > 0.0,
                   d[p + CSS_SIGMA] > 0.0)
        for sensor in range(len(SENSORS)):
            c = p + CLOCKS + CLOCK * sensor
            period = d[c]
            m = int(at(y, s + NEXT + sensor, j))
            tau = t0 + m * period
            if not present[sensor] or abs(t - tau) > SAMPLE_TOLERANCE * period:
                continue
            put(y, s + NEXT + sensor, j, m + 1.0)
            key = stream_key(seed, int(d[c + 2]))
            if sensor == GYRO:
                arw, rrw = d[p + ARW], d[p + RRW]
                walk = math.sqrt(period) * rrw * noise
                white = math.sqrt(arw * arw / period + rrw * rrw * period / 12.0) * noise
                rate = np.empty(3)
                for i in range(3):
                    beta = at(y, s + GYRO_BIAS + i, j)
                    w = white * normal(key, m, 3 + i)
                    if m > 0:
                        previous = beta
                        beta += walk * normal(key, m, i)
                        put(y, s + GYRO_BIAS + i, j, beta)
                        put(y, s + GYRO_ERROR + i, j, at(y, s + GYRO_ERROR + i, j)
                            + period * (0.5 * (beta + previous) + w))
                    rate[i] = at(y, 4 + i, j) + beta + w
                record(y, j, s, sensor, tau, rate[0], rate[1], rate[2], 0.0, 0.0, 0.0, 0.0)
            elif sensor == STAR_TRACKER:
                o = p + ST_SIGMA
                dw, dx, dy, dz = qexp(noise * d[o] * normal(key, m, 0), noise * d[o + 1] * normal(key, m, 1),
                                      noise * d[o + 2] * normal(key, m, 2))
                mw, mx, my, mz = qmul(qw, qx, qy, qz, dw, dx, dy, dz)
                record(y, j, s, sensor, tau, mw, mx, my, mz, 0.0, 0.0, 0.0)
            elif sensor == COARSE_SUN_SENSOR:  # heads on ±x, ±y, ±z: v_i = I₊ᵢ − I₋ᵢ
                sigma = noise * d[p + CSS_SIGMA]
                b = qrotate_inv(qw, qx, qy, qz, s1, s2, s3)
                v = np.empty(3)
                for i in range(3):
                    v[i] = (light * max(0.0, b[i]) + sigma * normal(key, m, 2 * i)
                            - light * max(0.0, -b[i]) - sigma * normal(key, m, 2 * i + 1))
                size = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                if size >= DARK:
                    record(y, j, s, sensor, tau, v[0] / size, v[1] / size, v[2] / size,
                           math.sqrt(2.0) * d[p + CSS_SIGMA] / size, s1, s2, s3)
            elif sensor == SUN_SENSOR:
                if light >= DARK:
                    b1, b2, b3 = qrotate_inv(qw, qx, qy, qz, s1, s2, s3)
                    m1, m2, m3 = turned(key, m, d[p + SUN_SIGMA], noise, b1, b2, b3)
                    record(y, j, s, sensor, tau, m1, m2, m3, 0.0, s1, s2, s3)
            else:
                r1, r2, r3 = qrotate(qw, qx, qy, qz, f1, f2, f3)
                m1, m2, m3 = turned(key, m, d[p + MAG_SIGMA], noise, f1, f2, f3)
                record(y, j, s, sensor, tau, m1, m2, m3, 0.0, r1, r2, r3)

    @inline
    def out_by(model, p, y, j, s, sensor, t, tolerance):
        """The offset of the newest reading of ``sensor`` that is out by ``t`` (its latency after its time), or
        −1 when none is."""
        latency = model.data[p + CLOCKS + CLOCK * sensor + 1]
        for newest in (True, False):
            o = reading(s, sensor, newest)
            tau = at(y, o + TAU, j)
            if tau > NEVER and tau + latency <= t + tolerance:
                return o
        return -1

    @inline
    def advance(model, p, y, j, q_hat, beta_hat, P, reference, o, dt):
        """Propagate ``(q̂, β̂, P)`` over ``dt`` (s) with the gyro's rate from its reading ``reference``
        (q, E: 7 values) to the reading at ``o``."""
        if dt <= 0.0:
            return
        aw, ax, ay, az = reference[0], reference[1], reference[2], reference[3]
        ew, ex, ey, ez = qmul(aw, -ax, -ay, -az, at(y, o + READ_Q, j), at(y, o + READ_Q + 1, j),
                              at(y, o + READ_Q + 2, j), at(y, o + READ_Q + 3, j))
        theta = qlog(ew, ex, ey, ez)
        rate = np.empty(3)
        for i in range(3):
            rate[i] = (theta[i] + at(y, o + READ_E + i, j) - reference[4 + i]) / dt
        arw, rrw = model.data[p + ARW], model.data[p + RRW]
        _propagate(q_hat, beta_hat, P, rate, dt, arw * arw, rrw * rrw, np.empty((6, 6)), np.empty((3, 3)))

    @inline
    def update(model, p, y, j, q_hat, beta_hat, P, sensor, o):
        """The MEKF's update with the reading of ``sensor`` at ``o``."""
        d = model.data
        if sensor == STAR_TRACKER:
            R = np.zeros((3, 3))
            for i in range(3):
                R[i, i] = d[p + ST_SIGMA + i] ** 2
            _update_star_tracker(q_hat, beta_hat, P, gather(y, j, o + VALUE, 4), R)
        else:
            sigma = (d[p + SUN_SIGMA] if sensor == SUN_SENSOR else d[p + MAG_SIGMA] if sensor == MAGNETOMETER
                     else at(y, o + VALUE + 3, j))
            _update_vector(q_hat, beta_hat, P, gather(y, j, o + VALUE, 3), gather(y, j, o + REFERENCE, 3), sigma)

    @inline
    def step(model, p, s, period, t, y, j):
        tolerance = SAMPLE_TOLERANCE * period
        q_hat, beta_hat = gather(y, j, s + FILTER_Q, 4), gather(y, j, s + BIAS_EST, 3)
        P = gather(y, j, s + FILTER_P, 36).reshape(6, 6)
        t_f, reference = at(y, s + FILTER_TIME, j), gather(y, j, s + FILTER_GYRO, 7)
        gyro = out_by(model, p, y, j, s, GYRO, t, tolerance)
        gyro_time = at(y, gyro + TAU, j) if gyro >= 0 else -math.inf
        for _ in range(len(SENSORS) - 1):  # the direction readings out and new, in the order of their times
            first, first_time = -1, math.inf
            for sensor in range(1, len(SENSORS)):
                o = out_by(model, p, y, j, s, sensor, t, tolerance)
                if o < 0:
                    continue
                tau = at(y, o + TAU, j)
                if tau <= at(y, s + USED + sensor, j) or tau > gyro_time:  # used, or the gyro's reading not out
                    continue
                if tau < t_f:  # overtaken by a reading of another sensor: not used
                    put(y, s + USED + sensor, j, tau)
                elif tau < first_time:
                    first, first_time = sensor, tau
            if first < 0:
                break
            o = out_by(model, p, y, j, s, first, t, tolerance)
            advance(model, p, y, j, q_hat, beta_hat, P, reference, o, first_time - t_f)
            update(model, p, y, j, q_hat, beta_hat, P, first, o)
            t_f, reference = first_time, gather(y, j, o + READ_Q, 7)
            put(y, s + USED + first, j, first_time)
        scatter(y, j, s + FILTER_Q, q_hat)
        scatter(y, j, s + FILTER_P, P.ravel())
        put(y, s + FILTER_TIME, j, t_f)
        scatter(y, j, s + FILTER_GYRO, reference)
        scatter(y, j, s + BIAS_EST, beta_hat)
        w1 = w2 = w3 = 0.0
        if gyro >= 0:  # predict to the gyro's newest reading, then on to t with its rate
            advance(model, p, y, j, q_hat, beta_hat, P, reference, gyro, gyro_time - t_f)
            rate = gather(y, j, gyro + VALUE, 3)
            ahead = t - max(gyro_time, t_f)
            if ahead > tolerance:
                arw, rrw = model.data[p + ARW], model.data[p + RRW]
                _propagate(q_hat, beta_hat, P, rate, ahead, arw * arw, rrw * rrw, np.empty((6, 6)),
                           np.empty((3, 3)))
            w1, w2, w3 = rate[0] - beta_hat[0], rate[1] - beta_hat[1], rate[2] - beta_hat[2]
            put(y, s + USED + GYRO, j, gyro_time)
        scatter(y, j, s + Q_EST, q_hat)
        scatter(y, j, s + COVARIANCE, P.ravel())
        put3(y, s + OMEGA_EST, j, w1, w2, w3)
        return q_hat[0], q_hat[1], q_hat[2], q_hat[3], w1, w2, w3

    @inline
    def pend(model, p, s, y, j, u1, u2, u3, m1, m2, m3):
        """Keep the command just computed pending when it acts after a delay (then True: the one held stays)."""
        if model.data[p + DELAY] == 0.0:
            return False
        put3(y, s + PENDING, j, u1, u2, u3)
        put3(y, s + PENDING + 3, j, m1, m2, m3)
        return True

    @inline
    def due(model, p, t):
        """True when the step end ``t`` is a time ``t₀ + k T + δ`` (k ≥ 0, δ > 0) a pending command starts acting."""
        d = model.data
        period, lag = d[PERIOD], d[p + DELAY] * d[PERIOD]
        k = round((t - d[START] - lag) / period)
        return lag > 0.0 and k >= 0 and abs(t - d[START] - k * period - lag) <= SAMPLE_TOLERANCE * period

    return sense, step, pend, due
