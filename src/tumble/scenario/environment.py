"""The environment tables of a spacecraft scenario: ``[spacecraft.environment]`` (the environment sampled along
an orbit, :class:`tumble.spacecraft.Environment`), ``[spacecraft.solar_pressure]`` and ``[spacecraft.drag]``
(facets, :mod:`tumble.spacecraft.surfaces`)::

    [spacecraft.environment]
    epoch = 2026-03-20T12:00:00Z        # UTC (a TOML date-time; without an offset taken as UTC)
    duration = 6000.0                   # s sampled from the epoch: at least the run's stop time
    step = 10.0                         # s (default min(10 s, period/600))
    shadow = "conical"                  # or "cylindrical"
    j2 = false                          # Kepler elements drift with the J2 secular rates
    space_weather = { f107 = 150.0, f107a = 150.0, ap = 15.0 }
    orbit = { altitude = 500e3, inclination = 97.4 }     # the orbit table, or
    # tle = ["1 25544U ...", "2 25544 ..."]              # a two-line element set (then epoch defaults to its own)

    [spacecraft.solar_pressure]
    box = { size = [1.0, 1.0, 2.0], centre_of_mass = [0.0, 0.0, 0.05] }   # six facets of a box, or
    # facets = [{ area = 2.0, normal = [1, 0, 0], centre = [0.5, 0, 0] }, ...]
    absorbed = 0.6                      # the coefficients of a box's facets
    specular = 0.3
    diffuse = 0.1

    [spacecraft.drag]
    box = { size = [1.0, 1.0, 2.0], centre_of_mass = [0.0, 0.0, 0.05] }
    drag_coefficient = 2.2
"""

from __future__ import annotations

from datetime import datetime
from typing import Annotated, Literal

from pydantic import Field, model_validator

from tumble.scenario._values import _Bool, _Number, _Positive, _Table, _Text, _Vector
from tumble.scenario.orbit import OrbitTable
from tumble.spacecraft.environment_table import Environment, SpaceWeather
from tumble.spacecraft.surfaces import Drag, Facet, SolarPressure, box_facets
from tumble.spacecraft.tle import TLE

__all__ = ["DragTable", "EnvironmentTable", "SolarPressureTable"]

_Fraction = Annotated[_Number, Field(ge=0.0, le=1.0)]
_NonNegative = Annotated[_Number, Field(ge=0.0)]


class SpaceWeatherTable(_Table):
    f107: _Positive = 150.0
    f107a: _Positive = 150.0
    ap: Annotated[_Number, Field(ge=0.0, le=400.0)] = 15.0

    def build(self) -> SpaceWeather:
        return SpaceWeather(**self.model_dump())


class EnvironmentTable(_Table):
    """``[spacecraft.environment]``: see the module docstring."""

    epoch: datetime | None = None
    duration: _Positive
    step: _Positive | None = None
    shadow: Literal["conical", "cylindrical"] = "conical"
    j2: _Bool = False
    space_weather: SpaceWeatherTable = SpaceWeatherTable()
    orbit: OrbitTable | None = None
    tle: Annotated[list[_Text], Field(min_length=2, max_length=2)] | None = None

    @model_validator(mode="after")
    def _one_orbit(self):
        if (self.orbit is None) == (self.tle is None):
            raise ValueError("give exactly one of orbit (a Kepler orbit table) or tle (its two lines)")
        if self.tle is None and self.epoch is None:
            raise ValueError("epoch: a Kepler orbit needs the UTC epoch of its elements")
        return self

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        keys.update({"tle.line1": f"{prefix}.tle[0]", "tle.line2": f"{prefix}.tle[1]",
                     **{f"space_weather.{k}": f"{prefix}.space_weather.{k}" for k in ("f107", "f107a", "ap")}})
        return keys

    def build(self) -> Environment:
        orbit = TLE(*self.tle) if self.tle is not None else self.orbit.build()    # type: ignore[union-attr]
        return Environment.sample(orbit, self.epoch, duration=self.duration, step=self.step, shadow=self.shadow,
                                  space_weather=self.space_weather.build(), j2=self.j2)


class FacetTable(_Table):
    """One facet: ``area`` (m²), ``normal`` (unit, body axes), ``centre`` (m from the centre of mass) and the
    coefficients of :class:`tumble.spacecraft.surfaces.Facet`."""

    area: _Positive
    normal: _Vector
    centre: _Vector = [0.0, 0.0, 0.0]
    absorbed: _Fraction = 1.0
    specular: _Fraction = 0.0
    diffuse: _Fraction = 0.0
    drag_coefficient: _NonNegative = 2.2
    lift_coefficient: _NonNegative = 0.0

    def build(self) -> Facet:
        return Facet(**self.model_dump())


class BoxTable(_Table):
    """A box of edge lengths ``size`` (m) centred at the body origin, ``centre_of_mass`` (m, body axes)."""

    size: _Vector
    centre_of_mass: _Vector = [0.0, 0.0, 0.0]


class _SurfaceTable(_Table):
    """``facets`` (a list of facet tables) or ``box`` (six facets with this table's coefficients)."""

    facets: list[FacetTable] = []
    box: BoxTable | None = None
    absorbed: _Fraction = 1.0
    specular: _Fraction = 0.0
    diffuse: _Fraction = 0.0
    drag_coefficient: _NonNegative = 2.2
    lift_coefficient: _NonNegative = 0.0

    @model_validator(mode="after")
    def _one_surface(self):
        if bool(self.facets) == (self.box is not None):
            raise ValueError("give exactly one of facets (a list of facet tables) or box")
        return self

    def facet_list(self) -> list[Facet]:
        if self.box is None:
            return [facet.build() for facet in self.facets]
        coefficients = self.model_dump(include={"absorbed", "specular", "diffuse", "drag_coefficient",
                                                "lift_coefficient"})
        return box_facets(self.box.size, centre_of_mass=self.box.centre_of_mass, **coefficients)


class SolarPressureTable(_SurfaceTable):
    """``[spacecraft.solar_pressure]``: facets or a box, and ``irradiance`` at 1 au (W/m², default 1361)."""

    irradiance: _Positive = 1361.0

    def build(self) -> SolarPressure:
        return SolarPressure(self.facet_list(), irradiance=self.irradiance)


class DragTable(_SurfaceTable):
    """``[spacecraft.drag]``: facets or a box."""

    def build(self) -> Drag:
        return Drag(self.facet_list())
