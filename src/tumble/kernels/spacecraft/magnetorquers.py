"""Magnetorquers: three orthogonal coils along the body axes, torque ``τ = m × B``.

The dipole command ``m_c`` (A·m², body axes, from the dipole laws of
:mod:`tumble.kernels.spacecraft.laws`) is clipped per axis to
``±max_dipole``; ``B`` is the magnetic field in body axes (T). The torque is
external: it changes the spacecraft's angular momentum. Diagnostics: the
dipole after the limits (3).
"""

from __future__ import annotations

import numpy as np

from tumble._vec import clip, cross
from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

MAX_DIPOLE = 0   # (3), A·m²
AUX_DIPOLE = 0   # (3), A·m², body axes


def program(max_dipole) -> Program:
    """The magnetorquers' :class:`~tumble.kernels.spacecraft._base.Program`: limits (3,), A·m²."""
    return Program("magnetorquers", np.asarray(max_dipole, dtype=np.float64), aux=3)


def aux_slices(n: int, a: int) -> dict[str, slice]:
    return {"dipole": slice(a + AUX_DIPOLE, a + AUX_DIPOLE + 3)}


def kernel(lane: Lane) -> Actuator:
    """The magnetorquers' :class:`~tumble.kernels.spacecraft._base.Actuator` for the diagnostics access ``lane``."""
    put3 = lane.put3

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        d = model.data
        m1 = clip(cmd[3], d[p + MAX_DIPOLE])
        m2 = clip(cmd[4], d[p + MAX_DIPOLE + 1])
        m3 = clip(cmd[5], d[p + MAX_DIPOLE + 2])
        if store:
            put3(aux, a + AUX_DIPOLE, j, m1, m2, m3)
        return cross(m1, m2, m3, cmd[6], cmd[7], cmd[8])

    return Actuator(act)
