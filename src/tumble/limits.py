"""Guard rails of the rigid model: warnings where a user's data leave its domain.

Euler's equations describe a Newtonian body whose particles keep their
distances. ``tumble`` refuses data that no rigid body can have (a negative,
vanishing or non-definite inertia: :class:`tumble.RigidBody`), and *warns*
with a :class:`RigidityWarning` where the data are possible but the model
stops describing a real body:

* **Speed.** For a body of mass ``m`` spinning at ``ω``, the mass-weighted
  RMS speed of its particles about the centre of mass is
  ``v_rms = √(ω·Iω / m) = √(2T/m)``; some particle moves at least that fast.

  - ``v_rms > 1e-3 c`` (300 km/s): relativistic corrections, of relative
    order ``(v/c)²`` ≥ 1e-6, are ignored by the Newtonian model, and so is
    the finite speed at which stresses propagate. Special-relativistic rigid
    bodies do not exist (Born rigidity forbids setting a body spinning), so
    the corrections are out of scope rather than an option. The warning
    states their size (:func:`relativistic_corrections`): for incoherent
    matter turning at ω, whatever its shape, the Newtonian kinetic energy
    and angular momentum are low by at least

        T/T₀ − 1 ≥ 2(γ − 1)/β² − 1 = (2γ + 1)(γ − 1)/(γ + 1) ≈ ¾ β²,    L·ω/(L₀·ω) − 1 ≥ γ − 1 ≈ ½ β²

    with ``β = v_rms/c`` and ``γ = 1/√(1 − β²)``: Jensen's inequality for
    ``(γ(v) − 1)c²`` and ``γ(v) v²``, convex functions of ``v²``, averaged
    over the mass; equality for a thin ring, where every particle moves at
    ``v_rms``. :mod:`tumble.lorentz` gives the exact figures of a ring, a
    disk, a sphere and a spherical shell.
  - ``v_rms > 2 km/s``: no material holds together. The hoop stress of a
    spinning ring is ``σ = ρ v²``, and the best specific strengths
    ``σ/ρ`` (carbon-fibre composites, about 2–4 MJ/kg) give bursting speeds
    of 1.4–2 km/s; the rigid model ignores the elastic stretching and the
    failure that a real rotor shows long before.

* **A nearly vanishing moment.** ``I_min < 1e-9 I_max`` (a body that is
  practically a line, or a point mass) is accepted by :class:`RigidBody`, but
  its spin about the thin axis is a rate ``~1/I_min`` stiffer than the rest:
  the motion about that axis is a property of the idealisation, not of a
  real rod, and steps must resolve it.

The speed checks need the mass (``RigidBody(..., mass=m)``); without it they
are skipped. :func:`tumble.simulate` runs the checks on the initial and the
final states of every body.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["RigidityWarning", "check_rigid_motion", "relativistic_corrections", "SPEED_OF_LIGHT", "RELATIVISTIC_SPEED",
           "BURST_SPEED", "THIN_RATIO"]

#: Speed of light in vacuum, m/s (exact, SI 2019).
SPEED_OF_LIGHT = 299_792_458.0
#: RMS particle speed above which relativistic corrections (≥ 1e-6 relative) are ignored, m/s.
RELATIVISTIC_SPEED = 1e-3 * SPEED_OF_LIGHT
#: RMS particle speed above which no known material holds together (``√(σ/ρ)`` of carbon fibre), m/s.
BURST_SPEED = 2e3
#: Smallest accepted ratio ``I_min / I_max`` before the body is treated as a line.
THIN_RATIO = 1e-9


class RigidityWarning(UserWarning):
    """The data are valid for a rigid body, but a real body would not behave like one (see :mod:`tumble.limits`)."""


def relativistic_corrections(moments: ArrayLike, omega: ArrayLike, mass: ArrayLike) -> dict[str, np.ndarray]:
    """Lower bounds of the relative corrections the Newtonian model neglects, from the RMS particle speed.

    moments : (..., 3) principal moments, kg·m²; omega : (..., 3) body rates in principal axes, rad/s;
    mass : kg. With ``v_rms = √(ω·Iω/m)``, ``β = v_rms/c`` and ``γ = 1/√(1 − β²)`` (module docstring):

    ``"speed"``    β (1); at or above 1 the bounds are ``inf``: no matter moves that fast
    ``"energy"``   ``(2γ + 1)(γ − 1)/(γ + 1)``, at most ``T/T₀ − 1`` (kinetic energy, ≈ ¾ β²)
    ``"momentum"`` ``γ − 1``, at most ``I(ω)/I₀ − 1`` along ω (angular momentum, ≈ ½ β²)

    ``γ − 1 = β²γ²/(1 + γ)``: no cancellation at small speeds.
    """
    moments = np.asarray(moments, dtype=np.float64)
    omega = np.asarray(omega, dtype=np.float64)
    beta = np.sqrt(np.sum(moments * omega * omega, axis=-1) / mass) / SPEED_OF_LIGHT
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.minimum(beta * beta, 1.0)
        gamma = 1.0 / np.sqrt(1.0 - k)
        excess = np.where(k < 1.0, k * gamma * gamma / (1.0 + gamma), np.inf)
        energy = np.where(k < 1.0, (2.0 * gamma + 1.0) * excess / (gamma + 1.0), np.inf)
    return {"speed": beta, "energy": energy, "momentum": excess}


def check_rigid_motion(moments: ArrayLike, omega: ArrayLike, mass: ArrayLike | None = None, *,
                       stacklevel: int = 2) -> None:
    """Warn (:class:`RigidityWarning`) where rigid bodies in the states ``omega`` leave the model's domain.

    moments : (..., 3) principal moments, kg·m² (ascending, as ``RigidBody.moments``)
    omega   : (..., 3) body rates in principal axes, rad/s (broadcast against ``moments``)
    mass    : kg, scalar or broadcastable to ``omega[..., 0]``, or None (speed checks skipped)

    One warning per kind of problem, naming the worst member and how many
    members are affected.
    """
    moments = np.asarray(moments, dtype=np.float64)
    omega = np.asarray(omega, dtype=np.float64)
    thin = moments[..., 0] < THIN_RATIO * moments[..., 2]
    if thin.any():
        ratio = np.broadcast_to(moments[..., 0] / moments[..., 2], thin.shape)
        warnings.warn(RigidityWarning(
            f"inertia: the smallest principal moment is {ratio.min():.3g} times the largest "
            f"{_count(thin)}: the body is practically a line, and its spin about that axis is an "
            "idealisation (a rate ~1/I_min stiffer than the rest) that a real body does not have"),
            stacklevel=stacklevel)
    if mass is None:
        return
    speed = np.sqrt(np.sum(moments * omega * omega, axis=-1) / mass)  # √(ω·Iω/m), m/s
    if np.any(speed > RELATIVISTIC_SPEED):
        worst = np.unravel_index(np.argmax(speed), speed.shape)
        bounds = relativistic_corrections(moments, omega, mass)
        warnings.warn(RigidityWarning(
            f"omega: particles move at {speed.max():.3g} m/s or more (RMS about the centre of mass, "
            f"{speed.max() / SPEED_OF_LIGHT:.2g} c){_count(speed > RELATIVISTIC_SPEED)}: the rigid "
            "model is Newtonian and ignores relativistic corrections: the Lorentz factor of its particles raises the kinetic "
            f"energy by at least {bounds['energy'][worst]:.2g} and the angular momentum by at least "
            f"{bounds['momentum'][worst]:.2g} (relative; exact for a thin ring, tumble.lorentz for other shapes), "
            "and no material holds together at such speeds (see tumble.limits)"), stacklevel=stacklevel)
    elif np.any(speed > BURST_SPEED):
        warnings.warn(RigidityWarning(
            f"omega: particles move at {speed.max():.3g} m/s or more (RMS about the centre of mass)"
            f"{_count(speed > BURST_SPEED)}, above the ~2 km/s at which the strongest materials "
            "burst (hoop stress rho v^2): the rigid model ignores the elastic deformation and the failure "
            "of a real body (see tumble.limits)"), stacklevel=stacklevel)


def _count(flags: np.ndarray) -> str:
    """``""`` for one body; ``" (member 3)"`` / ``" (4 of 100 members, first 3)"`` for a batch."""
    flags = np.atleast_1d(flags)
    where = np.flatnonzero(flags.reshape(-1))
    if flags.size == 1:
        return ""
    if where.size == 1:
        return f" (member {int(where[0])})"
    return f" ({where.size} of {flags.size} members, first {int(where[0])})"
