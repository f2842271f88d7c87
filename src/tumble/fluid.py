"""A rigid body in an ideal fluid: Kirchhoff's equations.

A rigid body moves through an unbounded, inviscid, incompressible fluid at
rest at infinity, in irrotational flow (Kirchhoff 1869; H. Lamb,
*Hydrodynamics*, 6th ed., 1932, §§ 117–126). The fluid's whole effect is an
*added mass*: its kinetic energy is a quadratic form in the body's velocities.
The body is **neutrally buoyant with coincident centres of mass and
buoyancy**: no gravity, no buoyancy moment, no other external force or
torque.

**Frames and velocities.** Body axes B, origin at the body's centre of mass
(which is also its centre of buoyancy; the added mass is taken about it).
``ω`` (rad/s) is the angular velocity and ``v`` (m/s) the velocity of the
origin, both relative to the fluid at infinity (inertial) and in body axes;
``q`` is the attitude (body → inertial, ``R(q)``), ``x`` (m, inertial axes)
the position of the origin.

**Kinetic energy and impulses.** The kinetic energy of body and fluid is
(Lamb §§ 117–121, with Kirchhoff's order: angular, then linear)::

    T = ½ ωᵀAω + ωᵀBv + ½ vᵀCv,     [[A, B], [Bᵀ, C]] = M_RB + M_A (reordered)

``M_RB = diag(m 1, I_B)`` is the body's own (mass ``m``, inertia ``I_B`` about
the centre of mass) and ``M_A`` the added mass, both given in Fossen's order
(*Handbook of Marine Craft Hydrodynamics and Motion Control*, 2011, ch. 6:
linear then angular: surge, sway, heave, roll, pitch, yaw), so that
``A = I_B + M_A[3:, 3:]`` (kg·m²), ``B = M_A[3:, :3]`` (kg·m),
``C = m 1 + M_A[:3, :3]`` (kg). ``M_A`` is the positive semi-definite matrix
of the fluid's energy ``½ νᵀ M_A ν`` (``ν = [v; ω]``), i.e. minus Fossen's
hydrodynamic derivatives (``M_A = −[[X_u̇, …]]``); the model needs
``M_RB + M_A`` positive definite (``T > 0`` for every motion). The impulses
(Lamb §§ 117–121: the impulsive wrench that would start the motion from rest) are::

    K = ∂T/∂ω = Aω + Bv     (angular, N·m·s, about the origin, body axes)
    P = ∂T/∂v = Bᵀω + Cv    (linear, N·s, body axes)

**Kirchhoff's equations** (Lamb §§ 123–124; ``d/dt`` of the components on the
moving body axes)::

    K̇ = K × ω + P × v,      Ṗ = P × ω,      q̇ = ½ q ⊗ [0, ω],      ẋ = R(q) v

The inertial impulses are constant, which these equations say:
``d/dt (R P) = R (ω × P + Ṗ) = 0`` and
``d/dt (R K + x × R P) = R (ω × K + K̇) + R v × R P = R (P × v + v × P) = 0``.
So are ``T`` (``Ṫ = ω·K̇ + v·Ṗ = ω·(P × v) + v·(P × ω) = 0``), ``|P|²`` and
``K·P`` (the Casimirs of the Lie–Poisson bracket on se(3)*).

**Exact reductions.** With ``B = 0`` and ``C = c 1`` (a sphere's added mass,
or none) ``P × v = c v × v = 0``: the rotation is Euler's free rigid body of
inertia ``A``, and ``R(q) v`` is constant (the origin moves on a straight
line at constant speed). Steady translation ``v = u e₁`` along a principal
axis of ``C`` (with ``B = 0``) is a relative equilibrium; with ``A``, ``C``
diagonal, a small pitch (``ω₂``, ``v₃``) obeys ``a₂ ω̇₂ = (c₃ − c₁) u v₃``,
``c₃ v̇₃ = c₁ u ω₂`` (Munk's moment), so it grows or oscillates as
``exp(λt)``, ``λ² = c₁ (c₃ − c₁) u² / (a₂ c₃)``: translation along the axis of
least total mass is unstable (Lamb § 126).

**The state** is ``[q, K, P, x]`` (13): the impulses rather than the
velocities, since the equations are explicit in them (the velocities are one
product with the inverse of the 6×6 matrix; the velocities as state would need
that product and the matrix itself at each evaluation), and the Casimirs and
the inertial impulse are functions of the state itself. The compiled
right-hand side: :mod:`tumble.kernels.fluid`.

**The added mass of an ellipsoid** (Lamb §§ 114–115) of semi-axes ``a, b, c``
along the body axes and fluid density ``ρ``, volume ``V = 4/3 π abc``, with
``α₀ = abc ∫₀^∞ dλ / ((a² + λ) Δ)``, ``Δ = √((a² + λ)(b² + λ)(c² + λ))``
(``β₀``, ``γ₀`` likewise; ``α₀ = ⅔ abc R_D(b², c², a²)``, Carlson's integral;
``α₀ + β₀ + γ₀ = 2``)::

    translation along x:  ρV α₀ / (2 − α₀)
    rotation about x:     ρV/5 · (b² − c²)² (γ₀ − β₀) / (2 (b² − c²) + (b² + c²)(β₀ − γ₀))

and cyclically: :func:`ellipsoid_added_mass`. A sphere's is ``½ ρV`` in
translation and none in rotation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._validate import ValidationError, as_array, require_positive
from tumble.kernels import fluid as _kernel
from tumble.rigid_body import RigidBody
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra, Trajectory

__all__ = ["KirchhoffBody", "ellipsoid_added_mass", "kirchhoff_matrix"]

#: Relative tolerances (of the largest |entry|) of the added mass's symmetry and of the smallest eigenvalue of the
#: kinetic-energy matrix.
_SYMMETRY_TOL = 1e-12
_DEFINITE_TOL = 1e-12

#: Fossen's order (linear, angular) → Kirchhoff's (angular, linear): the same reordering both ways.
_KIRCHHOFF_ORDER = np.array([3, 4, 5, 0, 1, 2])


def kirchhoff_matrix(fossen: ArrayLike) -> np.ndarray:
    """The 6×6 matrix ``[[A, B], [Bᵀ, C]]`` (angular, then linear) of a mass matrix in Fossen's order (linear,
    then angular: ``[[C, Bᵀ], [B, A]]``): the rows and columns swapped by halves."""
    M = np.asarray(fossen, dtype=np.float64)
    return M[np.ix_(_KIRCHHOFF_ORDER, _KIRCHHOFF_ORDER)]


def _check_added_mass(value: ArrayLike) -> np.ndarray:
    """``added_mass`` as a read-only (6, 6) array: finite, symmetric (to 1e-12 of its largest entry; then made
    exactly so), with a diagonal ≥ 0 (the fluid's energy of a motion along one axis is ≥ 0; a diagonal < 0 is
    a table of Fossen's hydrodynamic derivatives, ``X_u̇ = −M_A[0, 0]``, given by mistake)."""
    M = as_array(value, "added_mass")
    if M.shape != (6, 6):
        raise ValidationError(f"added_mass: must have shape (6, 6) (Fossen's order: surge, sway, heave, roll, "
                              f"pitch, yaw), got {M.shape}")
    scale = float(np.abs(M).max())
    asymmetry = float(np.abs(M - M.T).max())
    if asymmetry > _SYMMETRY_TOL * scale:
        raise ValidationError(f"added_mass: must be symmetric (an ideal fluid's added mass is), got max |M − Mᵀ| = "
                              f"{asymmetry:.3g}")
    M = 0.5 * (M + M.T)
    negative = np.flatnonzero(np.diagonal(M) < 0.0)
    if negative.size:
        k = int(negative[0])
        raise ValidationError(f"added_mass: its diagonal must be ≥ 0 (the added mass, M_A = −[X_u̇ …], not the "
                              f"hydrodynamic derivatives), got added_mass[{k}, {k}] = {M[k, k]:g}")
    M.setflags(write=False)
    return M


@dataclass(frozen=True, eq=False)
class KirchhoffBody(Model):
    """A rigid body in an ideal fluid (module docstring): ``KirchhoffBody(body, added_mass)``.

    body       : a :class:`tumble.RigidBody` with its ``mass`` (kg); its inertia is about the centre of mass,
                 the body origin (``com`` None or zero)
    added_mass : (6, 6) ``M_A`` in Fossen's order (surge, sway, heave, roll, pitch, yaw: kg, kg·m, kg·m²) about
                 the centre of mass, body axes: finite, symmetric, its diagonal ≥ 0, and ``M_RB + M_A`` positive
                 definite (an ideal fluid's ``M_A`` is positive semi-definite; a table measured or computed
                 otherwise may be slightly indefinite, which the total's energy allows)

    A model of :func:`tumble.simulate`: ``tumble.simulate(kbody, omega0=..., velocity0=..., t=...)``
    integrates Kirchhoff's equations (``dop853``, ``rk4``, ``cf4``; no torque: the body is free). Initial
    state: ``omega0`` (3,) rad/s and ``velocity0`` (3,) m/s (default zero), body axes; ``q0`` (4,) body →
    inertial (default identity); ``position0`` (3,) m, inertial (default zero); each with an optional
    leading batch axis. The :class:`~tumble.Trajectory` holds ``q``, ``omega``, the body's own ``inertia``,
    the extras ``velocity`` (m/s, body axes), ``angular_impulse`` ``K`` (N·m·s, body axes),
    ``linear_impulse`` ``P`` (N·s, body axes) and ``position`` ``x`` (m, inertial), and the totals of body
    and fluid: ``energy`` ``T`` (J) and ``momentum_body``, the angular impulse about the inertial origin in
    body axes, ``K + (Rᵀx) × P`` (N·m·s), so that ``momentum_inertial`` is ``R K + x × R P``.
    """

    body: RigidBody
    added_mass: np.ndarray

    torque = None

    def __post_init__(self):
        if not isinstance(self.body, RigidBody) or self.body.mass is None:
            raise ValidationError("body: must be a tumble.RigidBody with its mass (kg): the body's own mass "
                                  "matrix needs it")
        if self.body.com is not None and np.any(self.body.com != 0.0):
            raise ValidationError("body: its centre of mass must be the body origin (com None or zero): the "
                                  "added mass is taken about it, and the centres of mass and buoyancy coincide")
        object.__setattr__(self, "added_mass", _check_added_mass(self.added_mass))
        total = self.mass_matrix
        smallest = float(np.linalg.eigvalsh(total)[0])
        if not smallest > _DEFINITE_TOL * np.abs(total).max():
            raise ValidationError("added_mass: the body's mass matrix plus the added mass must be positive definite "
                                  f"(the kinetic energy of body and fluid), got the eigenvalue {smallest:.6g}")

    @property
    def mass_matrix(self) -> np.ndarray:
        """``M_RB + M_A`` (6, 6), Fossen's order (linear, angular), body axes: ``M_RB = diag(m 1, I_B)``."""
        assert self.body.mass is not None  # checked in __post_init__
        rigid = np.zeros((6, 6))
        rigid[:3, :3] = self.body.mass * np.eye(3)
        rigid[3:, 3:] = self.body.inertia
        return rigid + self.added_mass

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    attitude_in_state = True  # q = Y[0:4], omega = body_rate: made on the GPU with output="device"

    def state_fields(self) -> tuple[StateField, ...]:
        return (
            StateField("omega0", 3, "initial angular velocity, rad/s, body axes"),
            StateField("velocity0", 3, "initial velocity of the body origin (the centre of mass) through the fluid, "
                       "m/s, body axes", default=np.zeros(3)),
            StateField("q0", 4, "initial attitude, unit quaternion [w, x, y, z], body → inertial",
                       default=attitude.identity(), quaternion=True),
            StateField("position0", 3, "initial position of the body origin, m, inertial axes", default=np.zeros(3)),
        )

    def compile(self, torque: None, t0: float) -> _kernel.KirchhoffModel:
        """The compiled model (:class:`tumble.kernels.fluid.KirchhoffModel`): the inverse of the kinetic-energy
        matrix in Kirchhoff's order."""
        return _kernel.KirchhoffModel(mobility=np.linalg.inv(kirchhoff_matrix(self.mass_matrix)))

    def initial_states(self, kernel: _kernel.KirchhoffModel, values: dict[str, np.ndarray],
                       t0: float) -> np.ndarray:
        """``[q, K, P, x]`` (N, 13) with ``[K; P] = [[A, B], [Bᵀ, C]] [ω; v]``: the state of
        :mod:`tumble.kernels.fluid`."""
        impulses = np.concatenate([values["omega0"], values["velocity0"]], axis=1) @ kirchhoff_matrix(
            self.mass_matrix).T
        return np.concatenate([values["q0"], impulses, values["position0"]], axis=1)

    def outputs(self, kernel: _kernel.KirchhoffModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        q, impulses, x = states[..., :4], states[..., 4:10], states[..., 10:13]
        rates = impulses @ kernel.mobility.T
        omega, v, K, P = rates[..., :3], rates[..., 3:], impulses[..., :3], impulses[..., 3:]
        extras = {
            "velocity": Extra(v, ("body_axis",), "m/s", "velocity of the body origin through the fluid, body axes"),
            "angular_impulse": Extra(K, ("body_axis",), "N m s",
                                     "angular impulse K = A omega + B v of body and fluid about the body origin, "
                                     "body axes"),
            "linear_impulse": Extra(P, ("body_axis",), "N s",
                                    "linear impulse P = B^T omega + C v of body and fluid, body axes"),
            "position": Extra(x, ("inertial_axis",), "m", "position of the body origin, inertial axes"),
        }
        energy = 0.5 * (np.sum(omega * K, axis=-1) + np.sum(v * P, axis=-1))
        momentum = K + np.cross(attitude.rotate_inverse(q, x), P)
        return Outputs(q=q, omega=omega, inertia=self.body.inertia, extras=extras,
                       totals={"energy": energy, "momentum_body": momentum}, info={})

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """The integrals of Kirchhoff's equations: ``T``, the inertial impulses ``R K + x × R P``
        (``momentum_inertial``) and ``R P``, and the Casimirs ``|P|²`` and ``K·P``."""
        K, P = traj.angular_impulse, traj.linear_impulse
        return {"energy": traj.energy, "momentum_inertial": traj.momentum_inertial,
                "linear_impulse_inertial": attitude.rotate(cast(np.ndarray, traj.q), P),
                "impulse_squared": np.sum(P * P, axis=-1), "impulse_product": np.sum(K * P, axis=-1)}


def _alpha0(a: float, b: float, c: float) -> float:
    """Lamb's ``α₀ = abc ∫₀^∞ dλ / ((a² + λ) Δ) = ⅔ abc R_D(b², c², a²)`` of the semi-axis ``a`` (dimensionless)."""
    from scipy.special import elliprd

    return 2.0 / 3.0 * a * b * c * float(elliprd(b * b, c * c, a * a))


def _rotational(b: float, c: float, beta0: float, gamma0: float, volume_density: float) -> float:
    """Lamb's added moment of inertia (kg·m²) about the axis normal to semi-axes ``b``, ``c`` (§ 115)."""
    d = b * b - c * c
    if d == 0.0:  # a body of revolution about this axis displaces no fluid turning about it
        return 0.0
    return volume_density / 5.0 * d * d * (gamma0 - beta0) / (2.0 * d + (b * b + c * c) * (beta0 - gamma0))


def ellipsoid_added_mass(semi_axes: ArrayLike, density: float) -> np.ndarray:
    """The added mass ``M_A`` (6, 6; Fossen's order, diagonal) of an ellipsoid of ``semi_axes`` ``(a, b, c)`` (m,
    along the body axes x, y, z) in a fluid of ``density`` ``ρ`` (kg/m³): Lamb §§ 114–115 (module docstring)."""
    axes = as_array(semi_axes, "semi_axes")
    if axes.shape != (3,) or not np.all(axes > 0.0):
        raise ValidationError(f"semi_axes: must be three lengths > 0 (m), got {semi_axes!r}")
    rho = require_positive(density, "density")
    a, b, c = (float(s) for s in axes)
    mass = rho * 4.0 / 3.0 * np.pi * a * b * c  # the displaced fluid, kg
    alpha, beta, gamma = _alpha0(a, b, c), _alpha0(b, c, a), _alpha0(c, a, b)
    linear = [mass * k / (2.0 - k) for k in (alpha, beta, gamma)]
    angular = [_rotational(b, c, beta, gamma, mass), _rotational(c, a, gamma, alpha, mass),
               _rotational(a, b, alpha, beta, mass)]
    return np.diag(linear + angular)
