"""Error models of gyros and accelerometers (IEEE Std 952-1997 notation), applied to true increments.

A triad of rate-integrating sensors (a gyro triad measuring ``Δθ`` in rad, or
an accelerometer triad measuring ``Δv`` in m/s; "rate" below means rad/s or
m/s²) turns the true increment ``Δ_k`` over the sample interval
``[t_k, t_k + dt]`` into the measured one::

    Δ̃_k = Q[ (E + S + M) Δ_k + (b + b_BI,k + b_RRW,k) dt + N √dt w_k ]

========================  =====================  ==============================================================
term                      parameter              model
========================  =====================  ==============================================================
scale factor ``S``        ``scale_factor`` (3,)  ``diag(s)``, dimensionless (1e-6 = 1 ppm)
misalignment ``M``        ``misalignment``       (3, 3), zero diagonal: ``M_ij`` = sensitivity of axis i to
                                                 the input about (along) axis j, rad (small angles)
bias ``b``                ``bias`` (3,)          constant, rate units
angle random walk ``N``   ``white_noise``        white rate noise of PSD ``N²``: ``N √dt w_k``, ``w_k ~ N(0, 1)``,
                                                 rate units × √s (rad/√s; m/s/√s is *velocity* random walk)
bias instability ``B``    ``bias_instability``   flicker (1/f) rate noise, PSD ``B²/(2π f)``, realised as a sum of
                          ``flicker_band``       first-order Gauss–Markov processes (below), rate units
rate random walk ``K``    ``random_walk``        ``b_RRW,k = b_RRW,k−1 + K √dt w_k``, ``b_RRW,0 = 0``; rate/√s
quantization ``Q``        ``quantization``       the *accumulated* output is a whole number of quanta
                                                 ``q``: ``Σ_{i≤k} Δ̃_i = q round(Σ_{i≤k} Δ̂_i / q)``, so each
                                                 output carries the residual of the previous ones
========================  =====================  ==============================================================

Bias instability: 1/f noise has no finite-state model, so it is synthesised
as a bank of independent Gauss–Markov processes ``x_j`` (autocorrelation
``σ_j² exp(−|t|/T_j)``, PSD ``2σ_j² T_j / (1 + (2π f T_j)²)``) with
correlation times spaced by a factor ``r = √10`` (two per decade) across
``flicker_band = (T_min, T_max)``, each of variance ``σ_j² = B² ln r / π``.
Summing the Lorentzians over ``ln T`` gives ``S(f) ≈ (σ_j² / ln r) / (2 f) =
B² / (2π f)`` for ``1/(2π T_max) ≪ f ≪ 1/(2π T_min)``: the Allan deviation
is flat at ``0.664 B`` within 2.5 % for ``20 T_min ≤ τ ≤ T_max / 10``
(computed from :func:`tumble.ins.allan.gauss_markov_adev`, see
``docs/ins.md``). Each process is advanced exactly,
``x_{k+1} = e^{−dt/T} x_k + σ √(1 − e^{−2dt/T}) w_k``, from its stationary
distribution; its rate is held over each sample interval (keep
``T_min ≫ dt``). (N. J. Kasdin, Proc. IEEE 83(5), 1995; IEEE Std
952-1997, Annex C.)

Every random draw comes from one ``numpy.random.Generator`` seeded by the
caller, in a fixed order, so a seed gives the same numbers on every run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_non_negative
from tumble.ins.increments import Increments, from_trajectory
from tumble.trajectory import Trajectory

__all__ = ["Imu", "SensorErrors"]

#: Spacing factor of the correlation times of the Gauss–Markov bank that
#: realises bias instability: two per decade (flat to 2.5 %, see the module docstring).
FLICKER_SPACING = math.sqrt(10.0)


def _vector3(value, name):
    arr = as_array(value, name, tail=(3,))
    if arr.shape != (3,):
        raise ValidationError(f"{name}: must have shape (3,), got {arr.shape}")
    return arr



@dataclass(frozen=True)
class SensorErrors:
    """Errors of a sensor triad (module docstring); every term defaults to zero (a perfect sensor)."""

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    white_noise: float = 0.0
    bias_instability: float = 0.0
    flicker_band: tuple[float, float] = (1.0, 1000.0)
    random_walk: float = 0.0
    scale_factor: np.ndarray = field(default_factory=lambda: np.zeros(3))
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    quantization: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "bias", _vector3(self.bias, "bias"))
        object.__setattr__(self, "scale_factor", _vector3(self.scale_factor, "scale_factor"))
        m = as_array(self.misalignment, "misalignment", tail=(3, 3))
        if m.shape != (3, 3):
            raise ValidationError(f"misalignment: must have shape (3, 3), got {m.shape}")
        if np.any(np.diag(m) != 0.0):
            raise ValidationError("misalignment: the diagonal must be zero (scale errors go in scale_factor)")
        object.__setattr__(self, "misalignment", m)
        for name in ("white_noise", "bias_instability", "random_walk", "quantization"):
            object.__setattr__(self, name, require_non_negative(getattr(self, name), name))
        band = tuple(float(x) for x in as_array(self.flicker_band, "flicker_band"))
        if len(band) != 2 or not 0.0 < band[0] < band[1]:
            raise ValidationError(f"flicker_band: must be (T_min, T_max) with 0 < T_min < T_max (s), got {band}")
        object.__setattr__(self, "flicker_band", band)

    def correlation_times(self) -> np.ndarray:
        """Correlation times ``T_j`` (s) of the Gauss–Markov bank: ``T_min rʲ`` up to ``T_max``, ``r = √10``."""
        lo, hi = self.flicker_band
        count = int(math.floor(math.log(hi / lo) / math.log(FLICKER_SPACING) + 1e-9)) + 1
        return lo * FLICKER_SPACING ** np.arange(count)

    def apply(self, true_increments: ArrayLike, dt: float, rng: np.random.Generator) -> np.ndarray:
        """Measured increments (K, 3) from true ones (K, 3) over sample interval ``dt`` (s), drawing from ``rng``.

        Draws, in this order: the white noise (K, 3); for each Gauss–Markov
        process its initial state (3,) and driving noise (K, 3); the rate
        random walk (K, 3) — only for the terms that are non-zero.
        """
        delta = as_array(true_increments, "true_increments", tail=(3,))
        K = delta.shape[0]
        out = delta @ (np.eye(3) + np.diag(self.scale_factor) + self.misalignment).T
        rate = np.broadcast_to(self.bias, (K, 3)).copy()
        if self.white_noise:
            out += self.white_noise * math.sqrt(dt) * rng.standard_normal((K, 3))
        if self.bias_instability:
            from scipy.signal import lfilter  # here: scipy.signal imports scipy.stats (~0.8 CPU s), not for import

            variance = self.bias_instability**2 * math.log(FLICKER_SPACING) / math.pi
            for T in self.correlation_times():
                phi = math.exp(-dt / T)
                x0 = math.sqrt(variance) * rng.standard_normal(3)
                drive = math.sqrt(variance * (1.0 - phi * phi)) * rng.standard_normal((K, 3))
                drive[0] += phi * x0  # x_1 = φ x_0 + drive_0, held over the first interval
                rate += lfilter([1.0], [1.0, -phi], drive, axis=0)
        if self.random_walk:
            rate += np.cumsum(self.random_walk * math.sqrt(dt) * rng.standard_normal((K, 3)), axis=0)
        out += rate * dt
        if self.quantization:
            q = self.quantization
            total = np.round(np.cumsum(out, axis=0) / q) * q
            out = np.diff(total, axis=0, prepend=np.zeros((1, 3)))
        return out


@dataclass(frozen=True)
class Imu:
    """A strapdown IMU: a gyro triad and an accelerometer triad with their :class:`SensorErrors`."""

    gyro: SensorErrors = field(default_factory=SensorErrors)
    accel: SensorErrors = field(default_factory=SensorErrors)

    def measure(self, truth: Increments, *,
                seed: int | np.random.SeedSequence | np.random.Generator | None = None) -> Increments:
        """Measured increments from true ones; gyro draws first, then accelerometer draws.

        ``seed`` (int, SeedSequence or Generator) seeds ``numpy.random.default_rng``:
        the same seed gives the same measurements.
        """
        if not isinstance(truth, Increments):
            raise ValidationError(f"truth: must be an Increments, got {type(truth).__name__}")
        rng = np.random.default_rng(seed)
        delta_theta = self.gyro.apply(truth.delta_theta, truth.dt, rng)
        delta_v = None if truth.delta_v is None else self.accel.apply(truth.delta_v, truth.dt, rng)
        return Increments(t0=truth.t0, dt=truth.dt, delta_theta=delta_theta, delta_v=delta_v)

    def sample(self, trajectory: Trajectory, *, oversample: int = 2, specific_force: ArrayLike | None = None,
               lever_arm: ArrayLike | None = None,
               seed: int | np.random.SeedSequence | np.random.Generator | None = None) -> Increments:
        """Measure a true motion: :func:`~tumble.ins.increments.from_trajectory`, then :meth:`measure`.

        The sample rate is ``1 / (oversample (t[1] − t[0]))`` of the trajectory grid.
        """
        truth = from_trajectory(trajectory, oversample=oversample, specific_force=specific_force,
                                lever_arm=lever_arm)
        return self.measure(truth, seed=seed)
