"""Reaction wheels: symmetric rotors spun about fixed body axes by motors, with bearing friction.

Wheel ``i`` spins about the unit axis ``a_i`` (body axes); its state is its
absolute axial angular momentum ``h_i = I_s,i (a_i·ω + Ω_i)`` (N·m·s, ``Ω_i``
its speed relative to the hub), and the wheels together carry the work ``W``
(J) done on them by motors and bearings (Hughes, *Spacecraft Attitude
Dynamics*, §7.2; Markley & Crassidis 2014, §3.3.5)::

    ḣ_i = u_i − c_v Ω_i − c_c tanh(Ω_i/Ω_c)          Ẇ = Σ ḣ_i Ω_i
    u_i = clip(−r_i·u_c + w_i, ±max_torque)          (0 at |Ω_i| ≥ max_speed when it would speed up)

``u_c`` is the controller's torque command on the hub (body axes) when the
wheels deliver it, ``r_i`` row ``i`` of the pseudo-inverse ``A⁺`` of the axis
matrix ``A = [a_1 … a_n]`` (so ``−Σ a_i u_i = u_c`` for three or more
independent axes, within the limits), and ``w_i`` a motor torque commanded
directly (:mod:`tumble.kernels.spacecraft.laws`). The hub feels ``−Σ a_i ḣ_i``.
"""

from __future__ import annotations

import math

import numpy as np

from tumble._vec import clip
from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

# The block of wheel i starts at p + STRIDE·i; within it:
AXIS = 0            # a_i (3), unit spin axis, body axes
SPIN_INERTIA = 3    # I_s,i, kg·m²
MAX_TORQUE = 4      # motor torque limit, N·m (inf: none)
MAX_SPEED = 5       # speed limit relative to the hub, rad/s (inf: none)
VISCOUS = 6         # c_v, N·m·s/rad
COULOMB = 7         # c_c, N·m
COULOMB_SPEED = 8   # Ω_c, rad/s
ALLOCATION = 9      # r_i (3): row i of A⁺
STRIDE = 12

# State slice: h_i at s + MOMENTUM + i, then W at s + n.
MOMENTUM = 0
# Diagnostics: speed Ω_i (n), motor torque u_i (n), saturation flag (n).
AUX_SPEED, AUX_MOTOR, AUX_SATURATED = 0, 1, 2


def program(axes, spin_inertia, max_torque, max_speed, viscous, coulomb, coulomb_speed, allocation) -> Program:
    """The wheels' :class:`~tumble.kernels.spacecraft._base.Program`: per-wheel arrays (n,) or (n, 3) in the
    units of the block above; ``allocation`` (n, 3) the rows of ``A⁺`` (zeros when the wheels do not deliver
    the controller's torque)."""
    n = len(spin_inertia)
    block = np.zeros((n, STRIDE))
    block[:, AXIS:AXIS + 3] = axes
    block[:, SPIN_INERTIA] = spin_inertia
    block[:, MAX_TORQUE] = max_torque
    block[:, MAX_SPEED] = max_speed
    block[:, VISCOUS] = viscous
    block[:, COULOMB] = coulomb
    block[:, COULOMB_SPEED] = coulomb_speed
    block[:, ALLOCATION:ALLOCATION + 3] = allocation
    return Program("wheels", block.ravel(), count=n, state=n + 1, aux=3 * n)


def state_slices(n: int, s: int) -> dict[str, slice]:
    """Where the wheels' states are in a state vector whose wheel slice starts at ``s``."""
    return {"wheel_momentum": slice(s + MOMENTUM, s + MOMENTUM + n), "wheel_work": slice(s + n, s + n + 1)}


def aux_slices(n: int, a: int) -> dict[str, slice]:
    """Where the wheels' diagnostics are, their slice starting at ``a``."""
    return {name: slice(a + k * n, a + (k + 1) * n)
            for name, k in (("wheel_speed", AUX_SPEED), ("wheel_torque", AUX_MOTOR),
                            ("wheel_saturated", AUX_SATURATED))}


@inline
def speed(d, b, h, w1, w2, w3):
    """``Ω = h/I_s − a·ω`` (rad/s) of the wheel whose block starts at ``b``, momentum ``h``, hub rate ``ω``."""
    return h / d[b + SPIN_INERTIA] - (d[b + AXIS] * w1 + d[b + AXIS + 1] * w2 + d[b + AXIS + 2] * w3)


def kernel(lane: Lane, direct) -> Actuator:
    """The wheels' :class:`~tumble.kernels.spacecraft._base.Actuator` for the state access ``lane``;
    ``direct(model, t, y, j, i, source)`` is the motor torque commanded directly to wheel ``i`` (N·m; a
    compiled function of the wheel-torque law)."""
    at, put = lane.at, lane.put

    @inline
    def momentum(model, p, n, s, y, j):
        """``Σ a_i h_i``, N·m·s, body axes."""
        d = model.data
        h1 = h2 = h3 = 0.0
        for i in range(n):
            b = p + STRIDE * i
            h = at(y, s + MOMENTUM + i, j)
            h1 += d[b + AXIS] * h
            h2 += d[b + AXIS + 1] * h
            h3 += d[b + AXIS + 2] * h
        return h1, h2, h3

    @inline
    def energy(model, p, n, s, y, j):
        """``Σ h_i²/(2 I_s,i)``, J (each rotor's spin energy about its axis, absolute rate)."""
        d = model.data
        e = 0.0
        for i in range(n):
            h = at(y, s + MOMENTUM + i, j)
            e += 0.5 * h * h / d[p + STRIDE * i + SPIN_INERTIA]
        return e

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        d = model.data
        u1, u2, u3 = (cmd[0], cmd[1], cmd[2]) if routed else (0.0, 0.0, 0.0)
        t1 = t2 = t3 = power = 0.0
        for i in range(n):
            b = p + STRIDE * i
            a1, a2, a3 = d[b + AXIS], d[b + AXIS + 1], d[b + AXIS + 2]
            omega = speed(d, b, at(y, s + MOMENTUM + i, j), w1, w2, w3)
            wanted = direct(model, t, y, j, i, cmd[9]) - (d[b + ALLOCATION] * u1 + d[b + ALLOCATION + 1] * u2
                                                           + d[b + ALLOCATION + 2] * u3)
            motor = clip(wanted, d[b + MAX_TORQUE])
            saturated = abs(omega) >= d[b + MAX_SPEED] and motor * omega > 0.0
            if saturated:
                motor = 0.0
            hdot = motor - d[b + VISCOUS] * omega
            if d[b + COULOMB] != 0.0:  # Coulomb friction, smoothed
                hdot -= d[b + COULOMB] * math.tanh(omega / d[b + COULOMB_SPEED])
            put(out, s + MOMENTUM + i, j, hdot)
            t1 -= a1 * hdot
            t2 -= a2 * hdot
            t3 -= a3 * hdot
            power += hdot * omega
            if store:
                put(aux, a + AUX_SPEED * n + i, j, omega)
                put(aux, a + AUX_MOTOR * n + i, j, motor)
                put(aux, a + AUX_SATURATED * n + i, j, 1.0 if saturated else 0.0)
        put(out, s + n, j, power)
        return t1, t2, t3

    return Actuator(act, momentum, energy)
