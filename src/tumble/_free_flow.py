"""The exact flow of the torque-free rigid body, compiled: body rates and attitude in closed form.

The public face is :func:`tumble.analytic.torque_free` and
``tumble.simulate(..., method="exact")``; integrators that split a motion into
the free flow and torque kicks call :func:`setup` and :func:`evaluate` here.

Principal axes P, moments ``I₁ ≤ I₂ ≤ I₃`` (kg·m²), body rate ``ω`` in P
(rad/s). The motion conserves the kinetic energy ``T = ½ Σ Iᵢωᵢ²`` and the
angular momentum ``L_N`` (inertial axes), ``L² = Σ Iᵢ²ωᵢ²``. Everything below
is written with the differences

    Δᵢ = L² − 2T Iᵢ = Σⱼ Iⱼ (Iⱼ − Iᵢ) ωⱼ²        (J·kg·m²)

evaluated from the rates as these sums, so that ``Δ₁ ≥ 0 ≥ Δ₃`` are free of
cancellation; ``Δ₂`` (whose sign decides the regime, and which vanishes on the
separatrix) is summed in double-double arithmetic, so that ``1 − m ∝ Δ₂``
keeps its relative accuracy as ``m → 1``.

Regimes (:data:`REGIMES`) and the rates (Landau & Lifshitz, *Mechanics*,
§37; Celledoni, Fassò, Säfström, Zanna, SIAM J. Sci. Comput. 30 (2008)
2084-2112), derived again in ``docs/exact.md``:

* ``"major"`` (``Δ₂ > 0``: the polhode encircles the axis of the largest
  moment, k = 3, j = 1) and ``"minor"`` (``Δ₂ < 0``: around the smallest, k = 1,
  j = 3). With the axis ``k`` carrying ``dn`` and the axis ``j`` carrying ``cn``::

      ω_j = s_j A_j cn τ,   ω₂ = s₂ A₂ sn τ,   ω_k = s_k A_k dn τ,   τ = λ (t − t₀)
      A_j² = |Δ_k| / (I_j |I_k − I_j|),   A₂² = |Δ_k| / (I₂ |I_k − I₂|),
      A_k² = |Δ_j| / (I_k |I_k − I_j|)
      λ² = |I_k − I₂| |Δ_j| / (I₁I₂I₃),   m = |I₂ − I_j| |Δ_k| / (|I_k − I₂| |Δ_j|),
      1 − m = |I_k − I_j| |Δ₂| / (|I_k − I₂| |Δ_j|)

  with signs ``s₂ = s_j s_k`` (Euler's equations fix the product; the free
  sign is the half-period shift ``τ → τ + 2K``). For ``(k, j) = (3, 1)`` this
  is Landau–Lifshitz (37.10)-(37.11) with ``m = k²``.
* ``"separatrix"`` (``Δ₂ = 0`` exactly): the same with ``m = 1``, i.e.
  ``cn = dn = sech τ``, ``sn = tanh τ``; rotation about axis 2 is its fixed point.
* ``"oblate"`` (``I₁ = I₂ < I₃``), ``"prolate"`` (``I₁ < I₂ = I₃``): ``m = 0``,
  the rate precesses about the symmetry axis at ``λ = |I₃ − I₁| |ω_axis| / I_⊥``.
* ``"sphere"`` (``I₁ = I₃``) and ``"rest"`` (``ω = 0``): constant rate.

The attitude construction (third-kind integral ``Π``) is described with
:func:`torque_free`. Its periodic part is summed per time point by a nome
(theta-function) series whose coefficients are fixed per body
(:func:`_nome_series`: no ``R_J`` and no arctangent per point) while the
nome ``q ≤ 0.6``; closer to the separatrix by Carlson's ``R_J`` (:func:`_frame`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _elliptic, _quat

REGIMES = ("rest", "sphere", "oblate", "prolate", "major", "minor", "separatrix")
_REST, _SPHERE, _OBLATE, _PROLATE, _MAJOR, _MINOR, _SEPARATRIX = range(len(REGIMES))


@njit(cache=True)
def _two_sum(a, b):
    """``a + b = s + e`` exactly (Knuth's TwoSum)."""
    s = a + b
    v = s - a
    return s, (a - (s - v)) + (b - v)


@njit(cache=True)
def _two_prod(a, b):
    """``a b = p + e`` exactly (Dekker's product with Veltkamp's split; no FMA needed)."""
    p = a * b
    c = 134217729.0 * a  # 2^27 + 1
    ah = c - (c - a)
    c = 134217729.0 * b
    bh = c - (c - b)
    al, bl = a - ah, b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@njit(cache=True)
def _dd_scale(hi, lo, b):
    """Double-double ``(hi + lo) b``."""
    p, e = _two_prod(hi, b)
    return _two_sum(p, e + lo * b)


@njit(cache=True)
def _separatrix_distance(i1, i2, i3, w1, w2, w3):
    """``Δ₂ = I₃(I₃ − I₂)ω₃² − I₁(I₂ − I₁)ω₁²`` in double-double, rounded once.

    Near the separatrix the two terms cancel; evaluated in plain double each
    carries a rounding error ~eps × its size, which would leave ``m1 ∝ Δ₂``
    with a relative error eps/m1. Here ``m1`` keeps full relative accuracy
    for exactly given moments and rates.
    """
    terms = (0.0, 0.0)
    for moment, w in ((i3, w3), (i1, w1)):  # Iᵢ(Iᵢ − I₂)ωᵢ² for i = 3, 1
        hi, lo = _two_sum(moment, -i2)
        hi, lo = _dd_scale(hi, lo, moment)
        hi, lo = _dd_scale(hi, lo, w)
        hi, lo = _dd_scale(hi, lo, w)
        s, e = _two_sum(terms[0], hi)
        terms = _two_sum(s, e + terms[1] + lo)
    return terms[0] + terms[1]


@njit(cache=True)
def _deltas(i1, i2, i3, w1, w2, w3):
    """``(T, |L|, Δ₁, Δ₂, Δ₃)`` with ``Δᵢ = L² − 2T Iᵢ`` summed without cancellation in Δ₁, Δ₃.

    ``Δ₂`` changes sign on the separatrix; it is summed in double-double
    (:func:`_separatrix_distance`).
    """
    a1, a2, a3 = i1 * w1 * w1, i2 * w2 * w2, i3 * w3 * w3
    energy = 0.5 * (a1 + a2 + a3)
    momentum = math.sqrt(i1 * a1 + i2 * a2 + i3 * a3)
    d1 = (i2 - i1) * a2 + (i3 - i1) * a3
    d2 = _separatrix_distance(i1, i2, i3, w1, w2, w3)
    d3 = -((i3 - i1) * a1 + (i3 - i2) * a2)
    return energy, momentum, d1, d2, d3


@njit(cache=True)
def _regime(i1, i2, i3, w1, w2, w3, d2):
    """Regime code (index into :data:`REGIMES`) from the moments and the sign of Δ₂."""
    if w1 == 0.0 and w2 == 0.0 and w3 == 0.0:
        return _REST
    if i1 == i3:
        return _SPHERE
    if i1 == i2:
        return _OBLATE
    if i2 == i3:
        return _PROLATE
    if d2 > 0.0:
        return _MAJOR
    if d2 < 0.0:
        return _MINOR
    return _SEPARATRIX


@njit(cache=True)
def _axes_of(code):
    """``(k, j)``, 0-based: the axis carrying ``dn`` (encircled) and the one carrying ``cn``."""
    if code == _MINOR or code == _PROLATE:
        return 0, 2
    return 2, 0


@njit(cache=True)
def _parameters(i1, i2, i3, w1, w2, w3):
    """``(code, T, |L|, m, m1, λ, |Δ₁|, |Δ₂|, |Δ₃|)`` of the motion, formulas of the module docstring.

    ``m = 0, m1 = 1`` for symmetric bodies and for the sphere and rest
    (``λ = 0`` there); ``m = 1, m1 = 0`` on the separatrix.
    """
    energy, momentum, d1, d2, d3 = _deltas(i1, i2, i3, w1, w2, w3)
    code = _regime(i1, i2, i3, w1, w2, w3, d2)
    deltas = (abs(d1), abs(d2), abs(d3))
    m, m1, lam = 0.0, 1.0, 0.0
    if code != _REST and code != _SPHERE:
        moments = (i1, i2, i3)
        k, j = _axes_of(code)
        ik, ij = moments[k], moments[j]
        scale = abs(ik - i2) * deltas[j]
        lam = math.sqrt(scale / (i1 * i2 * i3))
        if code == _SEPARATRIX:
            m, m1 = 1.0, 0.0
        elif code == _MAJOR or code == _MINOR:
            m = abs(i2 - ij) * deltas[k] / scale
            m1 = abs(ik - ij) * deltas[1] / scale
    return code, energy, momentum, m, m1, lam, deltas[0], deltas[1], deltas[2]


@njit(cache=True)
def _parameters_batch(moments, omega, codes, values):
    """Fill ``codes[b]`` and ``values[b] = (T, |L|, m, m1, λ, K/λ)`` for each row ``b``."""
    for b in range(codes.shape[0]):
        code, energy, momentum, m, m1, lam, _, _, _ = _parameters(
            moments[b, 0], moments[b, 1], moments[b, 2], omega[b, 0], omega[b, 1], omega[b, 2]
        )
        codes[b] = code
        quarter = _elliptic.ellipk(m, m1) / lam if lam > 0.0 else math.inf
        values[b, 0], values[b, 1], values[b, 2] = energy, momentum, m
        values[b, 3], values[b, 4], values[b, 5] = m1, lam, quarter


# --------------------------------------------------------------------------
# The motion of one body in its principal axes: constants, then any time.
# --------------------------------------------------------------------------


class _Motion(NamedTuple):
    """Constants of one body's torque-free motion in principal axes (built by :func:`_setup`).

    The rates are ``ω_j = amp_j (−1)^i cn r``, ``ω₂ = amp_2 (−1)^i sn r``,
    ``ω_k = amp_k dn r`` at ``τ = tau0 + λ (t − t₀) = 2iK + r``; the attitude is
    ``q_NP(t) = h ⊗ exp(½ Δψ a) ⊗ p(t)*`` with ``a = axis_sign e_k``. With the
    nome series (``series``, coefficients ``theta``, :func:`_nome_series`)
    ``exp(½ Δψ a) = exp(½ precession (t − t₀) a) · (S(τ) S(τ0)*/|S(τ) S(τ0)|)^σ``
    (a complex number standing for a rotation about ``a``); otherwise
    ``Δψ = rate (t − t₀) + B(τ) − bracket0`` (see :func:`torque_free`).
    """

    steady: bool          # constant rate: q(t) = q0 ⊗ exp(½ ω0 (t − t0))
    separatrix: bool
    k: int                # 0-based axis carrying dn (encircled by the polhode)
    lam: float            # λ, rad/s
    quarter: float        # K(m); inf on the separatrix
    ks: np.ndarray        # Landen data of m (see _elliptic.landen)
    kcs: np.ndarray
    nlev: int
    agm: float
    amp_j: float          # signed amplitudes, rad/s
    amp_2: float
    amp_k: float
    axis_sign: float      # s_k
    inv_momentum: float   # 1/|L|
    beta: float           # a·l = beta dn
    sqrt1n: float         # √(1 − n), n the characteristic of Π
    tau0: float           # phase at t0        (this field and the next eight: _phase_constants)
    rate: float           # linear part of the precession rate, rad/s
    coef: float           # factor of the bracket B, s·rad/s
    kappa: float          # separatrix: √((1 − β)/(1 + β))
    nu: float             # characteristic of the R_J term (n, or m/n)
    nu3: float            # its factor (n/3, or −m/(3n))
    chi: float            # 1 where Π is written with the n → m/n transformation, else 0
    sqrt_d: float         # √(1 + m − n − m/n)
    half_pi: float        # Π part of the bracket per half period (R_J and arctan terms)
    series: bool          # the attitude by the nome series (else by R_J and arctangents)
    precession: float     # Ω = rate + λ B(K)/K: the mean rate of ψ, rad/s (nome series)
    theta: np.ndarray     # (N, 2) nome-series coefficients (c_j, σ s_j)
    moments: tuple        # (I₁, I₂, I₃)
    omega0: tuple         # rate at t0 (principal axes)
    unit: float           # u: every rate above is of ω̃ = u ω (a power of two), whose motion is ω(t0 + dt) = ω̃(dt/u)/u
    bracket0: float       # B(tau0) (R_J path)
    phase0: tuple         # (S(τ0)*/|S(τ0)|)^σ as (re, im) (nome series)
    h: tuple              # quaternion q_NP(t0) ⊗ p(t0)


@njit(cache=True)
def _frame(mo, tau):
    """Rates, frame quaternion ``p`` (``a → l``, normalised) and bracket ``B`` at phase ``τ`` (R_J path).

    ``p = (1 + a·l, a × l) / |·|`` is the shortest rotation taking the body
    axis ``a`` to the unit momentum ``l = Iω/|L|`` (body axes); ``a·l = β dn τ ≥ 0``.
    """
    if mo.separatrix:
        j, s, c, d = 0, math.tanh(tau), 1.0 / math.cosh(tau), 1.0 / math.cosh(tau)
        bracket = -mo.coef * math.atan(mo.kappa * math.tanh(0.5 * tau))
    else:
        j, s, c, d = _elliptic.jacobi(tau, mo.quarter, mo.ks, mo.kcs, mo.nlev, mo.agm)
        third = 0.0
        if mo.nu3 != 0.0:
            third = mo.nu3 * s * s * s * _elliptic.carlson_rj(c * c, d * d, 1.0, 1.0 - mo.nu * s * s)
        if mo.chi != 0.0:
            third += math.atan2(mo.sqrt_d * s, c * d) / mo.sqrt_d
        g = (j * math.pi + math.atan2(mo.sqrt1n * s, c)) / mo.sqrt1n
        bracket = mo.coef * (2.0 * j * mo.half_pi + third - mo.beta * g)
    w1, w2, w3, pw, px, py, pz = _rates_and_frame(mo, j, s, c, d)
    norm = _quat.qnorm(pw, px, py, pz)
    return w1, w2, w3, pw / norm, px / norm, py / norm, pz / norm, bracket


@njit(cache=True)
def _rates_and_frame(mo, j, s, c, d):
    """Rates ``(ω₁, ω₂, ω₃)`` from ``(sn, cn, dn)`` of the reduced phase and ``p`` *unnormalised*."""
    sign = 1.0 - 2.0 * (j & 1)
    wc, w2, wd = mo.amp_j * sign * c, mo.amp_2 * sign * s, mo.amp_k * d
    i1, i2, i3 = mo.moments
    ad = 1.0 + mo.beta * d
    sl = mo.axis_sign * mo.inv_momentum
    if mo.k == 2:
        return wc, w2, wd, ad, -sl * i2 * w2, sl * i1 * wc, 0.0      # a × l, a = ±e₃
    return wd, w2, wc, ad, 0.0, -sl * i3 * wc, sl * i2 * w2          # a × l, a = ±e₁


@njit(cache=True)
def _nome_sum(theta, sin_z, cos_z):
    """``S^σ`` at ``e^{2iz}`` (unnormalised): ``(1 + Σ c_j cos 2jz, Σ σ s_j sin 2jz)`` (:func:`_nome_series`)."""
    cx, sx = (cos_z - sin_z) * (cos_z + sin_z), 2.0 * sin_z * cos_z  # cos 2z, sin 2z
    cj, sj = cx, sx
    re, im = 1.0, 0.0
    for i in range(theta.shape[0]):
        re += theta[i, 0] * cj
        im += theta[i, 1] * sj
        cj, sj = cj * cx - sj * sx, sj * cx + cj * sx
    return re, im


@njit(cache=True)
def _evaluate(mo, dt):
    """``(ω₁, ω₂, ω₃, q_w, q_x, q_y, q_z)``: rate (P axes) and ``q_NP`` at ``t0 + dt``.

    The motion is that of the scaled rate ``ω̃ = u ω`` (:func:`_setup`) at ``dt/u``, its rates divided by ``u``:
    Euler's equations are quadratic in ω, so ``ω(t0 + dt) = ω̃(dt/u)/u`` and ``q(t0 + dt) = q̃(dt/u)``.
    """
    w1, w2, w3, qw, qx, qy, qz = _evaluate_scaled(mo, dt / mo.unit)
    return w1 / mo.unit, w2 / mo.unit, w3 / mo.unit, qw, qx, qy, qz


@njit(cache=True)
def _evaluate_scaled(mo, dt):
    """:func:`_evaluate` of the scaled motion: the rates ``ω̃`` and ``q̃`` at ``t0 + dt``."""
    w1, w2, w3 = mo.omega0
    hw, hx, hy, hz = mo.h
    if mo.steady:
        ew, ex, ey, ez = _quat.qexp(w1 * dt, w2 * dt, w3 * dt)
        return (w1, w2, w3, *_quat.qmul(hw, hx, hy, hz, ew, ex, ey, ez))
    if mo.series:
        j, s, c, d, sin_z, cos_z = _elliptic.jacobi_angle(mo.tau0 + mo.lam * dt, mo.quarter, mo.ks, mo.kcs,
                                                          mo.nlev, mo.agm)
        w1, w2, w3, pw, px, py, pz = _rates_and_frame(mo, j, s, c, d)
        re, im = _nome_sum(mo.theta, sin_z, cos_z)
        c0, s0 = mo.phase0
        re, im = re * c0 - im * s0, re * s0 + im * c0  # (S(τ) S(τ0)*/|S(τ0)|)^σ: near 1 for a short dt
        half = 0.5 * mo.precession * dt
        ch, sh = math.cos(half), math.sin(half)
        # exp(½Ω dt a) (S(τ)/|S(τ)| S(τ0)*/|S(τ0)|)^σ and p, both unnormalised: the product is normalised
        rot_c, rot_s = ch * re - sh * im, (sh * re + ch * im) * mo.axis_sign
    else:
        w1, w2, w3, pw, px, py, pz, bracket = _frame(mo, mo.tau0 + mo.lam * dt)
        half = 0.5 * (mo.rate * dt + (bracket - mo.bracket0))
        rot_c, rot_s = math.cos(half), math.sin(half) * mo.axis_sign
    if mo.k == 2:
        aw, ax, ay, az = _quat.qmul(hw, hx, hy, hz, rot_c, 0.0, 0.0, rot_s)
    else:
        aw, ax, ay, az = _quat.qmul(hw, hx, hy, hz, rot_c, rot_s, 0.0, 0.0)
    qw, qx, qy, qz = _quat.qmul(aw, ax, ay, az, pw, -px, -py, -pz)
    if not mo.series:
        return w1, w2, w3, qw, qx, qy, qz
    scale = 1.0 / math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)  # of order 1: no overflow
    return w1, w2, w3, qw * scale, qx * scale, qy * scale, qz * scale


