"""Attitude actuators: reaction wheels, control moment gyros, thrusters, magnetorquers.

Each class is an immutable, validated description in SI units and body axes
(the spacecraft's reference axes B). :class:`tumble.spacecraft.Spacecraft`
compiles them into the programs of its compiled model; the equations they
enter are in :mod:`tumble.kernels.spacecraft` (one file per actuator) and
``docs/spacecraft.md``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_positive
from tumble.rigid_body import Part
from tumble.kernels.spacecraft import cmgs as _cmgs
from tumble.kernels.spacecraft import magnetorquers as _magnetorquers
from tumble.kernels.spacecraft._base import Program

__all__ = ["ReactionWheel", "CMGCluster", "Thruster", "PWPF", "Magnetorquers", "pyramid_wheels"]


def _unit(value, name: str) -> np.ndarray:
    """``value`` as a unit (3,) vector (normalised here; a zero vector is refused)."""
    v = as_array(value, name, tail=(3,))
    if v.shape != (3,):
        raise ValidationError(f"{name}: must have shape (3,), got {v.shape}")
    n = float(np.linalg.norm(v))
    if n == 0.0:
        raise ValidationError(f"{name}: must be a non-zero vector (it is normalised here)")
    return v / n


def _limit(value, name: str) -> float:
    """A limit: a number > 0, or ``math.inf`` for none."""
    x = float(value)
    if math.isnan(x) or x <= 0.0:
        raise ValidationError(f"{name}: must be > 0 (math.inf for no limit), got {x}")
    return x


def _non_negative(value, name: str) -> float:
    x = float(value)
    if not math.isfinite(x) or x < 0.0:
        raise ValidationError(f"{name}: must be a finite number >= 0, got {x}")
    return x


def _vector(value, name: str) -> np.ndarray:
    v = as_array(value, name, tail=(3,))
    if v.shape != (3,):
        raise ValidationError(f"{name}: must have shape (3,), got {v.shape}")
    return v


@dataclass(frozen=True)
class ReactionWheel:
    """A reaction wheel: a symmetric rotor spun by a motor about a fixed ``axis`` of the body.

    axis : (3,) spin axis in body axes (normalised here)
    inertia : spin-axis moment of inertia of the rotor, kg·m²
    max_torque : motor torque limit, N·m (``math.inf``: none); commands are clipped
    max_speed : wheel speed limit relative to the body, rad/s: at ``|Ω| ≥ max_speed``
        the motor gives no torque that would spin the wheel faster (saturation)
    viscous : viscous bearing friction coefficient, N·m·s/rad (torque ``−viscous Ω``)
    coulomb : Coulomb friction torque, N·m (torque ``−coulomb tanh(Ω/coulomb_speed)``)
    coulomb_speed : smoothing width of the Coulomb friction, rad/s: the sign function
        is replaced by ``tanh(Ω/coulomb_speed)`` so that the right-hand side stays
        smooth and a fixed-step or adaptive method keeps its order across ``Ω = 0``
        (Karnopp-style stick–slip is not modelled)
    mass, position, transverse_inertia : the rotor's mass (kg), centre of mass in body axes (m)
        and moment of inertia about a diameter (kg·m²). Needed only when the spacecraft is
        described as a hub *without* its wheels (``Spacecraft(hub=...)``).
    """

    axis: np.ndarray
    inertia: float
    max_torque: float = math.inf
    max_speed: float = math.inf
    viscous: float = 0.0
    coulomb: float = 0.0
    coulomb_speed: float = 1.0
    mass: float | None = None
    position: np.ndarray | None = None
    transverse_inertia: float | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "axis", _unit(self.axis, "axis"))
        set_(self, "inertia", require_positive(self.inertia, "inertia"))
        set_(self, "max_torque", _limit(self.max_torque, "max_torque"))
        set_(self, "max_speed", _limit(self.max_speed, "max_speed"))
        set_(self, "viscous", _non_negative(self.viscous, "viscous"))
        set_(self, "coulomb", _non_negative(self.coulomb, "coulomb"))
        set_(self, "coulomb_speed", require_positive(self.coulomb_speed, "coulomb_speed"))
        given = [self.mass is not None, self.position is not None, self.transverse_inertia is not None]
        if any(given) and not all(given):
            raise ValidationError("mass: give mass, position and transverse_inertia together (or none of them)")
        if all(given):
            set_(self, "mass", require_positive(self.mass, "mass"))
            set_(self, "position", _vector(self.position, "position"))
            set_(self, "transverse_inertia", require_positive(self.transverse_inertia, "transverse_inertia"))

    @property
    def has_mass_properties(self) -> bool:
        return self.mass is not None

    def part(self) -> Part:
        """The rotor as a :class:`tumble.rigid_body.Part` of the spacecraft (body axes):
        inertia ``I_s a aᵀ + I_t (E − a aᵀ)`` about its centre at ``position``."""
        mass, position, transverse = self.mass, self.position, self.transverse_inertia
        if mass is None or position is None or transverse is None:  # all or none: checked in __post_init__
            raise ValidationError("wheels: with Spacecraft(hub=...), every wheel needs mass, position and "
                                  "transverse_inertia (the hub inertia excludes the wheels)")
        aa = np.outer(self.axis, self.axis)
        inertia = self.inertia * aa + transverse * (np.eye(3) - aa)
        return Part(mass=mass, com=position, inertia=inertia)


@dataclass(frozen=True)
class CMGCluster:
    """A cluster of single-gimbal control moment gyros (rate-commanded gimbals).

    Gyro ``i`` carries a rotor of constant angular momentum ``momentum[i]``
    (N·m·s) along its spin axis ``s_i(δ) = cos δ s0_i + sin δ (g_i × s0_i)``,
    turned about the gimbal axis ``g_i`` by the gimbal angle ``δ_i`` (rad).
    Gimbal rates follow the steering law instantly, clipped to
    ``max_gimbal_rate`` (rad/s): the gimbal servo is taken as ideal and the
    gimbal and transverse rotor inertias are neglected (the usual CMG model,
    Wie 2008, §7.3).

    gimbal_axes, spin_axes : (n, 3) ``g_i`` and ``s0_i`` (at δ = 0), body axes, orthogonal pairs
    momentum : (n,) rotor angular momentum, N·m·s
    max_gimbal_rate : rad/s
    robust_gain, robust_decay : λ₀ and μ of the singularity-robust inverse
        ``A# = Aᵀ (A Aᵀ + λ E)⁻¹``, ``λ = λ₀ exp(−μ det(Ā Āᵀ)) h̄²`` with ``Ā = A / h̄`` (Bedrossian,
        Paradiso & Bergmann, J. Guidance 13(6), 1990; Nakazawa 1988), h̄ the largest rotor momentum
    dither, dither_frequency, dither_phases : ε₀, ω_ε (rad/s) and φ₁, φ₂, φ₃ (rad) of the
        generalised SR inverse (Wie, Bailey & Heiberg, J. Guidance 24(5), 2001): ``E`` has the
        off-diagonal terms ``ε_i = ε₀ sin(ω_ε t + φ_i)`` (``E₁₂ = ε₃``, ``E₁₃ = ε₂``, ``E₂₃ = ε₁``),
        which steer the gimbals out of a singular configuration where the SR inverse (``ε₀ = 0``,
        the default) leaves them stuck. Wie's values: ε₀ = 0.01, ω_ε = π/2 rad/s, φ = (0, π/2, π)
        (:meth:`generalised`). ``|ε₀| < 0.5`` keeps ``E`` positive definite.

    The equations are in :mod:`tumble.kernels.spacecraft.cmgs`.
    """

    gimbal_axes: np.ndarray
    spin_axes: np.ndarray
    momentum: np.ndarray
    max_gimbal_rate: float = 1.0
    robust_gain: float = 0.01
    robust_decay: float = 10.0
    dither: float = 0.0
    dither_frequency: float = 0.5 * math.pi
    dither_phases: tuple = (0.0, 0.5 * math.pi, math.pi)

    def __post_init__(self):
        set_ = object.__setattr__
        g = as_array(self.gimbal_axes, "gimbal_axes", tail=(3,))
        s = as_array(self.spin_axes, "spin_axes", tail=(3,))
        if g.ndim != 2 or s.shape != g.shape or g.shape[0] < 1:
            raise ValidationError(f"spin_axes: must have the shape (n, 3) of gimbal_axes {g.shape}, got {s.shape}")
        h = np.broadcast_to(as_array(self.momentum, "momentum"), (g.shape[0],)).astype(float)
        if (h <= 0).any():
            raise ValidationError(f"momentum: each entry must be > 0, got {h.tolist()}")
        g = np.stack([_unit(x, f"gimbal_axes[{i}]") for i, x in enumerate(g)])
        s = np.stack([_unit(x, f"spin_axes[{i}]") for i, x in enumerate(s)])
        dots = np.abs(np.einsum("ij,ij->i", g, s))
        if (dots > 1e-9).any():
            i = int(np.argmax(dots))
            raise ValidationError(f"spin_axes[{i}]: must be perpendicular to gimbal_axes[{i}] "
                                  f"(|g·s| = {dots[i]:.3g} > 1e-9)")
        set_(self, "gimbal_axes", g)
        set_(self, "spin_axes", s)
        set_(self, "momentum", h)
        set_(self, "max_gimbal_rate", require_positive(self.max_gimbal_rate, "max_gimbal_rate"))
        set_(self, "robust_gain", _non_negative(self.robust_gain, "robust_gain"))
        set_(self, "robust_decay", _non_negative(self.robust_decay, "robust_decay"))
        dither = _non_negative(self.dither, "dither")
        if dither >= 0.5:
            raise ValidationError(f"dither: must be < 0.5 (E stays positive definite), got {dither}")
        set_(self, "dither", dither)
        set_(self, "dither_frequency", _non_negative(self.dither_frequency, "dither_frequency"))
        phases = as_array(self.dither_phases, "dither_phases")
        if phases.shape != (3,) or not np.all(np.isfinite(phases)):
            raise ValidationError(f"dither_phases: must be 3 finite angles (rad), got {phases.tolist()}")
        set_(self, "dither_phases", tuple(float(x) for x in phases))

    @classmethod
    def pyramid(cls, momentum: float, *, skew: float = math.degrees(math.atan(math.sqrt(2.0))),
                **options: Any) -> CMGCluster:
        """The four-CMG pyramid: gimbal axes normal to the faces of a pyramid whose faces are
        inclined by the skew angle ``β`` (degrees from the base plane; default 54.74°,
        ``atan √2``, for a nearly spherical momentum envelope), spin axes in the faces
        (Wie 2008, §7.3).

        Gyro ``i`` (i = 0…3) faces azimuth ``ψ_i = 90° i`` about the body z axis:
        ``g_i = (sin β cos ψ_i, sin β sin ψ_i, cos β)`` and, at δ = 0,
        ``s0_i = (−sin ψ_i, cos ψ_i, 0)``, so the cluster momentum is zero there.
        """
        beta = math.radians(require_positive(skew, "skew"))
        g, s = [], []
        for i in range(4):
            c, sn = math.cos(0.5 * math.pi * i), math.sin(0.5 * math.pi * i)
            g.append([math.sin(beta) * c, math.sin(beta) * sn, math.cos(beta)])
            s.append([-sn, c, 0.0])
        return cls(np.array(g), np.array(s), np.full(4, require_positive(momentum, "momentum")), **options)

    def generalised(self, dither: float = 0.01, dither_frequency: float = 0.5 * math.pi,
                    dither_phases: tuple[float, float, float] = (0.0, 0.5 * math.pi, math.pi)) -> CMGCluster:
        """The same cluster steered by the generalised singularity-robust inverse, with Wie's dither by default
        (ε₀ = 0.01, ω_ε = π/2 rad/s, φ = (0, π/2, π); Wie 2008, §7.3)."""
        return dataclasses.replace(self, dither=dither, dither_frequency=dither_frequency, dither_phases=dither_phases)

    @property
    def transverse_axes(self) -> np.ndarray:
        """``g_i × s0_i`` (n, 3): the direction of the gyro torque ``ḣ_i`` at δ = 0."""
        return np.cross(self.gimbal_axes, self.spin_axes)

    def _program(self) -> Program:
        return _cmgs.program(self.gimbal_axes, self.spin_axes, self.momentum, max_gimbal_rate=self.max_gimbal_rate,
                             robust_gain=self.robust_gain, robust_decay=self.robust_decay, dither=self.dither,
                             dither_frequency=self.dither_frequency, dither_phases=self.dither_phases)


@dataclass(frozen=True)
class Thruster:
    """An on–off thruster: ``force`` (N, > 0) along ``direction`` (body axes), applied at ``position``
    (m, body axes, from the spacecraft reference point). Its torque about the centre of mass ``c``
    is ``(position − c) × force direction``."""

    position: np.ndarray
    direction: np.ndarray
    force: float

    def __post_init__(self):
        object.__setattr__(self, "position", _vector(self.position, "position"))
        object.__setattr__(self, "direction", _unit(self.direction, "direction"))
        object.__setattr__(self, "force", require_positive(self.force, "force"))

    def torque(self, com: ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
        """``(r − c) × F`` (N·m, body axes)."""
        return np.cross(self.position - np.asarray(com, float), self.force * self.direction)


@dataclass(frozen=True)
class PWPF:
    """Pulse-width pulse-frequency modulator, one per torque axis (Wie 2008, §7.5).

    A first-order filter ``τ_m ḟ = K_m (r − y) − f`` of the normalised command
    ``r = u_k / T_k`` (``T_k`` the torque of the axis' thrusters) drives a
    Schmitt trigger: the output ``y`` turns on (±1) when ``|f| > u_on`` and
    off when ``|f| < u_off``. A pulse lasts at least ``min_on_time`` (the
    minimum impulse bit ``T_k · min_on_time``). Defaults: K_m = 4.5,
    τ_m = 0.85 s, u_on = 0.45, u_off = 0.15 (Wie's textbook example).
    """

    gain: float = 4.5
    time_constant: float = 0.85
    on: float = 0.45
    off: float = 0.15
    min_on_time: float = 0.0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "gain", require_positive(self.gain, "gain"))
        set_(self, "time_constant", require_positive(self.time_constant, "time_constant"))
        set_(self, "on", require_positive(self.on, "on"))
        set_(self, "off", _non_negative(self.off, "off"))
        set_(self, "min_on_time", _non_negative(self.min_on_time, "min_on_time"))
        if not self.off < self.on:
            raise ValidationError(f"off: must be < on = {self.on} (Schmitt trigger hysteresis), got {self.off}")

    def duty_cycle(self, r: float) -> float:
        """The exact duty cycle of the continuous modulator for a constant command ``0 < r < 1``:
        ``T_on/(T_on + T_off)`` with ``T_on = τ ln((u_on + K(1−r))/(u_off + K(1−r)))`` and
        ``T_off = τ ln((K r − u_off)/(K r − u_on))`` (0 when ``K r ≤ u_on``)."""
        k, tau = self.gain, self.time_constant
        if k * r <= self.on:
            return 0.0
        t_on = tau * math.log((self.on + k * (1.0 - r)) / (self.off + k * (1.0 - r)))
        t_off = tau * math.log((k * r - self.off) / (k * r - self.on))
        return t_on / (t_on + t_off)


@dataclass(frozen=True)
class Magnetorquers:
    """Three orthogonal magnetic torquers along the body axes: dipole ``m`` (A·m²), each
    component clipped to ``±max_dipole``; torque ``τ = m × B`` with ``B`` the Earth's field
    in body axes (tesla)."""

    max_dipole: np.ndarray

    def __post_init__(self):
        m = np.broadcast_to(as_array(self.max_dipole, "max_dipole"), (3,)).astype(float)
        if (m <= 0).any():
            raise ValidationError(f"max_dipole: each entry must be > 0 (A·m²), got {m.tolist()}")
        object.__setattr__(self, "max_dipole", m)

    def _program(self) -> Program:
        return _magnetorquers.program(self.max_dipole)


def pyramid_wheels(inertia: float, *, skew: float = math.degrees(math.atan(math.sqrt(2.0))),
                   **options: Any) -> list[ReactionWheel]:
    """Four identical reaction wheels in a pyramid about the body z axis: wheel ``i`` spins about
    ``(cos β cos ψ_i, cos β sin ψ_i, sin β)``, ``ψ_i = 90° i``, with ``β`` the elevation ``skew``
    (degrees; default 54.74°, equal control authority about the three axes). ``options`` go
    to every :class:`ReactionWheel`."""
    beta = math.radians(skew)
    return [ReactionWheel(axis=np.array([math.cos(beta) * math.cos(0.5 * math.pi * i),
                                         math.cos(beta) * math.sin(0.5 * math.pi * i), math.sin(beta)]),
                          inertia=inertia, **options) for i in range(4)]
