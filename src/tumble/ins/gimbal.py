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
Lagrange's equations::

    I_s ω̇₃ = −c_s ψ̇,                                        ψ̇ = ω₃ − φ̇ cos θ
    P θ̈ = ½ Q'(θ) φ̇² − I_s ω₃ φ̇ sin θ + m g l sin θ + τ_θ,   Q' = 2 (B + I_t − C) sin θ cos θ
    Q φ̈ = τ_φ − c_φ φ̇ − Q' θ̇ φ̇ − I_s ω̇₃ cos θ + I_s ω₃ θ̇ sin θ

With massless gimbals (A = B = C = J = 0) these are the heavy top's
(Goldstein §5.7; tested against ``tumble.simulate``). At ``θ = π/2`` a
steady precession under the torquer has ``φ̇ = τ_θ / (I_s ω₃)`` exactly, the
gimbal inertia notwithstanding; linearised about it, the nutation frequency is

    ω_n = I_s ω₃ / √(P Q(π/2)) = I_s ω₃ / √((A + I_t)(J + B + I_t)).

State for the integrators (:mod:`tumble._protocol`): ``[q_G (4), φ̇, θ̇, ω₃, ψ]``,
``q_G`` the attitude of the inner gimbal (``q̇_G = ½ q_G ⊗ ω_G``), from
which ``sin θ = R_G[2, 1]``, ``cos θ = R_G[2, 2]``, ``φ = atan2(R_G[1, 0], R_G[0, 0])``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from tumble import _protocol, _quat, attitude, integrate
from tumble._validate import ValidationError, require_non_negative, require_positive
from tumble.trajectory import Trajectory

__all__ = ["GimbalMotion", "GimbaledGyro"]

STATE_SIZE = 8
# parameter row: I_t, I_s, A, B, C, J, m g l, τ_θ, τ_φ, c_φ, c_s
_N_PARAMS = 11


