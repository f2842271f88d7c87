"""Allan deviation of gyro (or accelerometer) data and its noise terms (the figure: :func:`tumble.viz.ins.allan_figure`).

The overlapping Allan variance of a rate record ``Ω_k`` sampled at ``dt``
(s), for a cluster time ``τ = m dt``, from the integrated angle
``θ_k = Σ_{i<k} Ω_i dt`` (IEEE Std 952-1997, Annex C, eq. C.7; W. J. Riley,
*Handbook of Frequency Stability Analysis*, NIST SP 1065, 2008, eq. 14)::

    σ²(τ) = 1 / (2 τ² (K − 2m + 1)) Σ_{k=0}^{K−2m} (θ_{k+2m} − 2 θ_{k+m} + θ_k)²

(``K`` samples, so ``K + 1`` angles). In terms of the two-sided rate PSD
``S_Ω(f)``, ``σ²(τ) = 4 ∫₀^∞ S_Ω(f) sin⁴(π f τ) / (π f τ)² df``, and the
IEEE 952 noise terms appear as straight lines on a log-log plot:

=========================  ================================  ==========================
term (IEEE 952 symbol)     rate PSD ``S_Ω(f)``               ``σ(τ)``
=========================  ================================  ==========================
angle random walk ``N``    ``N²``                            ``N / √τ``
bias instability ``B``     ``(B² / 2π) / f``  (f ≤ f₀)       ``B √(2 ln 2 / π) ≈ 0.664 B``
rate random walk ``K``     ``(K / 2π)² / f²``                ``K √(τ / 3)``
=========================  ================================  ==========================

Units for a gyro: ``N`` rad/√s, ``B`` rad/s, ``K`` rad/s/√s (for an
accelerometer replace rad by m/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble._moved import moved
from tumble._validate import ValidationError, as_array, require_positive

__all__ = ["FLICKER_FACTOR", "AllanDeviation", "allan_deviation", "gauss_markov_adev"]

__getattr__ = moved(__name__, {"allan_figure": "tumble.viz.ins"})

#: ``σ(τ) / B`` on the flat part of the Allan deviation of bias instability: √(2 ln 2 / π).
FLICKER_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)


@dataclass(frozen=True)
class AllanDeviation:
    """Allan deviation ``sigma`` (units of the rate, e.g. rad/s) at cluster times ``tau`` (s).

    ``sigma`` has shape (len(tau),) for one axis or (len(tau), 3) for a triad.
    """

    tau: np.ndarray
    sigma: np.ndarray

    def white_noise(self, tau_max: float = 1.0) -> np.ndarray:
        """Angle random walk ``N`` (rate unit × √s) from the ``−½`` slope line.

        The line ``log σ = log N − ½ log τ`` fitted by least squares with its
        slope fixed (``log N = mean(log σ + ½ log τ)``) to the points with
        ``τ ≤ tau_max`` (s): ``N`` is its value at τ = 1 s (IEEE 952 C.1).
        """
        keep = self.tau <= tau_max
        if not keep.any():
            raise ValidationError(f"tau_max: no cluster time <= {tau_max} s (the shortest is {self.tau[0]} s)")
        tau = self.tau[keep].reshape((-1,) + (1,) * (self.sigma.ndim - 1))
        return np.exp(np.mean(np.log(self.sigma[keep]) + 0.5 * np.log(tau), axis=0))

    def bias_instability(self) -> np.ndarray:
        """Bias instability ``B = min σ(τ) / 0.664`` (rate units), from the flat minimum (IEEE 952 C.2)."""
        return self.sigma.min(axis=0) / FLICKER_FACTOR

    def rate_random_walk(self, tau_min: float) -> np.ndarray:
        """Rate random walk ``K`` from the ``+½`` slope line ``σ = K √(τ/3)`` fitted for ``τ ≥ tau_min`` (s)."""
        keep = self.tau >= tau_min
        if not keep.any():
            raise ValidationError(f"tau_min: no cluster time >= {tau_min} s (the longest is {self.tau[-1]} s)")
        tau = self.tau[keep].reshape((-1,) + (1,) * (self.sigma.ndim - 1))
        return np.exp(np.mean(np.log(self.sigma[keep]) - 0.5 * np.log(tau / 3.0), axis=0))


def allan_deviation(samples: ArrayLike, dt: float, *, kind: str = "rate", m: ArrayLike | None = None,
                    per_decade: int = 10) -> AllanDeviation:
    """Overlapping Allan deviation of a record of rates or of angle increments.

    Parameters
    ----------
    samples : (K,) or (K, 3) array_like
        ``kind="rate"``: mean rates over each sample interval (e.g. rad/s);
        ``kind="increment"``: angle increments (e.g. rad).
    dt : float
        Sample interval, s.
    m : array_like of int, optional
        Cluster sizes (``τ = m dt``), each in ``[1, (K − 1) // 2]``; default:
        ``per_decade`` logarithmically spaced sizes from 1 to ``K // 10``
        (cluster times up to a tenth of the record: longer ones rest on fewer
        than ten independent clusters, and their scatter would pass for a
        minimum).
    """
    dt = require_positive(dt, "dt")
    if kind not in ("rate", "increment"):
        raise ValidationError(f"kind: must be 'rate' or 'increment', got {kind!r}")
    x = as_array(samples, "samples")
    if x.ndim not in (1, 2) or x.shape[0] < 3:
        raise ValidationError(f"samples: must have shape (K,) or (K, 3) with K >= 3, got {x.shape}")
    increments = x * dt if kind == "rate" else x
    theta = np.concatenate([np.zeros((1,) + x.shape[1:]), np.cumsum(increments, axis=0)])
    K = x.shape[0]
    m_max = (K - 1) // 2
    if m is None:
        top = max(1, K // 10)
        m = np.unique(np.round(np.logspace(0.0, math.log10(top), max(2, int(per_decade * math.log10(top)) + 1))))
    m = np.asarray(m).astype(np.int64)
    if m.ndim != 1 or m.size == 0 or m.min() < 1 or m.max() > m_max:
        raise ValidationError(f"m: cluster sizes must lie in [1, {m_max}] for {K} samples")
    sigma = np.empty((m.size,) + x.shape[1:])
    for i, size in enumerate(m):
        d = theta[2 * size:] - 2.0 * theta[size:-size] + theta[:-2 * size]
        tau = size * dt
        sigma[i] = np.sqrt(np.mean(d * d, axis=0) / (2.0 * tau * tau))
    return AllanDeviation(tau=m * dt, sigma=sigma)


def gauss_markov_adev(tau: ArrayLike, sigma: float, correlation_time: float) -> np.ndarray:
    """Allan deviation of a first-order Gauss–Markov rate of standard deviation ``sigma`` and correlation time ``T``.

    Autocorrelation ``σ² exp(−|t|/T)``; with ``x = τ/T`` (IEEE 952, Annex C.6)::

        σ_A²(τ) = (2 σ² T / τ) [1 − (3 − 4 e^{−x} + e^{−2x}) / (2x)]
    """
    x = np.asarray(tau, dtype=np.float64) / correlation_time
    return np.sqrt(2.0 * sigma**2 / x * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x)))


