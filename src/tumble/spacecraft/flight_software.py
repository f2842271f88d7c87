"""The flight-software loop: a gyro, a star tracker and direction sensors (a fine Sun sensor, a magnetometer)
read at the control period, the MEKF, and the control law fed the estimate instead of the truth
(:mod:`tumble.kernels.spacecraft.flight_software`).

The estimator is :func:`tumble.estimation.mekf`'s compiled step; the sensors are
the MEKF's own models (gyro angle and rate random walks, star-tracker noise in
body axes, direction noise across the direction), their noise drawn from a counter-based generator keyed by the seed
of each run (``sensor_seed0``), so that a run is reproducible per seed and a
batch of seeds is a Monte-Carlo over sensor noise. ``docs/estimation.md``,
"The flight-software loop".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_non_negative, require_positive
from tumble.kernels.spacecraft import flight_software as _kernel
from tumble.kernels.spacecraft._base import Program

__all__ = ["FlightSoftware"]

#: Seeds are held in the float64 state: whole numbers below 2⁵³.
MAX_SEED = 2**53


@dataclass(frozen=True)
class FlightSoftware:
    """Gyro + star tracker and/or direction sensors + MEKF in the loop, sampled at the spacecraft's
    ``control_period`` ``T``.

    gyro_arw : σ_v, the gyro's angle random walk, rad/√s
    gyro_rrw : σ_u, its rate random walk (bias instability), rad/s^1.5
    star_tracker_sigma : σ_st, the star tracker's noise about each body axis, rad (a number or 3), or None
    star_tracker_every : the star tracker reads every n-th sample (n ≥ 1; its rate is 1/(n T))
    sun_sensor_sigma, sun_direction : a fine Sun sensor's noise (rad) and the Sun's direction (3, inertial
        axes, normalised here), or None
    magnetometer_sigma : a magnetometer's direction noise (rad; it reads the spacecraft's ``magnetic_field``),
        or None
    attitude_sigma0, bias_sigma0 : the filter's initial 1σ uncertainty of the attitude (rad) and the bias (rad/s)
    delay : the computation delay in control periods, 0 or 1: the command computed at ``t_k`` acts from
        ``t_k + delay·T`` (zero before the first one is out)
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
    star_tracker_every: int = 1
    sun_sensor_sigma: float | None = None
    sun_direction: np.ndarray | None = None
    magnetometer_sigma: float | None = None
    attitude_sigma0: float = 1e-2
    bias_sigma0: float = 1e-4
    delay: int = 1
    sensor_noise: bool = True
    seed: int = 0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "gyro_arw", require_non_negative(self.gyro_arw, "gyro_arw"))
        set_(self, "gyro_rrw", require_non_negative(self.gyro_rrw, "gyro_rrw"))
        if self.star_tracker_sigma is not None:
            set_(self, "star_tracker_sigma", _axes_sigma(self.star_tracker_sigma))
        if not isinstance(self.star_tracker_every, (int, np.integer)) or self.star_tracker_every < 1:
            raise ValidationError(f"star_tracker_every: must be a whole number ≥ 1 (samples), got "
                                  f"{self.star_tracker_every!r}")
        for name in ("sun_sensor_sigma", "magnetometer_sigma"):
            if getattr(self, name) is not None:
                set_(self, name, require_positive(getattr(self, name), name))
        if (self.sun_sensor_sigma is None) != (self.sun_direction is None):
            raise ValidationError("sun_direction: give it with sun_sensor_sigma (the fine Sun sensor), or neither")
        if self.sun_direction is not None:
            sun = as_array(self.sun_direction, "sun_direction")
            if sun.shape != (3,) or not np.any(sun):
                raise ValidationError(f"sun_direction: must be 3 numbers, not all zero (inertial axes), got "
                                      f"{self.sun_direction!r}")
            sun = sun / np.linalg.norm(sun)
            sun.setflags(write=False)
            set_(self, "sun_direction", sun)
        if self.star_tracker_sigma is None and self.sun_sensor_sigma is None and self.magnetometer_sigma is None:
            raise ValidationError("star_tracker_sigma: the filter needs an attitude sensor: a star tracker, a Sun "
                                  "sensor or a magnetometer")
        set_(self, "attitude_sigma0", require_positive(self.attitude_sigma0, "attitude_sigma0"))
        set_(self, "bias_sigma0", require_positive(self.bias_sigma0, "bias_sigma0"))
        if self.delay not in (0, 1) or isinstance(self.delay, bool):
            raise ValidationError(f"delay: must be 0 or 1 control period, got {self.delay!r}")
        if not isinstance(self.sensor_noise, (bool, np.bool_)):
            raise ValidationError(f"sensor_noise: must be True or False, got {self.sensor_noise!r}")
        check_seed(self.seed, "seed")

    @property
    def covariance0(self) -> np.ndarray:
        """The filter's initial covariance of ``[δθ, δβ]``: diag(σ_θ² I, σ_β² I) (rad², rad²/s²)."""
        return np.diag(np.repeat([self.attitude_sigma0**2, self.bias_sigma0**2], 3))

    def _program(self) -> Program:
        tracker = self.star_tracker_sigma is not None
        return _kernel.program(self.gyro_arw, self.gyro_rrw, self.star_tracker_sigma if tracker else np.ones(3),
                               self.star_tracker_every if tracker else 0, self.delay, bool(self.sensor_noise),
                               self.sun_sensor_sigma or 0.0,
                               self.sun_direction if self.sun_direction is not None else np.zeros(3),
                               self.magnetometer_sigma or 0.0)


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


def initial_state(fsw: FlightSoftware, values: dict[str, np.ndarray], y0: np.ndarray, s: int) -> None:
    """Write the flight software's initial state (estimate, covariance, true gyro bias, seed) into the rows of
    ``y0`` (N, size) at its state offset ``s``; ``values`` holds the state fields, each (N, size)."""
    for offset, name in ((_kernel.Q_EST, "q_estimate0"), (_kernel.BIAS_EST, "bias_estimate0"),
                         (_kernel.GYRO_BIAS, "gyro_bias0"), (_kernel.SEED, "sensor_seed0")):
        y0[:, s + offset:s + offset + values[name].shape[-1]] = values[name]
    y0[:, s + _kernel.COVARIANCE:s + _kernel.COVARIANCE + 36] = fsw.covariance0.ravel()
