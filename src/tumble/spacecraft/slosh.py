"""Fuel slosh as a part of the spacecraft: a spherical pendulum per tank.

``Spacecraft(inertia=I_B, slosh=[SloshPendulum(reduced_mass, length, hinge, damping), ...], ...)``
adds the sloshing liquid of each tank, as its pendulum analogue (:mod:`tumble.slosh`: Abramson (ed.),
NASA SP-106, 1966, ch. 6), to a hub that also carries wheels, thrusters and a controller. ``I_B`` is the
inertia of the hub (the liquid that does not slosh included) about its own centre of mass; tank ``k`` has
the reduced mass ``μ = m M / (m + M)`` (slosh mass ``m``, hub mass ``M``: the translation of the free-floating
craft removed, :class:`tumble.SloshBody`), the rod length ``l``, the hinge ``b`` (body axes, from the hub's
centre of mass) and the hinge damping ``d`` (1/s; friction torque ``−μ l² d ν``). The equations enter the
hub's as a part (:mod:`tumble.kernels.spacecraft.slosh`): each tank carries ``h = μ r × (ω × r + l ν × s)``
(``r = b + l s``) and adds ``μ (r × s)(r × s)ᵀ`` to the matrix the hub's ``ω̇`` is solved with.

Initial state ``direction0`` (3 per tank, tank by tank: the rods' directions, normalised) and ``rate0``
(3 per tank: their rates relative to the hub, the component along the rod removed; default zero);
outputs ``pendulum_direction`` and ``pendulum_rate`` (n, [N,] tanks, 3), as :class:`tumble.SloshBody`'s.
A spacecraft with only one tank moves as the ``SloshBody`` of the same hub and pendulum (tested).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tumble._validate import ValidationError, as_array, require_non_negative, require_positive
from tumble.kernels.spacecraft import slosh as _kernel
from tumble.kernels.spacecraft._base import Program

__all__ = ["SloshPendulum"]


@dataclass(frozen=True)
class SloshPendulum:
    """The slosh of one tank as a spherical pendulum, a part of :class:`tumble.spacecraft.Spacecraft`.

    reduced_mass : ``μ = m M / (m + M)`` (kg), > 0: slosh mass ``m`` and hub mass ``M``
    length : rod length ``l`` (m), > 0
    hinge : (3,) hinge point ``b`` from the hub's centre of mass (m, body axes)
    damping : hinge damping ``d`` (1/s), >= 0: friction torque ``−μ l² d ν`` on the rod
    """

    reduced_mass: float
    length: float
    hinge: np.ndarray
    damping: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "reduced_mass", require_positive(self.reduced_mass, "reduced_mass"))
        object.__setattr__(self, "length", require_positive(self.length, "length"))
        object.__setattr__(self, "damping", require_non_negative(self.damping, "damping"))
        hinge = as_array(self.hinge, "hinge", tail=(3,))
        if hinge.ndim != 1:
            raise ValidationError(f"hinge: must have shape (3,), got {hinge.shape}")
        hinge = hinge.copy()  # frozen: never the caller's array
        hinge.setflags(write=False)
        object.__setattr__(self, "hinge", hinge)


def slosh_program(tanks: Sequence[SloshPendulum]) -> Program:
    """The compiled part of the ``tanks``."""
    return _kernel.program([t.reduced_mass for t in tanks], [t.length for t in tanks],
                           [t.damping for t in tanks], np.array([t.hinge for t in tanks]))


def initial_rods(direction: np.ndarray, rate: np.ndarray, tanks: int) -> tuple[np.ndarray, np.ndarray]:
    """``(s₀, ν₀)`` (N, tanks, 3) of ``direction0`` and ``rate0`` (N, 3·tanks): the directions normalised,
    the rates' components along them removed (SloshBody's)."""
    s = direction.reshape(-1, tanks, 3)
    norm = np.linalg.norm(s, axis=-1, keepdims=True)
    if np.any(norm == 0.0):
        k = int(np.argwhere(norm[..., 0] == 0.0)[0, 1])
        raise ValidationError(f"direction0: the direction of tank {k} must be a non-zero vector (it is "
                              f"normalised here)")
    s = s / norm
    nu = rate.reshape(-1, tanks, 3)
    return s, nu - np.sum(nu * s, axis=-1, keepdims=True) * s
