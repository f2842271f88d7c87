"""Attitude control laws: quaternion-feedback PD, rate damping, B-dot, momentum dumping.

A controller is an immutable description; :class:`tumble.spacecraft.Spacecraft`
turns it into gains for its compiled model. The laws (body axes, SI units):

* :class:`QuaternionPD` (Wie, Weiss & Arapostathis, J. Guidance 12(3), 1989;
  rate limit after Wie & Lu, J. Guidance 18(6), 1995)::

      q_e = q_c* ⊗ q  (w ≥ 0),    ω_c = −C⁻¹K q_e,v  clipped to |ω_c| ≤ max_rate
      u   = C (ω_c − ω) + ω × H,  scaled so that max |u_k| ≤ max_torque

  with ``K = 2ω_n² J`` and ``C = 2ζω_n J``: linearised about the target, each
  axis obeys ``θ̈ + 2ζω_n θ̇ + ω_n² θ = 0`` (``q_e,v ≈ θ/2``).
* :class:`RateDamping`: ``u = −J ω / τ + ω × H``, so ``ω(t) = ω₀ e^{−t/τ}``.
* :class:`ConstantTorque`: ``u = u₀`` (open loop).
* :class:`BDot`: magnetic dipole ``m = −k Ḃ`` with ``Ḃ = −ω × B`` (the rate of
  change of the body-axes field due to the body's rotation; the slow orbital
  change of the field is left out), so ``τ = m × B = −k (|B|² E − B Bᵀ) ω``
  (Stickler & Alfriend, J. Spacecraft 13(5), 1976).
* :class:`MomentumDumping`: ``m = k (h × B)/|B|²`` with ``h`` the wheels'
  momentum in body axes, giving ``τ = −k h_⊥`` (the part of ``h`` normal to
  ``B``) while the attitude law holds the body (Sidi 1997, §7.5).

``H`` is the spacecraft's angular momentum in body axes (hub and wheels and
gyros). ``J`` is the inertia the body rate answers to: the total inertia less
the wheels' spin inertias (see ``docs/spacecraft.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tumble import attitude
from tumble._validate import ValidationError, as_array, require_positive

__all__ = ["QuaternionPD", "RateDamping", "ConstantTorque", "BDot", "MomentumDumping"]


@dataclass(frozen=True)
class QuaternionPD:
    """Quaternion-feedback PD regulator to the attitude ``target`` (body → inertial, scalar first).

    natural_frequency : ω_n, rad/s; damping_ratio : ζ (> 0);
    max_rate : eigen-axis slew rate limit, rad/s (``math.inf``: none);
    max_torque : limit on each component of the commanded torque, N·m (``math.inf``: none).
    """

    natural_frequency: float
    damping_ratio: float = 1.0 / math.sqrt(2.0)
    target: np.ndarray = (1.0, 0.0, 0.0, 0.0)
    max_rate: float = math.inf
    max_torque: float = math.inf

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "natural_frequency", require_positive(self.natural_frequency, "natural_frequency"))
        set_(self, "damping_ratio", require_positive(self.damping_ratio, "damping_ratio"))
        q = as_array(self.target, "target", tail=(4,))
        if q.shape != (4,) or np.linalg.norm(q) == 0.0:
            raise ValidationError(f"target: must be a non-zero quaternion [w, x, y, z], got {q.tolist()}")
        set_(self, "target", attitude.normalize(q))
        for name in ("max_rate", "max_torque"):
            value = float(getattr(self, name))
            if math.isnan(value) or value <= 0.0:
                raise ValidationError(f"{name}: must be > 0 (math.inf for no limit), got {value}")
            set_(self, name, value)

    def gains(self, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(K, C)`` = ``(2ω_n² J, 2ζω_n J)`` for the inertia ``J`` (kg·m²)."""
        wn, zeta = self.natural_frequency, self.damping_ratio
        return 2.0 * wn * wn * inertia, 2.0 * zeta * wn * inertia


@dataclass(frozen=True)
class RateDamping:
    """Rate damping ``u = −J ω/τ + ω × H``: every rate decays as ``e^{−t/τ}``; ``time_constant`` τ, s."""

    time_constant: float
    max_torque: float = math.inf

    def __post_init__(self):
        object.__setattr__(self, "time_constant", require_positive(self.time_constant, "time_constant"))
        value = float(self.max_torque)
        if math.isnan(value) or value <= 0.0:
            raise ValidationError(f"max_torque: must be > 0 (math.inf for no limit), got {value}")
        object.__setattr__(self, "max_torque", value)


@dataclass(frozen=True)
class ConstantTorque:
    """An open-loop torque command ``u = torque`` (N·m, body axes), for actuator studies (e.g. the
    pulse train a PWPF modulator makes of a constant command)."""

    torque: np.ndarray

    def __post_init__(self):
        u = as_array(self.torque, "torque", tail=(3,))
        if u.shape != (3,):
            raise ValidationError(f"torque: must have shape (3,), got {u.shape}")
        object.__setattr__(self, "torque", u)


@dataclass(frozen=True)
class BDot:
    """B-dot detumbling with magnetorquers: ``m = −k Ḃ = k ω × B``; ``gain`` k in A·m²·s/T."""

    gain: float

    def __post_init__(self):
        object.__setattr__(self, "gain", require_positive(self.gain, "gain"))


@dataclass(frozen=True)
class MomentumDumping:
    """Wheel momentum dumping with magnetorquers: ``m = k (h × B)/|B|²``; ``gain`` k in 1/s."""

    gain: float

    def __post_init__(self):
        object.__setattr__(self, "gain", require_positive(self.gain, "gain"))
