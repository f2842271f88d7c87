"""Flexible appendages as a part of the spacecraft: cantilever modes in hybrid coordinates.

``Spacecraft(inertia=I, flexible_modes=FlexibleModes(participation, frequency, damping), ...)``
adds ``m`` modes of the appendages (solar arrays, antennas) to a hub that also
carries wheels, thrusters and a controller. ``I`` is the inertia of the whole
spacecraft with its appendages undeformed (as ``body`` of
:class:`tumble.flexible.FlexibleBody`); mode ``k`` has the modal coordinate
``η_k`` (kg^½·m, mass-normalised), the cantilever frequency ``Ω_k`` (rad/s,
the appendage clamped to a hub held still), the damping ratio ``ζ_k`` and the
rotational participation vector ``δ_k`` (kg^½·m, body axes). The
hybrid-coordinate equations (Likins, JPL TR 32-1576, 1974; Wie, *Space Vehicle
Dynamics and Control*, 2nd ed., 2008)::

    I ω̇ + Σ δ_k η̈_k + ω × (I ω + Σ δ_k η̇_k) = τ
    η̈_k + 2ζ_kΩ_k η̇_k + Ω_k² η_k + δ_k·ω̇ = 0

enter the hub's equation as a part (:mod:`tumble.kernels.spacecraft.flexible_modes`):
the rate answers to ``J_ω = I − Σ δ_kδ_kᵀ − …``, the modes carry
``h = Σ δ_k (δ_k·ω + η̇_k)`` and exert ``Σ δ_k (2ζ_kΩ_k η̇_k + Ω_k² η_k)`` on the
hub. Initial state ``eta0``, ``eta_rate0`` (m,), default zero; outputs
``modal_coordinate`` and ``modal_rate``, as :class:`~tumble.flexible.FlexibleBody`'s.
A spacecraft with only these modes moves as the ``FlexibleBody`` of the same
``I`` and modes (tested).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array
from tumble.kernels.spacecraft import flexible_modes as _kernel
from tumble.kernels.spacecraft._base import Program

__all__ = ["FlexibleModes"]


@dataclass(frozen=True)
class FlexibleModes:
    """``m`` cantilever modes of the appendages, a part of :class:`tumble.spacecraft.Spacecraft`.

    participation : (m, 3) rotational participation vectors ``δ_k``, kg^½·m, body axes
    frequency : (m,) cantilever frequencies ``Ω_k`` (hub held still), rad/s, each > 0
    damping : (m,) damping ratios ``ζ_k``, each >= 0 (default 0)

    The spacecraft refuses modes that leave ``J_ω`` (its inertia less ``Σ δ_kδ_kᵀ`` and the
    rotors' spin) without a positive definite value: the appendages cannot carry more inertia
    than the whole body.
    """

    participation: np.ndarray
    frequency: np.ndarray
    damping: ArrayLike | None = None

    def __post_init__(self):
        delta = as_array(self.participation, "participation", tail=(3,))
        if delta.ndim != 2 or delta.shape[0] == 0:
            raise ValidationError(f"participation: must have shape (m, 3), one row per mode (m >= 1), "
                                  f"got {delta.shape}")
        m = delta.shape[0]
        frequency = _per_mode(self.frequency, "frequency", m)
        if np.any(frequency <= 0.0):
            k = int(np.argmax(frequency <= 0.0))
            raise ValidationError(f"frequency[{k}]: must be > 0 (rad/s), got {frequency[k]}")
        damping = np.zeros(m) if self.damping is None else _per_mode(self.damping, "damping", m)
        if np.any(damping < 0.0):
            k = int(np.argmax(damping < 0.0))
            raise ValidationError(f"damping[{k}]: must be a damping ratio >= 0, got {damping[k]}")
        for name, value in (("participation", delta), ("frequency", frequency), ("damping", damping)):
            value = value.copy()  # frozen: never the caller's array
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @property
    def count(self) -> int:
        """The number of modes ``m``."""
        return self.frequency.size

    @property
    def inertia(self) -> np.ndarray:
        """``Σ δ_kδ_kᵀ`` (3, 3), kg·m²: the inertia the modes take out of what the hub's rate answers to."""
        return self.participation.T @ self.participation

    def _program(self) -> Program:
        return _kernel.program(self.participation, self.frequency, self.damping)


def _per_mode(value, name: str, m: int) -> np.ndarray:
    """``value`` as a (m,) array of finite numbers, one per mode."""
    arr = as_array(value, name)
    if arr.shape != (m,):
        raise ValidationError(f"{name}: must have shape ({m},), one per mode of participation, got {arr.shape}")
    return arr
