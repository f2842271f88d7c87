"""Single-gimbal control moment gyros steered by the generalised singularity-robust inverse.

Gyro ``i`` carries a rotor of constant angular momentum ``h_i`` (N·m·s) along
``s_i(δ_i) = cos δ_i s0_i + sin δ_i t0_i`` (``t0_i = g_i × s0_i``), turned about
its gimbal axis ``g_i`` by the gimbal angle ``δ_i`` (the state, rad). Its
torque column is ``A_i = h_i (g_i × s_i) = h_i (cos δ_i t0_i − sin δ_i s0_i)``;
the gyros exert ``−A δ̇`` on the hub. The gimbal rates follow the steering law
at once (ideal rate servos), clipped to ``±max_gimbal_rate`` (Wie, *Space
Vehicle Dynamics and Control*, 2nd ed., 2008, §7.3)::

    δ̇ = A# (−u_c),   A# = Aᵀ (A Aᵀ + λ E)⁻¹,   λ = λ₀ exp(−μ det(Ā Āᵀ)) h̄²,   Ā = A/h̄

        ⎡ 1   ε₃  ε₂ ⎤
    E = ⎢ ε₃  1   ε₁ ⎥,   ε_i = ε₀ sin(ω_ε t + φ_i)
        ⎣ ε₂  ε₁  1  ⎦

With ``ε₀ = 0`` this is the singularity-robust (SR) inverse (Nakazawa 1988;
Bedrossian, Paradiso & Bergmann, J. Guidance 13(6), 1990): near a singular
configuration it trades a small torque error for bounded gimbal rates, but a
command along the singular direction ``v`` (``vᵀA = 0``) is an eigenvector of
``(A Aᵀ + λE)⁻¹`` and gives ``δ̇ = 0``: the gimbals never move. The
deterministic off-diagonal dither of the generalised SR inverse (Wie, Bailey &
Heiberg, J. Guidance 24(5), 2001) rotates the command out of that direction,
so the gimbals leave the singular set (elliptic singularities included) at
the cost of a transient torque error of order ``ε₀``. The diagnostics carry
the singularity measure ``√det(Ā Āᵀ)`` (0 at a singular configuration).
"""

from __future__ import annotations

import math

import numpy as np

from tumble._vec import clip, solve_symmetric
from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

# The cluster's block (steering law), at p:
GAIN = 0               # λ₀ (dimensionless: λ is λ₀ h̄² at a singularity)
DECAY = 1              # μ
NOMINAL = 2            # h̄, the largest rotor momentum, N·m·s
MAX_RATE = 3           # gimbal rate limit, rad/s
DITHER = 4             # ε₀
DITHER_FREQUENCY = 5   # ω_ε, rad/s
DITHER_PHASE = 6       # φ₁, φ₂, φ₃ (3), rad
HEAD = 9
# Gyro i's block at p + HEAD + STRIDE·i:
GIMBAL = 0             # g_i (3), body axes
SPIN = 3               # s0_i (3): spin axis at δ = 0
TRANSVERSE = 6         # t0_i = g_i × s0_i (3)
ROTOR = 9              # h_i, N·m·s
STRIDE = 10

# Diagnostics: gimbal rates (n), then the singularity measure (1).
AUX_RATE, AUX_SINGULARITY = 0, 1


def program(gimbal_axes, spin_axes, momentum, *, max_gimbal_rate, robust_gain, robust_decay, dither,
            dither_frequency, dither_phases) -> Program:
    """The cluster's :class:`~tumble.kernels.spacecraft._base.Program` (axes (n, 3), momenta (n,); units above)."""
    n = len(momentum)
    gyros = np.zeros((n, STRIDE))
    gyros[:, GIMBAL:GIMBAL + 3] = gimbal_axes
    gyros[:, SPIN:SPIN + 3] = spin_axes
    gyros[:, TRANSVERSE:TRANSVERSE + 3] = np.cross(gimbal_axes, spin_axes)
    gyros[:, ROTOR] = momentum
    head = np.zeros(HEAD)
    head[[GAIN, DECAY, NOMINAL, MAX_RATE, DITHER, DITHER_FREQUENCY]] = (
        robust_gain, robust_decay, np.max(momentum), max_gimbal_rate, dither, dither_frequency)
    head[DITHER_PHASE:DITHER_PHASE + 3] = dither_phases
    return Program("cmgs", np.concatenate([head, gyros.ravel()]), count=n, state=n, aux=n + 1)


