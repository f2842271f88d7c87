"""Measurement models of attitude sensors: star tracker, coarse and fine Sun sensors, three-axis magnetometer.

Each sensor reads a true motion — a :class:`~tumble.Trajectory` of one body,
or arrays ``t`` (s) and ``q`` (scalar first, body → inertial) — at its own
sample times and returns :class:`Measurements`. A sensor sampling at ``rate``
(Hz) with ``latency`` (s) outputs at ``t_k = t₀ + latency + k / rate`` the
truth of ``t_k − latency``; the attitude between trajectory samples is
interpolated along the geodesic (``q_i ⊗ exp(f log(q_i* ⊗ q_{i+1}))``), so
the rate may not exceed the trajectory's output rate. Every sensor draws its
noise from its own ``numpy.random.Generator`` seeded by the caller, in a
fixed order: a seed gives the same measurements on every run, whatever other
sensors are sampled. Gyros and accelerometers are :class:`tumble.ins.Imu`
(IEEE Std 952 error models on increments).

=====================  ==============================================================================
:class:`StarTracker`   attitude ``q̃ = q ⊗ q_BS,true ⊗ exp(v/2) ⊗ q_BS*``, ``v ~ N(0, diag(σ_c², σ_c², σ_a²))``
                       in sensor axes (boresight = sensor z); ``q_BS,true = q_BS ⊗ exp(μ/2)``
                       (misalignment ``μ``); NaN while the Sun, Earth or Moon is within its exclusion
                       angle of the boresight
:class:`CoarseSunSensor`  cosine heads: ``I_j = max(0, n_j · ŝ_B) + σ w``, full scale 1
:class:`FineSunSensor`    Sun direction ``ŝ_B`` turned by a small rotation ``v ⊥ ŝ_B``, ``E[vvᵀ] = σ²(I − ŝŝᵀ)``
                       (QUEST's model); NaN outside the field of view
:class:`Magnetometer`  ``B̃ = (I + M) R(q)ᵀ B_N + b + σ w`` (T); ``M`` scale and misalignment
=====================  ==============================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._validate import ValidationError, as_array, increasing_times, require_non_negative, require_positive
from tumble.trajectory import Trajectory

__all__ = ["CoarseSunSensor", "FineSunSensor", "Magnetometer", "Measurements", "StarTracker"]

Seed = int | np.random.SeedSequence | np.random.Generator | None


@dataclass(frozen=True)
class Measurements:
    """A sensor's output.

    t : (M,)          output times, s
    value : (M, …)    the measurements (NaN rows where the sensor gave none)
    """

    t: np.ndarray
    value: np.ndarray

    def on(self, times: ArrayLike) -> np.ndarray:
        """The measurements placed on a filter's ``times`` (len(times), …): each at the time equal to its own
        (within 1e-9 s), NaN at the others; a measurement at no such time is refused."""
        times = increasing_times(times, "times", what="filter times")
        idx = np.minimum(np.searchsorted(times, self.t - 1e-9), times.size - 1)
        missing = np.abs(times[idx] - self.t) > 1e-9
        if missing.any():
            k = int(np.flatnonzero(missing)[0])
            raise ValidationError(f"times: must contain every measurement time (t[{k}] = {self.t[k]} is missing)")
        out = np.full((times.size, *self.value.shape[1:]), np.nan)
        out[idx] = self.value
        return out


def _truth(t, q) -> tuple[np.ndarray, np.ndarray]:
    """(t, q) of a Trajectory of one body, or the arrays given, checked."""
    if isinstance(t, Trajectory):
        if t.batch_size is not None or t.q is None:
            raise ValidationError("t: must be a Trajectory of one body with an attitude (use trajectory.member(i))")
        return t.t, t.q
    t = increasing_times(t, "t", what="truth times", at_least=2)
    q = attitude._as_quat(q, "q")
    if q.shape != (t.size, 4):
        raise ValidationError(f"q: must have shape ({t.size}, 4), one attitude per time, got {q.shape}")
    return t, attitude.normalize(q)


def sample_times(t: np.ndarray, rate: float, latency: float) -> np.ndarray:
    """Output times ``t₀ + latency + k/rate`` (s) of a sensor on the truth times ``t``, up to ``t[-1]``.

    ``rate`` (Hz) must not exceed the truth's output rate ``1 / max(Δt)``: a sensor cannot read a truth
    sampled more coarsely than itself.
    """
    rate = require_positive(rate, "rate")
    latency = require_non_negative(latency, "latency")
    truth_rate = 1.0 / np.diff(t).max()
    if rate > truth_rate * (1.0 + 1e-12):
        raise ValidationError(f"rate: must not exceed the truth's output rate 1/Δt = {truth_rate:.6g} Hz "
                              f"(the integration's output times), got {rate:.6g} Hz")
    count = int(math.floor((t[-1] - t[0] - latency) * rate * (1.0 + 1e-12))) + 1
    if count < 1:
        raise ValidationError(f"latency: must be shorter than the truth's span {t[-1] - t[0]} s, got {latency}")
    return t[0] + latency + np.arange(count) / rate


def attitude_at(t: np.ndarray, q: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Attitude at ``times`` (within ``[t₀, t_end]``), along the geodesic between the neighbouring samples."""
    i = np.clip(np.searchsorted(t, times, side="right") - 1, 0, t.size - 2)
    f = (times - t[i]) / (t[i + 1] - t[i])
    step = attitude.to_rotvec(attitude.multiply(attitude.conjugate(q[i]), q[i + 1]))
    return attitude.multiply(q[i], attitude.from_rotvec(f[:, None] * step))


