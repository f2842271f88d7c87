"""Lie–Poisson splitting of the free rigid body into exact rotations (symplectic).

The torque-free body has the Hamiltonian ``H = ½ Σᵢ Lᵢ²/Iᵢ`` in the angular
momentum ``L`` (principal axes P; ``Lᵢ = Iᵢ ωᵢ``). Following the symmetric-top
split (A. Fassò, "Comparison of splitting algorithms for the rigid body",
*J. Comput. Phys.* 189 (2003) 527-538; R. I. McLachlan, "Explicit Lie–Poisson
integration and the Euler equations", *Phys. Rev. Lett.* 71 (1993) 3043) it is
written, with ``c`` the Casimir axis and ``a``, ``b`` the other two, as

    H = |L|²/(2 I_c) + ½ (1/I_a − 1/I_c) L_a² + ½ (1/I_b − 1/I_c) L_b²
      =      C       +          A             +          B

Each part has an exact flow with a constant body rate ``ν``: over a time
``τ`` the attitude turns by ``q ← q ⊗ qexp(τ ν)`` and the body-axes momentum
turns the other way, ``L ← R(qexp(τ ν))ᵀ L``, so that ``L_N = R(q) L`` and
``|L|`` are kept exactly (up to rounding):

    A:  ν = (1/I_a − 1/I_c) L_a e_a     (L_a is constant along it)
    B:  ν = (1/I_b − 1/I_c) L_b e_b
    C:  ν = L / I_c                     (L itself is constant: |L|² is a Casimir)

``C`` commutes with ``A`` and ``B``, so it is applied exactly, once per output
interval; ``A`` and ``B`` are composed as

    A(a₀h) B(b₁h) A(a₁h) … B(b_sh) A(a_sh)

with the last ``A`` of a step merged with the first of the next. Two
compositions are provided (symmetric, hence time-reversible):

* ``STRANG`` (``splitting2``, order 2): ``a = (½, ½)``, ``b = (1,)``; 2 rotations per step.
* ``BLANES_MOAN`` (``splitting4``, order 4): the 6-stage method S₆ of S. Blanes
  & P. C. Moan, "Practical symplectic partitioned Runge–Kutta and
  Runge–Kutta–Nyström methods", *J. Comput. Appl. Math.* 142 (2002) 313-330,
  Table 2; 12 rotations per step, and at equal work an error far below the
  Yoshida triple jump's (see ``docs/integrators.md``).

The axes: the Casimir axis is the one of the middle moment and ``A`` turns
about the axis of the smallest (``axes = (1, 0, 2)`` in principal-axis indices,
moments ascending). Of the orderings this one had the smallest energy error
(``docs/integrators.md``, measured by ``benchmarks/bench_geometric.py``); the
Casimir on the middle axis keeps the rates of ``A`` and ``B`` the smallest.

The state stays ``[q, ω]``: ``L = I ω`` is formed at the start of each output
interval and ``ω = L/I`` at its end.

Rounding: every turn rounds the two components of ``L`` it moves, so ``|L|``
would random-walk by about ``ε √(turns)`` (2.6e-13 after 1e6 steps of
``splitting4``, 12e6 turns). At the end of each output interval ``L`` is
therefore rescaled to its length at the start of the run (kept in the
workspace), a correction of a few ulps along ``L`` that leaves its direction,
the attitude and the order of the method untouched: ``|L|`` then stays within
a few roundings of its initial value however long the run. (A run reported
in segments, with a ``progress`` callback, rescales to the start of each
segment: 7e-15 after 1e6 steps in 100 segments.)
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _protocol, _quat
from tumble._protocol import inverse_moments
from tumble.integrate import _fixed
from tumble.integrate._method import FIXED_STEP, Method
from tumble.integrate._liegroup import rotate_right, times_unit


class Splitting(NamedTuple):
    """A composition ``A(a₀h) B(b₁h) A(a₁h) … B(b_sh) A(a_sh)`` of the free-rotor flows.

    a    : (s+1,) step fractions of the flow ``A`` (``a[0] = a[-1]``: merged across steps)
    b    : (s,) step fractions of the flow ``B``
    axes : (3,) int64 principal-axis indices ``(c, a, b)``: Casimir axis, axis of ``A``, axis of ``B``
    """

    a: np.ndarray
    b: np.ndarray
    axes: np.ndarray


#: The Casimir on the axis of the middle moment, A about the smallest, B about the largest.
AXES = np.array([1, 0, 2], dtype=np.int64)


def _blanes_moan_s6() -> tuple[np.ndarray, np.ndarray]:
    a1, a2, a3 = 0.0792036964311957, 0.353172906049774, -0.0420650803577195
    b1, b2 = 0.209515106613362, -0.143851773179818
    a4, b3 = 1.0 - 2.0 * (a1 + a2 + a3), 0.5 - (b1 + b2)
    return np.array([a1, a2, a3, a4, a3, a2, a1]), np.array([b1, b2, b3, b3, b2, b1])


STRANG = Splitting(np.array([0.5, 0.5]), np.array([1.0]), AXES)
BLANES_MOAN = Splitting(*_blanes_moan_s6(), AXES)




@_protocol.implements(_fixed.workspace, Splitting)
def _splitting_workspace(scheme, model, b0, Y):
    # the rates of A, B and C of each lane (1/(kg·m²)), and |L|² at the start of the run
    # (negative: not yet known; set by the first advance)
    return lambda scheme, model, b0, Y: (np.full((4, Y.size // Y.shape[0]), -1.0),)


# error_model="numpy": IEEE division without Python's zero check, which measured
# 2x in the rotation loop (no divisor below can be zero).
@_protocol.implements(_fixed.advance, Splitting)
def _splitting_advance(scheme, model, b0, t0, h, m, Y, work):

    def impl(scheme, model, b0, t0, h, m, Y, work):
        (rates,) = work
        y = Y.reshape((Y.shape[0], Y.size // Y.shape[0]))  # one body: a block of one lane
        a, b = scheme.a, scheme.b
        c, ia, ib = scheme.axes[0], scheme.axes[1], scheme.axes[2]
        for j in range(y.shape[1]):
            r = inverse_moments(model, b0 + j)
            rates[0, j], rates[1, j], rates[2, j] = r[ia] - r[c], r[ib] - r[c], r[c]
            y[4, j], y[5, j], y[6, j] = y[4, j] / r[0], y[5, j] / r[1], y[6, j] / r[2]  # L = I ω
            if rates[3, j] < 0.0:
                rates[3, j] = y[4, j] * y[4, j] + y[5, j] * y[5, j] + y[6, j] * y[6, j]
        # one turn of every lane at a time: the turns of different bodies are
        # independent and overlap in the processor (2x faster than all turns
        # of a step per lane)
        for s in range(m):
            for i in range(b.shape[0]):
                # the last A turn of the previous step merges with the first of this one
                fa = a[0] + a[-1] if (i == 0 and s > 0) else a[i]
                _turn_lanes(y, ia, fa * h, rates, 0)
                _turn_lanes(y, ib, b[i] * h, rates, 1)
        _turn_lanes(y, ia, a[-1] * h, rates, 0)
        for j in range(y.shape[1]):
            # the Casimir flow C over the whole interval: a turn about L, which it leaves unchanged
            tau = m * h * rates[2, j]
            y[0, j], y[1, j], y[2, j], y[3, j] = rotate_right(
                y[0, j], y[1, j], y[2, j], y[3, j], tau * y[4, j], tau * y[5, j], tau * y[6, j]
            )
            # |L| back to its length at the start of the run (the turns' rounding, see above)
            norm2 = y[4, j] * y[4, j] + y[5, j] * y[5, j] + y[6, j] * y[6, j]
            k = np.sqrt(rates[3, j] / norm2) if norm2 > 0.0 else 1.0
            r = inverse_moments(model, b0 + j)
            y[4, j], y[5, j], y[6, j] = k * y[4, j] * r[0], k * y[5, j] * r[1], k * y[6, j] * r[2]  # ω = L/I

    return impl


@njit(cache=True, inline="always")
def _turn_lanes(y, axis, tau, rates, row):
    """The flow ``A`` (``row = 0``) or ``B`` (``row = 1``) about ``axis`` over ``tau`` (s), for every
    lane of ``y = [q, L]`` (state × lanes)."""
    for j in range(y.shape[1]):
        y[0, j], y[1, j], y[2, j], y[3, j], y[4, j], y[5, j], y[6, j] = _turn(
            y[0, j], y[1, j], y[2, j], y[3, j], y[4, j], y[5, j], y[6, j], axis, tau * rates[row, j]
        )


@njit(cache=True, inline="always")
def _turn(qw, qx, qy, qz, l1, l2, l3, axis, tau):
    """The turn ``e = qexp(θ e_axis) = (cos θ/2, sin θ/2 e_axis)``, ``θ = tau·L_axis`` (``tau`` in
    s/(kg·m²)): ``q ← q ⊗ e``, ``L ← R(e)ᵀ L`` (``L_axis`` is unchanged)."""
    s, c = _sincos(0.5 * tau * (l1 if axis == 0 else (l2 if axis == 1 else l3)))
    ew, ex, ey, ez = c, (s if axis == 0 else 0.0), (s if axis == 1 else 0.0), (s if axis == 2 else 0.0)
    l1, l2, l3 = _quat.qrotate_inv(ew, ex, ey, ez, l1, l2, l3)
    qw, qx, qy, qz = times_unit(qw, qx, qy, qz, ew, ex, ey, ez)
    return qw, qx, qy, qz, l1, l2, l3


# π/2 = _PIO2_1 + _PIO2_2 + _PIO2_3 (to 1e-37); the first two carry 33 significant bits,
# so that k·_PIO2_1 and k·_PIO2_2 are exact for |k| < 2^20.
_PIO2_1 = 1.5707963267341256
_PIO2_2 = 6.077100506303966e-11
_PIO2_3 = 2.0222662487959506e-21
_2_OVER_PI = 0.6366197723675814


@njit(cache=True, inline="always")
def _sincos(x):
    """``(sin x, cos x)`` without a branch or a call, so that a loop over lanes vectorises.

    Without Intel's SVML, Numba calls the C library's ``sin`` and ``cos`` one
    value at a time, and the lane loops of the splitting cannot use SIMD: this
    version made the turns of a block 1.5x faster (and a lone body's 1.4x
    slower: one body is bound by the latency of the chain of turns, where a
    polynomial is longer than the C library's table-driven code).

    Method (Cody & Waite, *Software Manual for the Elementary Functions*,
    1980): ``x = k π/2 + r`` with ``|r| ≤ π/4``, ``r`` formed with π/2 in three
    parts; Taylor polynomials of ``sin r`` (to r¹⁷) and ``cos r`` (to r¹⁸), whose
    truncation error is below 1e-19, evaluated by Estrin's scheme (short
    dependency chains); the quadrant ``k mod 4`` swaps and negates them.
    Measured against the C library on 1e6 random ``x`` in [−1e3, 1e3]: within
    2.3e-16. (For ``|x|`` beyond 1e6 the reduction loses about ``1e-16 |x|`` in
    the angle, as much as the rounding of ``x`` itself.)
    """
    k = np.floor(x * _2_OVER_PI + 0.5)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3
    z = r * r
    z2 = z * z
    z4 = z2 * z2
    # sin r = r + r z Σ (−1)^(i+1) z^i / (2i + 3)!,   cos r = 1 + z Σ (−1)^(i+1) z^i / (2i + 2)!
    ps = ((-1.0 / 6.0 + z * (1.0 / 120.0)) + z2 * (-1.0 / 5040.0 + z * (1.0 / 362880.0))
          + z4 * ((-1.0 / 39916800.0 + z * (1.0 / 6227020800.0))
                  + z2 * (-1.0 / 1307674368000.0 + z * (1.0 / 355687428096000.0))))
    pc = ((-0.5 + z * (1.0 / 24.0)) + z2 * (-1.0 / 720.0 + z * (1.0 / 40320.0))
          + z4 * ((-1.0 / 3628800.0 + z * (1.0 / 479001600.0))
                  + z2 * (-1.0 / 87178291200.0 + z * (1.0 / 20922789888000.0))
                  + z4 * (-1.0 / 6402373705728000.0)))
    s = r + r * z * ps
    c = 1.0 + z * pc
    n = k - 4.0 * np.floor(0.25 * k)  # quadrant: 0, 1, 2 or 3
    odd = (n == 1.0) | (n == 3.0)
    sin, cos = (c, s) if odd else (s, c)
    sin = -sin if n >= 2.0 else sin
    cos = -cos if (n == 1.0) | (n == 2.0) else cos
    return sin, cos


_INVARIANTS = "|L|, L_N and |q| = 1 (exact rotations; energy error bounded, symplectic)"

# no right-hand side is evaluated: each step is 2 (Strang) or 12 (S₆) exact turns
METHODS = (
    Method("splitting2", order=2,
           description="Lie–Poisson splitting of the free body into exact rotations, Strang, fixed step dt",
           driver=_fixed.FixedSteps(STRANG), evaluations=0, options=FIXED_STEP,
           needs=frozenset({"torque_free"}), conserves=_INVARIANTS),
    Method("splitting4", order=4,
           description="Lie–Poisson splitting of the free body into exact rotations, Blanes–Moan S6, fixed step dt",
           driver=_fixed.FixedSteps(BLANES_MOAN), evaluations=0, options=FIXED_STEP,
           needs=frozenset({"torque_free"}), conserves=_INVARIANTS),
)
