"""The heavy symmetric (Lagrange) top on a fixed point: exact motion.

A body symmetric about an axis through a fixed pivot (transverse moment
``I1`` and axial moment ``I3``, both *about the pivot*, kg·m²), its centre of
mass at distance ``length`` (m) from the pivot along the symmetry axis, in
uniform gravity ``g`` (m/s²).

Conventions (H. Goldstein, C. Poole, J. Safko, *Classical Mechanics*, 3rd ed.,
§5.7; L. D. Landau, E. M. Lifshitz, *Mechanics*, §35, problem 1):

* inertial axes N with ``z`` pointing up (against gravity); body axes with
  ``z`` along the symmetry axis, from the pivot towards the centre of mass;
* Euler angles ``(φ, θ, ψ)``, intrinsic z-x-z: ``R(q) = R_z(φ) R_x(θ) R_z(ψ)``
  (``tumble.attitude.from_euler("ZXZ", [φ, θ, ψ])``). ``φ`` is the precession
  (azimuth of the line of nodes), ``θ ∈ [0, π]`` the nutation angle of the
  symmetry axis from the upward vertical, ``ψ`` the spin angle. The symmetry
  axis points along ``e₃ = (sin θ sin φ, −sin θ cos φ, cos θ)`` in N;
* body rates ``ω₁ = φ̇ sin θ sin ψ + θ̇ cos ψ``, ``ω₂ = φ̇ sin θ cos ψ − θ̇ sin ψ``,
  ``ω₃ = ψ̇ + φ̇ cos θ`` (the *spin*, constant);
* the potential energy is ``m g l cos θ`` (zero at the pivot's height).

Lagrangian ``L = ½I₁(θ̇² + φ̇² sin²θ) + ½I₃ω₃² − m g l cos θ``; conserved:

    p_ψ = I₃ ω₃ = I₁ a,    p_φ = I₁ φ̇ sin²θ + I₃ ω₃ cos θ = I₁ b   (= L_z)
    E = ½I₁(θ̇² + φ̇² sin²θ) + ½I₃ω₃² + m g l cos θ,   E' = E − ½I₃ω₃²
    α = 2E'/I₁,   β = 2 m g l / I₁                          (rad²/s²)

With ``u = cos θ`` the motion in θ separates (Goldstein §5.7):

    u̇² = f(u) = (α − β u)(1 − u²) − (b − a u)² = β (u − u₁)(u − u₂)(u − u₃),

``−1 ≤ u₁ ≤ u₂ ≤ 1 ≤ u₃``; ``u`` oscillates between the turning points
``u₁, u₂``. Substituting ``u = u₁ + (u₂ − u₁) sn²(τ | m)`` gives
``u − u₁ ∝ sn²``, ``u₂ − u ∝ cn²``, ``u₃ − u = (u₃ − u₁) dn²`` and
``dτ/dt = λ`` with

    λ = ½ √(β (u₃ − u₁)),   m = (u₂ − u₁)/(u₃ − u₁)               (1/s, 1)
    u(t) = u₁ + (u₂ − u₁) sn²(λ t + τ₀ | m),   T = 2 K(m) / λ.

(``sn²`` has period ``2K``.) The precession rate follows from ``p_φ``:
``φ̇ = (b − a u)/(1 − u²) = ½(b − a)/(1 − u) + ½(b + a)/(1 + u)``, and
``∫ dτ / (1 − n sn²τ) = Π(n; am τ | m)`` integrates it in closed form
(Legendre's incomplete integral of the third kind, evaluated through
Carlson's ``R_F`` and ``R_J``, DLMF §19.25(i)).

:class:`HeavyTop` is one unit (about 430 lines): its constructors, the
turning points, θ(t), φ(t) and the approximations all read the same
constants of motion. The axis measured on a simulation, to compare with it,
is :mod:`tumble.analytic._top_axis`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipj, ellipk, elliprf, elliprj

from tumble import attitude
from tumble._validate import ValidationError, as_array, require_positive
from tumble.analytic._top_axis import axis_state, nonzero_vector

__all__ = ["HeavyTop"]

#: Relative tolerance of the axisymmetry check of an inertia tensor about the
#: pivot in :meth:`HeavyTop.from_simulation_state`: ``|I − I_sym| ≤ 1e-9 |I|``.
SYMMETRY_RTOL = 1e-9


@dataclass(frozen=True)
class HeavyTop:
    """A heavy symmetric top on a fixed pivot and its initial state; the exact motion.

    Parameters (SI units; the Euler angles are those of the module docstring):

    I1, I3 : float
        Transverse and axial moments of inertia *about the pivot*, kg·m².
    mass : float
        kg.
    length : float
        Distance from the pivot to the centre of mass along the symmetry axis, m (> 0).
    g : float
        Gravitational acceleration, m/s² (> 0); gravity points along −z.
    theta0 : float
        Initial nutation angle θ of the symmetry axis from the upward vertical, rad, in [0, π].
    theta_dot0, phi_dot0 : float
        Initial θ̇ and φ̇, rad/s. At θ = 0 or π the precession angle is not
        defined: ``phi_dot0`` is then irrelevant and ``theta_dot0`` is the
        rate at which the axis leaves the pole.
    spin : float
        ω₃ = ψ̇ + φ̇ cos θ, the body rate about the symmetry axis, rad/s (conserved).

    Times ``t`` of the methods are seconds since this initial state.
    """

    I1: float
    I3: float
    mass: float
    length: float
    g: float
    theta0: float
    theta_dot0: float
    phi_dot0: float
    spin: float

    def __post_init__(self):
        for name in ("I1", "I3", "mass", "length", "g"):
            object.__setattr__(self, name, require_positive(getattr(self, name), name))
        for name in ("theta0", "theta_dot0", "phi_dot0", "spin"):
            value = as_array(getattr(self, name), name)
            if value.ndim != 0:
                raise ValidationError(f"{name}: must be a number, got shape {value.shape}")
            object.__setattr__(self, name, float(value))
        if not 0.0 <= self.theta0 <= math.pi:
            raise ValidationError(f"theta0: must lie in [0, π] (angle from the upward vertical), got {self.theta0}")

    # -- constructors -------------------------------------------------------

    @classmethod
    def from_state(cls, I1, I3, mass, length, g, theta0, theta_dot0, phi_dot0, spin) -> HeavyTop:
        """The top from its physical data and initial Euler-angle state (all SI, see the class)."""
        return cls(I1, I3, mass, length, g, theta0, theta_dot0, phi_dot0, spin)

    @classmethod
    def from_simulation_state(cls, body_inertia_about_pivot, mass, com, g, omega0, q0) -> HeavyTop:
        """The top whose state is a ``tumble.simulate`` state with ``tumble.torques.Gravity(mass, com, g)``.

        ``body_inertia_about_pivot`` (3, 3) kg·m² in body axes (e.g.
        ``RigidBody.inertia_about(pivot)``; not ``RigidBody.inertia``, which is
        about the centre of mass) must be axisymmetric about
        ``com`` (m, body axes, from the pivot to the centre of mass):
        ``I = I₁ (E − e eᵀ) + I₃ e eᵀ`` with ``e = com/|com|``, to
        :data:`SYMMETRY_RTOL`. ``g`` (m/s², inertial axes) fixes the vertical
        ``−g/|g|``; ``omega0`` (rad/s, body axes) and ``q0`` (body → inertial)
        are the state. The body and inertial axes may be any; θ, θ̇, φ̇ and
        ω₃ do not depend on them (φ itself does, see :func:`axis_motion`).
        """
        inertia = as_array(body_inertia_about_pivot, "body_inertia_about_pivot", tail=(3, 3))
        if inertia.shape != (3, 3):
            raise ValidationError(f"body_inertia_about_pivot: must have shape (3, 3), got {inertia.shape}")
        com, g = nonzero_vector(com, "com"), nonzero_vector(g, "g")
        omega0, q0 = nonzero_vector(omega0, "omega0"), as_array(q0, "q0", tail=(4,))
        axis = com / np.linalg.norm(com)
        I3 = float(axis @ inertia @ axis)
        I1 = 0.5 * (float(np.trace(inertia)) - I3)
        symmetric = I1 * (np.eye(3) - np.outer(axis, axis)) + I3 * np.outer(axis, axis)
        misfit = np.abs(inertia - symmetric).max()
        if misfit > SYMMETRY_RTOL * np.abs(inertia).max():
            raise ValidationError(
                f"body_inertia_about_pivot: must be axisymmetric about com "
                f"(|I - I_sym| = {misfit:.3g} > {SYMMETRY_RTOL:g} |I|)"
            )
        state = axis_state(q0, omega0, axis, -g / np.linalg.norm(g))
        return cls(I1, I3, mass, float(np.linalg.norm(com)), float(np.linalg.norm(g)),
                   state["theta"], state["theta_dot"], state["phi_dot"], state["spin"])

    def simulation_inputs(self, *, phi0: float = 0.0, psi0: float = 0.0) -> dict:
        """Keyword arguments of ``tumble.simulate`` that start this top at Euler angles ``(phi0, theta0, psi0)``.

        ``{"model": diag(I₁, I₁, I₃), "omega0", "q0", "torque": Gravity(mass, (0, 0, l), (0, 0, −g))}``:
        body z is the symmetry axis, inertial z is up; ``q0 = from_euler("ZXZ",
        [phi0, theta0, psi0])`` and ``omega0`` from the body-rate formulas of
        the module docstring. Use as ``tumble.simulate(**top.simulation_inputs(), t=t)``.
        """
        from tumble.torques import Gravity

        theta, psi = self.theta0, float(psi0)
        transverse = self.phi_dot0 * math.sin(theta)
        omega0 = np.array([
            transverse * math.sin(psi) + self.theta_dot0 * math.cos(psi),
            transverse * math.cos(psi) - self.theta_dot0 * math.sin(psi),
            self.spin,
        ])
        return {
            "model": np.diag([self.I1, self.I1, self.I3]),
            "omega0": omega0,
            "q0": attitude.from_euler("ZXZ", [float(phi0), theta, psi]),
            "torque": Gravity(self.mass, [0.0, 0.0, self.length], [0.0, 0.0, -self.g]),
        }

    # -- conserved quantities -------------------------------------------------

    @property
    def weight_torque(self) -> float:
        """``m g l``, N·m: the largest gravity torque (axis horizontal)."""
        return self.mass * self.g * self.length

    @property
    def p_psi(self) -> float:
        """``p_ψ = I₃ ω₃``, N·m·s: angular momentum about the symmetry axis."""
        return self.I3 * self.spin

    @property
    def p_phi(self) -> float:
        """``p_φ = I₁ φ̇ sin²θ + I₃ ω₃ cos θ = L_z``, N·m·s: vertical angular momentum."""
        return self.I1 * self._b_minus_au0 + self.p_psi * math.cos(self.theta0)

    @property
    def energy(self) -> float:
        """``E = ½I₁(θ̇² + φ̇² sin²θ) + ½I₃ω₃² + m g l cos θ``, J (potential zero at the pivot)."""
        return 0.5 * self.I1 * self._transverse_sq + 0.5 * self.I3 * self.spin**2 + self.weight_torque * self._u0

    @property
    def a(self) -> float:
        """``a = p_ψ / I₁ = I₃ ω₃ / I₁``, rad/s."""
        return self.p_psi / self.I1

    @property
    def b(self) -> float:
        """``b = p_φ / I₁``, rad/s."""
        return self.p_phi / self.I1

    @property
    def alpha(self) -> float:
        """``α = 2E'/I₁ = θ̇² + φ̇² sin²θ + β cos θ`` with ``E' = E − ½I₃ω₃²``, rad²/s²."""
        return self._transverse_sq + self.beta * self._u0

    @property
    def beta(self) -> float:
        """``β = 2 m g l / I₁``, rad²/s²."""
        return 2.0 * self.weight_torque / self.I1

    # -- θ motion -------------------------------------------------------------

    def effective_potential(self, theta) -> np.ndarray:
        """``V_eff(θ) = (p_φ − p_ψ cos θ)² / (2 I₁ sin²θ) + m g l cos θ``, J: ``E' = ½I₁θ̇² + V_eff(θ)``.

        Infinite at θ = 0 and π (returned as ``inf`` there), where the axis reaches a pole only if ``p_φ = ±p_ψ``.
        """
        theta = as_array(theta, "theta")
        num = (self.p_phi - self.p_psi * np.cos(theta)) ** 2
        den = 2.0 * self.I1 * np.sin(theta) ** 2
        centrifugal = np.divide(num, den, out=np.full_like(num, np.inf), where=den > 0.0)
        return centrifugal + self.weight_torque * np.cos(theta)

    def f(self, u) -> np.ndarray:
        """``f(u) = (α − β u)(1 − u²) − (b − a u)² = u̇²``, rad²/s², ``u = cos θ`` (Goldstein §5.7)."""
        u = as_array(u, "u")
        return (self.alpha - self.beta * u) * (1.0 - u * u) - (self.b - self.a * u) ** 2

    @property
    def u1(self) -> float:
        """Smallest root of ``f`` in [−1, 1]: ``cos θ_max``."""
        return self._u0 + self._x[0]

    @property
    def u2(self) -> float:
        """Largest root of ``f`` in [−1, 1]: ``cos θ_min``."""
        return self._u0 + self._x[1]

    @property
    def u3(self) -> float:
        """Third root of ``f``, ``≥ 1`` (no motion reaches it)."""
        return self._u0 + self._x[2]

    @property
    def theta_min(self) -> float:
        """Smallest nutation angle ``arccos u₂``, rad."""
        return _angle_from_poles(self._d_north - self._x[1], self._d_south + self._x[1])

    @property
    def theta_max(self) -> float:
        """Largest nutation angle ``arccos u₁``, rad."""
        return _angle_from_poles(self._d_north - self._x[0], self._d_south + self._x[0])

    @property
    def modulus(self) -> float:
        """Parameter ``m = (u₂ − u₁)/(u₃ − u₁)`` of the Jacobi functions (``k² = m``), in [0, 1]."""
        x1, x2, x3 = self._x
        return (x2 - x1) / (x3 - x1)

    @property
    def rate(self) -> float:
        """``λ = ½ √(β (u₃ − u₁))``, 1/s: ``τ = λ t`` is the argument of ``sn``."""
        return 0.5 * math.sqrt(self.beta * (self._x[2] - self._x[0]))

    @property
    def nutation_period(self) -> float:
        """``T = 2 K(m) / λ``, s: the period of θ(t) (``inf`` on a separatrix, m = 1).

        For ``u₁ = u₂`` (steady precession) this is the limit of small nutation.
        """
        return 2.0 * float(ellipk(self.modulus)) / self.rate

    def u(self, t) -> np.ndarray:
        """``u(t) = cos θ(t) = u₁ + (u₂ − u₁) sn²(λ t + τ₀ | m)`` (``t`` in s since the initial state)."""
        north, _ = self._poles(t)
        return 1.0 - north

    def theta(self, t) -> np.ndarray:
        """Nutation angle θ(t) of the symmetry axis from the upward vertical, rad (``t`` in s)."""
        return _angle_from_poles(*self._poles(t))

    # -- precession -----------------------------------------------------------

    def precession_rate(self, t) -> np.ndarray:
        """``φ̇(t) = (b − a u)/(1 − u²) = ½(b − a)/(1 − u) + ½(b + a)/(1 + u)``, rad/s (``t`` in s).

        Undefined when the axis stays on the vertical; this gives the limit
        of the second form there.
        """
        north, south = self._poles(t)
        rate = np.zeros_like(north)
        for half, distance in ((0.5 * self._b_minus_a, north), (0.5 * self._b_plus_a, south)):
            if half != 0.0:
                rate += half / distance
        return rate

    def precession_angle(self, t) -> np.ndarray:
        """``φ(t) − φ(0)``, rad: the exact integral of :meth:`precession_rate` (``t`` in s).

        With ``1 − u = (1 − u₁)(1 − n₊ sn²)``, ``n₊ = (u₂ − u₁)/(1 − u₁)``, and
        ``1 + u = (1 + u₁)(1 − n₋ sn²)``, ``n₋ = −(u₂ − u₁)/(1 + u₁)``:
        ``φ(t) − φ(0) = Σ± c± [Π(n±; am τ | m)]_{τ(0)}^{τ(t)} / λ``,
        ``c₊ = ½(b − a)/(1 − u₁)``, ``c₋ = ½(b + a)/(1 + u₁)``, ``τ = λ t + τ₀``.
        """
        tau = self._tau(t)
        angle = np.zeros_like(tau)
        for c, n_c in self._pi_terms():
            angle += c * (self._pi_integral(n_c, tau) - self._pi_integral(n_c, np.array(self._tau0)))
        return angle / self.rate

    @property
    def mean_precession_rate(self) -> float:
        """Mean of φ̇ over a nutation period, rad/s: ``Σ± c± Π(n± | m) / K(m)`` (see :meth:`precession_angle`).

        Closed form with the complete integral of the third kind; ``nan`` on a
        separatrix (``m = 1``, infinite period).
        """
        m = self.modulus
        k = float(ellipk(m))
        if not math.isfinite(k):
            return math.nan
        return sum(c * _complete_pi(n_c, m) for c, n_c in self._pi_terms()) / k

    @property
    def slow_precession_rate(self) -> float:
        """Gyroscopic approximation of the mean precession of a fast top, ``Ω_slow = m g l / (I₃ ω₃)``, rad/s.

        Exact mean minus this is O(1/ω₃²) relatively for a top released with
        θ̇ = φ̇ = 0 (Goldstein §5.7). ``inf`` without spin.
        """
        return self.weight_torque / self.p_psi if self.p_psi != 0.0 else math.inf

    @property
    def fast_precession_rate(self) -> float:
        """``Ω_fast = I₃ ω₃ / (I₁ cos θ₀)``, rad/s: fast-top limit of the fast steady precession at θ₀.

        The nutation frequency ``2π/T`` of a fast top tends to ``I₃ ω₃ / I₁ = a``.
        ``±inf`` at θ₀ = π/2.
        """
        den = self.I1 * math.cos(self.theta0)
        return self.p_psi / den if den != 0.0 else math.copysign(math.inf, self.p_psi)

    def steady_precession_rates(self, theta) -> np.ndarray:
        """Exact steady-precession rates at angle θ (rad), shape (…, 2) ``[slow, fast]``, rad/s.

        Roots of ``I₁ cos θ φ̇² − I₃ ω₃ φ̇ + m g l = 0`` (θ̇ = θ̈ = 0, Goldstein
        §5.7), computed without cancellation: ``q = ½(I₃ω₃ + sgn(ω₃) √D)``,
        ``D = I₃²ω₃² − 4 I₁ m g l cos θ``, slow ``= m g l / q``, fast
        ``= q / (I₁ cos θ)`` (``±inf`` at θ = π/2). ``nan`` where ``D < 0``: no
        steady precession at that angle with this spin.
        """
        cos = np.cos(as_array(theta, "theta"))
        disc = self.p_psi**2 - 4.0 * self.I1 * self.weight_torque * cos
        root = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        q = 0.5 * (self.p_psi + math.copysign(1.0, self.p_psi) * root)
        with np.errstate(divide="ignore", invalid="ignore"):  # θ = π/2: fast = ±inf; no spin: q may be 0
            return np.stack([self.weight_torque / q, q / (self.I1 * cos)], axis=-1)

    # -- sleeping top -----------------------------------------------------------

    @property
    def critical_spin(self) -> float:
        """``ω_c = 2 √(I₁ m g l) / I₃``, rad/s: above it the upright (sleeping) top is stable."""
        return 2.0 * math.sqrt(self.I1 * self.weight_torque) / self.I3

    def is_sleeping_stable(self) -> bool:
        """Whether the upright top is stable at this spin: ``I₃² ω₃² > 4 I₁ m g l``."""
        return self.p_psi**2 > 4.0 * self.I1 * self.weight_torque

    # -- internals ----------------------------------------------------------------

    @cached_property
    def _u0(self) -> float:
        return math.cos(self.theta0)

    @cached_property
    def _d_north(self) -> float:
        """``1 − u₀ = 2 sin²(θ₀/2)``, without cancellation near θ₀ = 0."""
        return 2.0 * math.sin(0.5 * self.theta0) ** 2

    @cached_property
    def _d_south(self) -> float:
        """``1 + u₀ = 2 cos²(θ₀/2)``, without cancellation near θ₀ = π."""
        return 2.0 * math.cos(0.5 * self.theta0) ** 2

    @cached_property
    def _transverse_sq(self) -> float:
        """``θ̇² + φ̇² sin²θ`` at t = 0 (the transverse rate squared), rad²/s²."""
        return self.theta_dot0**2 + (self.phi_dot0 * math.sin(self.theta0)) ** 2

    @cached_property
    def _b_minus_au0(self) -> float:
        """``b − a u₀ = φ̇₀ sin²θ₀``, rad/s."""
        return self.phi_dot0 * math.sin(self.theta0) ** 2

    @cached_property
    def _b_minus_a(self) -> float:
        return self._b_minus_au0 - self.a * self._d_north

    @cached_property
    def _b_plus_a(self) -> float:
        return self._b_minus_au0 + self.a * self._d_south

    @cached_property
    def _x(self) -> tuple[float, float, float]:
        """Roots ``u_i − u₀`` of ``g(x) = f(u₀ + x) = f₀ + f₁x + f₂x² + βx³``, ascending.

        The coefficients come from the initial state, without the
        cancellation of expanding ``f`` about 0: ``f₀ = u̇₀² = sin²θ₀ θ̇₀²``,
        ``f₁ = f'(u₀) = −β sin²θ₀ − 2u₀(θ̇₀² + φ̇₀² sin²θ₀) + 2a φ̇₀ sin²θ₀``,
        ``f₂ = 2βu₀ − θ̇₀² − φ̇₀² sin²θ₀ − a²``. As ``g(0) = f₀ ≥ 0`` and
        ``g ≤ 0`` at the poles, ``u₁ − u₀ ∈ [−1 − u₀, 0]`` and
        ``u₂ − u₀ ∈ [0, 1 − u₀]`` are bracketed roots (Brent's method to
        rounding), and ``u₃`` follows from the sum of the roots, ``−f₂/β``.
        With ``f₀ = 0`` (θ̇₀ = 0, a turning point: steady precession and the
        sleeping top included) 0 is a root and the quadratic ``βx² + f₂x + f₁``
        gives the other two in closed form, so double roots are exact.
        """
        beta, s2 = self.beta, math.sin(self.theta0) ** 2
        f0 = s2 * self.theta_dot0**2
        f1 = -beta * s2 - 2.0 * self._u0 * self._transverse_sq + 2.0 * self.a * self._b_minus_au0
        f2 = 2.0 * beta * self._u0 - self._transverse_sq - self.a**2
        if f0 == 0.0:
            disc = max(f2 * f2 - 4.0 * beta * f1, 0.0)
            q = -0.5 * (f2 + math.copysign(math.sqrt(disc), f2))
            others = (q / beta, f1 / q) if q != 0.0 else (0.0, 0.0)
            low, middle, high = sorted((0.0, *others))
            return low, middle, high

        def g(x):
            return f0 + x * (f1 + x * (f2 + x * beta))

        x1 = _bracketed_root(g, -self._d_south, 0.0)
        x2 = _bracketed_root(g, self._d_north, 0.0)
        return x1, x2, -f2 / beta - x1 - x2

    @cached_property
    def _tau0(self) -> float:
        """Phase: ``sn²(τ₀) = (u₀ − u₁)/(u₂ − u₁)``, ``τ₀ = ±F(arcsin √· | m)`` signed as ``u̇₀ = −θ̇₀ sin θ₀``."""
        x1, x2, _ = self._x
        if x2 == x1:
            return 0.0
        s2, c2 = min(max(-x1 / (x2 - x1), 0.0), 1.0), min(max(x2 / (x2 - x1), 0.0), 1.0)  # sin², cos² of am τ₀
        tau0 = math.sqrt(s2) * float(elliprf(c2, 1.0 - self.modulus * s2, 1.0))  # F(arcsin √s2 | m)
        return -tau0 if self.theta_dot0 > 0.0 else tau0

    def _tau(self, t) -> np.ndarray:
        t = as_array(t, "t")
        return self.rate * t + self._tau0

    def _poles(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``(1 − u(t), 1 + u(t))`` without cancellation near either pole."""
        tau = self._tau(t)
        x1, x2, _ = self._x
        _, sn, _ = _reduced_jacobi(tau, self.modulus)
        sn2 = sn * sn
        return self._d_north - x1 - (x2 - x1) * sn2, self._d_south + x1 + (x2 - x1) * sn2

    def _pi_terms(self) -> list[tuple[float, float]]:
        """``(c, 1 − n)`` for the two partial fractions of φ̇, dropping a zero numerator.

        ``1 − n₊ = (1 − u₂)/(1 − u₁)`` and ``1 − n₋ = (1 + u₂)/(1 + u₁)``, without cancellation.
        """
        x1, x2, _ = self._x
        pairs = ((0.5 * self._b_minus_a, self._d_north - x1, self._d_north - x2),   # 1 − u₁, 1 − u₂
                 (0.5 * self._b_plus_a, self._d_south + x1, self._d_south + x2))    # 1 + u₁, 1 + u₂
        return [(half / at_u1, at_u2 / at_u1) for half, at_u1, at_u2 in pairs if half != 0.0]

    def _pi_integral(self, n_c: float, tau: np.ndarray) -> np.ndarray:
        """``∫₀^τ dτ'/(1 − n sn²τ') = Π(n; am τ | m)``, ``n_c = 1 − n``, continued past ``am τ = ±π/2``.

        ``Π(n; jπ + φ) = 2jΠ(n) + Π(n; φ)`` with ``|φ| ≤ π/2``, and
        ``Π(n; φ) = s R_F(c², 1 − m s², 1) + (n/3) s³ R_J(c², 1 − m s², 1, c² + n_c s²)``,
        ``s = sin φ = sn``, ``c = cos φ = cn`` (DLMF §19.25(i)).
        """
        m = self.modulus
        j, s, c = _reduced_jacobi(tau, m)
        c2, s2, n = c * c, s * s, 1.0 - n_c
        delta2 = 1.0 - m * s2
        partial = s * elliprf(c2, delta2, 1.0) + (n / 3.0) * s * s2 * elliprj(c2, delta2, 1.0, c2 + n_c * s2)
        return 2.0 * j * _complete_pi(n_c, m) + partial


