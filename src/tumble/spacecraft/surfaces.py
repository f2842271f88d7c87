"""The spacecraft's outer surface as flat facets, and the two parts that act on them: solar radiation pressure
and aerodynamic drag, in the sunlight and the air of an :class:`~tumble.spacecraft.environment_table.Environment`.

Equations: :mod:`tumble.kernels.spacecraft.facets` (forces and torques),
:mod:`tumble.kernels.spacecraft.solar_pressure` and :mod:`tumble.kernels.spacecraft.drag`.

    >>> plate = Facet(area=2.0, normal=[1.0, 0.0, 0.0], centre=[0.1, 0.0, 0.0], specular=0.3, diffuse=0.2,
    ...               absorbed=0.5)
    >>> parts = {"solar_pressure": SolarPressure([plate]), "drag": Drag([plate])}   # Spacecraft(..., **parts)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_non_negative, require_positive
from tumble.kernels.spacecraft import drag as _drag
from tumble.kernels.spacecraft import facets as _facets
from tumble.kernels.spacecraft import solar_pressure as _solar_pressure
from tumble.kernels.spacecraft._base import Program

__all__ = ["SOLAR_IRRADIANCE", "Drag", "Facet", "SolarPressure", "box_facets"]

#: Total solar irradiance at 1 au, W/m² (Kopp & Lean 2011).
SOLAR_IRRADIANCE = 1361.0
#: How far from 1 a facet normal's length may be.
UNIT_NORMAL_TOL = 1e-9


@dataclass(frozen=True)
class Facet:
    """A flat facet of the outer surface, body axes.

    area             : A, m² (> 0)
    normal           : outward unit normal n̂ (3,): its length must be 1 to 1e-9
    centre           : centre of pressure r (3,), m, from the spacecraft's centre of mass
    absorbed, specular, diffuse : fractions of the sunlight absorbed, reflected specularly and diffusely, each in
                       [0, 1], summing to at most 1 (the rest passes through); default a black facet (1, 0, 0)
    drag_coefficient : C_D (≥ 0, default 2.2, the usual free-molecular value)
    lift_coefficient : C_L (≥ 0, default 0)
    """

    area: float
    normal: ArrayLike
    centre: ArrayLike = (0.0, 0.0, 0.0)
    absorbed: float = 1.0
    specular: float = 0.0
    diffuse: float = 0.0
    drag_coefficient: float = 2.2
    lift_coefficient: float = 0.0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "area", require_positive(self.area, "area"))
        for name in ("normal", "centre"):
            v = as_array(getattr(self, name), name)
            if v.shape != (3,):
                raise ValidationError(f"{name}: must be 3 numbers (body axes), got shape {v.shape}")
            v.setflags(write=False)
            set_(self, name, v)
        length = float(np.linalg.norm(self.normal))
        if abs(length - 1.0) > UNIT_NORMAL_TOL:
            raise ValidationError(f"normal: must be a unit vector (|n| = 1 to {UNIT_NORMAL_TOL:g}), got |n| = "
                                  f"{length:.17g}")
        for name in ("absorbed", "specular", "diffuse"):
            value = require_non_negative(getattr(self, name), name)
            if value > 1.0:
                raise ValidationError(f"{name}: must be in [0, 1] (a fraction of the sunlight), got {value}")
            set_(self, name, value)
        total = self.absorbed + self.specular + self.diffuse
        if total > 1.0 + 1e-12:
            raise ValidationError(f"absorbed + specular + diffuse: must be at most 1 (fractions of the same light), "
                                  f"got {total:.15g}")
        for name in ("drag_coefficient", "lift_coefficient"):
            set_(self, name, require_non_negative(getattr(self, name), name))


def box_facets(size: ArrayLike, *, centre_of_mass: ArrayLike = (0.0, 0.0, 0.0),
               **coefficients: float) -> list[Facet]:
    """The six facets of a box of edge lengths ``size`` (3,), m, centred at the body origin and aligned with the
    body axes, their centres of pressure measured from ``centre_of_mass`` (m, body axes); ``coefficients`` are
    :class:`Facet`'s (the same for all six)."""
    size = as_array(size, "size")
    com = as_array(centre_of_mass, "centre_of_mass")
    if size.shape != (3,) or np.any(size <= 0.0):
        raise ValidationError(f"size: must be 3 edge lengths > 0 (m), got {size}")
    faces = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            normal = np.zeros(3)
            normal[axis] = sign
            faces.append(Facet(area=float(np.prod(np.delete(size, axis))), normal=normal,
                               centre=0.5 * size[axis] * normal - com, **coefficients))
    return faces


def _facet_block(facets: Sequence[Facet], name: str) -> tuple[np.ndarray, int]:
    facets = tuple(facets)
    if not facets or not all(isinstance(f, Facet) for f in facets):
        raise ValidationError(f"{name}: must be a non-empty sequence of Facet")
    columns = [np.array([getattr(f, field) for f in facets]) for field in
               ("area", "normal", "centre", "absorbed", "specular", "diffuse", "drag_coefficient",
                "lift_coefficient")]
    return _facets.block(*columns), len(facets)


@dataclass(frozen=True)
class SolarPressure:
    """Solar radiation pressure on ``facets`` (a part of a :class:`~tumble.spacecraft.Spacecraft` with an
    ``environment``): ``P = ν Φ/c (AU/|s|)²`` on each lit facet; ``irradiance`` Φ at 1 au, W/m²."""

    facets: Sequence[Facet]
    irradiance: float = SOLAR_IRRADIANCE

    def __post_init__(self):
        object.__setattr__(self, "facets", tuple(self.facets))
        _facet_block(self.facets, "solar_pressure.facets")
        object.__setattr__(self, "irradiance", require_positive(self.irradiance, "solar_pressure.irradiance"))

    def _program(self) -> Program:
        block, count = _facet_block(self.facets, "solar_pressure.facets")
        return _solar_pressure.program(self.irradiance, block, count)


@dataclass(frozen=True)
class Drag:
    """Aerodynamic drag and lift on ``facets`` (a part of a :class:`~tumble.spacecraft.Spacecraft` with an
    ``environment``): the density and the velocity relative to the co-rotating air of the environment."""

    facets: Sequence[Facet]

    def __post_init__(self):
        object.__setattr__(self, "facets", tuple(self.facets))
        _facet_block(self.facets, "drag.facets")

    def _program(self) -> Program:
        block, count = _facet_block(self.facets, "drag.facets")
        return _drag.program(block, count)
