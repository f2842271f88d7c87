"""Compiled kernels of a central (point-mass) gravity field: the Kepler orbit and the gravity-gradient torque.

They live below :mod:`tumble.torques` (which evaluates the gravity-gradient
torque model with them) and :mod:`tumble.spacecraft` (which re-exports them as
:func:`tumble.spacecraft.orbit.orbit_state` and
:func:`tumble.spacecraft.environment.gravity_gradient_torque`), so that the
imports run one way only. Plain scalar functions: callable from any compiled
model, from the CPU integrators and, as device functions, from CUDA kernels.
"""

from __future__ import annotations

import math

from numba import njit

#: Newton iterations allowed for Kepler's equation (a guard: the tests see
#: convergence to rounding for e up to 0.999 over M in [-12, 12] rad). From
#: E0 = ±π the iteration converges monotonically, since E − e sin E − M is
#: convex on [0, π] and concave on [−π, 0].
KEPLER_ITERATIONS = 50


@njit(cache=True)
def eccentric_anomaly(mean_anomaly, e):
    """Solve Kepler's equation ``E − e sin E = M`` for ``E`` (rad) by Newton's method, 0 ≤ e < 1.

    ``M`` is first reduced to ``[−π, π)``; the iteration starts at ``E₀ = M``
    for ``e < 0.8`` and at ``E₀ = π sign(M)`` otherwise (Vallado, *Fundamentals
    of Astrodynamics and Applications*, 4th ed., Algorithm 2), and stops when
    the Newton correction is below 1e-15 rad. The result is in ``[−π, π]``.
    """
    m = mean_anomaly - 2.0 * math.pi * math.floor((mean_anomaly + math.pi) / (2.0 * math.pi))
    if e < 0.8:
        big_e = m
    else:
        big_e = math.copysign(math.pi, m) if m != 0.0 else 0.0
    for _ in range(KEPLER_ITERATIONS):
        delta = (big_e - e * math.sin(big_e) - m) / (1.0 - e * math.cos(big_e))
        big_e -= delta
        if abs(delta) <= 1e-15:
            break
    return big_e


@njit(cache=True)
def orbit_state(el, t):
    """Position (m) and velocity (m/s) in inertial (ECI) axes on a Kepler orbit at time ``t`` (s).

    ``el`` = ``[a, e, i, Ω, ω, M₀, μ]``: semi-major axis (m), eccentricity
    (0 ≤ e < 1), inclination, right ascension of the ascending node, argument
    of periapsis (rad), mean anomaly at ``t = 0`` (rad) and the gravitational
    parameter (m³/s²). Returns ``(rx, ry, rz, vx, vy, vz)``; see
    :func:`kepler_state`.
    """
    return kepler_state(el[0], el[1], el[2], el[3], el[4], el[5], el[6], t)


@njit(cache=True)
def kepler_state(a, e, inc, raan, argp, m0, mu, t):
    """:func:`orbit_state` with the elements as scalars (no array reads: for the integrators' inner loops).

    With ``n = √(μ/a³)``, ``M = M₀ + n t`` and ``E`` from
    Kepler's equation, the perifocal state is::

        x = a (cos E − e),       y = a √(1−e²) sin E
        ẋ = −a n sin E / (1 − e cos E),   ẏ = a n √(1−e²) cos E / (1 − e cos E)

    rotated to inertial axes by ``R₃(−Ω) R₁(−i) R₃(−ω)`` (Vallado, §2.3 and
    Algorithm 10; Curtis, *Orbital Mechanics for Engineering Students*, §4.6).
    """
    n = math.sqrt(mu / (a * a * a))
    big_e = eccentric_anomaly(m0 + n * t, e)
    ce, se = math.cos(big_e), math.sin(big_e)
    b = math.sqrt((1.0 - e) * (1.0 + e))
    x, y = a * (ce - e), a * b * se
    f = a * n / (1.0 - e * ce)
    xd, yd = -f * se, f * b * ce
    # columns P and Q of the perifocal -> inertial rotation R3(-raan) R1(-i) R3(-argp)
    cO, sO = math.cos(raan), math.sin(raan)
    cw, sw = math.cos(argp), math.sin(argp)
    ci, si = math.cos(inc), math.sin(inc)
    px, py, pz = cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si
    qx, qy, qz = -cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si
    return (px * x + qx * y, py * x + qy * y, pz * x + qz * y,
            px * xd + qx * yd, py * xd + qy * yd, pz * xd + qz * yd)


@njit(cache=True)
def gravity_gradient_torque(mu, r1, r2, r3, I11, I22, I33, I12, I13, I23):
    """Gravity-gradient torque on a body in a point-mass field, body axes (N·m).

    ``τ = (3 μ / |r|⁵) r × (I r)`` with ``r`` the position of the body's
    centre of mass relative to the attracting centre, in body axes (m), ``μ``
    the gravitational parameter (m³/s²) and ``I`` the inertia tensor about
    the centre of mass in the same axes (kg·m²); the leading term of the
    expansion in (body size / |r|) (Hughes, *Spacecraft Attitude Dynamics*,
    ch. 8; Wie, *Space Vehicle Dynamics and Control*, ch. 6).
    Equivalently ``τ = 3 (μ/R³) ô × (I ô)`` with ``ô = r/|r|``.
    """
    j1 = I11 * r1 + I12 * r2 + I13 * r3
    j2 = I12 * r1 + I22 * r2 + I23 * r3
    j3 = I13 * r1 + I23 * r2 + I33 * r3
    r_sq = r1 * r1 + r2 * r2 + r3 * r3
    k = 3.0 * mu / (r_sq * r_sq * math.sqrt(r_sq))
    return k * (r2 * j3 - r3 * j2), k * (r3 * j1 - r1 * j3), k * (r1 * j2 - r2 * j1)