def _directions_at(value, name: str, t: np.ndarray, times: np.ndarray) -> np.ndarray:
    """A direction or vector (3,) constant, or one per truth time (n, 3) linearly interpolated, at ``times``."""
    v = as_array(value, name, tail=(3,))
    if v.shape == (3,):
        return np.broadcast_to(v, (times.size, 3))
    if v.shape != (t.size, 3):
        raise ValidationError(f"{name}: must have shape (3,) or ({t.size}, 3), one per truth time, got {v.shape}")
    return np.stack([np.interp(times, t, v[:, j]) for j in range(3)], axis=-1)


def _body_vectors(t, q, rate: float, latency: float, value, name: str, unit: bool):
    """The sample times of a sensor of ``rate`` (Hz) and ``latency`` (s) on the truth ``(t, q)``, and the
    inertial vector ``value`` ((3,) or one per truth time; a unit direction when ``unit``) seen in body axes at
    them, ``R(q(t_k − latency))ᵀ v_N(t_k − latency)``: ``(t_k, v_B)``."""
    t, q = _truth(t, q)
    out_t = sample_times(t, rate, latency)
    v = _directions_at(value, name, t, out_t - latency)
    return out_t, attitude.rotate_inverse(attitude_at(t, q, out_t - latency), _unit_rows(v, name) if unit else v)


def _unit_rows(v: np.ndarray, name: str) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    if np.any(n == 0.0):
        raise ValidationError(f"{name}: directions must be non-zero")
    return v / n


@dataclass(frozen=True)
class StarTracker:
    """A star tracker (module docstring).

    rate : Hz; latency : s
    sigma_cross, sigma_about : rad, noise (1σ) about each cross-boresight axis and about the boresight
    mounting : (4,) ``q_BS``, sensor → body (boresight = sensor z); misalignment : (3,) ``μ``, rad, sensor axes
    exclusion : {"sun": rad, "earth": rad, "moon": rad}, half-angles of the exclusion cones
    """

    rate: float
    sigma_cross: float
    sigma_about: float
    latency: float = 0.0
    mounting: np.ndarray = field(default_factory=lambda: attitude.identity())
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    exclusion: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("sigma_cross", "sigma_about"):
            object.__setattr__(self, name, require_non_negative(getattr(self, name), name))
        require_positive(self.rate, "rate")
        object.__setattr__(self, "mounting", attitude.normalize(as_array(self.mounting, "mounting", tail=(4,))))
        object.__setattr__(self, "misalignment", as_array(self.misalignment, "misalignment", tail=(3,)))
        for body, angle in self.exclusion.items():
            if body not in ("sun", "earth", "moon"):
                raise ValidationError(f"exclusion: keys must be 'sun', 'earth' or 'moon', got {body!r}")
            if not 0.0 <= float(angle) < math.pi:
                raise ValidationError(f"exclusion.{body}: must be a half-angle in [0, π) rad, got {angle}")

    @property
    def covariance(self) -> np.ndarray:
        """Noise covariance (3, 3) of the attitude error in body axes (rad²), for :func:`~tumble.estimation.mekf`."""
        R_bs = attitude.to_matrix(self.mounting)
        return R_bs @ np.diag([self.sigma_cross**2, self.sigma_cross**2, self.sigma_about**2]) @ R_bs.T

    def sample(self, t: Trajectory | ArrayLike, q: ArrayLike | None = None, *,
               directions: dict | None = None, seed: Seed = None) -> Measurements:
        """Measured attitudes (M, 4) of the truth (Trajectory, or ``t``, ``q``).

        ``directions`` maps ``"sun"``/``"earth"``/``"moon"`` to the direction of that body from the spacecraft in
        inertial axes, (3,) or one per truth time; each key of ``exclusion`` needs one. Draws the noise (M, 3).
        """
        t, q = _truth(t, q)
        out_t = sample_times(t, self.rate, self.latency)
        q_true = attitude_at(t, q, out_t - self.latency)
        rng = np.random.default_rng(seed)
        v = rng.standard_normal((out_t.size, 3)) * [self.sigma_cross, self.sigma_cross, self.sigma_about]
        q_bs_true = attitude.multiply(self.mounting, attitude.from_rotvec(self.misalignment))
        q_is = attitude.multiply(attitude.multiply(q_true, q_bs_true), attitude.from_rotvec(v))
        value = attitude.multiply(q_is, attitude.conjugate(self.mounting))
        boresight = attitude.rotate(attitude.multiply(q_true, q_bs_true), [0.0, 0.0, 1.0])
        directions = directions or {}
        for body, half_angle in self.exclusion.items():
            if body not in directions:
                raise ValidationError(f"directions: must give the {body!r} direction for its exclusion angle")
            d = _unit_rows(_directions_at(directions[body], f"directions.{body}", t, out_t - self.latency),
                           f"directions.{body}")
            blinded = np.sum(boresight * d, axis=-1) > math.cos(half_angle)
            value[blinded] = np.nan
        return Measurements(t=out_t, value=value)


