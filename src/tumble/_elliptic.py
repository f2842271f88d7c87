"""Compiled elliptic functions and integrals for the exact torque-free motion.

Scalar Numba kernels, real arguments, parameter ``0 ≤ m ≤ 1`` given together
with its complement ``m1 = 1 − m``. Passing both keeps full relative accuracy
at both ends: ``m1`` near 0 (modulus ``k → 1``, where ``K(m)`` diverges like
``½ ln(16/m1)``) is never formed as ``1 − m``.

* :func:`landen` — the descending Landen (Gauss) sequence of moduli, computed
  once per parameter with the arithmetic–geometric mean (AGM) of ``1`` and
  ``k' = √m1``;
* :func:`ellipk` — ``K(m) = π / (2 AGM(1, √m1))`` (DLMF 19.8.5);
* :func:`jacobi` — ``sn, cn, dn`` of a real argument by the descending Landen
  transformation (DLMF 22.7.1-3), in a ratio form that keeps full *relative*
  accuracy of ``cn`` and ``dn`` near the quarter period, after reduction of the
  argument to ``[−K, K]``; :func:`jacobi_angle` also returns the theta-function
  argument ``z = πr/(2K)``'s sine and cosine; :func:`ellipj` adds the amplitude ``am``;
* :func:`carlson_rf`, :func:`carlson_rj` — Carlson's symmetric integrals by the
  duplication algorithm (B. C. Carlson, "Numerical computation of real or
  complex elliptic integrals", Numer. Algorithms 10 (1995) 13-26), which give
  ``F(φ|m)`` and ``Π(n; φ|m)`` (DLMF 19.25.5, 19.25.14).

The parameter convention is scipy's (``m = k²``); ``scipy.special`` (ellipj,
ellipk, ellipkm1, elliprf, elliprj) is the reference in the tests.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# The Landen descent stops once the modulus k_N ≤ _LANDEN_TOL: the functions of
# modulus k_N then equal sin, cos and 1 up to O(k_N²) ≤ 1e-18, below rounding.
_LANDEN_TOL = 1e-9
# Levels stored for the descent; k' = √m1 ≥ 1e-162 (m1 ≥ the smallest normal
# double) needs at most 9, from k_{n+1} ≈ k_n²/4 once k_n < 1.
MAX_LEVELS = 16
# Carlson's truncation parameter r: the duplication stops when the relative
# error of the fifth/seventh-order Taylor tail is below r (Carlson 1995, eq. 2.2, 2.19).
_CARLSON_R = 1e-17


@njit(cache=True)
def landen(m, m1):
    """Descending Landen moduli ``k_1 … k_N``, their complements ``1 − k_n`` and the AGM ``a_N``.

    With ``a_0 = 1``, ``b_0 = k' = √m1``, ``c_0 = k = √m``:
    ``a_{n+1} = (a_n + b_n)/2``, ``b_{n+1} = √(a_n b_n)``,
    ``c_{n+1} = c_n² / (4 a_{n+1})`` (= ``(a_n − b_n)/2`` without cancellation);
    the moduli of the Gauss transformation are ``k_{n+1} = c_{n+1}/a_{n+1}``
    and ``1 − k_{n+1} = b_n / a_{n+1}`` (DLMF 22.7.1, 19.8.1), both free of
    cancellation for ``m`` near 0 and near 1. Returns ``(k, 1 − k, N, a_N)``
    with the first ``N`` entries filled; ``a_N = AGM(1, k')`` to rounding once
    ``k_N ≤ 1e-9``. Needs ``m1 > 0``.
    """
    ks = np.zeros(MAX_LEVELS)
    kcs = np.ones(MAX_LEVELS)
    a, b, c = 1.0, math.sqrt(m1), math.sqrt(m)
    n = 0
    while c > _LANDEN_TOL * a and n < MAX_LEVELS:
        a_next = 0.5 * (a + b)
        c = 0.25 * c * c / a_next
        ks[n] = c / a_next
        kcs[n] = b / a_next
        b = math.sqrt(a * b)
        a = a_next
        n += 1
    return ks, kcs, n, a


@njit(cache=True)
def ellipk(m, m1):
    """Complete elliptic integral of the first kind ``K(m) = π / (2 AGM(1, √m1))``.

    ``m1 = 1 − m`` is used directly, so ``K`` keeps full relative accuracy as
    ``m1 → 0`` (the role of ``scipy.special.ellipkm1``). ``K(1) = +inf``.
    """
    if m1 == 0.0:
        return math.inf
    return 0.5 * math.pi / landen(m, m1)[3]


@njit(cache=True)
def jacobi(u, quarter, ks, kcs, n, agm):
    """Jacobi functions of ``u`` reduced to a half period: ``(j, sn r, cn r, dn r)``, ``r = u − 2jK``.

    ``quarter = K(m)``, and ``ks, kcs, n, agm`` come from :func:`landen` (for
    ``m = 1``, ``quarter = inf``: then ``j = 0`` and ``sn = tanh u``,
    ``cn = dn = sech u``). The full functions are ``sn u = (−1)^j sn r``,
    ``cn u = (−1)^j cn r``, ``dn u = dn r`` and the amplitude is
    ``am u = jπ + atan2(sn r, cn r)``, with ``|r| ≤ K`` and ``cn r ≥ 0``.
    The method is that of :func:`jacobi_angle`.
    """
    if quarter == math.inf:
        return 0, math.tanh(u), 1.0 / math.cosh(u), 1.0 / math.cosh(u)
    j, s, c, d, _, _ = jacobi_angle(u, quarter, ks, kcs, n, agm)
    return j, s, c, d


@njit(cache=True)
def jacobi_angle(u, quarter, ks, kcs, n, agm):
    """:func:`jacobi` for ``m < 1`` and also ``(sin z, cos z)``, ``z = π r / (2K)``: ``(j, sn, cn, dn, sin z, cos z)``.

    ``z`` is the argument of the theta functions, ``sn r = θ₃θ₁(z)/(θ₂θ₄(z))``
    (DLMF 22.2.4); :mod:`tumble._free_flow` sums its nome series for the
    attitude from these two numbers.

    Method: at the bottom of the Landen descent (modulus ``k_N ≈ 0``) the
    functions are ``sin θ, cos θ, 1`` with ``θ = |r| a_N = π|r|/(2K) = |z|``, and
    ``cos θ = sin((K − |r|) a_N)`` is used past ``π/4`` so that ``cn`` keeps
    its relative accuracy near ``r = K``. Climbing one level with the next
    modulus ``k`` (DLMF 22.7.1-3, with ``1 − k sn² = (1 − k) sn² + cn²``
    written without cancellation) maps unnormalised ``(s, c, d) ∝ (sn, cn, dn)``::

        s ← (1 + k) s,    c ← c d,    d ← ((1 − k) s² + c²) / ((1 + k) s² + c²)

    and finally ``sn = s/√(s² + c²)``, ``cn = c/√(s² + c²)``. Every step is a
    product or a sum of non-negative terms, so the relative error stays a few
    ulp for every ``r`` in ``[0, K]`` and every ``m`` in ``[0, 1)``.
    """
    j = math.floor(u / (2.0 * quarter) + 0.5)
    r = u - 2.0 * quarter * j
    x = abs(r)
    theta = x * agm
    sin_z = math.sin(theta)
    cos_z = math.cos(theta) if theta < 0.25 * math.pi else math.sin((quarter - x) * agm)
    s, c, d = sin_z, cos_z, 1.0
    for i in range(n - 1, -1, -1):
        k = ks[i]
        s2, c2 = s * s, c * c
        d_next = (kcs[i] * s2 + c2) / ((1.0 + k) * s2 + c2)
        s = (1.0 + k) * s
        c = c * d
        d = d_next
    h = math.hypot(s, c)
    return int(j), math.copysign(s / h, r), c / h, d, math.copysign(sin_z, r), cos_z


@njit(cache=True)
def ellipj(u, m, m1):
    """Jacobi elliptic functions ``(sn, cn, dn, am)`` of real ``u`` for ``m = 1 − m1`` in [0, 1].

    Same convention as ``scipy.special.ellipj(u, m)``; see :func:`jacobi` for
    the method. ``m = 0`` gives ``sin, cos, 1, u``; ``m = 1`` gives
    ``tanh, sech, sech, gd(u)``.
    """
    if m1 == 0.0:
        j, s, c, d = jacobi(u, math.inf, np.zeros(1), np.ones(1), 0, 1.0)
        return s, c, d, math.atan2(s, c)
    ks, kcs, n, agm = landen(m, m1)
    j, s, c, d = jacobi(u, 0.5 * math.pi / agm, ks, kcs, n, agm)
    sign = 1.0 - 2.0 * (j & 1)
    return sign * s, sign * c, d, j * math.pi + math.atan2(s, c)


@njit(cache=True)
def carlson_rf(x, y, z):
    """Carlson's ``R_F(x, y, z) = ½ ∫₀^∞ dt / √((t + x)(t + y)(t + z))`` for ``x, y, z ≥ 0``, at most one 0.

    Duplication (Carlson 1995, Algorithm 1): ``λ = √x√y + √y√z + √z√x``,
    ``(x, y, z) ← (x + λ, y + λ, z + λ)/4`` until the deviations from the mean
    ``A`` are small, then the fifth-order series
    ``R_F = A^{-1/2} (1 − E₂/10 + E₃/14 + E₂²/24 − 3E₂E₃/44)`` (DLMF 19.36.1).
    """
    a0 = (x + y + z) / 3.0
    q = (3.0 * _CARLSON_R) ** (-1.0 / 6.0) * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    dx, dy = a0 - x, a0 - y  # X = (A_0 − x) / (4^m A_m), Y likewise, after the loop
    a = a0
    scale = 1.0  # 4^-m
    while scale * q >= abs(a):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sy * sz + sz * sx
        x, y, z, a = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (a + lam)
        scale *= 0.25
    dx *= scale / a
    dy *= scale / a
    dz = -dx - dy
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)


@njit(cache=True)
def _rc_one(e):
    """``R_C(1, 1 + e)``, ``e > −1``: ``atan(√e)/√e`` (e > 0), ``atanh(√−e)/√−e`` (e < 0), DLMF 19.2.19-20.

    For ``|e| < 1e-3`` (every duplication step after the first few, as
    ``e_m`` shrinks 64-fold per step) the series
    ``Σ (−e)^i / (2i + 1)`` to ``e⁵`` is used: its remainder ``e⁶/13 < 1e-19``.
    """
    if abs(e) < 1e-3:
        return 1.0 - e * (1.0 / 3.0 - e * (1.0 / 5.0 - e * (1.0 / 7.0 - e * (1.0 / 9.0 - e / 11.0))))
    if e > 0.0:
        s = math.sqrt(e)
        return math.atan(s) / s
    s = math.sqrt(-e)
    return math.atanh(s) / s


@njit(cache=True)
def carlson_rj(x, y, z, p):
    """Carlson's ``R_J(x, y, z, p) = 3/2 ∫₀^∞ dt / ((t + p) √((t + x)(t + y)(t + z)))``.

    For ``x, y, z ≥ 0`` (at most one 0) and ``p > 0``. Duplication (Carlson
    1995, Algorithm 4): with ``d_m = (√p + √x)(√p + √y)(√p + √z)`` and
    ``e_m = 4^{-3m} δ / d_m²``, ``δ = (p − x)(p − y)(p − z)``,

        R_J = 4^{-M} A_M^{-3/2} (1 − 3E₂/14 + E₃/6 + 9E₂²/88 − 3E₄/22 − 9E₂E₃/52 + 3E₅/26)
              + 6 Σ_{m<M} 4^{-m} R_C(1, 1 + e_m) / d_m

    (DLMF 19.36.2). ``R_D(x, y, z) = R_J(x, y, z, z)``.
    """
    a0 = (x + y + z + 2.0 * p) / 5.0
    delta = (p - x) * (p - y) * (p - z)
    q = (0.25 * _CARLSON_R) ** (-1.0 / 6.0) * max(abs(a0 - x), abs(a0 - y), abs(a0 - z), abs(a0 - p))
    dx, dy, dz = a0 - x, a0 - y, a0 - z  # X = (A_0 − x) / (4^m A_m), Y, Z likewise, after the loop
    a = a0
    scale = 1.0  # 4^-m
    total = 0.0
    while scale * q >= abs(a):
        sx, sy, sz, sp = math.sqrt(x), math.sqrt(y), math.sqrt(z), math.sqrt(p)
        lam = sx * sy + sy * sz + sz * sx
        d = (sp + sx) * (sp + sy) * (sp + sz)
        total += scale / d * _rc_one(scale * scale * scale * delta / (d * d))
        x, y, z, p, a = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (p + lam), 0.25 * (a + lam)
        scale *= 0.25
    f = scale / a
    dx, dy, dz = dx * f, dy * f, dz * f
    dp = -0.5 * (dx + dy + dz)
    e2 = dx * dy + dx * dz + dy * dz - 3.0 * dp * dp
    e3 = dx * dy * dz + 2.0 * e2 * dp + 4.0 * dp * dp * dp
    e4 = (2.0 * dx * dy * dz + e2 * dp + 3.0 * dp * dp * dp) * dp
    e5 = dx * dy * dz * dp * dp
    series = (1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
              - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0)
    return scale * series / (a * math.sqrt(a)) + 6.0 * total
