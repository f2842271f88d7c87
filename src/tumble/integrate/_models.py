"""The models the integrators advance, behind one compiled switch.

Every model's state is a flat float64 vector whose first four entries are the
attitude quaternion (body principal axes → inertial, scalar first). A model
is selected by an integer ``kind``; its parameters are a float vector ``p``
and an integer vector ``codes`` (its torque program). Adding a model means
adding a kind here, a right-hand side, and its state layout in the docs
(``docs/architecture.md``). A module-level switch, rather than passing
functions to the integrators, keeps every compiled integrator cacheable on
disk.

Kinds:

``RIGID`` (0)
    state ``[q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃]`` in principal axes;
    ``p = [I₁, I₂, I₃, torque parameters…]``. Euler's equations in principal
    axes with ``q̇ = ½ q ⊗ [0, ω]``.
"""

from __future__ import annotations

from numba import njit

from tumble import _quat, torques
from tumble.dynamics import euler_principal

RIGID = 0

#: Number of state entries of each kind.
STATE_SIZE = {RIGID: 7}


@njit(cache=True)
def rigid_rhs(t, y, p, codes, out):
    """Right-hand side of the rigid body in principal axes (see the module docstring)."""
    qw, qx, qy, qz, w1, w2, w3 = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
    t1, t2, t3 = torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, p, codes)
    d = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
    out[0], out[1], out[2], out[3] = 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]
    out[4], out[5], out[6] = euler_principal(p[0], p[1], p[2], w1, w2, w3, t1, t2, t3)


@njit(cache=True)
def rhs(kind, t, y, p, codes, out):
    """``out = dy/dt`` of model ``kind`` at time ``t`` and state ``y``."""
    if kind == RIGID:
        rigid_rhs(t, y, p, codes, out)


@njit(cache=True)
def project(kind, y):
    """Put the state back on its manifold after a step: normalise the quaternion ``y[0:4]``.

    The exact flow keeps ``|q| = 1``; a Runge–Kutta step leaves it off by about
    the local error. Projecting (dividing by the norm) after every accepted
    step keeps it at 1 to rounding without changing the order of the method.
    """
    n = _quat.qnorm(y[0], y[1], y[2], y[3])
    for i in range(4):
        y[i] /= n
