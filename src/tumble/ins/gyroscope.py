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
reads ``φ(t)``, ``θ(t)`` off a simulation (:meth:`Gyroscope.axis`).

A :class:`Gyroscope` is a model of :func:`tumble.simulate`: the rigid rotor
``diag(I_t, I_t, I_s)`` about the pivot under its own torques (the
compiled torque models above), from the initial state named
``precession_rate0``.

**Invariants.** With no friction and no other torque the energy
``E = ½ ω·Iω + m g l cos θ`` (kinetic about the pivot plus the imbalance's
potential), the vertical angular momentum ``L_N·ẑ`` (gravity acts about
horizontal axes) and the axial momentum ``I_s ω₃`` (a symmetric rotor) are
conserved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np

from tumble import attitude, dynamics, torques
from tumble._validate import ValidationError, require_non_negative, require_positive
from tumble.analytic import AxisMotion, HeavyTop, axis_motion
from tumble.rigid_model import RigidBodies
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from tumble.kernels.rigid import RigidModel

__all__ = ["Gyroscope"]

STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True)
class Gyroscope(Model):
    """A symmetric rotor on a pivot (a two-degree-of-freedom free gyroscope); a model of :func:`tumble.simulate`.

    spin_inertia : I_s, axial moment, kg·m²
    transverse_inertia : I_t, transverse moment *about the pivot*, kg·m²
    spin : ω_s, body rate about the spin axis, rad/s (non-zero)
    mass : rotor mass, kg
    offset : l, centre of mass from the pivot along the spin axis, m (≥ 0; the imbalance)
    g : gravitational acceleration, m/s²
    spin_friction : Coulomb drag torque on the spin axis, N·m (≥ 0)
    pivot_friction : torque about the vertical opposing the precession, N·m (≥ 0)
    tilt : initial θ, the axis from the upward vertical, rad (default π/2: horizontal)

    ``tumble.simulate(gyro, t=..., precession_rate0=...)`` integrates the rotor from
    azimuth φ = 0, θ = ``tilt``, ψ = 0, θ̇ = 0 and spin ``spin`` (dop853 at a
    tight tolerance suits it: ``rtol=atol=1e-12``). ``precession_rate0`` is the
    initial azimuth rate φ̇ (rad/s, about the upward vertical; a number or a batch
    (N, 1)): 0 (the default) releases the axis at rest, and it nutates;
    ``gyro.steady_precession_rate`` starts it in steady precession, with no
    nutation. ``torque=`` adds an external torque to gravity and friction. The
    :class:`~tumble.Trajectory` is that of the rotor (``inertia`` about the
    pivot); its total ``energy`` is ``½ ω·Iω + m g l cos θ``.
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

    torque = ("external torque on the rotor in addition to its gravity and friction, body axes (N·m): "
              "a tumble.torques model or f(t, q, omega)")

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

    def heavy_top(self, *, precession_rate0: float = 0.0) -> HeavyTop:
        """The exact heavy top of this rotor (needs ``offset > 0``) started with the azimuth rate
        ``precession_rate0`` (rad/s): 0 releases it at rest, :attr:`steady_precession_rate` is steady precession."""
        if self.offset == 0.0:
            raise ValidationError("offset: a heavy top needs a centre of mass off the pivot (offset > 0)")
        return HeavyTop(self.transverse_inertia, self.spin_inertia, self.mass, self.offset, self.g,
                        self.tilt, 0.0, float(precession_rate0), self.spin)

    @property
    def steady_precession_rate(self) -> float:
        """The azimuth rate (rad/s) of steady precession at ``tilt``: the slow root of
        ``I_t Ω² cos θ − I_s ω_s Ω + m g l = 0`` (exactly ``m g l / (I_s ω_s)`` at θ = π/2).

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

    def torque_model(self) -> torques.TorqueModel | None:
        """The rotor's own torques: gravity on the imbalance + spin-bearing drag + pivot friction (those non-zero)."""
        model = None
        if self.offset:
            model = torques.Gravity(self.mass, [0.0, 0.0, self.offset], [0.0, 0.0, -self.g])
        if self.spin_friction:
            model = torques.ConstantBody([0.0, 0.0, -math.copysign(self.spin_friction, self.spin)]) + model
        if self.pivot_friction:
            sense = math.copysign(1.0, self.precession_rate)
            model = torques.ConstantInertial([0.0, 0.0, -sense * self.pivot_friction]) + model
        return model

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    def _rotor(self) -> RigidBodies:
        """The rotor as a rigid body, inertia ``diag(I_t, I_t, I_s)`` about the pivot."""
        return RigidBodies.of(np.diag([self.transverse_inertia, self.transverse_inertia, self.spin_inertia]))

    def state_fields(self) -> tuple[StateField, ...]:
        return (StateField("precession_rate0", 1, "initial azimuth rate of the spin axis about the upward vertical, "
                           "rad/s (0: released at rest; gyro.steady_precession_rate: steady precession)",
                           default=0.0),)

    def compile(self, torque: torques.TorqueLike, t0: float) -> RigidModel:
        extra = torques.as_torque_model(torque)
        return self._rotor().compile(self.torque_model() if extra is None else extra + self.torque_model(), t0)

    def initial_states(self, kernel: RigidModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """The rotor at φ = 0, θ = ``tilt``, ψ = 0 with body rate ``(0, φ̇₀ sin θ, ω_s)`` (θ̇ = 0)."""
        phi_dot0 = values["precession_rate0"][:, 0]
        omega0 = np.stack([np.zeros_like(phi_dot0), phi_dot0 * math.sin(self.tilt), np.full_like(phi_dot0, self.spin)],
                          axis=-1)
        q0 = np.broadcast_to(attitude.from_euler("ZXZ", [0.0, self.tilt, 0.0]), (phi_dot0.size, 4))
        return self._rotor().initial_states(kernel, {"omega0": omega0, "q0": q0}, t0)

    def outputs(self, kernel: RigidModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        out = self._rotor().outputs(kernel, t, states)
        height = attitude.rotate(cast(np.ndarray, out.q), [0.0, 0.0, 1.0])[..., 2]   # cos θ
        energy = (dynamics.kinetic_energy(cast(np.ndarray, out.inertia), cast(np.ndarray, out.omega))
                  + self.imbalance_torque * height)
        return out._replace(totals={"energy": energy})

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """Without friction and another torque: ``E``, ``L_N·ẑ`` and ``I_s ω₃`` (module docstring)."""
        if traj.info.get("torque") != "none" or self.spin_friction or self.pivot_friction:
            return {}
        return {"energy": traj.energy, "momentum_vertical": traj.momentum_inertial[..., 2],
                "momentum_axial": traj.momentum_body[..., 2]}

    def axis(self, trajectory: Trajectory) -> AxisMotion:
        """Azimuth φ, tilt θ, their rates and the spin of the axis along a simulation (``analytic.axis_motion``)."""
        return axis_motion(trajectory, com=[0.0, 0.0, 1.0], g=[0.0, 0.0, -self.g])