def state_slices(n: int, s: int) -> dict[str, slice]:
    return {"gimbal_angle": slice(s, s + n)}


def aux_slices(n: int, a: int) -> dict[str, slice]:
    return {"gimbal_rate": slice(a + AUX_RATE, a + AUX_RATE + n), "singularity": slice(a + n, a + n + 1)}


@inline
def spin_axis(d, b, delta):
    """``h_i s_i(δ_i)``, N·m·s, of the gyro whose block starts at ``b``."""
    c, s, h = math.cos(delta), math.sin(delta), d[b + ROTOR]
    return (h * (c * d[b + SPIN] + s * d[b + TRANSVERSE]), h * (c * d[b + SPIN + 1] + s * d[b + TRANSVERSE + 1]),
            h * (c * d[b + SPIN + 2] + s * d[b + TRANSVERSE + 2]))


@inline
def column(d, b, delta):
    """The torque column ``A_i = h_i (cos δ t0 − sin δ s0)`` (N·m per rad/s) of the gyro whose block starts at
    ``b``."""
    c, s, h = math.cos(delta), math.sin(delta), d[b + ROTOR]
    return (h * (c * d[b + TRANSVERSE] - s * d[b + SPIN]), h * (c * d[b + TRANSVERSE + 1] - s * d[b + SPIN + 1]),
            h * (c * d[b + TRANSVERSE + 2] - s * d[b + SPIN + 2]))


def kernel(lane: Lane) -> Actuator:
    """The gyros' :class:`~tumble.kernels.spacecraft._base.Actuator` for the state access ``lane`` (their
    rotors' constant spin energy is left out of the total energy)."""
    at, put = lane.at, lane.put

    @inline
    def momentum(model, p, n, s, y, j):
        """``Σ h_i s_i(δ_i)``, N·m·s, body axes."""
        d = model.data
        h1 = h2 = h3 = 0.0
        for i in range(n):
            x1, x2, x3 = spin_axis(d, p + HEAD + STRIDE * i, at(y, s + i, j))
            h1 += x1
            h2 += x2
            h3 += x3
        return h1, h2, h3

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        """Gimbal rates by the generalised SR inverse of ``−u_c`` (zero when the gyros do not deliver the
        command); returns ``−A δ̇``."""
        d = model.data
        m00 = m01 = m02 = m11 = m12 = m22 = 0.0
        for i in range(n):  # A Aᵀ
            x1, x2, x3 = column(d, p + HEAD + STRIDE * i, at(y, s + i, j))
            m00 += x1 * x1
            m01 += x1 * x2
            m02 += x1 * x3
            m11 += x2 * x2
            m12 += x2 * x3
            m22 += x3 * x3
        hb2 = d[p + NOMINAL] * d[p + NOMINAL]
        det = (m00 * (m11 * m22 - m12 * m12) - m01 * (m01 * m22 - m12 * m02)
               + m02 * (m01 * m12 - m11 * m02)) / (hb2 * hb2 * hb2)
        if routed:
            lam = d[p + GAIN] * math.exp(-d[p + DECAY] * det) * hb2
            e0, wt = d[p + DITHER], d[p + DITHER_FREQUENCY] * t
            e1 = lam * e0 * math.sin(wt + d[p + DITHER_PHASE])
            e2 = lam * e0 * math.sin(wt + d[p + DITHER_PHASE + 1])
            e3 = lam * e0 * math.sin(wt + d[p + DITHER_PHASE + 2])
            x1, x2, x3 = solve_symmetric(m00 + lam, m01 + e3, m02 + e2, m11 + lam, m12 + e1, m22 + lam,
                                         -cmd[0], -cmd[1], -cmd[2])
        else:
            x1 = x2 = x3 = 0.0
        t1 = t2 = t3 = 0.0
        for i in range(n):
            a1, a2, a3 = column(d, p + HEAD + STRIDE * i, at(y, s + i, j))
            rate = clip(a1 * x1 + a2 * x2 + a3 * x3, d[p + MAX_RATE])
            put(out, s + i, j, rate)
            t1 -= a1 * rate
            t2 -= a2 * rate
            t3 -= a3 * rate
            if store:
                put(aux, a + AUX_RATE + i, j, rate)
        if store:
            put(aux, a + n, j, math.sqrt(max(det, 0.0)))
        return t1, t2, t3

    return Actuator(act, momentum)