@dataclass(frozen=True)
class CoarseSunSensor:
    """Cosine Sun sensors: heads with unit normals ``normals`` (J, 3) in body axes, output ``max(0, n·ŝ) + σw``.

    rate : Hz; sigma : noise (1σ) as a fraction of the full-Sun output; latency : s
    """

    rate: float
    normals: np.ndarray
    sigma: float = 0.0
    latency: float = 0.0

    def __post_init__(self):
        n = as_array(self.normals, "normals", tail=(3,))
        if n.ndim != 2:
            raise ValidationError(f"normals: must have shape (J, 3), got {n.shape}")
        object.__setattr__(self, "normals", _unit_rows(n, "normals"))
        object.__setattr__(self, "sigma", require_non_negative(self.sigma, "sigma"))
        require_positive(self.rate, "rate")

    def sample(self, t: Trajectory | ArrayLike, q: ArrayLike | None = None, *,
               sun: ArrayLike, seed: Seed = None) -> Measurements:
        """Head outputs (M, J); ``sun``: direction to the Sun, inertial axes, (3,) or one per truth time."""
        out_t, s_b = _body_vectors(t, q, self.rate, self.latency, sun, "sun", unit=True)
        rng = np.random.default_rng(seed)
        value = np.maximum(s_b @ self.normals.T, 0.0) + self.sigma * rng.standard_normal((out_t.size,
                                                                                          len(self.normals)))
        return Measurements(t=out_t, value=value)


@dataclass(frozen=True)
class FineSunSensor:
    """A fine Sun sensor: the Sun's unit vector in body axes, noise σ (rad, per axis across it), within
    ``field_of_view`` (half-angle, rad) of ``boresight`` (body axes)."""

    rate: float
    sigma: float
    boresight: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    field_of_view: float = math.radians(60.0)
    latency: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "boresight", _unit_rows(as_array(self.boresight, "boresight", tail=(3,)),
                                                         "boresight"))
        object.__setattr__(self, "sigma", require_non_negative(self.sigma, "sigma"))
        require_positive(self.rate, "rate")
        if not 0.0 < float(self.field_of_view) <= math.pi:
            raise ValidationError(f"field_of_view: must be a half-angle in (0, π] rad, got {self.field_of_view}")

    def sample(self, t: Trajectory | ArrayLike, q: ArrayLike | None = None, *,
               sun: ArrayLike, seed: Seed = None) -> Measurements:
        """Measured Sun directions (M, 3), unit, NaN outside the field of view."""
        out_t, s_b = _body_vectors(t, q, self.rate, self.latency, sun, "sun", unit=True)
        rng = np.random.default_rng(seed)
        v = self.sigma * rng.standard_normal((out_t.size, 3))
        v -= np.sum(v * s_b, axis=-1, keepdims=True) * s_b      # v ⊥ ŝ: a small rotation of ŝ
        value = attitude.rotate(attitude.from_rotvec(v), s_b)
        value[s_b @ self.boresight < math.cos(self.field_of_view)] = np.nan
        return Measurements(t=out_t, value=value)


@dataclass(frozen=True)
class Magnetometer:
    """A three-axis magnetometer: ``B̃ = (I + M) R(q)ᵀ B_N + bias + σ w`` (T, body axes).

    rate : Hz; sigma : T (1σ per axis); bias : (3,) T; errors : (3, 3) ``M``, scale factors on the diagonal
    and misalignments off it (dimensionless); latency : s
    """

    rate: float
    sigma: float = 0.0
    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    errors: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    latency: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "sigma", require_non_negative(self.sigma, "sigma"))
        object.__setattr__(self, "bias", as_array(self.bias, "bias", tail=(3,)).reshape(3))
        m = as_array(self.errors, "errors", tail=(3, 3))
        if m.shape != (3, 3):
            raise ValidationError(f"errors: must have shape (3, 3), got {m.shape}")
        object.__setattr__(self, "errors", m)
        require_positive(self.rate, "rate")

    def sample(self, t: Trajectory | ArrayLike, q: ArrayLike | None = None, *,
               field_inertial: ArrayLike, seed: Seed = None) -> Measurements:
        """Measured field (M, 3), T; ``field_inertial``: the field in inertial axes, (3,) or one per truth time."""
        out_t, b_body = _body_vectors(t, q, self.rate, self.latency, field_inertial, "field_inertial", unit=False)
        rng = np.random.default_rng(seed)
        value = b_body @ (np.eye(3) + self.errors).T + self.bias + self.sigma * rng.standard_normal(b_body.shape)
        return Measurements(t=out_t, value=value)
