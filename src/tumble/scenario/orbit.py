"""The one ``orbit`` table of scenario files: a Kepler orbit, :class:`tumble.spacecraft.orbit.Orbit`.

Used by every kind that needs an orbit (the ``gravity_gradient`` torque of a
rigid body, ``[spacecraft.orbit]``), with one meaning:

* the size: exactly one of ``semi_major_axis`` a (m) or ``altitude`` h (m),
  with ``a = 6378137 m + h`` (the Earth's equatorial radius, WGS 84); for the
  default eccentricity 0 this is the circular orbit of
  ``Orbit.circular(h, ...)``, for an ellipse ``h`` is the height of the
  semi-major axis, not of the perigee;
* ``eccentricity`` e (default 0) and the angles ``inclination`` i, ``raan``
  Ω, ``arg_periapsis`` ω and ``mean_anomaly`` M₀ (at t = 0), all default 0,
  passed to :class:`~tumble.spacecraft.orbit.Orbit` as they are (no folding of
  ω into M₀): in degrees, or rad with ``degrees = false``;
* ``mu`` (m³/s², default the Earth's 3.986004418e14).
"""

from __future__ import annotations

import math
from pydantic import Field, field_validator

from tumble.scenario._values import _Bool, _Number, _Positive, _Table
from tumble.spacecraft.orbit import EARTH_RADIUS, Orbit

__all__ = ["OrbitTable"]

_ANGLES = ("inclination", "raan", "arg_periapsis", "mean_anomaly")


class OrbitTable(_Table):
    """A Kepler orbit (see the module docstring): ``altitude`` (m above 6378137 m) or ``semi_major_axis``
    (m); ``eccentricity``; ``inclination``, ``raan``, ``arg_periapsis``, ``mean_anomaly`` in degrees (or rad
    with ``degrees = false``); ``mu`` (m³/s²)."""

    altitude: _Number | None = Field(None, gt=-EARTH_RADIUS)
    semi_major_axis: _Positive | None = Field(None, validate_default=True)
    eccentricity: _Number = 0.0
    inclination: _Number = 0.0
    raan: _Number = 0.0
    arg_periapsis: _Number = 0.0
    mean_anomaly: _Number = 0.0
    degrees: _Bool = True
    mu: _Positive | None = None

    @field_validator("semi_major_axis")
    @classmethod
    def _one_size(cls, semi_major_axis, info):
        if "altitude" in info.data and (info.data["altitude"] is None) == (semi_major_axis is None):
            raise ValueError(f"give exactly one of altitude (m above {EARTH_RADIUS:.0f} m) or semi_major_axis (m)")
        return semi_major_axis

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        if self.altitude is not None:  # a = R + altitude: a refusal of a is one of the altitude
            keys["semi_major_axis"] = f"{prefix}.altitude"
        return keys

    def build(self) -> Orbit:
        a = self.semi_major_axis if self.altitude is None else EARTH_RADIUS + self.altitude
        assert a is not None  # the validator gives exactly one of altitude and semi_major_axis
        angle = math.radians if self.degrees else float
        options = {} if self.mu is None else {"mu": self.mu}
        return Orbit(semi_major_axis=a, eccentricity=self.eccentricity,
                     **{name: angle(getattr(self, name)) for name in _ANGLES}, **options)
