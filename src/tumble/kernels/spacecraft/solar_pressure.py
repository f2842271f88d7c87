"""Solar radiation pressure on the spacecraft's facets, in the sunlight of the environment table.

The pressure at the craft (Montenbruck & Gill 2000, §3.4)::

    P = ν Φ/c (AU/|s|)²

with ``Φ = 1361 W/m²`` the total solar irradiance at 1 au (Kopp & Lean,
*Geophys. Res. Lett.* 38, L01706, 2011), ``c`` the speed of light, ``|s|``
the distance to the Sun and ``ν`` the fraction of the solar disc seen (the
table's ``sun_distance`` and ``shadow``); the Sun's direction is the table's,
turned into body axes by ``q``. Facet forces and torque:
:mod:`tumble.kernels.spacecraft.facets`. Diagnostics: ``τ`` (3), N·m, body axes.
"""

import numpy as np
from numba import njit

from tumble import _quat
from tumble.kernels.spacecraft import environment_table as table
from tumble.kernels.spacecraft import facets
from tumble.kernels.spacecraft._base import Actuator, Lane, Program

#: The astronomical unit, m (IAU 2012 Resolution B2).
AU = 149597870700.0
#: The speed of light, m/s.
LIGHT_SPEED = 299792458.0

PRESSURE = 0     # Φ/c at 1 au, N/m²
HEAD = 1         # then the facets (count × facets.STRIDE)
AUX_TORQUE = facets.AUX_TORQUE   # τ (3), N·m, body axes


def program(irradiance: float, facet_block: np.ndarray, count: int) -> Program:
    """The part's program: the irradiance at 1 au ``Φ`` (W/m²) and the facets' rows."""
    return Program("solar_pressure", np.concatenate([[irradiance / LIGHT_SPEED], facet_block]), count=count, aux=3)


def aux_slices(n: int, a: int) -> dict[str, slice]:
    return {"solar_pressure_torque": slice(a + AUX_TORQUE, a + AUX_TORQUE + 3)}


@njit(cache=True)
def torque(d, p, n, tp, t, qw, qx, qy, qz):
    """``τ`` (N·m, body axes) of the part at ``d[p:]`` (``n`` facets) in the sunlight of the table part at
    ``d[tp:]`` at ``t``, attitude ``q`` (a function of its own: see :func:`.environment_table.field_body`)."""
    row, f = table.interval(d, tp, t)
    distance = table.linear(d, row, f, table.SUN_DISTANCE)
    pressure = table.linear(d, row, f, table.SHADOW) * d[p + PRESSURE] * (AU / distance) ** 2
    s1, s2, s3 = table.direction(d, row, f, table.SUN_DIRECTION)
    s1, s2, s3 = _quat.qrotate_inv(qw, qx, qy, qz, s1, s2, s3)
    return facets.radiation_torque(d, p + HEAD, n, pressure, s1, s2, s3)


def kernel(lane: Lane) -> Actuator:
    """The :class:`~tumble.kernels.spacecraft._base.Actuator` of the facets in sunlight (an external torque)."""
    return facets.actuator(lane, torque)
