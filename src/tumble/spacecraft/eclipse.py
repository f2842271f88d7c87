"""The Earth's shadow: the fraction ν of the solar disc a spacecraft sees (1 in sunlight, 0 in umbra).

Conical model (Montenbruck & Gill, *Satellite Orbits*, Springer 2000, §3.4.2),
with ``r`` the craft's geocentric position and ``s = r_☉ − r`` the vector from
the craft to the Sun: the apparent radii of the Sun and the Earth and their
apparent separation are::

    a = arcsin(R_☉/|s|),   b = arcsin(R_⊕/|r|),   c = arccos(−r·s / (|r| |s|))

    c ≥ a + b          ν = 1                         (sunlight)
    c ≤ b − a          ν = 0                         (umbra)
    c < a − b          ν = 1 − b²/a²                 (antumbra: the Earth inside the Sun's disc)
    otherwise          ν = 1 − A/(π a²),             (penumbra: two overlapping discs)
                       A = a² arccos(x/a) + b² arccos((c − x)/b) − c y,
                       x = (c² + a² − b²)/(2c),  y = √(a² − x²)

Cylindrical model (the shadow a cylinder of radius R_⊕ behind the Earth)::

    ν = 0  if  r·ŝ < 0  and  |r − (r·ŝ) ŝ| < R_⊕,   else 1      (ŝ = s/|s|)

The Earth is a sphere of the WGS 84 equatorial radius and its atmosphere is
left out (it bends and dims sunlight a few tens of km above the limb); the
Sun is a uniform disc (no limb darkening) of the IAU 2015 nominal radius.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array
from tumble.spacecraft.orbit import EARTH_RADIUS

__all__ = ["SHADOW_MODELS", "SUN_RADIUS", "shadow_fraction"]

#: Nominal solar radius, m (IAU 2015 Resolution B3).
SUN_RADIUS = 695700e3
#: The shadow models :func:`shadow_fraction` knows.
SHADOW_MODELS = ("conical", "cylindrical")


def shadow_fraction(r: ArrayLike, r_sun: ArrayLike, model: str = "conical") -> np.ndarray:
    """Fraction ν (…,) of the solar disc seen from the geocentric positions ``r`` (…, 3), m, with the
    Sun at the geocentric ``r_sun`` (…, 3), m (same inertial axes; broadcast together): the module
    docstring gives both models."""
    if model not in SHADOW_MODELS:
        raise ValidationError(f"shadow: must be one of {', '.join(SHADOW_MODELS)}, got {model!r}")
    r = as_array(r, "r", tail=(3,))
    s = as_array(r_sun, "r_sun", tail=(3,)) - r
    r_norm = np.linalg.norm(r, axis=-1)
    s_norm = np.linalg.norm(s, axis=-1)
    if np.any(r_norm <= EARTH_RADIUS):
        raise ValidationError(f"r: must lie outside the Earth (|r| > {EARTH_RADIUS} m)")
    along = np.einsum("...i,...i->...", r, s) / s_norm
    if model == "cylindrical":
        across = np.sqrt(np.maximum(r_norm**2 - along**2, 0.0))
        return np.where((along < 0.0) & (across < EARTH_RADIUS), 0.0, 1.0)
    a = np.arcsin(SUN_RADIUS / s_norm)
    b = np.arcsin(EARTH_RADIUS / r_norm)
    c = np.arccos(np.clip(-along / r_norm, -1.0, 1.0))
    return _overlap_visible(a, b, c)


def _overlap_visible(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """1 − (area of the Sun's disc, radius a, hidden by the Earth's, radius b, at separation c) / (π a²)."""
    a, b, c = np.broadcast_arrays(a, b, c)
    nu = np.ones(a.shape)
    nu[c <= b - a] = 0.0
    inside = c < a - b
    nu[inside] = 1.0 - (b[inside] / a[inside]) ** 2
    partial = (c < a + b) & (c > np.abs(a - b))
    a, b, c = a[partial], b[partial], c[partial]
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = np.sqrt(np.maximum(a * a - x * x, 0.0))
    hidden = a * a * np.arccos(np.clip(x / a, -1.0, 1.0)) + b * b * np.arccos(np.clip((c - x) / b, -1.0, 1.0)) - c * y
    nu[partial] = 1.0 - hidden / (np.pi * a * a)
    return nu
