"""Exact torque-free motion of a rigid body: body rates and attitude in closed form.

Principal axes P, moments ``I₁ ≤ I₂ ≤ I₃`` (kg·m²), body rate ``ω`` in P
(rad/s). The motion conserves the kinetic energy ``T = ½ Σ Iᵢωᵢ²`` and the
angular momentum ``L_N`` (inertial axes), ``L² = Σ Iᵢ²ωᵢ²``. Everything below
is written with the differences

    Δᵢ = L² − 2T Iᵢ = Σⱼ Iⱼ (Iⱼ − Iᵢ) ωⱼ²        (J·kg·m²)

evaluated from the rates as these sums, so that ``Δ₁ ≥ 0 ≥ Δ₃`` are free of
cancellation and only ``Δ₂`` (whose sign decides the regime) carries the
unavoidable cancellation of a motion near the separatrix.

Regimes (:data:`REGIMES`) and the rates (Landau & Lifshitz, *Mechanics*,
§37; Celledoni, Fassò, Säfström, Zanna, SIAM J. Sci. Comput. 30 (2008)
2084-2112), derived again in ``docs/exact.md``:

* ``"major"`` (``Δ₂ > 0``: the polhode encircles the axis of the largest
  moment, k = 3, j = 1) and ``"minor"`` (``Δ₂ < 0``: around the smallest, k = 1,
  j = 3). With the axis ``k`` carrying ``dn`` and the axis ``j`` carrying ``cn``::

      ω_j = s_j A_j cn τ,   ω₂ = s₂ A₂ sn τ,   ω_k = s_k A_k dn τ,   τ = λ (t − t₀)
      A_j² = |Δ_k| / (I_j |I_k − I_j|),  A₂² = |Δ_k| / (I₂ |I_k − I₂|),  A_k² = |Δ_j| / (I_k |I_k − I_j|)
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
:func:`torque_free`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from tumble import _quat, attitude
from tumble._validate import ValidationError, as_array
from tumble.analytic import _elliptic
from tumble.simulate import _batch_size, _bodies, _output_times
from tumble.trajectory import Trajectory

__all__ = ["REGIMES", "FreeParameters", "free_parameters", "torque_free"]

#: Names of the regimes of torque-free motion, indexed by the codes used in the kernels.
REGIMES = ("rest", "sphere", "oblate", "prolate", "major", "minor", "separatrix")
_REST, _SPHERE, _OBLATE, _PROLATE, _MAJOR, _MINOR, _SEPARATRIX = range(len(REGIMES))


@njit(cache=True)
def _deltas(i1, i2, i3, w1, w2, w3):
    """``(T, |L|, Δ₁, Δ₂, Δ₃)`` with ``Δᵢ = L² − 2T Iᵢ`` summed without cancellation in Δ₁, Δ₃."""
    a1, a2, a3 = i1 * w1 * w1, i2 * w2 * w2, i3 * w3 * w3
    energy = 0.5 * (a1 + a2 + a3)
    momentum = math.sqrt(i1 * a1 + i2 * a2 + i3 * a3)
    d1 = (i2 - i1) * a2 + (i3 - i1) * a3
    d2 = (i3 - i2) * a3 - (i2 - i1) * a1
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


@dataclass(frozen=True)
class FreeParameters:
    """Constants of the torque-free motion of a body with principal moments ``I₁ ≤ I₂ ≤ I₃``.

    Scalars for one body, arrays of the batch shape for a batch. The formulas
    are those of the module docstring (Landau & Lifshitz §37), with
    ``Δᵢ = L² − 2T Iᵢ``.

    Attributes
    ----------
    moments : (…, 3) ndarray
        Principal moments ``I₁ ≤ I₂ ≤ I₃``, kg·m².
    energy : float or ndarray
        Kinetic energy ``T = ½ Σ Iᵢ ωᵢ²``, J.
    momentum : float or ndarray
        ``|L| = √(Σ Iᵢ² ωᵢ²)``, N·m·s.
    regime : str or ndarray of str
        One of :data:`REGIMES`: ``"major"`` (``L² > 2T I₂``: the polhode
        encircles the axis of the largest moment ``I₃``), ``"minor"``
        (``L² < 2T I₂``: it encircles the axis of ``I₁``), ``"separatrix"``
        (``L² = 2T I₂`` exactly), ``"oblate"`` (``I₁ = I₂``), ``"prolate"``
        (``I₂ = I₃``), ``"sphere"`` (``I₁ = I₃``), ``"rest"`` (``ω = 0``).
    m : float or ndarray
        Elliptic parameter ``k²`` of the Jacobi functions, in [0, 1]:
        ``m = (I₂ − I₁)(2T I₃ − L²) / ((I₃ − I₂)(L² − 2T I₁))`` (major),
        the same with 1 and 3 swapped (minor); 0 for symmetric bodies, 1 on
        the separatrix.
    m1 : float or ndarray
        ``1 − m`` computed without cancellation,
        ``m1 = (I₃ − I₁)(L² − 2T I₂) / ((I₃ − I₂)(L² − 2T I₁))`` (major, and
        1 ↔ 3 for minor), from ``Δ₂`` summed over the rates: it keeps its
        relative accuracy as ``k → 1``, where ``K(m) ≈ ½ ln(16/m1)``.
    lam : float or ndarray
        ``λ``, rad/s, the rate multiplying ``t`` in the argument of the Jacobi
        functions: ``λ² = (I₃ − I₂)(L² − 2T I₁) / (I₁I₂I₃)`` (major, and 1 ↔ 3
        for minor); for a symmetric top ``λ = |I₃ − I₁| |ω_axis| / I_⊥``,
        the precession rate of ``ω`` about the symmetry axis in body axes;
        0 for the sphere and rest.
    quarter_period : float or ndarray
        ``K(m) / λ``, s: the polhode period is ``4K/λ``, and the rate about
        the intermediate axis changes sign every ``2K/λ``; ``inf`` on the
        separatrix and where ``λ = 0``.
    """

    moments: np.ndarray
    energy: float | np.ndarray
    momentum: float | np.ndarray
    regime: str | np.ndarray
    m: float | np.ndarray
    m1: float | np.ndarray
    lam: float | np.ndarray
    quarter_period: float | np.ndarray

    @property
    def period(self) -> float | np.ndarray:
        """Period of the body rate (the polhode), ``4K/λ`` = 4 × :attr:`quarter_period`, s."""
        return 4.0 * self.quarter_period


def free_parameters(moments, omega_p) -> FreeParameters:
    """Energy, momentum, regime and elliptic constants of the torque-free motion.

    Parameters
    ----------
    moments : (3,) or (…, 3) array_like
        Principal moments ``I₁ ≤ I₂ ≤ I₃`` (kg·m², ascending, > 0), as
        :attr:`tumble.RigidBody.moments`.
    omega_p : (3,) or (…, 3) array_like
        Body rate in principal axes, rad/s. Batch axes broadcast with those of
        ``moments``.

    Returns
    -------
    FreeParameters
        Scalars for one body, arrays of the batch shape otherwise.
    """
    moments = as_array(moments, "moments", tail=(3,))
    omega_p = as_array(omega_p, "omega_p", tail=(3,))
    _check_moments(moments)
    try:
        shape = np.broadcast_shapes(moments.shape[:-1], omega_p.shape[:-1])
    except ValueError:
        raise ValidationError(
            f"moments, omega_p: batch shapes must broadcast, got {moments.shape[:-1]} and {omega_p.shape[:-1]}"
        ) from None
    flat_moments = np.ascontiguousarray(np.broadcast_to(moments, shape + (3,))).reshape(-1, 3)
    flat_omega = np.ascontiguousarray(np.broadcast_to(omega_p, shape + (3,))).reshape(-1, 3)
    codes = np.empty(flat_omega.shape[0], dtype=np.int64)
    values = np.empty((flat_omega.shape[0], 6))
    _parameters_batch(flat_moments, flat_omega, codes, values)
    regime = np.asarray(REGIMES)[codes].reshape(shape)
    fields = [values[:, i].reshape(shape) for i in range(6)]
    if not shape:
        regime, fields = str(regime), [float(f) for f in fields]
    energy, momentum, m, m1, lam, quarter = fields
    return FreeParameters(
        moments=np.broadcast_to(moments, shape + (3,)).copy(), energy=energy, momentum=momentum,
        regime=regime, m=m, m1=m1, lam=lam, quarter_period=quarter,
    )


def _check_moments(moments: np.ndarray) -> None:
    """Refuse principal moments that are not positive and ascending."""
    if np.any(moments <= 0.0):
        raise ValidationError(f"moments: principal moments must be > 0, got {moments.tolist()}")
    if np.any(np.diff(moments, axis=-1) < 0.0):
        raise ValidationError(
            f"moments: principal moments must be ascending I1 <= I2 <= I3 (as RigidBody.moments), "
            f"got {moments.tolist()}"
        )


# --------------------------------------------------------------------------
# The motion of one body in its principal axes: constants, then any time.
# --------------------------------------------------------------------------


class _Motion(NamedTuple):
    """Constants of one body's torque-free motion in principal axes (built by :func:`_setup`).

    The rates are ``ω_j = amp_j (−1)^n cn r``, ``ω₂ = amp_2 (−1)^n sn r``,
    ``ω_k = amp_k dn r`` at ``τ = tau0 + λ (t − t₀) = 2nK + r``; the attitude is
    ``q_NP(t) = h ⊗ exp(½ Δψ a) ⊗ p(t)*`` with ``a = axis_sign e_k`` and
    ``Δψ = rate (t − t₀) + B(τ) − bracket0`` (see :func:`torque_free`).
    """

    steady: bool          # constant rate: q(t) = q0 ⊗ exp(½ ω0 (t − t0))
    separatrix: bool
    k: int                # 0-based axis carrying dn (encircled by the polhode)
    lam: float            # λ, rad/s
    tau0: float           # phase at t0
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
    n: float              # characteristic of Π
    sqrt1n: float         # √(1 − n)
    coef: float           # factor of the bracket B, s·rad/s
    rjc: float            # R_J(0, m1, 1, 1 − n)
    kappa: float          # separatrix: √((1 − β)/(1 + β))
    rate: float           # linear part of the precession rate, rad/s
    moments: tuple        # (I₁, I₂, I₃)
    omega0: tuple         # rate at t0 (principal axes)
    bracket0: float       # B(tau0)
    h: tuple              # quaternion q_NP(t0) ⊗ p(t0)


@njit(cache=True)
def _frame(mo, tau):
    """Rates, frame quaternion ``p`` (``a → l``) and bracket ``B`` at phase ``τ``.

    ``p = (1 + a·l, a × l) / |·|`` is the shortest rotation taking the body
    axis ``a`` to the unit momentum ``l = Iω/|L|`` (body axes); ``a·l = β dn τ ≥ 0``.
    """
    if mo.separatrix:
        j, s, c, d = 0, math.tanh(tau), 1.0 / math.cosh(tau), 1.0 / math.cosh(tau)
        bracket = -mo.coef * math.atan(mo.kappa * math.tanh(0.5 * tau))
    else:
        j, s, c, d = _elliptic.jacobi(tau, mo.quarter, mo.ks, mo.kcs, mo.nlev, mo.agm)
        third = 0.0
        if mo.n != 0.0:
            rj = _elliptic.carlson_rj(c * c, d * d, 1.0, 1.0 - mo.n * s * s)
            third = mo.n / 3.0 * (2.0 * j * mo.rjc + s * s * s * rj)
        g = (j * math.pi + math.atan2(mo.sqrt1n * s, c)) / mo.sqrt1n
        bracket = mo.coef * (third - mo.beta * g)
    sign = 1.0 - 2.0 * (j & 1)
    wc, w2, wd = mo.amp_j * sign * c, mo.amp_2 * sign * s, mo.amp_k * d
    i1, i2, i3 = mo.moments
    ad = 1.0 + mo.beta * d
    sl = mo.axis_sign * mo.inv_momentum
    if mo.k == 2:
        w1, w3 = wc, wd
        px, py, pz = -sl * i2 * w2, sl * i1 * w1, 0.0      # a × l, a = ±e₃
    else:
        w1, w3 = wd, wc
        px, py, pz = 0.0, -sl * i3 * w3, sl * i2 * w2      # a × l, a = ±e₁
    norm = _quat.qnorm(ad, px, py, pz)
    return w1, w2, w3, ad / norm, px / norm, py / norm, pz / norm, bracket


@njit(cache=True)
def _evaluate(mo, dt):
    """``(ω₁, ω₂, ω₃, q_w, q_x, q_y, q_z)``: rate (P axes) and ``q_NP`` at ``t0 + dt``."""
    w1, w2, w3 = mo.omega0
    hw, hx, hy, hz = mo.h
    if mo.steady:
        ew, ex, ey, ez = _quat.qexp(w1 * dt, w2 * dt, w3 * dt)
        return (w1, w2, w3, *_quat.qmul(hw, hx, hy, hz, ew, ex, ey, ez))
    w1, w2, w3, pw, px, py, pz, bracket = _frame(mo, mo.tau0 + mo.lam * dt)
    half = 0.5 * (mo.rate * dt + (bracket - mo.bracket0))
    c, s = math.cos(half), math.sin(half) * mo.axis_sign
    if mo.k == 2:
        aw, ax, ay, az = _quat.qmul(hw, hx, hy, hz, c, 0.0, 0.0, s)
    else:
        aw, ax, ay, az = _quat.qmul(hw, hx, hy, hz, c, s, 0.0, 0.0)
    return (w1, w2, w3, *_quat.qmul(aw, ax, ay, az, pw, -px, -py, -pz))


@njit(cache=True)
def _setup(i1, i2, i3, w1, w2, w3, qw, qx, qy, qz):
    """The :class:`_Motion` of a body with moments ``I₁ ≤ I₂ ≤ I₃`` from ``ω(t0)``, ``q_NP(t0)`` (principal axes).

    Phase: with ``s_k = sign ω_k``, ``s_j = sign ω_j``, ``s₂ = s_j s_k``, the
    point ``(cn τ0, sn τ0) ∝ (|ω_j|/A_j, s₂ω₂/A₂)`` has ``cn ≥ 0``, so
    ``τ0 = F(φ0 | m) = sn R_F(cn², cn² + m1 sn², 1)`` with ``|τ0| ≤ K``
    (DLMF 19.25.5, ``dn² = cn² + m1 sn²`` without cancellation); on the
    separatrix ``τ0 = asinh(sn/cn)``.
    """
    code, _, momentum, m, m1, lam, d1, d2, d3 = _parameters(i1, i2, i3, w1, w2, w3)
    moments, omega, deltas = (i1, i2, i3), (w1, w2, w3), (d1, d2, d3)
    k, j = _axes_of(code)
    ik, ij = moments[k], moments[j]
    steady = code == _REST or code == _SPHERE or lam == 0.0
    separatrix = code == _SEPARATRIX
    amp_j = math.sqrt(deltas[k] / (ij * abs(ik - ij))) if not steady else 0.0
    amp_2 = math.sqrt(deltas[k] / (i2 * abs(ik - i2))) if not steady else 0.0
    amp_k = math.sqrt(deltas[j] / (ik * abs(ik - ij))) if not steady else 0.0
    sk, sj = math.copysign(1.0, omega[k]), math.copysign(1.0, omega[j])
    cn0, sn0 = 1.0, 0.0
    if amp_j > 0.0:
        cn0, sn0 = abs(omega[j]) / amp_j, sj * sk * w2 / amp_2
        scale = math.hypot(cn0, sn0)
        cn0, sn0 = cn0 / scale, sn0 / scale
    steady = steady or (separatrix and cn0 == 0.0)  # the fixed point ω ∥ e₂
    ks, kcs, nlev, agm = _elliptic.landen(m, m1) if not separatrix else (np.zeros(1), np.ones(1), 0, 1.0)
    quarter = 0.5 * math.pi / agm if not separatrix else math.inf
    beta = ik * amp_k / momentum if momentum > 0.0 else 1.0
    n = -ik * abs(i2 - ij) / (ij * abs(ik - i2)) if not steady else 0.0
    coef, kappa, rjc, rate, tau0 = 0.0, 0.0, 0.0, 0.0, 0.0
    if separatrix and not steady:
        tau0 = math.asinh(sn0 / cn0)
        one_beta2 = i1 * (i3 - i2) / ((i3 - i1) * i2)  # 1 − β² on the separatrix
        coef = momentum * (i3 - i2) / (i2 * i3 * lam) * 2.0 * beta / math.sqrt(one_beta2)
        kappa = math.sqrt(one_beta2) / (1.0 + beta)
        rate = momentum / i2
    elif not steady:
        tau0 = sn0 * _elliptic.carlson_rf(cn0 * cn0, cn0 * cn0 + m1 * sn0 * sn0, 1.0)
        coef = momentum * (ik - ij) / (ij * ik * lam)
        rjc = _elliptic.carlson_rj(0.0, m1, 1.0, 1.0 - n) if n != 0.0 else 0.0
        rate = momentum / ij
    inv_momentum = 1.0 / momentum if momentum > 0.0 else 0.0
    mo = _Motion(
        steady, separatrix, k, lam, tau0, quarter, ks, kcs, nlev, agm, sj * amp_j, sj * sk * amp_2, sk * amp_k,
        sk, inv_momentum, beta, n, math.sqrt(1.0 - n), coef, rjc, kappa, rate, moments, omega,
        0.0, (qw, qx, qy, qz),
    )
    if steady:
        return mo
    _, _, _, pw, px, py, pz, bracket0 = _frame(mo, tau0)
    return _Motion(*mo[:-2], bracket0, _quat.qmul(qw, qx, qy, qz, pw, px, py, pz))


# Output times per task of the parallel loop: one task sets a body up (about a
# microsecond) and evaluates up to this many times, so that a single body with
# many times also runs on every core.
_CHUNK = 512


@njit(cache=True, parallel=True)
def _torque_free_batch(moments, q_bp, omega0, q0, t, out_q, out_w):
    """Fill ``out_q[i, b]`` (``q_NB``) and ``out_w[i, b]`` (``ω_B``) at ``t[i]`` for every body ``b``.

    ``moments``, ``q_bp`` have one row per body or one shared row; ``omega0``
    (body axes) and ``q0`` (unit, body → inertial) one row per body. Into
    principal axes: ``ω_P = R_BPᵀ ω_B``, ``q_NP = q_NB ⊗ q_BP``; back:
    ``q_NB = q_NP ⊗ q_BP*``, ``ω_B = R_BP ω_P`` (as :func:`tumble.simulate`).
    """
    n_bodies, n_times = omega0.shape[0], t.shape[0]
    n_chunks = (n_times + _CHUNK - 1) // _CHUNK
    shared = moments.shape[0] == 1
    for task in prange(n_bodies * n_chunks):
        b, chunk = task // n_chunks, task % n_chunks
        r = 0 if shared else b
        bw, bx, by, bz = q_bp[r, 0], q_bp[r, 1], q_bp[r, 2], q_bp[r, 3]
        wp = _quat.qrotate_inv(bw, bx, by, bz, omega0[b, 0], omega0[b, 1], omega0[b, 2])
        qp = _quat.qmul(q0[b, 0], q0[b, 1], q0[b, 2], q0[b, 3], bw, bx, by, bz)
        mo = _setup(moments[r, 0], moments[r, 1], moments[r, 2], *wp, *qp)
        for i in range(chunk * _CHUNK, min(n_times, (chunk + 1) * _CHUNK)):
            w1, w2, w3, qw, qx, qy, qz = _evaluate(mo, t[i] - t[0])
            out_w[i, b, 0], out_w[i, b, 1], out_w[i, b, 2] = _quat.qrotate(bw, bx, by, bz, w1, w2, w3)
            q = _quat.qmul(qw, qx, qy, qz, bw, -bx, -by, -bz)
            out_q[i, b, 0], out_q[i, b, 1], out_q[i, b, 2], out_q[i, b, 3] = q


def torque_free(body, omega0, q0=None, *, t) -> Trajectory:
    """Exact torque-free motion of a rigid body (or a batch): body rate and attitude at the times ``t``.

    Closed form (no integration): Jacobi elliptic functions for the rate and
    an incomplete elliptic integral of the third kind for the attitude,
    evaluated at each output time independently; accurate to rounding over
    any time span. See the module docstring and ``docs/exact.md``.

    Attitude (Celledoni et al. 2008). ``L_N`` is constant; with the unit
    momentum ``l = Iω/|L|`` in principal axes (given by the rates), a fixed
    body axis ``a = ±e_k`` with ``a·l ≥ 0`` throughout the motion, and
    ``p(t)`` the shortest rotation taking ``a`` to ``l``::

        q_NP(t) = q_NP(t0) ⊗ p(t0) ⊗ exp(½ Δψ a) ⊗ p(t)*

    maps ``l(t)`` to the constant ``L_N/|L|`` at all times. Matching
    ``q̇ = ½ q ⊗ ω`` along ``l`` gives ``ψ̇ = (2T/|L| + a·ω) / (1 + a·l)``, which
    integrates to (``a·l = β dn τ``, ``β = I_k A_k / |L|``)::

        ψ(τ) = |L| t / I_j + |L|(I_k − I_j)/(I_j I_k λ) [Π(n; am τ | m) − τ − β G(am τ)],
        n = −I_k |I₂ − I_j| / (I_j |I_k − I₂|),   G(φ) = ∫₀^φ dθ / (1 − n sin²θ)

    and on the separatrix ``ψ = |L| t / I₂ − (|L|(I₃ − I₂)/(I₂I₃λ)) (2β/√(1−β²)) atan(κ tanh(τ/2))``,
    ``κ = √((1 − β)/(1 + β))``.

    Parameters
    ----------
    body : RigidBody, (3, 3) or (N, 3, 3) inertia array (kg·m², body axes), or a sequence of RigidBody
        The body, or one body per batch member (as :func:`tumble.simulate`).
    omega0 : (3,) or (N, 3) array_like
        Rate at ``t[0]``, rad/s, body axes; a leading axis of length N gives
        a batch.
    q0 : (4,) or (N, 4) array_like, optional
        Attitude at ``t[0]``, unit quaternion ``[w, x, y, z]``, body →
        inertial (normalised here; default: identity).
    t : (n,) array_like
        Output times, s, strictly increasing; ``t[0]`` is the initial time.

    Returns
    -------
    Trajectory
        ``method="exact"``; ``t`` (n,), ``q`` (n, [N,] 4), ``omega`` (n, [N,] 3).
    """
    times = _output_times(t)
    bodies, batch_inertia = _bodies(body)
    omega0 = as_array(omega0, "omega0", tail=(3,))
    q0 = attitude.identity() if q0 is None else as_array(q0, "q0", tail=(4,))
    n = _batch_size(bodies, batch_inertia, omega0, q0)
    if np.any(np.linalg.norm(q0, axis=-1) == 0.0):
        raise ValidationError("q0: must be a non-zero quaternion [w, x, y, z] (it is normalised here)")
    q0 = np.ascontiguousarray(attitude.normalize(np.broadcast_to(q0, (n or 1, 4))))
    omega0 = np.ascontiguousarray(np.broadcast_to(omega0, (n or 1, 3)))
    moments = np.stack([b.moments for b in bodies])
    q_bp = attitude.from_matrix(np.stack([b.axes for b in bodies]))
    out_q = np.empty((times.size, n or 1, 4))
    out_w = np.empty((times.size, n or 1, 3))
    _torque_free_batch(moments, q_bp, omega0, q0, times, out_q, out_w)
    if n is None:
        out_q, out_w = out_q[:, 0], out_w[:, 0]
    return Trajectory(t=times, q=out_q, omega=out_w, inertia=batch_inertia, method="exact", info={})
