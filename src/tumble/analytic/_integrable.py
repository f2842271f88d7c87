"""The heavy top in Euler–Poisson variables; the Kovalevskaya and Goryachev–Chaplygin invariants.

A rigid body turns about a fixed pivot in uniform gravity: inertia ``I`` about
the pivot (kg·m², body axes), mass ``m`` (kg), centre of mass ``r`` from the
pivot (m, body axes), gravity ``g_N`` (m/s², inertial axes) — the model
``tumble.simulate(RigidBody(I), torque=Gravity(m, r, g_N))``. With the upward
vertical in body axes

    γ = R(q)ᵀ ẑ,   ẑ = −g_N / |g_N|,   g = |g_N|        (unit, dimensionless)

(``q`` scalar-first, body → inertial) the motion obeys the Euler–Poisson equations

    I ω̇ = (I ω) × ω + m g γ × r,     γ̇ = γ × ω                      (body axes)

with three conserved quantities for every body: the energy, the vertical
angular momentum (the "area" integral) and ``|γ| = 1``,

    H = ½ ω·I ω + m g r·γ  (J),     L_z = (I ω)·γ  (N·m·s).

A fourth, independent invariant — integrability — exists for the Euler top
(``r = 0``), the Lagrange top (``I`` axisymmetric about ``r``) and two more
cases, both with two equal principal moments ``A = B`` about the pivot, a
third ``C`` about the symmetry axis ``e₃``, and the centre of mass in the
equatorial plane at distance ``ℓ`` along ``e₁``; ``e₂ = e₃ × e₁``. In these
axes ``ω = (p, q, r)``, ``γ = (γ₁, γ₂, γ₃)``, and ``c = m g ℓ / C`` (rad²/s²):

* Kovalevskaya (1889), ``A = B = 2C``, on every level of ``H`` and ``L_z``:

      K = (p² − q² − c γ₁)² + (2 p q − c γ₂)²                     (rad⁴/s⁴)

  (with ``z = p + i q``: ``ξ = z² − c (γ₁ + i γ₂)`` obeys ``ξ̇ = −i r ξ``, so ``|ξ|²`` is constant);
* Goryachev–Chaplygin (1900), ``A = B = 4C``, on the level ``L_z = 0`` only:

      G = |r (p² + q²) − c p γ₃|                                  (rad³/s³).

  The expression inside is odd in ``e₃``: reversing the symmetry axis (``r``,
  ``γ₃`` change sign, ``p`` does not) reverses it. The top has no preferred
  side of that axis — a half-turn about ``e₁`` maps the body, and its
  centre of mass, onto itself — so the sign would be that of the body axes
  chosen, not of the motion; its magnitude is conserved all the same, and is
  what is returned.

References: S. Kowalevski, "Sur le problème de la rotation d'un corps solide
autour d'un point fixe", *Acta Math.* 12 (1889) 177; D. N. Goryachev, *Trudy
Otd. Fiz. Nauk* 10 (1900); S. A. Chaplygin, *Trudy Otd. Fiz. Nauk* 10 (1901);
A. V. Borisov, I. S. Mamaev, *Rigid Body Dynamics* (De Gruyter 2018), ch. 2;
A. M. Perelomov, "Kovalevskaya top – an elementary approach", *Theor. Math.
Phys.* 131 (2002) 612. The signs above are those of tumble's conventions
(``γ`` up, potential ``+m g r·γ``), derived by differentiating along the
equations of motion (``docs/chaos.md``).
"""

from __future__ import annotations

import numpy as np

from tumble import attitude
from tumble._inertia import principal_axes
from tumble._validate import ValidationError, as_array

__all__ = ["CASE_RTOL", "goryachev_chaplygin_invariant", "heavy_top_energy", "kovalevskaya_invariant",
           "omega_at_energy", "upward_vertical", "vertical_momentum"]

#: Relative tolerance of the conditions of an integrable case: ``|A − B|``, ``|A − k C|`` ≤ CASE_RTOL·A
#: and the centre of mass off the equatorial plane by ≤ CASE_RTOL·|r|; on the Goryachev–Chaplygin
#: level ``|L_z| ≤ CASE_RTOL · |I ω|``.
CASE_RTOL = 1e-9


