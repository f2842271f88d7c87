"""Aerodynamic drag (and lift) on the spacecraft's facets, in the air of the environment table.

The table gives the density ``ρ`` (NRLMSIS) and the velocity relative to the
atmosphere turning with the Earth, ``v − ω⊕ × r`` (GCRS), turned into body
axes by ``q``. Facet forces and torque: :mod:`tumble.kernels.spacecraft.facets`.
Diagnostics: ``τ`` (3), N·m, body axes.
"""

import numpy as np
from numba import njit

from tumble import _quat
from tumble.kernels.spacecraft import environment_table as table
from tumble.kernels.spacecraft import facets
from tumble.kernels.spacecraft._base import Actuator, Lane, Program

AUX_TORQUE = facets.AUX_TORQUE   # τ (3), N·m, body axes


def program(facet_block: np.ndarray, count: int) -> Program:
    """The part's program: the facets' rows."""
    return Program("drag", np.asarray(facet_block, dtype=np.float64), count=count, aux=3)


def aux_slices(n: int, a: int) -> dict[str, slice]:
    return {"drag_torque": slice(a + AUX_TORQUE, a + AUX_TORQUE + 3)}


@njit(cache=True)
def torque(d, p, n, tp, t, qw, qx, qy, qz):
    """``τ`` (N·m, body axes) of the part at ``d[p:]`` (``n`` facets) in the air of the table part at ``d[tp:]``
    at ``t``, attitude ``q`` (a function of its own: see :func:`.environment_table.field_body`)."""
    row, f = table.interval(d, tp, t)
    v1, v2, v3 = table.linear3(d, row, f, table.VELOCITY_AIR)
    v1, v2, v3 = _quat.qrotate_inv(qw, qx, qy, qz, v1, v2, v3)
    return facets.air_torque(d, p, n, table.linear(d, row, f, table.DENSITY), v1, v2, v3)


def kernel(lane: Lane) -> Actuator:
    """The :class:`~tumble.kernels.spacecraft._base.Actuator` of the facets in the air (an external torque)."""
    return facets.actuator(lane, torque)
