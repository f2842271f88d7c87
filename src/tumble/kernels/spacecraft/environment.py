"""The spacecraft's own environment: the magnetic field in body axes and the gravity-gradient torque.

Both follow a Kepler orbit propagated in closed form with the attitude
(:func:`tumble._gravity.kepler_state`, inertial axes). Kinds of part:

* ``"dipole_field"``: the tilted dipole of :func:`dipole_field` (parameters of
  :meth:`tumble.spacecraft.environment.DipoleField.params`) at the orbit position, rotated into
  body axes, T;
* ``"uniform_field"``: a field fixed in inertial axes, rotated into body axes, T;
* ``"gravity_gradient"``: ``τ = 3μ/|r|⁵ r_B × (J r_B)`` with the total inertia ``J``
  (Hughes, *Spacecraft Attitude Dynamics*, ch. 8), N·m, body axes; with an environment table
  (:mod:`.environment_table`) ``r`` is the table's position and only ``μ`` of the elements is read.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tumble import _quat
from tumble._gravity import gravity_gradient_torque, kepler_state
from tumble.kernels.spacecraft._base import Program, inline

ORBIT = 0    # Kepler elements [a, e, i, Ω, ω, M₀, μ] (7; μ at ORBIT + 6): dipole field, gravity gradient
DIPOLE = 7   # dipole-field parameters (6) of DipoleField.params(), after the orbit
UNIFORM = 0  # a uniform field (3), T, inertial axes


@njit(cache=True)
def dipole_field(t, rx, ry, rz, params):
    """Tilted-dipole geomagnetic field ``(Bx, By, Bz)`` (T, inertial axes) at time ``t`` (s) and inertial
    position ``r`` (m).

    ``B = (B₀a³/|r|³) [3 (m̂·r̂) r̂ − m̂]`` with ``m̂`` turned from Earth-fixed
    to inertial axes by ``R₃(greenwich_angle + earth_rate·t)``; ``params`` =
    ``[B₀a³, m̂ₓ, m̂_y, m̂_z, earth_rate, greenwich_angle]`` (T·m³, Earth-fixed
    unit vector, rad/s, rad), from :meth:`tumble.spacecraft.environment.DipoleField.params`.
    """
    k = params[0]
    angle = params[5] + params[4] * t
    c, s = math.cos(angle), math.sin(angle)
    mx = c * params[1] - s * params[2]
    my = s * params[1] + c * params[2]
    mz = params[3]
    r_sq = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r_sq)
    f = k / (r_sq * r)
    proj = 3.0 * (mx * rx + my * ry + mz * rz) / r_sq
    return f * (proj * rx - mx), f * (proj * ry - my), f * (proj * rz - mz)


def dipole_program(elements, params) -> Program:
    return Program("dipole_field", np.concatenate([elements, params]).astype(np.float64))


def uniform_program(field) -> Program:
    return Program("uniform_field", np.asarray(field, dtype=np.float64))


def gravity_gradient_program(elements) -> Program:
    return Program("gravity_gradient", np.asarray(elements, dtype=np.float64))


@inline
def position(d, o, t):
    """The orbit position (m, inertial axes) at ``t`` from the elements at ``d[o:o + 7]``."""
    x, y, z, _, _, _ = kepler_state(d[o], d[o + 1], d[o + 2], d[o + 3], d[o + 4], d[o + 5], d[o + 6], t)
    return x, y, z


@inline
def dipole_body(model, p, t, qw, qx, qy, qz):
    d = model.data
    r1, r2, r3 = position(d, p + ORBIT, t)
    b = dipole_field(t, r1, r2, r3, d[p + DIPOLE:p + DIPOLE + 6])
    return _quat.qrotate_inv(qw, qx, qy, qz, b[0], b[1], b[2])


@inline
def uniform_body(model, p, t, qw, qx, qy, qz):
    d = model.data
    return _quat.qrotate_inv(qw, qx, qy, qz, d[p + UNIFORM], d[p + UNIFORM + 1], d[p + UNIFORM + 2])


@inline
def gravity_gradient(model, p, j_offset, r1, r2, r3, qw, qx, qy, qz):
    """The gravity-gradient torque on the total inertia ``J = d[j_offset:j_offset + 9]`` (row-major) at the
    position ``r`` (m, inertial axes; the orbit's or the environment table's), with ``μ`` of the part's
    elements."""
    d = model.data
    r1, r2, r3 = _quat.qrotate_inv(qw, qx, qy, qz, r1, r2, r3)
    o = j_offset  # row-major: J₁₁ at o, J₂₂ at o + 4, J₃₃ at o + 8, J₁₂ at o + 1, J₁₃ at o + 2, J₂₃ at o + 5
    return gravity_gradient_torque(d[p + ORBIT + 6], r1, r2, r3, d[o], d[o + 4], d[o + 8], d[o + 1], d[o + 2],
                                   d[o + 5])
