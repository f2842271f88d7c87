"""Poincaré sections of a heavy top: where its state crosses a plane, located between output samples.

The state of a top on a pivot is ``x = (ω, γ)``: the body rate (rad/s) and
the upward unit vertical ``γ = R(q)ᵀ ẑ``, both in body axes
(:mod:`tumble.analytic._integrable`). A section is a plane ``x_c = value``
of one coordinate ``c`` of ``(ω₁, ω₂, ω₃, γ₁, γ₂, γ₃)``, crossed in a given
direction. On an energy level of the reduced motion (fixed ``H``, ``L_z``,
``|γ| = 1``) the crossings of one orbit lie on a curve when the motion is
regular (an invariant torus cut by the plane) and fill an area when it is
chaotic.

**Event location on the output of any integrator.** The samples of a
trajectory are joined by the quintic Hermite interpolant of each coordinate,
matching its value and first two time derivatives at both ends, which the
Euler–Poisson equations give exactly at every sample (``I`` the inertia about
the pivot, ``w = m g r``)::

    I ω̇ = (I ω) × ω + γ × w,                  γ̇ = γ × ω
    I ω̈ = (I ω̇) × ω + (I ω) × ω̇ + γ̇ × w,       γ̈ = γ̇ × ω + γ × ω̇

The crossing is the root of the interpolated ``x_c(t) − value`` in the
interval whose end samples straddle it (bisection to rounding), and the
state there is the interpolant at the root. The interpolation error is at
most ``h⁶ max|x⁽⁶⁾| / 46080`` for samples ``h`` apart (the remainder of
two-point Hermite interpolation, ``max|s³(1 − s)³| = 1/64``); with ``Ω`` the
fastest rate of the motion, ``|x⁽⁶⁾| ≲ Ω⁶``, so ``Ω h = 0.1`` gives ≲ 2e-11,
below a dop853 run at ``rtol = 1e-10``. Sample densely enough that ``x_c``
crosses the plane at most once between two samples (``Ω h ≲ 0.3``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tumble._validate import ValidationError
from tumble.analytic._integrable import upward_vertical
from tumble.trajectory import Trajectory

__all__ = ["COORDINATES", "PoincareSection", "poincare_section"]

#: The coordinates a section may cut, in the order of the state ``(ω, γ)``.
COORDINATES = ("omega1", "omega2", "omega3", "gamma1", "gamma2", "gamma3")

_BISECTIONS = 60  # halves the interval to below 2⁻⁶⁰ of a sample spacing: rounding


@dataclass(frozen=True)
class PoincareSection:
    """The crossings of a section (see :func:`poincare_section`).

    t      : (k,) crossing times, s
    omega  : (k, 3) body rate at the crossings, rad/s, body axes
    gamma  : (k, 3) upward unit vertical at the crossings, body axes
    coordinate, value, direction : the section crossed
    """

    t: np.ndarray
    omega: np.ndarray
    gamma: np.ndarray
    coordinate: str
    value: float
    direction: int

    def __getitem__(self, name: str) -> np.ndarray:
        """One coordinate of the crossings by name (``"omega1"`` … ``"gamma3"``), shape (k,)."""
        if name not in COORDINATES:
            raise ValidationError(f"name: must be one of {list(COORDINATES)}, got {name!r}")
        i = COORDINATES.index(name)
        return self.omega[:, i] if i < 3 else self.gamma[:, i - 3]


def poincare_section(source, gravity, *, section: dict, direction: int = 1, **simulate_options) -> PoincareSection:
    """The crossings of a heavy top's state ``(ω, γ)`` with the plane ``section`` (module docstring).

    source    : a :class:`tumble.Trajectory` of one top (its ``inertia`` about the pivot, as simulated),
                or a model (a :class:`tumble.RigidBody`) to simulate with ``torque=gravity`` and
                ``simulate_options`` (``omega0``, ``q0``, ``t``, ``method``, …) through :func:`tumble.simulate`
    gravity   : the :class:`tumble.torques.Gravity` torque of the motion
    section   : ``{coordinate: value}``, one of :data:`COORDINATES` (body axes; rad/s for ``omega``)
    direction : +1 crossings where the coordinate increases, −1 where it decreases, 0 both

    A section the motion never crosses is refused (:class:`~tumble.ValidationError` naming ``section``).
    """
    if not isinstance(section, dict) or len(section) != 1 or next(iter(section)) not in COORDINATES:
        raise ValidationError(f"section: must be {{coordinate: value}} with one coordinate of {list(COORDINATES)}, "
                              f"got {section!r}")
    if direction not in (-1, 0, 1):
        raise ValidationError(f"direction: must be +1, -1 or 0, got {direction!r}")
    (coordinate, value), = section.items()
    value = float(value)
    if isinstance(source, Trajectory):
        if simulate_options:
            raise ValidationError(f"{sorted(simulate_options)[0]}: simulation options need a model, not a trajectory")
        trajectory = source
    else:
        import tumble

        trajectory = tumble.simulate(source, torque=gravity, **simulate_options)
    if trajectory.batch_size is not None or trajectory.omega is None:
        raise ValidationError("source: must be one rigid top (a trajectory with omega of shape (n, 3))")
    x, rate, curvature = _derivatives(trajectory, gravity)
    i = COORDINATES.index(coordinate)
    s = x[:, i] - value
    rising, falling = (s[:-1] < 0.0) & (s[1:] >= 0.0), (s[:-1] > 0.0) & (s[1:] <= 0.0)
    k = np.flatnonzero({1: rising, -1: falling, 0: rising | falling}[direction])
    if k.size == 0:
        sense = {1: "upwards", -1: "downwards", 0: "at all"}[direction]
        raise ValidationError(f"section: the motion never crosses {coordinate} = {value:g} {sense} "
                              f"({coordinate} stays in [{x[:, i].min():.6g}, {x[:, i].max():.6g}])")
    t = trajectory.t
    h = (t[k + 1] - t[k])[:, None]
    ends = (x[k], h * rate[k], h * h * curvature[k], x[k + 1], h * rate[k + 1], h * h * curvature[k + 1])
    lo, hi = np.zeros(k.size), np.ones(k.size)
    below = s[k] < 0.0  # the side of the start sample
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        past = (_hermite(ends, mid)[:, i] - value < 0.0) != below
        hi, lo = np.where(past, mid, hi), np.where(past, lo, mid)
    root = 0.5 * (lo + hi)
    state = _hermite(ends, root)
    return PoincareSection(t[k] + root * h[:, 0], state[:, :3], state[:, 3:], coordinate, value, direction)


def _derivatives(trajectory, gravity):
    """``x = (ω, γ)`` (n, 6) and its first and second time derivatives from the Euler–Poisson equations."""
    inertia = np.asarray(trajectory.inertia, dtype=np.float64)
    omega, gamma = trajectory.omega, upward_vertical(trajectory.q, gravity)
    weight = gravity.mass * float(np.linalg.norm(gravity.g)) * np.asarray(gravity.com, dtype=np.float64)
    momentum = omega @ inertia.T
    omega_dot = np.linalg.solve(inertia, (np.cross(momentum, omega) + np.cross(gamma, weight)).T).T
    gamma_dot = np.cross(gamma, omega)
    omega_ddot = np.linalg.solve(inertia, (np.cross(omega_dot @ inertia.T, omega) + np.cross(momentum, omega_dot)
                                           + np.cross(gamma_dot, weight)).T).T
    gamma_ddot = np.cross(gamma_dot, omega) + np.cross(gamma, omega_dot)
    return (np.concatenate([omega, gamma], axis=1), np.concatenate([omega_dot, gamma_dot], axis=1),
            np.concatenate([omega_ddot, gamma_ddot], axis=1))


def _hermite(ends, s):
    """The quintic Hermite interpolant at fractions ``s`` (k,) of the intervals.

    ``ends = (y₀, h y₀', h² y₀'', y₁, h y₁', h² y₁'')``, each (k, 6).
    """
    y0, d0, c0, y1, d1, c1 = ends
    s = s[:, None]
    s2, s3 = s * s, s * s * s
    return (y0 * (1.0 - s3 * (10.0 - 15.0 * s + 6.0 * s2)) + d0 * s * (1.0 - s2 * (6.0 - 8.0 * s + 3.0 * s2))
            + c0 * 0.5 * s2 * (1.0 - s) ** 3 + c1 * 0.5 * s3 * (1.0 - s) ** 2
            + d1 * s3 * (-4.0 + 7.0 * s - 3.0 * s2) + y1 * s3 * (10.0 - 15.0 * s + 6.0 * s2))