class GimbalModel(NamedTuple):
    """Compiled parameters of a gimbaled gyro: ``params`` (1, 11) = I_t, I_s, A, B, C, J, m g l, τ_θ, τ_φ, c_φ, c_s."""

    params: np.ndarray

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side."""
        return frozenset({"rhs"})

    @property
    def calls_python(self) -> bool:
        """False: the gimbal equations run compiled."""
        return False


@njit(inline="always")
def _derivative(p, qw, qx, qy, qz, phi_dot, theta_dot, spin):
    """d/dt of the state (the equations of the module docstring); ψ does not enter."""
    It, Is, A, B, C, J, mgl, tau_theta, tau_phi, c_phi, c_spin = (
        p[0, 0], p[0, 1], p[0, 2], p[0, 3], p[0, 4], p[0, 5], p[0, 6], p[0, 7], p[0, 8], p[0, 9], p[0, 10])
    n2 = qw * qw + qx * qx + qy * qy + qz * qz
    s = 2.0 * (qy * qz + qw * qx) / n2           # R_G[2, 1] = sin θ
    c = 1.0 - 2.0 * (qx * qx + qy * qy) / n2     # R_G[2, 2] = cos θ
    psi_dot = spin - phi_dot * c
    spin_dot = -c_spin * psi_dot / Is
    P = A + It
    Q = J + (B + It) * s * s + C * c * c
    dQ = 2.0 * (B + It - C) * s * c
    theta_ddot = (0.5 * dQ * phi_dot * phi_dot - Is * spin * phi_dot * s + mgl * s + tau_theta) / P
    phi_ddot = (tau_phi - c_phi * phi_dot - dQ * theta_dot * phi_dot - Is * spin_dot * c
                + Is * spin * theta_dot * s) / Q
    d = _quat.qmul(qw, qx, qy, qz, 0.0, theta_dot, phi_dot * s, phi_dot * c)
    return 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3], phi_ddot, theta_ddot, spin_dot, psi_dot


@overload(_protocol.rhs, inline="always", jit_options={"cache": True})
def _gimbal_rhs(model, b0, t, Y, OUT):
    if not _protocol.is_type(model, GimbalModel):
        return None
    if Y.ndim == 1:

        def impl(model, b0, t, Y, OUT):
            (OUT[0], OUT[1], OUT[2], OUT[3], OUT[4], OUT[5], OUT[6], OUT[7]) = _derivative(
                model.params, Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6])

    else:

        def impl(model, b0, t, Y, OUT):
            for j in range(Y.shape[1]):
                (OUT[0, j], OUT[1, j], OUT[2, j], OUT[3, j], OUT[4, j], OUT[5, j], OUT[6, j], OUT[7, j]) = (
                    _derivative(model.params, Y[0, j], Y[1, j], Y[2, j], Y[3, j], Y[4, j], Y[5, j], Y[6, j]))

    return impl


@overload(_protocol.project, inline="always", jit_options={"cache": True})
def _gimbal_project(model, b0, t, Y):
    if not _protocol.is_type(model, GimbalModel):
        return None
    return _protocol.quaternion_projection(Y)


@overload(_protocol.state_size, jit_options={"cache": True})
def _gimbal_state_size(model):
    if not _protocol.is_type(model, GimbalModel):
        return None
    return lambda model: STATE_SIZE


@dataclass(frozen=True)
class GimbalMotion:
    """A simulated gimbaled gyro: gimbal angles and rates (rad, rad/s) at ``t`` (s), and the rotor's motion.

    ``rotor`` is a Trajectory of the rotor (attitude ``R_G R_z(ψ)``, body rate in
    rotor axes, inertia ``diag(I_t, I_t, I_s)`` about the gimbal centre).
    """

    t: np.ndarray
    phi: np.ndarray
    theta: np.ndarray
    psi: np.ndarray
    phi_dot: np.ndarray
    theta_dot: np.ndarray
    spin: np.ndarray
    rotor: Trajectory



@dataclass(frozen=True)
class GimbaledGyro:
    """A symmetric rotor in a two-axis gimbal (module docstring); SI units.

    spin_inertia, transverse_inertia : I_s, I_t of the rotor about the gimbal centre, kg·m²
    inner_gimbal : (A, B, C), moments of the inner ring in G axes, kg·m² (A about its pivot axis)
    outer_gimbal : J, moment of the outer gimbal about the vertical, kg·m²
    imbalance : m g l, gravity torque of the rotor's offset centre of mass on a horizontal axis, N·m
    inner_torque, outer_torque : τ_θ, τ_φ, torquers on the inner and outer gimbal axes, N·m
    outer_friction, spin_friction : c_φ, c_s, viscous coefficients, N·m·s
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

    def simulate(self, t, *, spin: float, theta0: float = math.pi / 2, phi_dot0: float = 0.0,
                 theta_dot0: float = 0.0, method: str = "dop853", rtol: float = 1e-12, atol: float = 1e-12,
                 dt: float | None = None) -> GimbalMotion:
        """Integrate from ``φ = ψ = 0``, ``θ = theta0`` with rates ``phi_dot0``, ``theta_dot0`` and spin ω₃.

        Runs on :func:`tumble.integrate.solve` (any method that takes a torque).
        """
        times = np.asarray(t, dtype=np.float64)
        spin = float(spin)
        if not math.isfinite(spin) or spin == 0.0:
            raise ValidationError(f"spin: must be a finite non-zero rate (rad/s), got {spin}")
        A, B, C = self.inner_gimbal
        params = np.array([[self.transverse_inertia, self.spin_inertia, A, B, C, self.outer_gimbal,
                            self.imbalance, self.inner_torque, self.outer_torque, self.outer_friction,
                            self.spin_friction]])
        y0 = np.zeros((1, STATE_SIZE))
        y0[0, :4] = attitude.from_euler("ZXZ", [0.0, float(theta0), 0.0])
        y0[0, 4:7] = phi_dot0, theta_dot0, spin
        solution = integrate.solve(GimbalModel(params), y0, times, method=method, dt=dt, rtol=rtol,
                                        atol=atol)
        states, stats = solution.states, solution.statistics()
        y = states[:, 0]
        R = attitude.to_matrix(y[:, :4])
        phi = np.unwrap(np.arctan2(R[:, 1, 0], R[:, 0, 0]))
        theta = np.arctan2(R[:, 2, 1], R[:, 2, 2])
        psi = y[:, 7]
        q_spin = attitude.from_rotvec(np.stack([np.zeros_like(psi), np.zeros_like(psi), psi], axis=-1))  # R_z(ψ)
        omega_g = np.stack([y[:, 5], y[:, 4] * np.sin(theta), y[:, 6]], axis=-1)  # rotor rate in G axes
        rotor = Trajectory(t=times, q=attitude.multiply(y[:, :4], q_spin),
                           omega=attitude.rotate_inverse(q_spin, omega_g),
                           inertia=np.diag([self.transverse_inertia, self.transverse_inertia, self.spin_inertia]),
                           method=method, info=dict(stats))
        return GimbalMotion(t=times, phi=phi, theta=theta, psi=psi, phi_dot=y[:, 4], theta_dot=y[:, 5],
                            spin=y[:, 6], rotor=rotor)
