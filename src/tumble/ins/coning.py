"""The classic coning motion and the coning drift of strapdown attitude algorithms.

Coning: the body's rotation vector has a fixed length ``α`` (the cone
half-angle, rad) and turns about the inertial z axis (the cone axis) at
``Ω`` (rad/s)::

    q(t) = [cos(α/2), sin(α/2) cos Ωt, sin(α/2) sin Ωt, 0]          (body → inertial)
    ω(t) = 2 q* ⊗ q̇ = (−Ω sin α sin Ωt,  Ω sin α cos Ωt,  −Ω (1 − cos α))   (body axes)

The attitude is periodic (no net rotation), yet the body rate has a
constant component along z: summing angle increments without coning
compensation drifts about the cone axis. Angle increments are exact closed
forms::

    Δθ = (sin α (cos Ωt₁ − cos Ωt₀),  sin α (sin Ωt₁ − sin Ωt₀),  −Ω (1 − cos α)(t₁ − t₀))

so the truth carries no integration error (P. G. Savage, *Strapdown
Analytics*, 2nd ed., ch. 7; Titterton & Weston, 2nd ed., ch. 11).

The drift of each strapdown algorithm about the cone axis follows the laws
of :func:`drift_law` (leading order in α, ``T`` the *update* interval;
derived in ``docs/ins.md``); :func:`measure_drift` measures it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._validate import ValidationError, require_positive
from tumble.ins.increments import Increments
from tumble.ins.strapdown import ALGORITHMS, strapdown
from tumble.trajectory import Trajectory

__all__ = ["CONING_RANGES", "Coning", "drift_law", "measure_drift"]

#: Update intervals (as Ω T) over which each coning law holds to 5 % at α = 0.01 rad (checked by
#: the tests): below 0.3 the three-sample drift meets an α⁴ term and float64 rounding.
CONING_RANGES = {"none": (0.05, 1.0), "one-sample": (0.05, 0.5), "two-sample": (0.05, 1.0),
                 "three-sample": (0.3, 1.0)}



@dataclass(frozen=True)
class Coning:
    """Coning of half-angle ``half_angle`` (rad, in (0, π/2]) at ``frequency`` Ω (rad/s) about inertial z."""

    half_angle: float
    frequency: float

    def __post_init__(self):
        alpha = require_positive(self.half_angle, "half_angle")
        if alpha > math.pi / 2:
            raise ValidationError(f"half_angle: must be in (0, π/2] rad, got {alpha}")
        object.__setattr__(self, "half_angle", alpha)
        object.__setattr__(self, "frequency", require_positive(self.frequency, "frequency"))

    def attitude(self, t: ArrayLike) -> np.ndarray:
        """``q(t)`` (body → inertial, scalar first), shape (n, 4)."""
        phase = self.frequency * np.asarray(t, dtype=np.float64)
        s = math.sin(self.half_angle / 2)
        return np.stack([np.full_like(phase, math.cos(self.half_angle / 2)), s * np.cos(phase),
                         s * np.sin(phase), np.zeros_like(phase)], axis=-1)

    def rate(self, t: ArrayLike) -> np.ndarray:
        """Body rate ``ω(t)`` (rad/s, body axes), shape (n, 3)."""
        phase = self.frequency * np.asarray(t, dtype=np.float64)
        a = self.frequency * math.sin(self.half_angle)
        return np.stack([-a * np.sin(phase), a * np.cos(phase),
                         np.full_like(phase, -self.frequency * (1.0 - math.cos(self.half_angle)))], axis=-1)

    def trajectory(self, t: ArrayLike) -> Trajectory:
        """The exact motion at times ``t`` as a Trajectory (inertia: identity, the motion is kinematic)."""
        t = np.asarray(t, dtype=np.float64)
        return Trajectory(t=t, q=self.attitude(t), omega=self.rate(t), inertia=np.eye(3), method="coning")

    def increments(self, dt: float, count: int, *, t0: float = 0.0) -> Increments:
        """Exact angle increments ``∫ ω dt`` over ``count`` intervals of ``dt`` s from ``t0``."""
        dt = require_positive(dt, "dt")
        phase = self.frequency * (t0 + dt * np.arange(int(count) + 1))
        s = math.sin(self.half_angle)
        dtheta = np.stack([s * np.diff(np.cos(phase)), s * np.diff(np.sin(phase)),
                           np.full(int(count), -self.frequency * (1.0 - math.cos(self.half_angle)) * dt)], axis=-1)
        return Increments(t0=t0, dt=dt, delta_theta=dtheta)


def drift_law(algorithm: str, half_angle: float, frequency: float, update_interval: ArrayLike) -> np.ndarray:
    """Predicted coning drift rate about the cone axis (rad/s) of a strapdown algorithm.

    ``T`` = ``update_interval`` (s), ``x = ΩT``, ``α`` = ``half_angle``:

    ================  =============================
    ``none``          ½ α² Ω (1 − sin x / x)
    ``one-sample``    α² Ω x⁴ / 60
    ``two-sample``    α² Ω x⁴ / 960
    ``three-sample``  α² Ω x⁶ / 204120
    ================  =============================

    Leading order in α (relative corrections O(α²)); the compensated laws
    are the leading terms in x as well (relative corrections O(x²)). The
    uncompensated law (``none``: one gyro sample per update, no coning term)
    is exact in x: ``≈ α² Ω x² / 12 (1 − x²/20 + …)`` for small x, and
    ``Ω α²/2`` (the whole mean body rate about the cone axis) for large x.
    With ``sin²α`` in place of ``α²`` it also holds to O(α² x²) relative
    (measured in ``docs/ins.md``). ``1 − sin x / x`` is summed as its Taylor
    series below x = 1, where the difference would lose digits.
    """
    x = frequency * np.asarray(update_interval, dtype=np.float64)
    scale = half_angle**2 * frequency
    if algorithm == "none":
        return 0.5 * scale * _one_minus_sinc(x)
    if algorithm == "one-sample":
        return scale * x**4 / 60.0
    if algorithm == "two-sample":
        return scale * x**4 / 960.0
    if algorithm == "three-sample":
        return scale * x**6 / 204120.0
    raise ValidationError(f"algorithm: must be one of {sorted(ALGORITHMS)}, got {algorithm!r}")


def _one_minus_sinc(x: np.ndarray) -> np.ndarray:
    """``1 − sin x / x`` to full precision: below |x| = 1 its Taylor series
    ``x²/3! − x⁴/5! + … − x¹⁶/17!`` in Horner form (remainder under 6e-17 of the sum), above it the
    closed form (which below |x| = 1 would lose up to ``log10(6/x²)`` digits to cancellation)."""
    x = np.asarray(x, dtype=np.float64)
    x2 = x * x
    series = np.ones_like(x2)
    for k in range(8, 1, -1):  # 1 − x²/((2k)(2k+1)) (…), k = 8 … 2
        series = 1.0 - x2 / (2 * k * (2 * k + 1)) * series
    series *= x2 / 6.0
    with np.errstate(divide="ignore", invalid="ignore"):
        closed = 1.0 - np.sin(x) / x
    return np.where(np.abs(x) < 1.0, series, closed)


def measure_drift(coning: Coning, algorithm: str, update_interval: float, updates: int = 200) -> float:
    """Measured drift rate (rad/s) about the cone axis of ``algorithm`` over ``updates`` updates.

    Feeds the exact increments (``ALGORITHMS[algorithm]`` per update, at
    ``update_interval / n``) to :func:`~tumble.ins.strapdown.strapdown`
    started on the true attitude, takes the attitude error in inertial axes,
    ``E_k = q_alg,k ⊗ q_true,k*``, and accumulates the z components (the cone
    axis) of the rotation vectors of its per-update changes,
    ``e_k = Σ_{j<k} [log(E_{j+1} ⊗ E_j*)]_z`` (equal to ``[log E_k]_z`` while
    the error is small, and unlike it not wrapped at π rad when the error grows
    large). Returns the least-squares slope of ``e_k`` against time from the
    end of the first update on (the one-sample algorithm has no previous
    increment there, so its first update errs by a constant), sign included:
    every algorithm here under-compensates, and the computed attitude turns
    about −z.
    """
    T = require_positive(update_interval, "update_interval")
    n = ALGORITHMS.get(algorithm, 1)
    increments = coning.increments(T / n, n * int(updates))
    result = strapdown(increments, q0=coning.attitude(0.0), algorithm=algorithm)
    t = result.attitude.t
    error = attitude.multiply(cast(np.ndarray, result.attitude.q), attitude.conjugate(coning.attitude(t)))
    change = attitude.to_rotvec(attitude.multiply(error[1:], attitude.conjugate(error[:-1])))[:, 2]
    accumulated = np.concatenate([[0.0], np.cumsum(change)])
    return float(np.polyfit(t[1:], accumulated[1:], 1)[0])
