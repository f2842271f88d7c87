"""The International Geomagnetic Reference Field, IGRF-14, to its full degree (13).

The main field outside the Earth is the gradient of a scalar potential
(Alken et al., "International Geomagnetic Reference Field: the
fourteenth generation", 2025; Langel, "The main field", in *Geomagnetism*
vol. 1, 1987)::

    V(r, θ, φ, t) = a Σₙ₌₁¹³ (a/r)ⁿ⁺¹ Σₘ₌₀ⁿ [gₙᵐ(t) cos mφ + hₙᵐ(t) sin mφ] Pₙᵐ(cos θ)
    B = −∇V:  B_r = Σ (n+1) (a/r)ⁿ⁺² Σ (g cos mφ + h sin mφ) Pₙᵐ
              B_θ = −Σ (a/r)ⁿ⁺² Σ (g cos mφ + h sin mφ) dPₙᵐ/dθ
              B_φ = −(1/sin θ) Σ (a/r)ⁿ⁺² Σ m (−g sin mφ + h cos mφ) Pₙᵐ

with ``r, θ, φ`` the geocentric radius, colatitude and east longitude in the
Earth-fixed frame (ITRS), ``a = 6371.2 km`` and ``Pₙᵐ`` the Schmidt
semi-normalised associated Legendre functions (no Condon–Shortley phase).
The Gauss coefficients are those of the file ``IGRF14.shc`` that ships with
the ``ppigrf`` package (definitive to 2020, IGRF-14 for 2025 and its
predicted secular variation to 2030), read once and interpolated linearly in
time between their epochs (1 January of each fifth year), as the IGRF
prescribes. Valid from 1900-01-01 to 2030-01-01.

:func:`igrf_field_itrs` is the compiled synthesis (``nₘₐₓ = 13``) in Cartesian
ITRS axes and tesla; :func:`igrf_field` is its NumPy face. They are checked
against ``ppigrf``'s own values (``tests/spacecraft/test_spacecraft_environment_table.py``).
"""

from __future__ import annotations

import bisect
import functools
import math
from datetime import datetime, timezone
from importlib.resources import files

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array

__all__ = ["IGRF_RADIUS", "igrf_coefficients", "igrf_field", "igrf_field_itrs"]

#: IGRF reference radius a, m.
IGRF_RADIUS = 6371.2e3


class _Coefficients:
    """The Gauss coefficients of IGRF14.shc: ``g, h`` of shape (epochs, n+1, n+1), nT; epochs as datetimes."""

    def __init__(self, text: str):
        rows = [line.split() for line in text.splitlines() if line.strip() and not line.startswith("#")]
        degree = int(rows[0][1])
        years = [float(y) for y in rows[1]]
        self.epochs = [datetime(int(y), 1, 1) for y in years]
        self.g = np.zeros((len(years), degree + 1, degree + 1))
        self.h = np.zeros_like(self.g)
        for row in rows[2:]:
            n, m = int(row[0]), int(row[1])
            target = self.g if m >= 0 else self.h
            target[:, n, abs(m)] = [float(v) for v in row[2:]]


@functools.cache
def _igrf14() -> _Coefficients:
    return _Coefficients(files("ppigrf").joinpath("IGRF14.shc").read_text(encoding="utf-8"))


def igrf_coefficients(when: datetime) -> tuple[np.ndarray, np.ndarray]:
    """IGRF-14 Gauss coefficients ``(g, h)`` at the UTC time ``when`` (naive = UTC): two (14, 14) arrays in
    tesla, ``g[n, m]``, ``h[n, m]``, linear in time between the model's epochs."""
    data = _igrf14()
    when = when if when.tzinfo is None else when.astimezone(timezone.utc).replace(tzinfo=None)
    first, last = data.epochs[0], data.epochs[-1]
    if not first <= when <= last:
        raise ValidationError(f"epoch: must be within IGRF-14 ({first:%Y-%m-%d} to {last:%Y-%m-%d}), got {when}")
    k = min(bisect.bisect_right(data.epochs, when) - 1, len(data.epochs) - 2)
    w = (when - data.epochs[k]) / (data.epochs[k + 1] - data.epochs[k])
    g = (1.0 - w) * data.g[k] + w * data.g[k + 1]
    h = (1.0 - w) * data.h[k] + w * data.h[k + 1]
    return 1e-9 * g, 1e-9 * h


