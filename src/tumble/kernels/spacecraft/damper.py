"""A spherical viscous nutation damper: a sphere in a concentric cavity at the centre of mass.

The sphere (moment of inertia ``J`` about any diameter, kg·m²) turns at
``ω_d`` relative to inertial space (the state, rad/s, body axes); a viscous
film couples it to the hub with the torque ``−c (ω_d − ω)`` on the sphere
(``c`` N·m·s). Its equation in body axes (the sphere is isotropic, so its
inertial derivative seen from the rotating hub adds ``ω × J ω_d``; Hughes,
*Spacecraft Attitude Dynamics*, ch. 5; ``docs/passive_stability.md``)::

    J (ω̇_d + ω × ω_d) = −c (ω_d − ω)

It carries ``J ω_d`` of the angular momentum and ``½ J |ω_d|²`` of the
energy, and exerts ``−J ω̇_d = c (ω_d − ω) + J ω × ω_d`` on the hub. Without
external torque the total momentum is fixed in inertial space and the energy
falls at ``−c |ω_d − ω|²``.
"""

from __future__ import annotations

import numpy as np

from tumble._vec import cross
from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

INERTIA = 0   # J, kg·m²
DAMPING = 1   # c, N·m·s
RATE = 0      # state: ω_d (3), rad/s, body axes


def program(inertia: float, damping: float) -> Program:
    """The damper's :class:`~tumble.kernels.spacecraft._base.Program`."""
    return Program("damper", np.array([inertia, damping], dtype=np.float64), state=3)


def state_slices(n: int, s: int) -> dict[str, slice]:
    return {"damper_omega": slice(s + RATE, s + RATE + 3)}


def kernel(lane: Lane) -> Actuator:
    """The damper's :class:`~tumble.kernels.spacecraft._base.Actuator` for the state access ``lane``."""
    at, put3 = lane.at, lane.put3

    @inline
    def momentum(model, p, n, s, y, j):
        J = model.data[p + INERTIA]
        return J * at(y, s + RATE, j), J * at(y, s + RATE + 1, j), J * at(y, s + RATE + 2, j)

    @inline
    def energy(model, p, n, s, y, j):
        d1, d2, d3 = at(y, s + RATE, j), at(y, s + RATE + 1, j), at(y, s + RATE + 2, j)
        return 0.5 * model.data[p + INERTIA] * (d1 * d1 + d2 * d2 + d3 * d3)

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        J, c = model.data[p + INERTIA], model.data[p + DAMPING]
        d1, d2, d3 = at(y, s + RATE, j), at(y, s + RATE + 1, j), at(y, s + RATE + 2, j)
        x1, x2, x3 = cross(w1, w2, w3, d1, d2, d3)
        k = c / J
        b1 = -k * (d1 - w1) - x1  # ω̇_d = −(c/J)(ω_d − ω) − ω × ω_d
        b2 = -k * (d2 - w2) - x2
        b3 = -k * (d3 - w3) - x3
        put3(out, s + RATE, j, b1, b2, b3)
        return -J * b1, -J * b2, -J * b3

    return Actuator(act, momentum, energy)