# The nome series is used while q = exp(−πK'/K) ≤ 0.6 (1 − m ≳ 7e-8): it then
# needs at most 6 terms, and |S| ≥ 0.236 on the real axis against a sum of
# term sizes ≤ 1.87 (worst over v ∈ [0, πK'/K], measured), so S/|S| keeps an
# absolute error ≤ 8 eps. Closer to the separatrix (q → 1) |S| dips towards 0
# between terms of size ~1, and the R_J path is used instead.
_NOME_MAX = 0.6
# Terms are summed while the bound q^{2j²}e^{jv} on the j-th exceeds 2^-60.
_NOME_TAIL = 2.0 ** -60


@njit(cache=True)
def _nome_series(m, m1, n, quarter, sigma):
    """``(usable, θ)``: coefficients ``θ[j−1] = (c_j, σ s_j)``, j ≥ 1, of the attitude's periodic part.

    ``usable`` is False past :data:`_NOME_MAX` (then the R_J path is taken).

    With ``1 − β² dn² = (1 − β²)(1 − n sn²)``, ``n = −β² m/(1 − β²)``, the
    precession integrand ``1/(1 + β dn τ)`` is an elliptic function of ``τ``
    (periods ``2K``, ``4iK'``) with simple poles only where ``dn τ = −1/β``:
    ``τ = ±i(2K' − F*)`` with ``F* = F(asin (1 − n)^{-1/2} | m1) = R_F(−n, m − n, 1 − n)``.
    Summing it by its poles (Whittaker & Watson §21.5; the Jacobi form of
    ``Π``, DLMF 19.4, 22.16.30-32) gives, with ``z = πτ/(2K)``,
    ``v = πF*/K`` and the nome of the doubled period ``q² = exp(−2πK'/K)``::

        ψ(t) = Ω t + 2σ arg S(τ),   S = θ₄(z − iv/2 | q²) = 1 + Σ_j (c_j cos 2jz + i s_j sin 2jz),
        c_j = 2(−1)^j q^{2j²} cosh jv,   s_j = 2(−1)^j q^{2j²} sinh jv          (DLMF 20.2.4)

    where the weight of the residues is exactly ``2σ``, ``σ = sign(I_k − I_j)``
    (so ``exp(iψ/2)`` is single-valued: no arctangent, no branch), and
    ``Ω`` is the mean rate. ``S`` is ``2K``-periodic, with no zeros on the real
    axis and no winding. Since ``v ≤ πK'/K``, the j-th term is below
    ``2 q^{2j² − j}``.
    """
    if m == 0.0:  # a symmetric top: no periodic part
        return True, np.zeros((0, 2))
    complementary = _elliptic.carlson_rf(0.0, m, 1.0)  # K' = K(m1)
    log_q2 = -2.0 * math.pi * complementary / quarter
    if log_q2 > 2.0 * math.log(_NOME_MAX):
        return False, np.zeros((0, 2))
    v = math.pi * _elliptic.carlson_rf(-n, m - n, 1.0 - n) / quarter
    terms = 1
    while terms < 64 and math.exp(terms * terms * log_q2 + terms * v) > _NOME_TAIL:
        terms += 1
    theta = np.empty((terms - 1, 2))
    for j in range(1, terms):
        sign = 1.0 - 2.0 * (j & 1)  # (−1)^j; 2 cosh jv and 2 sinh jv as sums of exponentials
        low = math.exp(j * j * log_q2 - j * v)
        theta[j - 1, 0] = sign * (math.exp(j * j * log_q2 + j * v) + low)
        theta[j - 1, 1] = sign * sigma * low * math.expm1(2.0 * j * v)
    return True, theta