# -- helpers ----------------------------------------------------------------------


def _bracketed_root(g, end: float, inner: float) -> float:
    """Root of ``g`` between ``inner`` (``g > 0``) and ``end`` (``g ≤ 0`` in exact arithmetic).

    Where rounding makes ``g(end)`` come out ≥ 0, ``end`` is a root to rounding.
    """
    if g(end) >= 0.0:
        return end
    lo, hi = sorted((end, inner))
    return brentq(g, lo, hi, xtol=np.finfo(float).tiny, rtol=4.0 * np.finfo(float).eps)


def _reduced_jacobi(tau: np.ndarray, m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(j, sn τ_r, cn τ_r)`` with ``τ = 2Kj + τ_r``, ``|τ_r| ≤ K`` (``sn²`` has period 2K; ``am τ = jπ + am τ_r``).

    For ``m = 1`` (``K = ∞``): ``j = 0``, ``sn = tanh``, ``cn = sech``.
    """
    k = float(ellipk(m))
    if not math.isfinite(k):
        return np.zeros_like(tau), np.tanh(tau), 1.0 / np.cosh(tau)
    j = np.round(tau / (2.0 * k))
    sn, cn, _, _ = ellipj(tau - 2.0 * k * j, m)
    return j, sn, cn


def _complete_pi(n_c: float, m: float) -> float:
    """``Π(n | m) = R_F(0, 1 − m, 1) + (n/3) R_J(0, 1 − m, 1, 1 − n)``, ``n_c = 1 − n`` (DLMF §19.25(i))."""
    return float(elliprf(0.0, 1.0 - m, 1.0) + (1.0 - n_c) / 3.0 * elliprj(0.0, 1.0 - m, 1.0, n_c))


def _angle_from_poles(north, south):
    """``θ = 2 atan2(√(1 − u), √(1 + u))`` from ``1 − u`` and ``1 + u``: accurate near both poles."""
    return 2.0 * np.arctan2(np.sqrt(np.maximum(north, 0.0)), np.sqrt(np.maximum(south, 0.0)))
