"""Mechanical gyroscopes: a spinning symmetric rotor on a pivot, simulated with Euler's equations.

The rotor (axial moment ``I_s``, transverse moment ``I_t`` about the pivot,
kg·m²) spins at ``ω_s`` (rad/s) about its symmetry axis, body z. Its angular
momentum is ``H ≈ I_s ω_s`` along the spin axis, and a torque ``τ``
perpendicular to the axis turns it (precession) rather than tilting it::

    Ω_p = τ / (I_s ω_s)                                              (rad/s)

released from rest the axis also *nutates*, a fast small coning at

    ω_n = I_s ω_s / I_t                                              (rad/s)

(Goldstein, Poole, Safko, *Classical Mechanics*, 3rd ed., §5.7; Titterton &
Weston, *Strapdown Inertial Navigation Technology*, 2nd ed., ch. 4). These
are the fast-top limits of the exact heavy top (:class:`tumble.analytic.HeavyTop`):
for a horizontal axis the steady precession rate is *exactly* ``τ/(I_s ω_s)``,
and a rotor released at rest precesses on average at
``τ/(I_s ω_s) (1 − 2ε² + …)`` with nutation period
``2π/ω_n (1 − 3ε² + …)``, ``ε = τ I_t / (I_s ω_s)²`` (measured from the
exact solution; ``docs/ins.md``). Drift sources of a gyro built this way:

* **mass imbalance** — the centre of mass at ``offset`` ``l`` from the pivot
  along the spin axis: gravity exerts ``τ = m g l sin θ`` (``tumble.torques.Gravity``)
  and the axis drifts in azimuth at ``m g l / (I_s ω_s)``;
* **spin-bearing friction** — a Coulomb drag torque ``τ_f`` on the spin axis
  (``ConstantBody``): the spin decays, ``ω_s(t) = ω_s0 − τ_f t / I_s``, and
  the imbalance drift grows; the azimuth turned is
  ``φ(t) = (m g l / τ_f) ln(ω_s0 / ω_s(t))``;
* **pivot friction** — a torque ``τ_p`` about the vertical opposing the
  precession (``ConstantInertial``): by the same law the axis *tilts*,
  ``θ̇ = τ_p / (I_s ω_s)``.

Conventions (those of :class:`~tumble.analytic.HeavyTop`): inertial z up,
gravity ``(0, 0, −g)``; body z is the spin axis from the pivot; Euler angles
``(φ, θ, ψ)`` intrinsic z-x-z, ``θ`` the angle of the axis from the upward
vertical, so ``θ = π/2`` is a horizontal axis; the axis points along
``(sin θ sin φ, −sin θ cos φ, cos θ)``. ``tumble.analytic.axis_motion``
reads ``φ(t)``, ``θ(t)`` off a simulation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tumble import attitude, torques
from tumble._validate import ValidationError, require_non_negative, require_positive
from tumble.analytic import AxisMotion, HeavyTop, axis_motion
from tumble.simulate import simulate
from tumble.trajectory import Trajectory

__all__ = ["Gyroscope"]

STANDARD_GRAVITY = 9.80665



@dataclass(frozen=True)
class Gyroscope:
    """A symmetric rotor on a pivot (a two-degree-of-freedom free gyroscope) and its initial state.

    spin_inertia : I_s, axial moment, kg·m²
    transverse_inertia : I_t, transverse moment *about the pivot*, kg·m²
    spin : ω_s, body rate about the spin axis, rad/s (non-zero)
    mass : rotor mass, kg
    offset : l, centre of mass from the pivot along the spin axis, m (≥ 0; the imbalance)
    g : gravitational acceleration, m/s²
    spin_friction : Coulomb drag torque on the spin axis, N·m (≥ 0)
    pivot_friction : torque about the vertical opposing the precession, N·m (≥ 0)
    tilt : initial θ, the axis from the upward vertical, rad (default π/2: horizontal)
    """

    spin_inertia: float
    transverse_inertia: float
    spin: float
    mass: float = 1.0
    offset: float = 0.0
    g: float = STANDARD_GRAVITY
    spin_friction: float = 0.0
    pivot_friction: float = 0.0
    tilt: float = math.pi / 2

    def __post_init__(self):
        for name in ("spin_inertia", "transverse_inertia", "mass", "g"):
            object.__setattr__(self, name, require_positive(getattr(self, name), name))
        for name in ("offset", "spin_friction", "pivot_friction"):
            object.__setattr__(self, name, require_non_negative(getattr(self, name), name))
        spin = float(self.spin)
        if not math.isfinite(spin) or spin == 0.0:
            raise ValidationError(f"spin: must be a finite non-zero rate (rad/s), got {spin}")
        object.__setattr__(self, "spin", spin)
        if not 0.0 < float(self.tilt) < math.pi:
            raise ValidationError(f"tilt: must lie in (0, π) rad (angle of the axis from the vertical), got {self.tilt}")
        object.__setattr__(self, "tilt", float(self.tilt))

    @property
    def momentum(self) -> float:
        """Spin angular momentum ``H = I_s ω_s``, N·m·s."""
        return self.spin_inertia * self.spin

    @property
    def imbalance_torque(self) -> float:
        """Gravity torque of the imbalance on a horizontal axis, ``m g l`` (N·m)."""
        return self.mass * self.g * self.offset

    @property
    def precession_rate(self) -> float:
        """Gyroscopic drift rate ``m g l / (I_s ω_s)`` of the imbalance (rad/s, about the upward vertical)."""
        return self.imbalance_torque / self.momentum

    @property
    def nutation_frequency(self) -> float:
        """``ω_n = I_s ω_s / I_t`` (rad/s), the fast-top nutation frequency."""
        return abs(self.momentum) / self.transverse_inertia

    def heavy_top(self, *, released: bool = True) -> HeavyTop:
        """The exact heavy top of this rotor (needs ``offset > 0``): released at rest, or in steady precession."""
        if self.offset == 0.0:
            raise ValidationError("offset: a heavy top needs a centre of mass off the pivot (offset > 0)")
        phi_dot0 = 0.0 if released else self._steady_rate()
        return HeavyTop(self.transverse_inertia, self.spin_inertia, self.mass, self.offset, self.g,
                        self.tilt, 0.0, phi_dot0, self.spin)

    def _steady_rate(self) -> float:
        """The slow root of ``I_t Ω² cos θ − I_s ω_s Ω + m g l = 0`` (exactly ``m g l / (I_s ω_s)`` at θ = π/2).

        Written as ``2c / (b + sign(b) √(b² − 4ac))``, which keeps full
        precision when ``4ac ≪ b²`` (a fast rotor) and is ``c/b`` at ``a = 0``.
        """
        a = self.transverse_inertia * math.cos(self.tilt)
        b, c = self.momentum, self.imbalance_torque
        discriminant = b * b - 4.0 * a * c
        if discriminant < 0.0:
            raise ValidationError(f"spin: {self.spin} rad/s is too slow for steady precession at tilt {self.tilt} "
                                  "rad (I_s² ω_s² < 4 I_t m g l cos θ)")
        return 2.0 * c / (b + math.copysign(math.sqrt(discriminant), b))

    def torque(self) -> torques.TorqueModel | None:
        """The torque model: gravity on the imbalance + spin-bearing drag + pivot friction (those non-zero)."""
        model = None
        if self.offset:
            model = torques.Gravity(self.mass, [0.0, 0.0, self.offset], [0.0, 0.0, -self.g])
        if self.spin_friction:
            model = torques.ConstantBody([0.0, 0.0, -math.copysign(self.spin_friction, self.spin)]) + model
        if self.pivot_friction:
            sense = math.copysign(1.0, self.precession_rate)
            model = torques.ConstantInertial([0.0, 0.0, -sense * self.pivot_friction]) + model
        return model

    def simulate(self, t, *, released: bool = True, rtol: float = 1e-12, atol: float = 1e-12) -> Trajectory:
        """Simulate with ``tumble.simulate`` (dop853) from azimuth φ = 0, θ = ``tilt``, ψ = 0.

        ``released=True``: the axis starts at rest (φ̇ = θ̇ = 0) and nutates;
        ``False``: it starts in steady precession (φ̇ = the slow root), with no nutation.
        """
        phi_dot0 = 0.0 if released else self._steady_rate()
        omega0 = np.array([0.0, phi_dot0 * math.sin(self.tilt), self.spin])
        body = np.diag([self.transverse_inertia, self.transverse_inertia, self.spin_inertia])
        return simulate(body, omega0, q0=attitude.from_euler("ZXZ", [0.0, self.tilt, 0.0]), t=t,
                        torque=self.torque(), method="dop853", rtol=rtol, atol=atol)

    def axis(self, trajectory: Trajectory) -> AxisMotion:
        """Azimuth φ, tilt θ, their rates and the spin of the axis along a simulation (``analytic.axis_motion``)."""
        return axis_motion(trajectory, com=[0.0, 0.0, 1.0], g=[0.0, 0.0, -self.g])
