"""Fuel slosh: a rigid hub carrying a spherical pendulum, free-floating in space.

The liquid's sloshing mass is replaced by its classical mechanical analogue, a
spherical pendulum (Abramson (ed.), *The Dynamic Behavior of Liquids in Moving
Containers*, NASA SP-106, 1966, ch. 6; used for spinning spacecraft by Hill,
Baumgarten & Miller, *J. Guidance* 11(6), 1988): a point mass ``m`` on a
massless rod of length ``l`` hinged at ``b`` (body axes, from the hub's centre
of mass), with viscous friction at the hinge. The hub has mass ``M`` and
inertia ``I_B`` about its own centre of mass; the liquid that does not slosh
is part of the hub.

**Translation removed.** The spacecraft is free-floating: no external force,
so its total linear momentum is zero (in the frame of its centre of mass) and
the system centre of mass does not move. The hub's centre of mass and the
pendulum mass then move about it as a two-body problem: only their relative
position ``r = b + l s`` (``s`` the unit direction of the rod, body axes)
appears, carried by the reduced mass ``μ = m M / (m + M)`` (Goldstein,
*Classical Mechanics*, §3.1). Kinetic energy and angular momentum about the
system centre of mass (body axes)::

    T = ½ ω·I_B ω + ½ μ |ω × r + l ν × s|²
    H = I_B ω + μ r × (ω × r + l ν × s)

where ``ν`` (⊥ s) is the angular velocity of the rod relative to the hub,
``ṡ = ν × s``. The rod transmits the force ``F = μ a`` (``a`` the inertial
acceleration of ``r``) and the hinge friction torque ``−μ l² d ν`` (``d`` in
1/s); the pendulum's moment equation and the total moment equation are::

    μ l s × a = −μ l² d ν
    I_B ω̇ + ω × I_B ω + μ r × a = τ          (i.e. dH/dt + ω × H = τ)
    a = l ν̇ × s + ω̇ × r + l ν × (ν × s) + 2 ω × (l ν × s) + ω × (ω × r)

Solving the first for ``ν̇`` and substituting leaves a 3×3 system for ``ω̇``
with the matrix ``I_B + μ (r × s)(r × s)ᵀ`` (the pendulum adds inertia only
through the motion of its mass along the rod): :mod:`tumble.kernels.slosh`. The
inertial momentum ``R(q) H`` is conserved without torque (the friction torque
is internal), and ``Ṫ = ω·τ − μ l² d |ν|²``: with damping the energy
decreases monotonically while ``|H|`` stays constant, which drives a spinner
toward its axis of largest inertia (the energy-sink argument: Hughes,
*Spacecraft Attitude Dynamics*, Wiley 1986, ch. 5). With ``m = 0`` the hub
obeys Euler's equations exactly.

**Small oscillations under spin.** For a hub spinning at ``Ω`` about its axis
of inertia ``C`` with the hinge at distance ``ρ`` from the spin axis, in the
spin plane, and the rod pointing radially outward, the pendulum swings in the
spin plane at (Routh reduction of the planar motion; a centrifugal pendulum for
``C → ∞``)::

    σ² = Ω² (ρ / l) (C + μ (ρ + l)²) / C

relative to the hub: :func:`in_plane_frequency`.

A :class:`SloshBody` is a model of :func:`tumble.simulate` (its compiled
right-hand side: :mod:`tumble.kernels.slosh`); the trajectory's totals are
``T`` and ``H``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude, dynamics, torques
from tumble._moved import moved
from tumble._validate import ValidationError, as_array, require_non_negative, require_positive
from tumble.rigid_body import RigidBody
from tumble.kernels import slosh as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra, Trajectory

__all__ = ["Pendulum", "SloshBody", "energy", "momentum_body", "nutation_angle",
           "in_plane_frequency", "flat_spin_energy", "growth_time_constant", "steady_spin_eigenvalues"]

__getattr__ = moved(__name__, {"demo_slosh": "tumble.viz.slosh", "nutation_figure": "tumble.viz.slosh"})


@dataclass(frozen=True)
class Pendulum:
    """The pendulum analogue of a sloshing liquid.

    mass    : slosh mass ``m`` (kg), ≥ 0 (0: no slosh, the hub is a rigid body)
    length  : rod length ``l`` (m), > 0
    hinge   : (3,) hinge point from the hub's centre of mass (m, body axes)
    damping : hinge friction as a rate ``d`` (1/s), ≥ 0: the friction torque on the rod is
              ``−μ l² d ν`` (``μ`` the reduced mass, ``ν`` the rate relative to the hub)
    """

    mass: float
    length: float
    hinge: np.ndarray
    damping: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "mass", require_non_negative(self.mass, "mass"))
        object.__setattr__(self, "length", require_positive(self.length, "length"))
        object.__setattr__(self, "damping", require_non_negative(self.damping, "damping"))
        hinge = as_array(self.hinge, "hinge", tail=(3,))
        if hinge.ndim != 1:
            raise ValidationError(f"hinge: must have shape (3,), got {hinge.shape}")
        hinge = hinge.copy()  # frozen below: never the caller's array
        hinge.setflags(write=False)
        object.__setattr__(self, "hinge", hinge)


@dataclass(frozen=True)
class SloshBody(Model):
    """A hub (RigidBody with its mass: inertia about its own centre of mass, body axes) and a slosh pendulum.

    A model of :func:`tumble.simulate`: ``tumble.simulate(sbody, omega0=..., t=..., direction0=...)``
    integrates the equations of the module docstring (``dop853``, ``rk4`` or ``cf4``). Initial state:
    ``omega0`` (3,) hub rate, rad/s, body axes (required); ``q0`` (4,) hub attitude, body → inertial
    (default identity); ``direction0`` (3,) direction of the rod from the hinge, body axes (required,
    normalised); ``rate0`` (3,) angular velocity of the rod relative to the hub, rad/s, body axes
    (default zero; its component along the rod is removed); each with an optional leading batch
    axis. The :class:`~tumble.Trajectory` holds ``q``, ``omega`` and ``inertia`` of the hub, the
    extras ``pendulum_direction`` and ``pendulum_rate`` (n, [N,] 3), and the totals of the whole
    system about its centre of mass: ``energy`` ``T`` (:func:`energy`) and ``momentum_body``
    ``H`` (:func:`momentum_body`).
    """

    body: RigidBody
    pendulum: Pendulum

    torque = "external torque on the hub, body axes (N·m): a tumble.torques model or f(t, q, omega)"

    def __post_init__(self):
        if not isinstance(self.body, RigidBody) or self.body.mass is None:
            raise ValidationError("body: must be a tumble.RigidBody with its mass (kg): the reduced mass needs it")
        if not isinstance(self.pendulum, Pendulum):
            raise ValidationError(f"pendulum: must be a tumble.slosh.Pendulum, got {type(self.pendulum).__name__}")

    @property
    def reduced_mass(self) -> float:
        """``μ = m M / (m + M)`` (kg)."""
        m, M = self.pendulum.mass, self.body.mass
        assert M is not None  # checked in __post_init__
        return m * M / (m + M)

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    attitude_in_state = True  # q = Y[0:4], omega = body_rate: made on the GPU with output="device"

    def state_fields(self) -> tuple[StateField, ...]:
        return (
            StateField("omega0", 3, "initial hub rate, rad/s, body axes"),
            StateField("q0", 4, "initial hub attitude, unit quaternion [w, x, y, z], body → inertial",
                       default=attitude.identity(), quaternion=True),
            StateField("direction0", 3, "initial direction of the pendulum rod from its hinge, body axes "
                       "(normalised)"),
            StateField("rate0", 3, "initial angular velocity of the rod relative to the hub, rad/s, body axes "
                       "(its component along the rod is removed)", default=np.zeros(3)),
        )

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.SloshModel:
        """The compiled model (:class:`tumble.kernels.slosh.SloshModel`) under a torque on the hub (body axes)."""
        codes, params = torques.compile_program(torques.as_torque_model(torque), np.eye(3), offset=0)
        p = self.pendulum
        return _kernel.SloshModel(
            inertia=np.ascontiguousarray(self.body.inertia), inverse=np.linalg.inv(self.body.inertia),
            hinge=p.hinge.copy(), constants=np.array([self.reduced_mass, p.length, p.damping]),
            params=params[None, :], codes=codes,
        )

    def initial_states(self, kernel: _kernel.SloshModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """``[q, ω, s, ν]`` (N, 13) with ``s`` normalised and ``ν ⊥ s``: the state of :mod:`tumble.kernels.slosh`."""
        direction = values["direction0"]
        norm = np.linalg.norm(direction, axis=-1, keepdims=True)
        if np.any(norm == 0.0):
            raise ValidationError("direction0: must be a non-zero vector (it is normalised here)")
        s0 = direction / norm
        rate = values["rate0"]
        nu0 = rate - np.sum(rate * s0, axis=-1, keepdims=True) * s0
        return np.concatenate([values["q0"], values["omega0"], s0, nu0], axis=1)

    def outputs(self, kernel: _kernel.SloshModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        omega, s, nu = states[..., 4:7], states[..., 7:10], states[..., 10:13]
        extras = {
            "pendulum_direction": Extra(s, ("body_axis",), "1",
                                        "unit direction of the slosh pendulum from its hinge, body axes"),
            "pendulum_rate": Extra(nu, ("body_axis",), "rad/s",
                                   "angular velocity of the slosh pendulum relative to the hub, body axes"),
        }
        kinetic, momentum = _totals(self, omega, s, nu)
        return Outputs(q=states[..., :4], omega=omega, inertia=self.body.inertia, extras=extras,
                       totals={"energy": kinetic, "momentum_body": momentum}, info={})

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """Without torque the inertial momentum ``R(q) H``; without hinge damping too, the energy ``T``."""
        if traj.info.get("torque") != "none":
            return {}
        kept = {"momentum_inertial": traj.momentum_inertial}
        if self.pendulum.damping == 0.0:
            kept["energy"] = traj.energy
        return kept


def _totals(sbody: SloshBody, omega, s, nu) -> tuple[np.ndarray, np.ndarray]:
    """``T`` (J) and ``H`` (N·m·s, body axes) from the hub rate ω and the rod's ``s`` and ``ν`` (…, 3).

    With ``r = b + l s`` and its inertial velocity ``ṙ = ω × r + l ν × s`` (body axes):
    ``T = ½ ω·I_B ω + ½ μ |ṙ|²``, ``H = I_B ω + μ r × ṙ`` (module docstring).
    """
    p = sbody.pendulum
    r = p.hinge + p.length * s
    v = np.cross(omega, r) + p.length * np.cross(nu, s)
    mu = sbody.reduced_mass
    kinetic = dynamics.kinetic_energy(sbody.body.inertia, omega) + 0.5 * mu * np.sum(v * v, axis=-1)
    return kinetic, dynamics.angular_momentum(sbody.body.inertia, omega) + mu * np.cross(r, v)


def momentum_body(sbody: SloshBody, trajectory: Trajectory) -> np.ndarray:
    """Total angular momentum about the system centre of mass, ``I_B ω + μ r × ṙ`` (N·m·s, body axes).

    ``trajectory.momentum_body`` of a run of ``sbody`` holds the same numbers.
    """
    return _totals(sbody, trajectory.omega, trajectory.pendulum_direction, trajectory.pendulum_rate)[1]


def energy(sbody: SloshBody, trajectory: Trajectory) -> np.ndarray:
    """Total kinetic energy ``½ ω·I_B ω + ½ μ |ṙ|²`` (J), shape (n, [N]).

    ``trajectory.energy`` of a run of ``sbody`` holds the same numbers.
    """
    return _totals(sbody, trajectory.omega, trajectory.pendulum_direction, trajectory.pendulum_rate)[0]


def nutation_angle(sbody: SloshBody, trajectory: Trajectory, axis: ArrayLike = (0.0, 0.0, 1.0)) -> np.ndarray:
    """Angle (rad) between the body ``axis`` (the nominal spin axis) and the total angular momentum."""
    axis = as_array(axis, "axis", tail=(3,))
    h = momentum_body(sbody, trajectory)
    cos = h @ axis / (np.linalg.norm(h, axis=-1) * np.linalg.norm(axis))
    return np.arccos(np.clip(cos, -1.0, 1.0))


def in_plane_frequency(spin: float, hinge_radius: float, length: float, axial_inertia: float,
                       reduced_mass: float) -> float:
    """Small in-plane swing frequency ``σ`` (rad/s, relative to the hub) of a pendulum in a spinning hub.

    ``σ² = Ω² (ρ/l) (C + μ (ρ + l)²) / C`` (module docstring): spin ``Ω`` (rad/s) about the
    axis of inertia ``C`` (kg·m²), hinge at ``ρ`` (m) from the spin axis in the spin plane, rod
    of length ``l`` (m) pointing radially outward, reduced mass ``μ`` (kg).
    """
    C = axial_inertia
    return abs(spin) * math.sqrt(hinge_radius / length * (C + reduced_mass * (hinge_radius + length) ** 2) / C)


def steady_spin_eigenvalues(sbody: SloshBody, omega: ArrayLike, direction: ArrayLike) -> np.ndarray:
    """Eigenvalues (1/s) of the torque-free motion linearised about a steady spin, largest real part first.

    The steady spin (a relative equilibrium) has the hub rate ``omega`` (rad/s, body axes) and the
    rod at rest relative to the hub along ``direction`` (body axes); it is refused unless the
    right-hand side vanishes there (to 1e-9 of ``|ω|²``). The Jacobian of ``(ω̇, ṡ, ν̇)`` with respect
    to ``(ω, s, ν)`` is taken by central differences (step 1e-6 of ``|ω|``) of the compiled
    right-hand side. A positive real part is an unstable spin: small nutation grows as
    ``exp(Re λ t)``; two zero eigenvalues belong to the constraints ``|s| = 1``, ``s·ν = 0``.
    """
    omega = as_array(omega, "omega", tail=(3,))
    direction = as_array(direction, "direction", tail=(3,))
    scale = float(np.linalg.norm(omega))
    if omega.ndim != 1 or direction.ndim != 1 or scale == 0.0 or not np.linalg.norm(direction) > 0.0:
        raise ValidationError("omega, direction: must be non-zero vectors of shape (3,)")
    model = sbody.compile(None, 0.0)
    state = np.zeros(_kernel.STATE_SIZE)
    state[0], state[4:7], state[7:10] = 1.0, omega, direction / np.linalg.norm(direction)

    def rate(x):
        y, out = state.copy(), np.empty(_kernel.STATE_SIZE)
        y[4:] = x
        _kernel.derivative(model, 0.0, y, out)
        return out[4:]

    x0 = state[4:].copy()
    residual = float(np.abs(rate(x0)).max())
    if residual > 1e-9 * scale**2:
        raise ValidationError(f"omega, direction: not a steady spin (|dy/dt| = {residual:.3g} there)")
    step = 1e-6 * scale
    columns = [(rate(x0 + step * e) - rate(x0 - step * e)) / (2.0 * step) for e in np.eye(x0.size)]
    eigenvalues = np.linalg.eigvals(np.stack(columns, axis=1))
    return eigenvalues[np.argsort(-eigenvalues.real, kind="stable")]


#: The demo spinner: a prolate hub spinning about its minor axis z with a tank off the axis.
DEMO_BODY = SloshBody(
    body=RigidBody(np.diag([600.0, 600.0, 300.0]), mass=900.0),
    pendulum=Pendulum(mass=60.0, length=0.6, hinge=np.array([0.2, 0.0, 0.0]), damping=1.0),
)
_FIT_RANGE = (math.radians(2.0), math.radians(20.0))  # nutation angles of the exponential fit (rad)


def growth_time_constant(t: np.ndarray, angle: np.ndarray, bounds: tuple[float, float] = _FIT_RANGE) -> float:
    """Time constant ``τ`` (s) of ``angle ∝ exp(t/τ)``: a least-squares line through ``log(angle)``
    over the samples with ``bounds[0] ≤ angle ≤ bounds[1]`` (rad), before the angle first exceeds ``bounds[1]``."""
    end = np.argmax(angle > bounds[1]) if np.any(angle > bounds[1]) else angle.size
    keep = np.flatnonzero(angle[:end] >= bounds[0])
    if keep.size < 3:
        raise ValidationError(f"angle: fewer than 3 samples in {bounds} rad to fit an exponential growth")
    slope = np.polyfit(t[keep], np.log(angle[keep]), 1)[0]
    return float(1.0 / slope)


def flat_spin_energy(sbody: SloshBody, momentum_norm: float) -> float:
    """``|H|²/(2 I_max)`` (J): the energy of a flat spin at momentum ``|H|`` (N·m·s), a rotation about the
    largest principal axis of the hub frozen with its rod pointing radially out from the hinge
    (``r = b + l b/|b|``, ``I_max`` the largest eigenvalue of ``I_B + μ (|r|² 1 − r rᵀ)``): the state
    that dissipation drives the demo spinner to."""
    b = sbody.pendulum.hinge
    r = b * (1.0 + sbody.pendulum.length / np.linalg.norm(b))
    frozen = sbody.body.inertia + sbody.reduced_mass * (r @ r * np.eye(3) - np.outer(r, r))
    return float(momentum_norm**2 / (2.0 * np.linalg.eigvalsh(frozen)[-1]))


