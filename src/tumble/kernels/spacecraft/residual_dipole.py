"""A residual magnetic dipole: a constant dipole fixed in the body, turned by the magnetic field.

Currents in the spacecraft's wiring, magnetised parts and the like leave a
dipole ``m`` (A·m², body axes) that no controller commands. In the field
``B`` (T, body axes; the spacecraft's ``magnetic_field``) it feels the
external torque (Wertz, *Spacecraft Attitude Determination and Control*,
1978, §17.2)::

    τ = m × B

the torque of the potential ``U = −m·B``: with a field fixed in inertial axes
and no other torque, ``T − m·B`` is conserved. Diagnostics: ``τ`` (3).
"""

from __future__ import annotations

import numpy as np

from tumble._vec import cross
from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

DIPOLE = 0       # m (3), A·m², body axes
AUX_TORQUE = 0   # τ (3), N·m, body axes


def program(dipole) -> Program:
    """The residual dipole's :class:`~tumble.kernels.spacecraft._base.Program`: ``m`` (3,), A·m², body axes."""
    return Program("residual_dipole", np.asarray(dipole, dtype=np.float64), aux=3)


def aux_slices(n: int, a: int) -> dict[str, slice]:
    return {"residual_dipole_torque": slice(a + AUX_TORQUE, a + AUX_TORQUE + 3)}


def kernel(lane: Lane) -> Actuator:
    """The residual dipole's :class:`~tumble.kernels.spacecraft._base.Actuator` for the diagnostics access
    ``lane``: ``τ = m × B`` with ``B`` the field of ``cmd``."""
    put3 = lane.put3

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        d = model.data
        t1, t2, t3 = cross(d[p + DIPOLE], d[p + DIPOLE + 1], d[p + DIPOLE + 2], cmd[6], cmd[7], cmd[8])
        if store:
            put3(aux, a + AUX_TORQUE, j, t1, t2, t3)
        return t1, t2, t3

    return Actuator(act)
