"""Flat facets of the spacecraft's surface: the forces of sunlight and of the air on each, and their torques.

A facet is a flat plate of area ``A`` (m²) with outward unit normal ``n̂`` and
centre of pressure ``r`` (m, from the centre of mass), body axes; it reflects
a fraction ``ρs`` of the light specularly and ``ρd`` diffusely and absorbs
``ρa`` (the rest, ``1 − ρa − ρs − ρd``, passes through and pushes nothing).
Only the side the normal points out of is lit or struck; facets shading each
other are left out, and so is the facet's own motion ``ω × r`` against the
air (``|ω × r| ≪ |v|``).

Solar radiation pressure (Montenbruck & Gill, *Satellite Orbits*, 2000, eq. 3.73;
Wertz, *Spacecraft Attitude Determination and Control*, §17.2), ``ŝ`` the unit
vector to the Sun, ``cos θ = n̂·ŝ > 0``, ``P`` the radiation pressure (N/m²)::

    F = −P A cos θ [(ρa + ρd) ŝ + 2 (ρs cos θ + ρd/3) n̂]

Aerodynamic drag and lift (free-molecular flat plate; Wertz §17.2, Vallado
§8.6.2), ``v`` the velocity relative to the air, ``v̂ = v/|v|``,
``c = n̂·v̂ > 0``, ``ρ`` the density::

    F = −½ ρ |v|² A c [C_D v̂ + C_L l̂],    l̂ = (n̂ − c v̂)/|n̂ − c v̂|

(the lift along the part of the normal across the flow; none head-on).
The torque about the centre of mass is ``τ = Σ r × F``.
"""

import math

import numpy as np

from tumble._vec import cross
from tumble.kernels.spacecraft._base import Actuator, Lane, inline
from tumble.kernels.spacecraft._layout import locator

AREA = 0           # A, m²
NORMAL = 1         # n̂ (3), body axes
CENTRE = 4         # r (3), m, body axes, from the centre of mass
ABSORBED = 7       # ρa
SPECULAR = 8       # ρs
DIFFUSE = 9        # ρd
DRAG = 10          # C_D
LIFT = 11          # C_L
STRIDE = 12


def block(area, normal, centre, absorbed, specular, diffuse, drag, lift) -> np.ndarray:
    """The facets' rows (n, :data:`STRIDE`), flattened."""
    rows = np.column_stack([area, normal, centre, absorbed, specular, diffuse, drag, lift])
    return np.ascontiguousarray(rows, dtype=np.float64).ravel()


@inline
def radiation_torque(d, o, n, pressure, s1, s2, s3):
    """``Σ r × F`` (N·m, body axes) of the ``n`` facets at ``d[o:]`` in sunlight of pressure ``pressure``
    (N/m²) from the direction ``ŝ`` (body axes)."""
    t1 = t2 = t3 = 0.0
    for i in range(n):
        f = o + i * STRIDE
        c = d[f + NORMAL] * s1 + d[f + NORMAL + 1] * s2 + d[f + NORMAL + 2] * s3
        if c > 0.0:
            k = -pressure * d[f + AREA] * c
            along_s = k * (d[f + ABSORBED] + d[f + DIFFUSE])
            along_n = k * 2.0 * (d[f + SPECULAR] * c + d[f + DIFFUSE] / 3.0)
            x1, x2, x3 = cross(d[f + CENTRE], d[f + CENTRE + 1], d[f + CENTRE + 2],
                               along_s * s1 + along_n * d[f + NORMAL], along_s * s2 + along_n * d[f + NORMAL + 1],
                               along_s * s3 + along_n * d[f + NORMAL + 2])
            t1, t2, t3 = t1 + x1, t2 + x2, t3 + x3
    return t1, t2, t3


@inline
def air_torque(d, o, n, density, v1, v2, v3):
    """``Σ r × F`` (N·m, body axes) of the ``n`` facets at ``d[o:]`` moving at ``v`` (m/s, body axes) through
    air of density ``density`` (kg/m³)."""
    t1 = t2 = t3 = 0.0
    speed = math.sqrt(v1 * v1 + v2 * v2 + v3 * v3)
    if speed == 0.0:
        return t1, t2, t3
    u1, u2, u3 = v1 / speed, v2 / speed, v3 / speed
    for i in range(n):
        f = o + i * STRIDE
        n1, n2, n3 = d[f + NORMAL], d[f + NORMAL + 1], d[f + NORMAL + 2]
        c = n1 * u1 + n2 * u2 + n3 * u3
        if c > 0.0:
            k = -0.5 * density * speed * speed * d[f + AREA] * c
            l1, l2, l3 = n1 - c * u1, n2 - c * u2, n3 - c * u3
            across = math.sqrt(l1 * l1 + l2 * l2 + l3 * l3)
            lift = k * d[f + LIFT] / across if across > 0.0 else 0.0
            drag = k * d[f + DRAG]
            x1, x2, x3 = cross(d[f + CENTRE], d[f + CENTRE + 1], d[f + CENTRE + 2],
                               drag * u1 + lift * l1, drag * u2 + lift * l2, drag * u3 + lift * l3)
            t1, t2, t3 = t1 + x1, t2 + x2, t3 + x3
    return t1, t2, t3


#: The diagnostics of a facet part: its torque τ (3), N·m, body axes.
AUX_TORQUE = 0


def actuator(lane: Lane, torque) -> Actuator:
    """The :class:`~tumble.kernels.spacecraft._base.Actuator` of a facet part (an external torque, no state):
    ``torque(d, p, n, tp, t, q) -> τ`` (N·m, body axes) of its ``n`` facets at ``d[p:]`` in the environment of
    the table part at ``d[tp:]``, stored as its diagnostics (:data:`AUX_TORQUE`)."""
    at, put3 = lane.at, lane.put3
    _, where_table = locator("environment_table")

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        tp, _, _, _ = where_table(model)
        t1, t2, t3 = torque(model.data, p, n, tp, t, at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j))
        if store:
            put3(aux, a + AUX_TORQUE, j, t1, t2, t3)
        return t1, t2, t3

    return Actuator(act)
