"""Moment of inertia as a function of the Lorentz factor: incoherent matter in rigid rotation.

Near the speed of light the moment of inertia of a spinning body is no longer
a constant (``docs/limits.md``). This module gives the special-relativistic
figures for the simplest model that has them: **incoherent matter** (dust:
particles that exert no stresses on each other) whose particles all turn at
the same angular velocity ω about one axis, each moving at ``v = ω r⊥`` on its
circle (``r⊥`` its distance from the axis; ``m`` the rest mass). Each particle
carries its own ``γ = 1/√(1 − v²/c²)``, so (SI units; ω in rad/s)::

    I(ω) = ∫ γ(ω r⊥) r⊥² dm            (kg·m²)
    L(ω) = I(ω) ω                      (N·m·s: each particle's γ m v r⊥)
    T(ω) = ∫ (γ(ω r⊥) − 1) c² dm       (J), with dT = ω dL

What this is not. It is not a Born-rigid body: a body that is rigid in
relativity cannot be set spinning (Ehrenfest's paradox; Born rigidity allows
no change of angular velocity), so the rotation here is simply prescribed,
and the stresses that would hold real matter together, and the energy they
carry, are left out. It is not general relativity either: no gravity of the
body, no frame dragging, no change of its shape, flat space-time throughout.
For a neutron star (``tumble demo lorentz``) the figures show the size of
the special-relativistic kinematic correction only; the star's own gravity
changes its moment of inertia far more.

Shapes (``R`` the radius; mass distributions of uniform density, with
``x = r⊥/R`` and ``β = ωR/c`` the rim speed over c)::

    ring    all mass at x = 1                 I = γ_R m R²,   T = (γ_R − 1) m c²      (γ_R = γ(ωR))
    disk    dm/m = 2x dx                      I = ⅔ (2 + g)/(1 + g)² m R²,   T = β²/(1 + g)² m c²,   g = 1/γ_R
    shell   thin spherical shell              I = (A(1 + β²) − 1)/(2β²) m R²,   T = (A − 1) m c²,   A = artanh(β)/β
    sphere  solid ball, dm/m = 3x√(1 − x²) dx  I = 3(M₂ − M₄) m R²,   T = (3M₂ − 1) m c²

with ``M₂ = (1 − g²A)/(2β²)``, ``M₄ = (1 − 3g²M₂)/(4β²)``, the moments
``Mₙ = ∫₀¹ vⁿ/√(g² + β²v²) dv`` that the substitution ``x = √(1 − v²)``
gives and the reduction ``1 = (n − 1)g²Mₙ₋₂ + nβ²Mₙ`` relates. As ωR → c the
disk tends to ``I = 4/3 m R²``, ``T = m c²`` and the sphere to
``I = 3/4 m R²``, ``T = ½ m c²``; the ring and the shell diverge (the shell
like ``log(1/(1 − β))``). The closed forms lose digits to cancellation at
small β; there (β ≤ ½) the same integrals are summed as the series
``γ(βx) = Σ cₙ β²ⁿ x²ⁿ``, ``cₙ = (2n choose n)/4ⁿ``, over the moments
``μⱼ = ∫ xʲ dm/m`` of each shape, which converge like ``β²ⁿ``.
:meth:`SpinningMatter.quadrature` integrates the definitions themselves
(``scipy.integrate.quad``); the tests check every closed form against it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import quad
from scipy.special import beta as beta_function

from tumble._validate import ValidationError, as_array, require_positive
from tumble.limits import SPEED_OF_LIGHT

__all__ = ["SHAPES", "SpinningMatter"]

#: The shapes and their Newtonian moments of inertia about the spin axis, in units of m R².
SHAPES = {"ring": 1.0, "disk": 0.5, "shell": 2.0 / 3.0, "sphere": 0.4}

#: Below this β = ωR/c the series is summed instead of the closed forms (which cancel there).
_SERIES_BELOW = 0.5
#: Terms of the series: cₙ β²ⁿ ≤ 0.25ⁿ, below 1e-18 of the first term after 30; 48 for margin.
_TERMS = 48
_N = np.arange(_TERMS)
#: cₙ = (2n choose n) / 4ⁿ, the coefficients of 1/√(1 − z) = Σ cₙ zⁿ.
_C = np.cumprod(np.concatenate([[1.0], (2.0 * _N[1:] - 1.0) / (2.0 * _N[1:])]))


def _moments(shape: str, j: np.ndarray) -> np.ndarray:
    """``μⱼ = ∫ xʲ dm/m`` (x = r⊥/R) of a shape, for arrays of even ``j``."""
    if shape == "ring":
        return np.ones_like(j, dtype=np.float64)
    if shape == "disk":
        return 2.0 / (j + 2.0)
    if shape == "sphere":  # 3 ∫₀¹ x^(j+1) √(1 − x²) dx
        return 1.5 * beta_function(j / 2.0 + 1.0, 1.5)
    return 0.5 * beta_function(0.5, j / 2.0 + 1.0)  # shell: ∫₀¹ (1 − μ²)^(j/2) dμ


@dataclass(frozen=True)
class SpinningMatter:
    """Incoherent matter of a given ``shape`` turning rigidly about its symmetry axis (see the module docstring).

    shape  : ``"ring"`` (thin ring), ``"disk"`` (thin uniform disk), ``"shell"`` (thin spherical
             shell) or ``"sphere"`` (uniform solid ball)
    mass   : rest mass m, kg (> 0)
    radius : R, m (> 0)

    Every method takes ``omega`` (rad/s, any shape of array); its rim speed ``|ω| R`` must be below c.
    """

    shape: str
    mass: float
    radius: float

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise ValidationError(f"shape: must be one of {sorted(SHAPES)}, got {self.shape!r}")
        object.__setattr__(self, "mass", require_positive(self.mass, "mass"))
        object.__setattr__(self, "radius", require_positive(self.radius, "radius"))

    @property
    def newtonian_moment(self) -> float:
        """``I₀``, kg·m²: the moment of inertia at rest (ring m R², disk ½ m R², shell ⅔ m R², sphere ⅖ m R²)."""
        return SHAPES[self.shape] * self.mass * self.radius**2

    def rim_speed(self, omega: ArrayLike) -> np.ndarray:
        """``β = |ω| R / c`` (1), refused (``omega``) unless below 1."""
        omega = as_array(omega, "omega")
        beta = np.abs(omega) * self.radius / SPEED_OF_LIGHT
        if np.any(beta >= 1.0):
            raise ValidationError(f"omega: the rim speed |omega| R must be below c = {SPEED_OF_LIGHT:.0f} m/s, got "
                                  f"{beta.max():.6g} c (|omega| = {np.abs(omega).max():.6g} rad/s, R = {self.radius:g} m)")
        return beta

    def moment(self, omega: ArrayLike) -> np.ndarray:
        """``I(ω) = ∫ γ(ω r⊥) r⊥² dm``, kg·m²."""
        return self._ratios(self.rim_speed(omega))[0] * self.mass * self.radius**2

    def angular_momentum(self, omega: ArrayLike) -> np.ndarray:
        """``L = I(ω) ω``, N·m·s (the sign of ω)."""
        return self.moment(omega) * as_array(omega, "omega")

    def kinetic_energy(self, omega: ArrayLike) -> np.ndarray:
        """``T = ∫ (γ(ω r⊥) − 1) c² dm``, J."""
        return self._ratios(self.rim_speed(omega))[1] * self.mass * SPEED_OF_LIGHT**2

    def corrections(self, omega: ArrayLike) -> dict[str, np.ndarray]:
        """What the Newtonian figures miss, relative to them: ``"moment"`` ``I(ω)/I₀ − 1`` (also that of
        ``L``) and ``"energy"`` ``T/(½ I₀ ω²) − 1``, both computed without cancellation (0 at ω = 0)."""
        beta = self.rim_speed(omega)
        moment, energy = self._ratios(beta, excess=True)
        newtonian_energy = 0.5 * SHAPES[self.shape] * beta * beta
        return {"moment": moment / SHAPES[self.shape],
                "energy": np.divide(energy, newtonian_energy, out=np.zeros_like(energy), where=beta > 0.0)}

    def quadrature(self, quantity: str, omega: float) -> float:
        """``"moment"`` I(ω) (kg·m²) or ``"energy"`` T (J) by adaptive quadrature of the definition
        (``scipy.integrate.quad``, relative tolerance 2e-14), for one ``omega``: the check of the closed forms.

        The variable is θ with ``x = r⊥/R = sin θ``, in which every density is smooth: ``dm/m`` is
        ``2 sin θ cos θ dθ`` (disk), ``3 sin θ cos²θ dθ`` (sphere), ``sin θ dθ`` (shell, θ the polar angle).
        ``γ − 1 = β²x²γ²/(1 + γ)`` keeps the energy free of cancellation. (The ring has no integral: its
        closed form is the definition.)
        """
        if quantity not in ("moment", "energy"):
            raise ValidationError(f"quantity: must be 'moment' or 'energy', got {quantity!r}")
        beta = float(self.rim_speed(omega))
        if self.shape == "ring" or beta == 0.0:
            return float(self.moment(omega) if quantity == "moment" else self.kinetic_energy(omega))
        density = {"disk": lambda s, c: 2.0 * s * c, "sphere": lambda s, c: 3.0 * s * c * c,
                   "shell": lambda s, c: s}[self.shape]

        def integrand(theta):
            s, c = math.sin(theta), math.cos(theta)
            k = (beta * s) ** 2
            gamma = 1.0 / math.sqrt(1.0 - k)
            weight = s * s * gamma if quantity == "moment" else k * gamma * gamma / (1.0 + gamma)
            return density(s, c) * weight

        value, _ = quad(integrand, 0.0, 0.5 * math.pi, epsabs=0.0, epsrel=2e-14, limit=1000)
        return value * (self.mass * self.radius**2 if quantity == "moment" else self.mass * SPEED_OF_LIGHT**2)

    def _ratios(self, beta: np.ndarray, *, excess: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """``I/(m R²)`` and ``T/(m c²)`` at rim speeds ``β`` (or, with ``excess``, ``I/(m R²) − I₀/(m R²)`` and
        ``T/(m c²) − ½ I₀/(m R²) β²``, for the corrections)."""
        beta = np.asarray(beta, dtype=np.float64)
        if self.shape == "ring" and not excess:  # γ and γ − 1 = β²γ²/(1 + γ) do not cancel
            return _closed_form("ring", beta)
        small = beta <= _SERIES_BELOW
        moment, energy = np.empty_like(beta), np.empty_like(beta)
        if np.any(small):
            z = (beta[small] ** 2)[..., None] ** _N  # β²ⁿ
            terms_i = _C * _moments(self.shape, 2.0 * _N + 2.0)  # I: Σ cₙ β²ⁿ μ₂ₙ₊₂
            terms_t = _C * _moments(self.shape, 2.0 * _N)  # T: Σₙ≥₁ cₙ β²ⁿ μ₂ₙ
            start = 1 if excess else 0
            moment[small] = np.sum(z[..., start:] * terms_i[start:], axis=-1)
            energy[small] = np.sum(z[..., 1 + start:] * terms_t[1 + start:], axis=-1)
        if np.any(~small):
            b = beta[~small]
            i, t = _closed_form(self.shape, b)
            if excess:
                i, t = i - SHAPES[self.shape], t - 0.5 * SHAPES[self.shape] * b * b
            moment[~small], energy[~small] = i, t
        return moment, energy


def _closed_form(shape: str, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``I/(m R²)`` and ``T/(m c²)`` in closed form (module docstring), for ``0 < β < 1``."""
    k = beta * beta
    g = np.sqrt(1.0 - k)  # 1/γ at the rim
    if shape == "ring":
        gamma = 1.0 / g
        return gamma, k * gamma * gamma / (1.0 + gamma)
    if shape == "disk":
        return (2.0 / 3.0) * (2.0 + g) / (1.0 + g) ** 2, k / (1.0 + g) ** 2
    a = np.arctanh(beta) / beta
    if shape == "shell":
        return (a * (1.0 + k) - 1.0) / (2.0 * k), a - 1.0
    m2 = (1.0 - g * g * a) / (2.0 * k)
    m4 = (1.0 - 3.0 * g * g * m2) / (4.0 * k)
    return 3.0 * (m2 - m4), 3.0 * m2 - 1.0


