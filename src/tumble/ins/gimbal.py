"""A gyro rotor in a two-axis gimbal (Cardan suspension) with gimbal inertia: Lagrange's equations.

Angles (the z-x-z Euler angles of :class:`~tumble.analytic.HeavyTop`):
``φ`` turns the outer gimbal about the inertial vertical z; ``θ`` turns the
inner gimbal about the outer gimbal's horizontal axis (the line of nodes),
so that ``θ`` is the angle of the spin axis from the upward vertical; ``ψ``
turns the rotor about the spin axis relative to the inner gimbal. The inner
gimbal frame G has ``R_G = R_z(φ) R_x(θ)``, the rotor ``R_R = R_G R_z(ψ)``;
the angular velocity of G in G axes is ``(θ̇, φ̇ sin θ, φ̇ cos θ)``.

Inertias about the common centre of the gimbals (kg·m²): the rotor
``(I_t, I_t, I_s)`` in G axes; the inner gimbal ring ``(A, B, C)`` in G axes
(A about its pivot axis, the line of nodes); the outer gimbal ``J`` about
the vertical. With the rotor's absolute spin ``ω₃ = ψ̇ + φ̇ cos θ``::

    T = ½ J φ̇² + ½ A θ̇² + ½ (B sin²θ + C cos²θ) φ̇² + ½ I_t (θ̇² + φ̇² sin²θ) + ½ I_s ω₃²
      = ½ P θ̇² + ½ Q(θ) φ̇² + ½ I_s ω₃²,     P = A + I_t,   Q = J + (B + I_t) sin²θ + C cos²θ
    V = m g l cos θ                      (rotor centre of mass at l along the spin axis)

Generalised forces: ``τ_θ`` (a torquer on the inner gimbal axis), ``τ_φ − c_φ φ̇``
(a torquer and viscous friction on the outer axis), ``−c_s ψ̇`` (viscous
spin-bearing friction, on the rotor's rate relative to the inner gimbal).
Lagrange's equations (the compiled model: :mod:`tumble.kernels.gimbal`)::

    I_s ω̇₃ = −c_s ψ̇,                                        ψ̇ = ω₃ − φ̇ cos θ
    P θ̈ = ½ Q'(θ) φ̇² − I_s ω₃ φ̇ sin θ + m g l sin θ + τ_θ,   Q' = 2 (B + I_t − C) sin θ cos θ
    Q φ̈ = τ_φ − c_φ φ̇ − Q' θ̇ φ̇ − I_s ω̇₃ cos θ + I_s ω₃ θ̇ sin θ

With massless gimbals (A = B = C = J = 0) these are the heavy top's
(Goldstein §5.7; tested against ``tumble.simulate`` of the :class:`Gyroscope`).
At ``θ = π/2`` a steady precession under the torquer has ``φ̇ = τ_θ / (I_s ω₃)``
exactly, the gimbal inertia notwithstanding; linearised about it, the nutation
frequency is

    ω_n = I_s ω₃ / √(P Q(π/2)) = I_s ω₃ / √((A + I_t)(J + B + I_t)).

**Invariants.** ``Ė = τ_θ θ̇ + (τ_φ − c_φ φ̇) φ̇ − c_s ψ̇²`` for ``E = T + V``:
the energy is conserved without torquers and friction. ``φ`` is cyclic, so
its momentum ``p_φ = ∂T/∂φ̇ = Q φ̇ + I_s ω₃ cos θ`` (the vertical component of
the angular momentum of rotor and gimbals, N·m·s) obeys ``ṗ_φ = τ_φ − c_φ φ̇``:
it is conserved without the outer torquer and friction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tumble import attitude
from tumble._validate import ValidationError, require_non_negative, require_positive
from tumble.kernels import gimbal as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra, Trajectory
from tumble.torques import TorqueLike

__all__ = ["GimbaledGyro"]

# Extras of the trajectory: name, units, description.
_ANGLES = (
    ("phi", "rad", "outer gimbal angle phi about the upward vertical (unwrapped)"),
    ("theta", "rad", "inner gimbal angle theta: the spin axis from the upward vertical"),
    ("psi", "rad", "rotor angle psi about the spin axis, relative to the inner gimbal"),
    ("phi_dot", "rad/s", "outer gimbal rate dphi/dt"),
    ("theta_dot", "rad/s", "inner gimbal rate dtheta/dt"),
    ("spin", "rad/s", "absolute spin of the rotor omega_3 = dpsi/dt + dphi/dt cos(theta)"),
)


@dataclass(frozen=True)
class GimbaledGyro(Model):
    """A symmetric rotor in a two-axis gimbal (module docstring); SI units; a model of :func:`tumble.simulate`.

    spin_inertia, transverse_inertia : I_s, I_t of the rotor about the gimbal centre, kg·m²
    inner_gimbal : (A, B, C), moments of the inner ring in G axes, kg·m² (A about its pivot axis)
    outer_gimbal : J, moment of the outer gimbal about the vertical, kg·m²
    imbalance : m g l, gravity torque of the rotor's offset centre of mass on a horizontal axis, N·m
    inner_torque, outer_torque : τ_θ, τ_φ, torquers on the inner and outer gimbal axes, N·m
    outer_friction, spin_friction : c_φ, c_s, viscous coefficients, N·m·s

    ``tumble.simulate(gyro, t=..., spin=..., theta0=..., phi_dot0=..., theta_dot0=...)``
    integrates Lagrange's equations from ``φ = ψ = 0`` (``dop853`` or ``rk4``; the
    torquers are parameters, so ``torque=`` is refused). Initial state, each a number
    or a batch (N, 1): ``spin`` ω₃ (rad/s, non-zero, required), ``theta0`` (rad,
    default π/2: the spin axis horizontal), ``phi_dot0``, ``theta_dot0`` (rad/s,
    default 0; ``phi_dot0=gyro.precession_rate(spin)`` starts a horizontal axis in
    steady precession). The :class:`~tumble.Trajectory` is the rotor's: ``q`` =
    ``R_G R_z(ψ)``, ``omega`` its body rate in rotor axes, ``inertia`` =
    ``diag(I_t, I_t, I_s)`` about the gimbal centre; extras ``phi``, ``theta``,
    ``psi``, ``phi_dot``, ``theta_dot``, ``spin``; total ``energy`` ``E = T + V`` of
    rotor and gimbals. (The total angular momentum is not given: its horizontal
    part needs the outer gimbal's products of inertia, which the model does not
    have; ``momentum_body`` is the rotor's ``I ω``.)
    """

    spin_inertia: float
    transverse_inertia: float
    inner_gimbal: tuple[float, float, float] = (0.0, 0.0, 0.0)
    outer_gimbal: float = 0.0
    imbalance: float = 0.0
    inner_torque: float = 0.0
    outer_torque: float = 0.0
    outer_friction: float = 0.0
    spin_friction: float = 0.0

    torque = None  # the torquers are the parameters inner_torque and outer_torque

    def __post_init__(self):
        for name in ("spin_inertia", "transverse_inertia"):
            object.__setattr__(self, name, require_positive(getattr(self, name), name))
        ring = tuple(require_non_negative(v, f"inner_gimbal[{i}]") for i, v in enumerate(self.inner_gimbal))
        if len(ring) != 3:
            raise ValidationError(f"inner_gimbal: must be three moments (A, B, C), got {len(ring)}")
        object.__setattr__(self, "inner_gimbal", ring)
        for name in ("outer_gimbal", "outer_friction", "spin_friction"):
            object.__setattr__(self, name, require_non_negative(getattr(self, name), name))
        for name in ("imbalance", "inner_torque", "outer_torque"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValidationError(f"{name}: must be finite, got {value}")
            object.__setattr__(self, name, value)

    def nutation_frequency(self, spin: float) -> float:
        """``I_s ω₃ / √((A + I_t)(J + B + I_t))`` (rad/s), linearised about a horizontal spin axis."""
        A, B, _ = self.inner_gimbal
        It = self.transverse_inertia
        return abs(self.spin_inertia * spin) / math.sqrt((A + It) * (self.outer_gimbal + B + It))

    def precession_rate(self, spin: float) -> float:
        """Steady precession of a horizontal spin axis, ``(τ_θ + m g l) / (I_s ω₃)`` (rad/s, about +z)."""
        return (self.inner_torque + self.imbalance) / (self.spin_inertia * spin)

    def energy(self, theta: float | np.ndarray, phi_dot: float | np.ndarray, theta_dot: float | np.ndarray,
               spin: float | np.ndarray) -> np.ndarray:
        """``E = ½ P θ̇² + ½ Q(θ) φ̇² + ½ I_s ω₃² + m g l cos θ`` (J) of rotor and gimbals, broadcast."""
        A, B, C = self.inner_gimbal
        s, c = np.sin(theta), np.cos(theta)
        Q = self.outer_gimbal + (B + self.transverse_inertia) * s * s + C * c * c
        return (0.5 * (A + self.transverse_inertia) * theta_dot**2 + 0.5 * Q * phi_dot**2
                + 0.5 * self.spin_inertia * spin**2 + self.imbalance * c)

    def vertical_momentum(self, theta: float | np.ndarray, phi_dot: float | np.ndarray,
                          spin: float | np.ndarray) -> np.ndarray:
        """``p_φ = Q(θ) φ̇ + I_s ω₃ cos θ`` (N·m·s): the vertical angular momentum of rotor and gimbals, broadcast."""
        _, B, C = self.inner_gimbal
        s, c = np.sin(theta), np.cos(theta)
        Q = self.outer_gimbal + (B + self.transverse_inertia) * s * s + C * c * c
        return Q * phi_dot + self.spin_inertia * spin * c

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    def state_fields(self) -> tuple[StateField, ...]:
        return (
            StateField("spin", 1, "absolute spin of the rotor omega_3, rad/s (non-zero)"),
            StateField("theta0", 1, "initial angle of the spin axis from the upward vertical, rad",
                       default=math.pi / 2),
            StateField("phi_dot0", 1, "initial outer gimbal rate (precession about the vertical), rad/s", default=0.0),
            StateField("theta_dot0", 1, "initial inner gimbal rate, rad/s", default=0.0),
        )

    def compile(self, torque: TorqueLike, t0: float) -> _kernel.GimbalModel:
        A, B, C = self.inner_gimbal
        return _kernel.GimbalModel(np.array([[self.transverse_inertia, self.spin_inertia, A, B, C, self.outer_gimbal,
                                              self.imbalance, self.inner_torque, self.outer_torque,
                                              self.outer_friction, self.spin_friction]]))

    def initial_states(self, kernel: _kernel.GimbalModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """``[q_G, φ̇, θ̇, ω₃, ψ = 0]`` (N, 8) with ``q_G`` the z-x-z rotation (0, θ₀, 0)."""
        spin = values["spin"][:, 0]
        if not np.all(np.isfinite(spin) & (spin != 0.0)):
            raise ValidationError(f"spin: must be a finite non-zero rate (rad/s), got {spin.tolist()}")
        theta0 = values["theta0"][:, 0]
        y0 = np.zeros((theta0.size, _kernel.STATE_SIZE))
        y0[:, :4] = attitude.from_euler("ZXZ", np.stack([np.zeros_like(theta0), theta0, np.zeros_like(theta0)], -1))
        y0[:, 4], y0[:, 5], y0[:, 6] = values["phi_dot0"][:, 0], values["theta_dot0"][:, 0], spin
        return y0

    def outputs(self, kernel: _kernel.GimbalModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        R = attitude.to_matrix(states[..., :4])
        phi = np.unwrap(np.arctan2(R[..., 1, 0], R[..., 0, 0]), axis=0)
        theta = np.arctan2(R[..., 2, 1], R[..., 2, 2])
        phi_dot, theta_dot, spin, psi = states[..., 4], states[..., 5], states[..., 6], states[..., 7]
        q_spin = attitude.from_rotvec(np.stack([np.zeros_like(psi), np.zeros_like(psi), psi], axis=-1))  # R_z(ψ)
        omega_g = np.stack([theta_dot, phi_dot * np.sin(theta), spin], axis=-1)  # rotor rate in G axes
        values = dict(phi=phi, theta=theta, psi=psi, phi_dot=phi_dot, theta_dot=theta_dot, spin=spin)
        extras = {name: Extra(values[name], (), units, description) for name, units, description in _ANGLES}
        return Outputs(q=attitude.multiply(states[..., :4], q_spin), omega=attitude.rotate_inverse(q_spin, omega_g),
                       inertia=np.diag([self.transverse_inertia, self.transverse_inertia, self.spin_inertia]),
                       extras=extras, totals={"energy": self.energy(theta, phi_dot, theta_dot, spin)}, info={})

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """``E`` without torquers and friction; ``p_φ`` without the outer torquer and friction (module docstring)."""
        kept = {}
        if not (self.outer_torque or self.outer_friction):
            kept["momentum_vertical"] = self.vertical_momentum(traj.theta, traj.phi_dot, traj.spin)
            if not (self.inner_torque or self.spin_friction):
                kept["energy"] = traj.energy
        return kept