@njit(cache=True)
def _phase_constants(separatrix, moments, k, j, m, m1, lam, momentum, beta, cn0, sn0):
    """``(τ0, rate, coef, κ, ν, ν₃, χ, √D, Π per half period)``: the phase fields of :class:`_Motion`.

    Phase: ``τ0 = F(φ0 | m) = sn R_F(cn², cn² + m1 sn², 1)`` at the point
    ``(cn, sn)`` of the initial rate, ``cn ≥ 0`` so ``|τ0| ≤ K`` (DLMF 19.25.5,
    ``dn² = cn² + m1 sn²`` without cancellation); ``τ0 = asinh(sn/cn)`` on
    the separatrix. ``ψ(τ) = rate t + B(τ)`` with the bracket ``B`` of
    :func:`_frame`; ``Π(n; φ | m) = F + (n/3) sn³ R_J(cn², dn², 1, 1 − n sn²)``
    (DLMF 19.25.14), and for ``n < −1`` the equivalent
    ``Π(n) = F − Π(m/n) + atan2(sn √D, cn dn)/√D``, ``D = 1 + m − n − m/n``
    (DLMF 19.7.9 with ``R_C`` in closed form) keeps ``B`` free of a large
    ``F − F`` cancellation when ``|n| ≫ 1`` (nearly symmetric bodies).
    """
    i1, i2, i3 = moments
    ik, ij = moments[k], moments[j]
    n = -ik * abs(i2 - ij) / (ij * abs(ik - i2))
    if separatrix:
        one_beta2 = i1 * (i3 - i2) / ((i3 - i1) * i2)  # 1 − β² on the separatrix
        coef = momentum * (i3 - i2) / (i2 * i3 * lam) * 2.0 * beta / math.sqrt(one_beta2)
        kappa = math.sqrt(one_beta2) / (1.0 + beta)
        return math.asinh(sn0 / cn0), momentum / i2, coef, kappa, n, 0.0, 0.0, 1.0, 0.0
    tau0 = sn0 * _elliptic.carlson_rf(cn0 * cn0, cn0 * cn0 + m1 * sn0 * sn0, 1.0)
    coef = momentum * (ik - ij) / (ij * ik * lam)
    rate, nu, nu3, chi, sqrt_d, half_pi = momentum / ij, n, n / 3.0, 0.0, 1.0, 0.0
    if n < -1.0:
        nu, nu3, chi = m / n, -m / (3.0 * n), 1.0
        sqrt_d = math.sqrt(1.0 + m - n - nu)
        half_pi = 0.5 * math.pi / sqrt_d
        rate = momentum / ik
    if nu3 != 0.0:
        half_pi += nu3 * _elliptic.carlson_rj(0.0, m1, 1.0, 1.0 - nu)
    return tau0, rate, coef, 0.0, nu, nu3, chi, sqrt_d, half_pi