def upward_vertical(q, gravity) -> np.ndarray:
    """``γ = R(q)ᵀ (−g_N/|g_N|)``: the upward unit vertical in body axes, shape (…, 3).

    ``q`` (…, 4) body → inertial (scalar first); ``gravity`` a :class:`tumble.torques.Gravity`.
    """
    q = as_array(q, "q", tail=(4,))
    return attitude.rotate_inverse(q, -gravity.g / _magnitude(gravity))


def heavy_top_energy(inertia, gravity, omega, q) -> np.ndarray:
    """``H = ½ ω·I ω + m g r·γ`` (J, potential zero at the pivot's height), shape (…).

    ``inertia`` (3, 3) about the pivot in body axes (or the simulated :class:`tumble.RigidBody`),
    ``gravity`` the :class:`tumble.torques.Gravity` of the simulation, ``omega`` (…, 3) rad/s body
    axes, ``q`` (…, 4) body → inertial.
    """
    tensor, omega = _tensor(inertia), as_array(omega, "omega", tail=(3,))
    kinetic = 0.5 * np.einsum("...i,ij,...j->...", omega, tensor, omega)
    return kinetic + gravity.mass * _magnitude(gravity) * (upward_vertical(q, gravity) @ gravity.com)


def omega_at_energy(inertia, gravity, energy, direction, q) -> np.ndarray:
    """The body rate along ``direction`` (…, 3) that gives the top at attitude ``q`` (…, 4) the energy ``energy`` (J).

    ``ω = s d`` with ``½ s² d·I d = H − m g r·γ`` and ``s ≥ 0``: initial states on one energy level (a Poincaré
    section, a chaos map). Refused (``energy``) where the potential at ``q`` exceeds ``energy``.
    """
    tensor, direction = _tensor(inertia), as_array(direction, "direction", tail=(3,))
    kinetic = float(as_array(energy, "energy")) - heavy_top_energy(tensor, gravity, np.zeros(3), q)
    if np.any(kinetic < 0.0):
        raise ValidationError(f"energy: must be at least the potential energy m g r.gamma at q, "
                              f"short by {-float(np.min(kinetic)):.3g} J")
    unit = np.einsum("...i,ij,...j->...", direction, tensor, direction)
    return direction * np.sqrt(2.0 * kinetic / unit)[..., None]


def vertical_momentum(inertia, gravity, omega, q) -> np.ndarray:
    """``L_z = (I ω)·γ``, N·m·s: the angular momentum about the upward vertical through the pivot, shape (…)."""
    tensor, omega = _tensor(inertia), as_array(omega, "omega", tail=(3,))
    return np.einsum("...i,...i->...", omega @ tensor.T, upward_vertical(q, gravity))


def kovalevskaya_invariant(inertia, gravity, omega, q) -> np.ndarray:
    """Kovalevskaya's quartic invariant ``K = (p² − q² − c γ₁)² + (2pq − c γ₂)²``, rad⁴/s⁴, shape (…).

    The body must be a Kovalevskaya top: principal moments about the pivot
    ``A = B = 2C`` and the centre of mass in the equatorial plane (to
    :data:`CASE_RTOL`), else :class:`~tumble.ValidationError` naming
    ``inertia`` or ``gravity.com``. ``p, q, r`` and ``γᵢ`` are the
    components of ``omega`` (rad/s, body axes) and of the upward vertical
    (:func:`upward_vertical`) along ``e₁ = r_⊥/|r_⊥|``, ``e₂ = e₃ × e₁``,
    ``e₃`` the symmetry axis; ``c = m g ℓ / C``. Arguments as
    :func:`heavy_top_energy`. Constant along every motion of the top (module
    docstring).
    """
    frame, c = _case_frame(inertia, gravity, 2.0, "a Kovalevskaya top")
    (p, q_, _), (g1, g2, _) = _in_frame(frame, omega, q, gravity)
    return (p * p - q_ * q_ - c * g1) ** 2 + (2.0 * p * q_ - c * g2) ** 2


