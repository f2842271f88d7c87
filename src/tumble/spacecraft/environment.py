"""The space environment of an Earth-orbiting spacecraft: gravity gradient and the geomagnetic field.

Gravity gradient (:func:`gravity_gradient_torque`, compiled; as a torque model
:class:`tumble.torques.GravityGradient`)::

    τ_B = (3 μ / |r|⁵) r_B × (I r_B)      r_B: position in body axes, m

Tilted-dipole geomagnetic field (:func:`dipole_field`, compiled, in
:mod:`tumble.kernels.spacecraft.environment`; :class:`DipoleField`),
in inertial axes, tesla::

    B(r) = B₀ (a/|r|)³ [3 (m̂·r̂) r̂ − m̂]

``m̂`` is the unit dipole moment, fixed in the Earth: it points from the
north geomagnetic pole (colatitude ``tilt``, east ``longitude``) to the
south one, and turns with the Earth about the inertial z axis at
``earth_rate``; the Earth-fixed x axis (Greenwich) is at ``greenwich_angle``
from the inertial x axis at ``t = 0``. At the magnetic equator ``|B| = B₀
(a/r)³``, at the magnetic poles ``2 B₀ (a/r)³``. (Wertz (ed.), *Spacecraft Attitude
Determination and Control*, ch. 5 and appendix H; Markley & Crassidis,
*Fundamentals of Spacecraft Attitude Determination and Control*, ch. 3.)

A residual magnetic dipole ``m`` (A·m², fixed in the body; :class:`ResidualDipole`)
feels ``τ = m × B`` in the body-axes field ``B`` (Wertz, §17.2).

Default numbers: the dipole (degree-1) terms of IGRF-13 at epoch 2020.0
(Alken et al., "International Geomagnetic Reference Field: the thirteenth
generation", Earth Planets Space 73:49, 2021), ``g₁⁰ = −29404.8 nT``,
``g₁¹ = −1450.9 nT``, ``h₁¹ = 4652.5 nT``, reference radius ``a = 6371.2 km``:
``B₀ = √(g₁⁰² + g₁¹² + h₁¹²) = 29805.9 nT``, north geomagnetic pole at
colatitude ``θ = arccos(−g₁⁰/B₀) = 9.41°`` (80.59° N) and east longitude
``φ = atan2(−h₁¹, −g₁¹) = −72.68°`` (72.68° W). Earth rate 7.2921159e-5 rad/s
(IERS/WGS 84).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from tumble._gravity import gravity_gradient_torque
from tumble._validate import ValidationError, as_array, require_finite, require_positive
from tumble.kernels.spacecraft import residual_dipole as _residual_dipole
from tumble.kernels.spacecraft._base import Program
from tumble.kernels.spacecraft.environment import dipole_field

__all__ = ["DipoleField", "IGRF2020_DIPOLE", "ResidualDipole", "dipole_field", "gravity_gradient_torque"]

#: IGRF-13 degree-1 Gauss coefficients at epoch 2020.0, nT: (g₁⁰, g₁¹, h₁¹) (Alken et al. 2021).
IGRF2020_DIPOLE = (-29404.8, -1450.9, 4652.5)
#: IGRF reference radius, m.
IGRF_RADIUS = 6371.2e3
#: Earth rotation rate relative to inertial space, rad/s (WGS 84).
EARTH_RATE = 7.2921159e-5


def _igrf_dipole():
    g10, g11, h11 = (1e-9 * c for c in IGRF2020_DIPOLE)
    b0 = math.sqrt(g10 * g10 + g11 * g11 + h11 * h11)
    return b0, math.acos(-g10 / b0), math.atan2(-h11, -g11)


_B0, _TILT, _LONGITUDE = _igrf_dipole()


@dataclass(frozen=True)
class DipoleField:
    """A tilted dipole fixed in the rotating Earth (see the module docstring; default: IGRF-13, 2020.0).

    strength        : B₀, field at the magnetic equator at ``radius``, T (> 0)
    tilt            : colatitude of the north geomagnetic pole, rad, in [0, π]
    longitude       : east longitude of the north geomagnetic pole, rad
    earth_rate      : rotation rate of the Earth about inertial z, rad/s
    greenwich_angle : angle of the Earth-fixed x axis from inertial x at t = 0, rad
    radius          : reference radius a, m (> 0)
    """

    strength: float = _B0
    tilt: float = _TILT
    longitude: float = _LONGITUDE
    earth_rate: float = EARTH_RATE
    greenwich_angle: float = 0.0
    radius: float = IGRF_RADIUS

    def __post_init__(self):
        for name in ("strength", "radius"):
            object.__setattr__(self, name, require_positive(getattr(self, name), name))
        for name in ("tilt", "longitude", "earth_rate", "greenwich_angle"):
            value = float(getattr(self, name))
            require_finite(np.asarray(value), name)
            object.__setattr__(self, name, value)
        if not 0.0 <= self.tilt <= math.pi:
            raise ValidationError(f"tilt: must be in [0, π] rad (a colatitude), got {self.tilt}")

    def moment_direction(self) -> np.ndarray:
        """Unit dipole moment ``m̂`` in Earth-fixed axes: from the north geomagnetic pole to the south one."""
        st = math.sin(self.tilt)
        return -np.array([st * math.cos(self.longitude), st * math.sin(self.longitude), math.cos(self.tilt)])

    def params(self) -> np.ndarray:
        """``[B₀ a³, m̂ₓ, m̂_y, m̂_z, earth_rate, greenwich_angle]`` (T·m³, Earth-fixed unit vector, rad/s,
        rad): the argument of :func:`dipole_field`."""
        return np.concatenate([[self.strength * self.radius**3], self.moment_direction(),
                               [self.earth_rate, self.greenwich_angle]])

    def field(self, t: ArrayLike, r: ArrayLike) -> np.ndarray:
        """Field (…, 3), T, inertial axes, at the times ``t`` (s) and inertial positions ``r`` (…, 3), m
        (broadcast together)."""
        t = as_array(t, "t")
        r = as_array(r, "r", tail=(3,))
        if np.any(np.linalg.norm(r, axis=-1) == 0.0):
            raise ValidationError("r: the dipole field is singular at r = 0")
        t, _ = np.broadcast_arrays(t, r[..., 0])
        r = np.broadcast_to(r, (*t.shape, 3))
        out = np.empty((t.size, 3))
        _fields(t.ravel(), np.ascontiguousarray(r.reshape(-1, 3)), self.params(), out)
        return out.reshape((*t.shape, 3))


@njit(cache=True)
def _fields(t, r, params, out):
    for k in range(t.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = dipole_field(t[k], r[k, 0], r[k, 1], r[k, 2], params)


@dataclass(frozen=True)
class ResidualDipole:
    """A residual magnetic dipole fixed in the body: torque ``τ = m × B`` (N·m, body axes) in the spacecraft's
    ``magnetic_field`` ``B`` (T, body axes); :mod:`tumble.kernels.spacecraft.residual_dipole`.

    dipole : m, (3,) A·m², body axes
    """

    dipole: np.ndarray

    def __post_init__(self):
        m = as_array(self.dipole, "dipole")
        if m.shape != (3,):
            raise ValidationError(f"dipole: must be 3 numbers (A·m², body axes), got shape {m.shape}")
        m.setflags(write=False)
        object.__setattr__(self, "dipole", m)

    def _program(self) -> Program:
        return _residual_dipole.program(self.dipole)
