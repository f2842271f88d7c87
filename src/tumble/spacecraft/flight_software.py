"""The flight-software loop: a gyro, a star tracker and direction sensors (fine and coarse Sun sensors, a
magnetometer), each read at its own rate with its own latency, the MEKF fed their time-stamped readings, and
the control law fed the estimate instead of the truth (:mod:`tumble.kernels.spacecraft.flight_software`).

The estimator is :func:`tumble.estimation.mekf`'s compiled step; the sensors are
the MEKF's own models (gyro angle and rate random walks, star-tracker noise in
body axes, direction noise across the direction), each drawing its noise from a
counter-based generator keyed by the seed of each run (``sensor_seed0``) and
its own stream number, so that a run is reproducible per seed, a batch of seeds
is a Monte-Carlo over sensor noise, and no sensor's rate or stream changes
another's noise. ``docs/estimation.md``, "The flight-software loop".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_non_negative, require_positive
from tumble.kernels.spacecraft import flight_software as _kernel
from tumble.kernels.spacecraft._base import Program

__all__ = ["FlightSoftware", "Sampling"]

#: The sensors of the flight software, in the order of their clocks.
SENSORS = _kernel.SENSORS

#: Seeds are held in the float64 state: whole numbers below 2⁵³.
MAX_SEED = 2**53


@dataclass(frozen=True)
class Sampling:
    """When a sensor reads: at ``t₀ + m·period`` (``t₀`` the run's start), its reading out ``latency`` later.

    period : s, > 0, a whole number of integration steps; None: the spacecraft's ``control_period``
    latency : s, ≥ 0 and shorter than the period (one reading in flight at a time)
    stream : the number of the sensor's own noise stream (a whole number in [0, 2⁵³)); None: the sensor's
        place in :data:`SENSORS`. Two sensors of one flight software need two streams.
    """

    period: float | None = None
    latency: float = 0.0
    stream: int | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        if self.period is not None:
            set_(self, "period", require_positive(self.period, "period"))
        set_(self, "latency", require_non_negative(self.latency, "latency"))
        if self.period is not None and self.latency >= self.period:
            raise ValidationError(f"latency: must be shorter than the period {self.period} s (one reading in "
                                  f"flight at a time), got {self.latency} s")
        if self.stream is not None:
            check_seed(self.stream, "stream")


@dataclass(frozen=True)
class FlightSoftware:
    """Gyro + star tracker and/or direction sensors + MEKF in the loop, the filter run at the spacecraft's
    ``control_period`` ``T``, each sensor at its own rate.

    gyro_arw : σ_v, the gyro's angle random walk, rad/√s
    gyro_rrw : σ_u, its rate random walk (bias instability), rad/s^1.5
    star_tracker_sigma : σ_st, the star tracker's noise about each body axis, rad (a number or 3), or None
    sun_sensor_sigma : a fine Sun sensor's noise (rad), or None
    magnetometer_sigma : a magnetometer's direction noise (rad; it reads the spacecraft's ``magnetic_field``),
        or None
    coarse_sun_sensor_sigma : the noise of each of six coarse (cosine) Sun sensor heads on the body's faces
        ±x, ±y, ±z (of full scale 1), or None
    sun_direction : the Sun's direction (3, inertial axes, normalised here) the Sun sensors see, or None: the
        spacecraft's ``environment`` (the Sun's direction and the eclipses along the orbit). A Sun sensor gives
        no reading while less than half the Sun is seen.
    gyro_sampling, star_tracker_sampling, sun_sensor_sampling, magnetometer_sampling,
    coarse_sun_sensor_sampling : each sensor's :class:`Sampling` (default: at the control period, no
        latency). The direction sensors read at gyro sample times: their periods are whole numbers of the
        gyro's.
    attitude_sigma0, bias_sigma0 : the filter's initial 1σ uncertainty of the attitude (rad) and the bias (rad/s)
    delay : the computation delay in control periods, a number in [0, 1]: the command computed at ``t_k`` acts
        from ``t_k + delay·T`` exactly, the steps ending there (the one before it until then; zero before the
        first one is out)
    sensor_noise : False: the sensors read the truth exactly (the filter keeps its noise model)
    seed : the default of ``sensor_seed0`` (each run's noise seed, a whole number in [0, 2⁵³)), the same for
        every run of a batch: give ``sensor_seed0`` one per run for a Monte-Carlo over the noise

    The filter models the sensors as they are (the same σ of each). The initial estimate is
    ``q_estimate0`` (default ``q0``) and ``bias_estimate0`` (default 0); the gyro's true bias starts at
    ``gyro_bias0`` (default 0) and walks with σ_u.
    """

    gyro_arw: float
    gyro_rrw: float
    star_tracker_sigma: float | np.ndarray | None = None
    sun_sensor_sigma: float | None = None
    sun_direction: np.ndarray | None = None
    magnetometer_sigma: float | None = None
    coarse_sun_sensor_sigma: float | None = None
    gyro_sampling: Sampling = Sampling()
    star_tracker_sampling: Sampling = Sampling()
    sun_sensor_sampling: Sampling = Sampling()
    magnetometer_sampling: Sampling = Sampling()
    coarse_sun_sensor_sampling: Sampling = Sampling()
    attitude_sigma0: float = 1e-2
    bias_sigma0: float = 1e-4
    delay: float = 1
    sensor_noise: bool = True
    seed: int = 0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "gyro_arw", require_non_negative(self.gyro_arw, "gyro_arw"))
        set_(self, "gyro_rrw", require_non_negative(self.gyro_rrw, "gyro_rrw"))
        if self.star_tracker_sigma is not None:
            set_(self, "star_tracker_sigma", _axes_sigma(self.star_tracker_sigma))
        for name in ("sun_sensor_sigma", "magnetometer_sigma", "coarse_sun_sensor_sigma"):
            if getattr(self, name) is not None:
                set_(self, name, require_positive(getattr(self, name), name))
        if self.sun_direction is not None and not self.sees_the_sun:
            raise ValidationError("sun_direction: give it with a Sun sensor (sun_sensor_sigma, "
                                  "coarse_sun_sensor_sigma), or not at all")
        if self.sun_direction is not None:
            sun = as_array(self.sun_direction, "sun_direction")
            if sun.shape != (3,) or not np.any(sun):
                raise ValidationError(f"sun_direction: must be 3 numbers, not all zero (inertial axes), got "
                                      f"{self.sun_direction!r}")
            sun = sun / np.linalg.norm(sun)
            sun.setflags(write=False)
            set_(self, "sun_direction", sun)
        if self.sensors == ("gyro",):
            raise ValidationError("star_tracker_sigma: the filter needs an attitude sensor: a star tracker, a Sun "
                                  "sensor or a magnetometer")
        for sensor in SENSORS:
            sampling = getattr(self, f"{sensor}_sampling")
            if not isinstance(sampling, Sampling):
                raise ValidationError(f"{sensor}_sampling: must be a Sampling, got {type(sampling).__name__}")
        streams = [self._stream(sensor) for sensor in SENSORS]
        if len(set(streams)) < len(streams):
            raise ValidationError(f"stream: each sensor needs its own noise stream, got {streams} for {SENSORS}")
        set_(self, "attitude_sigma0", require_positive(self.attitude_sigma0, "attitude_sigma0"))
        set_(self, "bias_sigma0", require_positive(self.bias_sigma0, "bias_sigma0"))
        if isinstance(self.delay, (bool, np.bool_)) or not 0.0 <= require_non_negative(self.delay, "delay") <= 1.0:
            raise ValidationError(f"delay: must be a number in [0, 1] (control periods), got {self.delay!r}")
        set_(self, "delay", float(self.delay))
        if not isinstance(self.sensor_noise, (bool, np.bool_)):
            raise ValidationError(f"sensor_noise: must be True or False, got {self.sensor_noise!r}")
        check_seed(self.seed, "seed")

    @property
    def sensors(self) -> tuple[str, ...]:
        """The sensors present, of :data:`SENSORS` (the gyro always)."""
        sigma = {"gyro": self.gyro_arw, "star_tracker": self.star_tracker_sigma, "sun_sensor": self.sun_sensor_sigma,
                 "magnetometer": self.magnetometer_sigma, "coarse_sun_sensor": self.coarse_sun_sensor_sigma}
        return tuple(sensor for sensor in SENSORS if sigma[sensor] is not None)

    @property
    def sees_the_sun(self) -> bool:
        """True with a Sun sensor, fine or coarse."""
        return self.sun_sensor_sigma is not None or self.coarse_sun_sensor_sigma is not None

    def _stream(self, sensor: str) -> int:
        stream = getattr(self, f"{sensor}_sampling").stream
        return SENSORS.index(sensor) if stream is None else int(stream)

    def clocks(self, control_period: float) -> np.ndarray:
        """(5, 3): period (s; 0 for a sensor absent), latency (s) and stream number of each of :data:`SENSORS`,
        a period of None being ``control_period``."""
        rows = []
        for sensor in SENSORS:
            sampling = getattr(self, f"{sensor}_sampling")
            period = control_period if sampling.period is None else sampling.period
            rows.append([period if sensor in self.sensors else 0.0, sampling.latency, self._stream(sensor)])
        return np.array(rows, dtype=np.float64)

    def check_clocks(self, control_period: float) -> None:
        """Each sensor's latency shorter than its period, the direction sensors' periods whole numbers of the
        gyro's (their readings fall on its samples), else a ValidationError naming the sensor's sampling."""
        clocks = self.clocks(control_period)
        gyro = clocks[0, 0]
        for sensor, (period, latency, _) in zip(SENSORS, clocks):
            if period == 0.0:
                continue
            name = f"{sensor}_sampling"
            if latency >= period:
                raise ValidationError(f"{name}: the latency {latency} s must be shorter than the period {period} s "
                                      "(one reading in flight at a time)")
            ratio = period / gyro
            if abs(ratio - round(ratio)) > 1e-9 * ratio:
                raise ValidationError(f"{name}: the period {period} s must be a whole number of the gyro's period "
                                      f"{gyro} s (the filter propagates to each reading with the gyro's)")

    @property
    def covariance0(self) -> np.ndarray:
        """The filter's initial covariance of ``[δθ, δβ]``: diag(σ_θ² I, σ_β² I) (rad², rad²/s²)."""
        return np.diag(np.repeat([self.attitude_sigma0**2, self.bias_sigma0**2], 3))

    def _program(self, control_period: float) -> Program:
        tracker = self.star_tracker_sigma is not None
        return _kernel.program(self.gyro_arw, self.gyro_rrw, self.star_tracker_sigma if tracker else np.ones(3),
                               self.delay, bool(self.sensor_noise), self.sun_sensor_sigma or 0.0,
                               self.sun_direction if self.sun_direction is not None else np.zeros(3),
                               self.magnetometer_sigma or 0.0, self.coarse_sun_sensor_sigma or 0.0,
                               self.clocks(control_period))


def _axes_sigma(value) -> np.ndarray:
    """σ about each body axis: a number or 3 numbers > 0 (rad), as (3,), else a ValidationError."""
    sigma = as_array(value, "star_tracker_sigma")
    if sigma.shape not in ((), (1,), (3,)) or np.any(sigma <= 0.0):
        raise ValidationError(f"star_tracker_sigma: must be a number or 3 numbers > 0 (rad), got {value!r}")
    sigma = np.broadcast_to(sigma, (3,)).copy()
    sigma.setflags(write=False)
    return sigma


def check_seed(seed: ArrayLike, name: str) -> np.ndarray:
    """``seed`` (a number or an array) as float64, each a whole number in [0, 2⁵³), else a ValidationError."""
    values = as_array(seed, name)
    if np.any(values != np.floor(values)) or np.any(values < 0) or np.any(values >= MAX_SEED):
        raise ValidationError(f"{name}: must be whole numbers in [0, 2**53), got {seed!r}")
    return values


def initial_state(fsw: FlightSoftware, values: dict[str, np.ndarray], y0: np.ndarray, s: int, t0: float) -> None:
    """Write the flight software's initial state (estimate, covariance, true gyro bias, seed; the filter at
    ``t0``, s) into the rows of ``y0`` (N, size) at its state offset ``s``; ``values`` holds the state fields,
    each (N, size)."""
    for offset, name in ((_kernel.Q_EST, "q_estimate0"), (_kernel.BIAS_EST, "bias_estimate0"),
                         (_kernel.GYRO_BIAS, "gyro_bias0"), (_kernel.SEED, "sensor_seed0")):
        y0[:, s + offset:s + offset + values[name].shape[-1]] = values[name]
    _kernel.initial_state(y0, s, t0, values["q0"], fsw.covariance0)