@njit(cache=True)
def igrf_field_itrs(x: float, y: float, z: float, g: np.ndarray, h: np.ndarray) -> tuple[float, float, float]:
    """IGRF field ``(Bx, By, Bz)``, T, ITRS axes, at the ITRS position ``(x, y, z)`` (m), for the Gauss
    coefficients ``g[n, m]``, ``h[n, m]`` (T) of :func:`igrf_coefficients`; the module docstring gives the
    equations. ``P/sin θ`` is carried by its own recursion, so the field is finite on the polar axis."""
    nmax = g.shape[0] - 1
    rho = math.sqrt(x * x + y * y)
    r = math.sqrt(rho * rho + z * z)
    c, s = z / r, rho / r
    phi = math.atan2(y, x)
    # p[n, m] = Pₙᵐ(cos θ) (Schmidt), dp = dPₙᵐ/dθ, q = Pₙᵐ / sin θ for m ≥ 1
    p = np.zeros((nmax + 1, nmax + 1))
    dp = np.zeros((nmax + 1, nmax + 1))
    q = np.zeros((nmax + 1, nmax + 1))
    p[0, 0] = 1.0
    p[1, 1], dp[1, 1], q[1, 1] = s, c, 1.0
    for n in range(2, nmax + 1):
        k = math.sqrt(1.0 - 0.5 / n)
        q[n, n] = k * s * q[n - 1, n - 1]
        p[n, n] = k * s * p[n - 1, n - 1]
        dp[n, n] = k * (c * p[n - 1, n - 1] + s * dp[n - 1, n - 1])
    for m in range(0, nmax):
        for n in range(m + 1, nmax + 1):
            a1 = (2 * n - 1) / math.sqrt(n * n - m * m)
            a2 = math.sqrt(((n - 1) * (n - 1) - m * m) / (n * n - m * m)) if n - 1 > m else 0.0
            p[n, m] = a1 * c * p[n - 1, m] - (a2 * p[n - 2, m] if n - 2 >= m else 0.0)
            q[n, m] = a1 * c * q[n - 1, m] - (a2 * q[n - 2, m] if n - 2 >= m else 0.0)
            dp[n, m] = a1 * (c * dp[n - 1, m] - s * p[n - 1, m]) - (a2 * dp[n - 2, m] if n - 2 >= m else 0.0)
    br = bt = bp = 0.0
    ratio = IGRF_RADIUS / r
    scale = ratio * ratio
    for n in range(1, nmax + 1):
        scale *= ratio                      # (a/r)ⁿ⁺²
        for m in range(0, n + 1):
            cm, sm = math.cos(m * phi), math.sin(m * phi)
            gh = g[n, m] * cm + h[n, m] * sm
            br += (n + 1) * scale * gh * p[n, m]
            bt -= scale * gh * dp[n, m]
            if m > 0:
                bp -= scale * m * (h[n, m] * cm - g[n, m] * sm) * q[n, m]
    cp, sp = math.cos(phi), math.sin(phi)
    bx = (br * s + bt * c) * cp - bp * sp
    by = (br * s + bt * c) * sp + bp * cp
    bz = br * c - bt * s
    return bx, by, bz


@njit(cache=True)
def _fields(r, g, h, out):
    for k in range(r.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = igrf_field_itrs(r[k, 0], r[k, 1], r[k, 2], g[k], h[k])


def igrf_field(r_itrs: ArrayLike, when: datetime | list[datetime]) -> np.ndarray:
    """IGRF-14 field (…, 3), T, ITRS axes, at ITRS positions ``r_itrs`` (…, 3), m, at the UTC time ``when``
    (one datetime, or one per position)."""
    r = as_array(r_itrs, "r_itrs", tail=(3,))
    if np.any(np.linalg.norm(r, axis=-1) == 0.0):
        raise ValidationError("r_itrs: the field is singular at r = 0")
    flat = np.ascontiguousarray(r.reshape(-1, 3))
    whens = [when] * len(flat) if isinstance(when, datetime) else list(when)
    if len(whens) != len(flat):
        raise ValidationError(f"when: must be one datetime or one per position ({len(flat)}), got {len(whens)}")
    g = np.empty((len(flat), *_igrf14().g.shape[1:]))
    h = np.empty_like(g)
    for k, w in enumerate(whens):
        g[k], h[k] = igrf_coefficients(w)
    out = np.empty((len(flat), 3))
    _fields(flat, g, h, out)
    return out.reshape(r.shape)
