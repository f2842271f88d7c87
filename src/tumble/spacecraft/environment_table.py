"""The space environment along an orbit, sampled before the attitude is integrated.

The orbit does not depend on the attitude, so the environment along it can
be computed first, with the field's libraries, and read by the compiled loop
by interpolation. :meth:`Environment.sample` builds, on a uniform time grid
from a UTC epoch, one table whose columns are (GCRS axes, SI units; the
column layout is :mod:`tumble.kernels.spacecraft.environment_table`):

=================  ==========================================================================
``position``       r: Kepler elements (:class:`~tumble.spacecraft.orbit.Orbit`, optionally with
                   the J₂ secular drift) or a TLE through SGP4 (:class:`~tumble.spacecraft.tle.TLE`,
                   TEME → GCRS), m
``velocity``       v, m/s
``sun_direction``  ŝ = s/|s|, s the astrometric vector from the craft to the Sun (JPL DE421 through
                   skyfield, light time from the craft; no aberration)
``sun_distance``   |s|, m
``shadow``         ν ∈ [0, 1], the fraction of the solar disc seen (:mod:`tumble.spacecraft.eclipse`:
                   conical, or cylindrical)
``magnetic_field`` B = R_ITRS_GCRSᵀ B_IGRF(R_ITRS_GCRS r): IGRF-14 to degree 13
                   (:mod:`tumble.spacecraft.igrf`) in the ITRS, turned to GCRS axes, T
``density``        ρ, kg/m³: NRLMSIS 2.1 (``pymsis``) at the WGS 84 geodetic latitude, longitude and
                   height, with the :class:`SpaceWeather` given (never downloaded)
``velocity_air``   v − ω⊕ × r, the velocity relative to the atmosphere turning with the Earth
                   (ω⊕ = 7.2921159e-5 rad/s about the ITRS z axis; no winds), m/s
``moon_direction`` unit vector from the craft to the Moon (DE421, astrometric as the Sun)
=================  ==========================================================================

Time ``t`` counts SI seconds from the epoch (TT-uniform); the IGRF and
NRLMSIS read UTC as ``epoch + t`` (a leap second inside the run is 1 s off).

    >>> from datetime import datetime, timezone
    >>> import numpy as np
    >>> from tumble.spacecraft import Environment, Orbit
    >>> env = Environment.sample(Orbit.circular(500e3, np.radians(97.4)),
    ...                          datetime(2026, 3, 20, tzinfo=timezone.utc), duration=5700.0)
    >>> env.shadow.min(), env.density.max() > 0
    (0.0, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timedelta

import numpy as np

from tumble._validate import ValidationError, as_array, readonly, require_non_negative, require_positive
from tumble.kernels.spacecraft import environment_table as _table
from tumble.kernels.spacecraft._base import Program
from tumble.kernels.spacecraft.environment_table import COLUMNS, WIDTH
from tumble.spacecraft import _ephemeris
from tumble.spacecraft.eclipse import SHADOW_MODELS, shadow_fraction
from tumble.spacecraft.environment import EARTH_RATE
from tumble.spacecraft.igrf import igrf_field
from tumble.spacecraft.orbit import Orbit
from tumble.spacecraft.tle import TLE

__all__ = ["Environment", "SpaceWeather"]

#: the longest default sample step, s
MAX_STEP = 10.0
#: the least number of samples per orbit of the default step
SAMPLES_PER_ORBIT = 600


@dataclass(frozen=True)
class SpaceWeather:
    """The solar and geomagnetic activity NRLMSIS reads (held constant over the run).

    f107  : F10.7 solar radio flux of the previous day, solar flux units (10⁻²² W m⁻² Hz⁻¹), > 0
    f107a : its 81-day centred average, sfu, > 0
    ap    : daily geomagnetic Ap index, in [0, 400]

    The defaults (150, 150, 15) are a moderate solar and geomagnetic activity.
    """

    f107: float = 150.0
    f107a: float = 150.0
    ap: float = 15.0

    def __post_init__(self):
        for name in ("f107", "f107a"):
            object.__setattr__(self, name, require_positive(getattr(self, name), f"space_weather.{name}"))
        ap = require_non_negative(self.ap, "space_weather.ap")
        if ap > 400.0:
            raise ValidationError(f"space_weather.ap: must be in [0, 400], got {ap}")
        object.__setattr__(self, "ap", ap)


@dataclass(frozen=True, eq=False)
class Environment:
    """The environment table along an orbit: ``t`` (n,) s from ``epoch``, ``data`` (n, 21), columns as in the
    module docstring (each also a property: ``env.position``, ``env.shadow``, ...). Build it with
    :meth:`sample`."""

    orbit: Orbit | TLE
    epoch: datetime
    t: np.ndarray
    data: np.ndarray
    shadow_model: str
    space_weather: SpaceWeather
    j2: bool

    @classmethod
    def sample(cls, orbit: Orbit | TLE, epoch: datetime | None = None, *, duration: float,
               step: float | None = None, shadow: str = "conical",
               space_weather: SpaceWeather | None = None, j2: bool = False) -> Environment:
        """Sample the environment every ``step`` seconds from ``epoch`` over ``duration`` (s, > 0).

        orbit         : an :class:`Orbit` (its elements, GCRS axes, hold at ``epoch``) or a :class:`TLE`
        epoch         : UTC datetime (naive = UTC) of ``t = 0``; for a TLE, default the TLE's epoch
        step          : s, > 0; default ``min(10 s, period/600)``
        shadow        : ``"conical"`` (umbra and penumbra) or ``"cylindrical"``
        space_weather : :class:`SpaceWeather` for NRLMSIS (default moderate activity)
        j2            : Kepler elements drift with the J₂ secular rates (:meth:`Orbit.j2_rates`)
        """
        if not isinstance(orbit, (Orbit, TLE)):
            raise ValidationError(f"orbit: must be an Orbit or a TLE, got {type(orbit).__name__}")
        if epoch is None and isinstance(orbit, TLE):
            epoch = orbit.epoch
        epoch = _ephemeris.as_utc(epoch)
        duration = require_positive(duration, "duration")
        period = orbit.period
        step = min(MAX_STEP, period / SAMPLES_PER_ORBIT) if step is None else require_positive(step, "step")
        if shadow not in SHADOW_MODELS:
            raise ValidationError(f"shadow: must be one of {', '.join(SHADOW_MODELS)}, got {shadow!r}")
        if j2 and isinstance(orbit, TLE):
            raise ValidationError("j2: applies to Kepler elements only (SGP4 has its own J₂)")
        weather = SpaceWeather() if space_weather is None else space_weather
        if not isinstance(weather, SpaceWeather):
            raise ValidationError(f"space_weather: must be a SpaceWeather, got {type(weather).__name__}")
        t = step * np.arange(math.ceil(duration / step * (1.0 - 1e-12)) + 1)
        time = _ephemeris.times(epoch, t)
        r, v = orbit.state_gcrs(epoch, t) if isinstance(orbit, TLE) else orbit.state(t, j2=j2)
        data = np.empty((len(t), WIDTH))
        _fill(data, "position", r)
        _fill(data, "velocity", v)
        to_sun, to_moon = _ephemeris.sun_and_moon_from(r, v, time)
        _fill(data, "sun_distance", np.linalg.norm(to_sun, axis=1))
        _fill(data, "sun_direction", _unit(to_sun))
        _fill(data, "moon_direction", _unit(to_moon))
        _fill(data, "shadow", shadow_fraction(r, r + to_sun, shadow))
        rot = _ephemeris.rotation_itrs_gcrs(time)                  # r_ITRS = R r_GCRS
        utc = [epoch.replace(tzinfo=None) + timedelta(seconds=float(s)) for s in t]
        b_itrs = igrf_field(np.einsum("kij,kj->ki", rot, r), utc)
        _fill(data, "magnetic_field", np.einsum("kji,kj->ki", rot, b_itrs))
        _fill(data, "velocity_air", v - np.cross(EARTH_RATE * rot[:, 2, :], r))
        _fill(data, "density", _density(r, time, utc, weather))
        return cls(orbit=orbit, epoch=epoch, t=readonly(t), data=readonly(data), shadow_model=shadow,
                   space_weather=weather, j2=bool(j2))

    def column(self, name: str) -> np.ndarray:
        """The column ``name`` (n, 3) or (n,) (a read-only view of ``data``)."""
        if name not in COLUMNS:
            raise ValidationError(f"name: must be one of {', '.join(COLUMNS)}, got {name!r}")
        first, width = COLUMNS[name]
        return self.data[:, first] if width == 1 else self.data[:, first:first + width]

    @property
    def step(self) -> float:
        """The sample step h, s."""
        return float(self.t[1] - self.t[0])

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """The table interpolated at the times ``t`` (s from the epoch, within ``[0, t[-1]]``): (…, 21) rows, by
        the compiled reader the spacecraft's parts use (:mod:`tumble.kernels.spacecraft.environment_table`:
        cubic Hermite position and velocity, the rest linear, directions normalised)."""
        times = as_array(t, "t")
        self.check_times(times.ravel())
        out = np.empty((times.size, WIDTH))
        _table.read(self._program().params, np.ascontiguousarray(times.ravel()), out)
        return out.reshape((*times.shape, WIDTH))

    def check_times(self, t: np.ndarray) -> None:
        """Refuse times outside the table, naming ``t``."""
        if t.size and (t.min() < 0.0 or t.max() > self.t[-1] * (1.0 + 1e-12)):
            raise ValidationError(f"t: must lie within the environment table, [0, {self.t[-1]}] s from its epoch, "
                                  f"got [{t.min()}, {t.max()}]")

    def _program(self) -> Program:
        return _table.program(self.step, self.data)

    position = property(lambda self: self.column("position"), doc="r (n, 3), m, GCRS")
    velocity = property(lambda self: self.column("velocity"), doc="v (n, 3), m/s, GCRS")
    sun_direction = property(lambda self: self.column("sun_direction"), doc="ŝ (n, 3), craft → Sun, GCRS")
    sun_distance = property(lambda self: self.column("sun_distance"), doc="|r_☉ − r| (n,), m")
    shadow = property(lambda self: self.column("shadow"), doc="ν (n,): fraction of the solar disc seen")
    magnetic_field = property(lambda self: self.column("magnetic_field"), doc="B (n, 3), T, GCRS (IGRF-14)")
    density = property(lambda self: self.column("density"), doc="ρ (n,), kg/m³ (NRLMSIS 2.1)")
    velocity_air = property(lambda self: self.column("velocity_air"), doc="v − ω⊕ × r (n, 3), m/s, GCRS")
    moon_direction = property(lambda self: self.column("moon_direction"), doc="craft → Moon (n, 3), GCRS")


def _fill(data: np.ndarray, name: str, values: np.ndarray) -> None:
    first, width = COLUMNS[name]
    data[:, first:first + width] = values.reshape(len(data), width)


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.linalg.norm(x, axis=1)[:, None]


def _density(r: np.ndarray, time, utc: list[datetime], weather: SpaceWeather) -> np.ndarray:
    """NRLMSIS 2.1 total mass density (kg/m³) at the GCRS positions ``r`` (n, 3)."""
    import pymsis

    lat, lon, height = _ephemeris.geodetic(r, time)
    n = len(r)
    out = pymsis.calculate(np.array(utc, dtype="datetime64[us]"), lon, lat, height / 1e3,
                           np.full(n, weather.f107), np.full(n, weather.f107a), np.full((n, 7), weather.ap),
                           version=2.1)
    return np.asarray(out[:, pymsis.Variable.MASS_DENSITY], dtype=float)