@njit(cache=True)
def _steady(moments, omega, unit, q):
    """The :class:`_Motion` of a constant rate: ``q(t) = q0 ⊗ exp(½ ω0 (t − t0))``."""
    return _Motion(True, False, 2, 0.0, 0.0, np.zeros(1), np.ones(1), 0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0,
                   1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, False, 0.0, np.zeros((0, 2)),
                   moments, omega, unit, 0.0, (1.0, 0.0), q)


@njit(cache=True)
def _setup(i1, i2, i3, w1, w2, w3, qw, qx, qy, qz):
    """The :class:`_Motion` of moments ``I₁ ≤ I₂ ≤ I₃`` from ``ω(t0)`` and ``q_NP(t0)`` (principal axes).

    Signs ``s_k = sign ω_k``, ``s_j = sign ω_j``, ``s₂ = s_j s_k`` and the
    initial point ``(cn, sn) ∝ (|ω_j|/A_j, s₂ω₂/A₂)`` (normalised; ``(1, 0)``
    for a rotation about axis k) as in the module docstring. Constant rates:
    rest, the sphere, a symmetric top turning about a transverse axis
    (``λ = 0``) and the fixed point ``ω ∥ e₂`` of the separatrix. The mean
    precession rate is ``Ω = rate + λ B(K)/K`` with the bracket over a half
    period ``B(K) = coef (half_pi − β π/(2√(1 − n)))`` (``sn K = 1``, ``cn K = 0``).

    The motion depends on the ratios of the moments only, and the rates set its time scale: the moments are
    first multiplied by the power of two that brings ``I₃`` into [0.5, 1), and the rates by the power of two
    ``u`` that brings the largest into [0.5, 1) (:func:`_evaluate` undoes it). Both scalings are exact (the
    same numbers, bit for bit, at any ordinary size), so that ``L² = Σ Iᵢ²ωᵢ²`` and the ``Δᵢ`` neither
    underflow (``I ~ 1e-200 kg·m²``, ``|ω| ~ 1e-160 rad/s``) nor overflow.
    """
    scale = math.ldexp(1.0, -math.frexp(i3)[1])
    i1, i2, i3 = i1 * scale, i2 * scale, i3 * scale
    unit = math.ldexp(1.0, -math.frexp(max(abs(w1), abs(w2), abs(w3)))[1])
    w1, w2, w3 = w1 * unit, w2 * unit, w3 * unit
    code, _, momentum, m, m1, lam, d1, d2, d3 = _parameters(i1, i2, i3, w1, w2, w3)
    moments, omega, deltas, q0 = (i1, i2, i3), (w1, w2, w3), (d1, d2, d3), (qw, qx, qy, qz)
    if code == _REST or code == _SPHERE or lam == 0.0:
        return _steady(moments, omega, unit, q0)
    k, j = _axes_of(code)
    ik, ij = moments[k], moments[j]
    separatrix = code == _SEPARATRIX
    amp_j = math.sqrt(deltas[k] / (ij * abs(ik - ij)))
    amp_2 = math.sqrt(deltas[k] / (i2 * abs(ik - i2)))
    amp_k = math.sqrt(deltas[j] / (ik * abs(ik - ij)))
    sk, sj = math.copysign(1.0, omega[k]), math.copysign(1.0, omega[j])
    cn0, sn0 = 1.0, 0.0
    if amp_j > 0.0:
        cn0, sn0 = abs(omega[j]) / amp_j, sj * sk * w2 / amp_2
        scale = math.hypot(cn0, sn0)
        cn0, sn0 = cn0 / scale, sn0 / scale
    if separatrix and cn0 == 0.0:
        return _steady(moments, omega, unit, q0)
    ks, kcs, nlev, agm = _elliptic.landen(m, m1) if not separatrix else (np.zeros(1), np.ones(1), 0, 1.0)
    quarter = 0.5 * math.pi / agm if not separatrix else math.inf
    beta = ik * amp_k / momentum
    n = -ik * abs(i2 - ij) / (ij * abs(ik - i2))
    sqrt1n = math.sqrt(1.0 - n)
    phase = _phase_constants(separatrix, moments, k, j, m, m1, lam, momentum, beta, cn0, sn0)
    tau0, rate, coef, half_pi = phase[0], phase[1], phase[2], phase[8]
    series, theta = False, np.zeros((0, 2))
    if not separatrix:
        series, theta = _nome_series(m, m1, n, quarter, math.copysign(1.0, coef))
    precession = rate + lam * coef * (half_pi - 0.5 * math.pi * beta / sqrt1n) / quarter
    mo = _Motion(
        False, separatrix, k, lam, quarter, ks, kcs, nlev, agm, sj * amp_j, sj * sk * amp_2, sk * amp_k, sk,
        1.0 / momentum, beta, sqrt1n, *phase, series, precession, theta, moments, omega, unit, 0.0, (1.0, 0.0), q0,
    )
    if series:
        j0, s, c, d, sin_z, cos_z = _elliptic.jacobi_angle(tau0, quarter, ks, kcs, nlev, agm)
        _, _, _, pw, px, py, pz = _rates_and_frame(mo, j0, s, c, d)
        norm = _quat.qnorm(pw, px, py, pz)
        pw, px, py, pz = pw / norm, px / norm, py / norm, pz / norm
        re, im = _nome_sum(theta, sin_z, cos_z)
        size = math.hypot(re, im)
        return _Motion(*mo[:-3], 0.0, (re / size, -im / size), _quat.qmul(qw, qx, qy, qz, pw, px, py, pz))
    _, _, _, pw, px, py, pz, bracket0 = _frame(mo, tau0)
    return _Motion(*mo[:-3], bracket0, (1.0, 0.0), _quat.qmul(qw, qx, qy, qz, pw, px, py, pz))