def goryachev_chaplygin_invariant(inertia, gravity, omega, q) -> np.ndarray:
    """The Goryachev–Chaplygin cubic invariant ``G = |r (p² + q²) − c p γ₃|``, rad³/s³, shape (…).

    The magnitude: the expression is odd in the orientation of the symmetry
    axis ``e₃``, which the top does not fix (module docstring), so that the
    same motion described in body axes turned by a half-turn about ``e₁``
    gives the same ``G``.

    The body must be a Goryachev–Chaplygin top: principal moments about the
    pivot ``A = B = 4C`` and the centre of mass in the equatorial plane, and
    the motion on the zero level of the vertical momentum, ``|L_z| ≤
    CASE_RTOL·|I ω|`` at every sample (:func:`vertical_momentum`); otherwise
    :class:`~tumble.ValidationError` naming ``inertia``, ``gravity.com`` or
    ``omega``. Notation and arguments as :func:`kovalevskaya_invariant`.
    """
    frame, c = _case_frame(inertia, gravity, 4.0, "a Goryachev-Chaplygin top")
    tensor, omega = _tensor(inertia), as_array(omega, "omega", tail=(3,))
    momentum = np.abs(vertical_momentum(tensor, gravity, omega, q))
    scale = np.linalg.norm(omega @ tensor.T, axis=-1)
    if np.any(momentum > CASE_RTOL * scale):
        worst = float(np.max(momentum / np.where(scale > 0.0, scale, 1.0)))
        raise ValidationError(f"omega: the Goryachev-Chaplygin invariant holds on the zero level of the vertical "
                              f"momentum only (|L_z| <= {CASE_RTOL:g} |I omega|), got |L_z| = {worst:.3g} |I omega|")
    (p, q_, r), (_, _, g3) = _in_frame(frame, omega, q, gravity)
    return np.abs(r * (p * p + q_ * q_) - c * p * g3)


# -- helpers ----------------------------------------------------------------------


def _tensor(inertia) -> np.ndarray:
    """The (3, 3) inertia tensor of a RigidBody (its ``inertia``) or of an array."""
    tensor = as_array(getattr(inertia, "inertia", inertia), "inertia", tail=(3, 3))
    if tensor.shape != (3, 3):
        raise ValidationError(f"inertia: must have shape (3, 3), got {tensor.shape}")
    return tensor


def _magnitude(gravity) -> float:
    g = float(np.linalg.norm(gravity.g))
    if g == 0.0:
        raise ValidationError("gravity.g: must be non-zero (it fixes the vertical)")
    return g


def _case_frame(inertia, gravity, ratio: float, name: str) -> tuple[np.ndarray, float]:
    """Axes ``(e₁, e₂, e₃)`` (rows, body axes) and ``c = m g ℓ / C`` of a top with ``A = B = ratio·C``."""
    moments, axes = principal_axes(_tensor(inertia), "inertia", check_triangle=False)[1:]
    small, large = moments[0], moments[2]
    if abs(moments[1] - large) > CASE_RTOL * large or abs(large - ratio * small) > CASE_RTOL * large:
        raise ValidationError(f"inertia: must be {name} (principal moments about the pivot A = B = {ratio:g} C), "
                              f"got moments {moments.tolist()} kg m^2")
    e3 = axes[:, 0]
    com = np.asarray(gravity.com, dtype=np.float64)
    along = float(com @ e3)
    if abs(along) > CASE_RTOL * np.linalg.norm(com):
        raise ValidationError(f"gravity.com: must lie in the equatorial plane of {name} (perpendicular to the "
                              f"symmetry axis {e3.tolist()}), got {along:.3g} m along it")
    perpendicular = com - along * e3
    length = float(np.linalg.norm(perpendicular))
    e1 = perpendicular / length if length > 0.0 else axes[:, 1]
    frame = np.stack([e1, np.cross(e3, e1), e3])
    return frame, gravity.mass * _magnitude(gravity) * length / small


def _in_frame(frame, omega, q, gravity):
    """Components of ``omega`` and of the upward vertical along the rows of ``frame``."""
    omega = as_array(omega, "omega", tail=(3,))
    w = np.moveaxis(omega @ frame.T, -1, 0)
    g = np.moveaxis(upward_vertical(q, gravity) @ frame.T, -1, 0)
    return w, g
