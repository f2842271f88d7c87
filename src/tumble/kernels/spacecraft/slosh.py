"""Fuel slosh as a part of the hub: spherical pendulums, one per tank.

Tank ``k`` has the reduced mass ``μ`` (kg), the hinge ``b`` (m, body axes,
from the hub's centre of mass), the rod length ``l`` (m) and the hinge damping
``d`` (1/s); its state is the rod's unit direction ``s`` (body axes) and its
angular velocity ``ν`` relative to the hub (rad/s, body axes, ``ν ⊥ s``). The
slosh mass sits at ``r = b + l s`` relative to the hub and moves at
``ṙ = ω × r + l ν × s`` (inertial rate, body axes). The equations of one tank
(:mod:`tumble.slosh`, :mod:`tumble.kernels.slosh`)::

    v  = l ν × s
    a₀ = l ν × (ν × s) + 2 ω × v + ω × (ω × r)     (acceleration of r, all but the ω̇ and ν̇ terms)
    p  = −d ν − s × a₀ / l
    (I_B + μ g gᵀ) ω̇ = τ − ω × I_B ω − μ r × a₀ + μ l r × (s × p),    g = r × s
    ν̇ = p + s × (r × ω̇) / l,      ṡ = ν × s

As a part of the hub (``(J_ω + Σ ΔM) ω̇ = τ_ext + Σ τ_k − ω × H``, ``H = J_ω ω + Σ h_k``, with
``J_ω = I_B``), each tank

* carries the momentum ``h = μ r × (ω × r + l ν × s)`` (then ``H = I_B ω + μ r × ṙ``, SloshBody's);
* adds ``ΔM = μ g gᵀ`` to the hub's matrix (the mass moves along the rod only as the hub turns it);
* exerts on the hub ``τ = ω × h − μ r × a₀ + μ l r × (s × p)``: the hub's ``− ω × H`` holds
  ``− ω × h`` besides SloshBody's ``− ω × I_B ω``, which ``ω × h`` gives back;
* carries the energy ``½ μ |ω × r + l ν × s|²``;
* integrates ``ṡ = ν × s`` and ``ν̇``: ``act`` writes ``p``, ``finish`` adds ``s × (r × ω̇) / l``
  once the hub's ``ω̇`` is known;
* keeps ``|s| = 1`` and ``ν·s = 0`` at every step end (``project``), both invariants of the exact flow.

Without external torque ``R(q) H`` is constant and the energy falls at ``Ė = −Σ μ l² d |ν|²`` (plus the
work of other parts' motors).
"""

from __future__ import annotations

import math

import numpy as np

from tumble._vec import cross
from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

# The block of tank k starts at p + STRIDE·k; within it:
MASS = 0       # reduced mass μ, kg
LENGTH = 1     # rod length l, m
DAMPING = 2    # hinge damping d, 1/s
HINGE = 3      # hinge b (3), m, body axes
STRIDE = 6

# State slice of tank k from s + STATE·k: the rod's direction s (3), then its relative rate ν (3).
DIRECTION, RATE, STATE = 0, 3, 6


def program(mass, length, damping, hinge) -> Program:
    """The tanks' :class:`~tumble.kernels.spacecraft._base.Program`: ``mass`` (k,) reduced masses μ (kg),
    ``length`` (k,) rod lengths l (m), ``damping`` (k,) hinge damping d (1/s), ``hinge`` (k, 3) hinges b (m,
    body axes)."""
    length = np.asarray(length, dtype=np.float64)
    k = length.size
    block = np.zeros((k, STRIDE))
    block[:, MASS], block[:, LENGTH], block[:, DAMPING] = mass, length, damping
    block[:, HINGE:HINGE + 3] = hinge
    return Program("slosh", block.ravel(), count=k, state=STATE * k)


def state_slices(n: int, s: int) -> dict[str, np.ndarray]:
    """Where the ``n`` tanks' states are, their slice starting at ``s``: index arrays (n, 3) under the names
    of :class:`tumble.SloshBody`'s outputs."""
    start = s + STATE * np.arange(n)[:, None] + np.arange(3)
    return {"pendulum_direction": start + DIRECTION, "pendulum_rate": start + RATE}


def kernel(lane: Lane) -> Actuator:
    """The tanks' :class:`~tumble.kernels.spacecraft._base.Actuator` for the state access ``lane``."""
    at, put, put3 = lane

    @inline
    def tank(model, p, s, y, j, k):
        """``(μ, l, d, r, s, ν)`` of tank ``k``: ``r = b + l s`` (m), the rod's ``s`` and ``ν``, body axes."""
        d = model.data
        b, x = p + STRIDE * k, s + STATE * k
        mu, length, damping = d[b + MASS], d[b + LENGTH], d[b + DAMPING]
        s1, s2, s3 = at(y, x + DIRECTION, j), at(y, x + DIRECTION + 1, j), at(y, x + DIRECTION + 2, j)
        n1, n2, n3 = at(y, x + RATE, j), at(y, x + RATE + 1, j), at(y, x + RATE + 2, j)
        r1, r2, r3 = d[b + HINGE] + length * s1, d[b + HINGE + 1] + length * s2, d[b + HINGE + 2] + length * s3
        return mu, length, damping, r1, r2, r3, s1, s2, s3, n1, n2, n3

    @inline
    def velocity(length, r1, r2, r3, s1, s2, s3, n1, n2, n3, w1, w2, w3):
        """``ṙ = ω × r + l ν × s`` (m/s, body axes)."""
        u1, u2, u3 = cross(w1, w2, w3, r1, r2, r3)
        e1, e2, e3 = cross(n1, n2, n3, s1, s2, s3)
        return u1 + length * e1, u2 + length * e2, u3 + length * e3

    @inline
    def momentum(model, p, n, s, y, j):
        """``Σ μ r × ṙ``, N·m·s, body axes."""
        w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
        h1 = h2 = h3 = 0.0
        for k in range(n):
            mu, length, _, r1, r2, r3, s1, s2, s3, n1, n2, n3 = tank(model, p, s, y, j, k)
            v1, v2, v3 = velocity(length, r1, r2, r3, s1, s2, s3, n1, n2, n3, w1, w2, w3)
            c1, c2, c3 = cross(r1, r2, r3, v1, v2, v3)
            h1, h2, h3 = h1 + mu * c1, h2 + mu * c2, h3 + mu * c3
        return h1, h2, h3

    @inline
    def energy(model, p, n, s, y, j):
        """``Σ ½ μ |ṙ|²``, J."""
        w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
        e = 0.0
        for k in range(n):
            mu, length, _, r1, r2, r3, s1, s2, s3, n1, n2, n3 = tank(model, p, s, y, j, k)
            v1, v2, v3 = velocity(length, r1, r2, r3, s1, s2, s3, n1, n2, n3, w1, w2, w3)
            e += 0.5 * mu * (v1 * v1 + v2 * v2 + v3 * v3)
        return e

    @inline
    def added_inertia(model, p, n, s, y, j):
        """``Σ μ g gᵀ`` with ``g = r × s`` (kg·m², upper triangle)."""
        m00 = m01 = m02 = m11 = m12 = m22 = 0.0
        for k in range(n):
            mu, _, _, r1, r2, r3, s1, s2, s3, _, _, _ = tank(model, p, s, y, j, k)
            g1, g2, g3 = cross(r1, r2, r3, s1, s2, s3)
            m00, m01, m02 = m00 + mu * g1 * g1, m01 + mu * g1 * g2, m02 + mu * g1 * g3
            m11, m12, m22 = m11 + mu * g2 * g2, m12 + mu * g2 * g3, m22 + mu * g3 * g3
        return m00, m01, m02, m11, m12, m22

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        """``ṡ = ν × s`` and ``p`` into the slot of ``ν̇`` (completed by ``finish``); returns
        ``Σ ω × h − μ r × a₀ + μ l r × (s × p)``."""
        t1 = t2 = t3 = 0.0
        for k in range(n):
            mu, length, damping, r1, r2, r3, s1, s2, s3, n1, n2, n3 = tank(model, p, s, y, j, k)
            e1, e2, e3 = cross(n1, n2, n3, s1, s2, s3)                  # ṡ = ν × s
            v1, v2, v3 = length * e1, length * e2, length * e3
            x1, x2, x3 = cross(n1, n2, n3, e1, e2, e3)                  # ν × (ν × s)
            c1, c2, c3 = cross(w1, w2, w3, v1, v2, v3)                  # ω × v
            u1, u2, u3 = cross(w1, w2, w3, r1, r2, r3)
            z1, z2, z3 = cross(w1, w2, w3, u1, u2, u3)                  # ω × (ω × r)
            a1, a2, a3 = length * x1 + 2.0 * c1 + z1, length * x2 + 2.0 * c2 + z2, length * x3 + 2.0 * c3 + z3
            f1, f2, f3 = cross(s1, s2, s3, a1, a2, a3)
            p1, p2, p3 = -damping * n1 - f1 / length, -damping * n2 - f2 / length, -damping * n3 - f3 / length
            m1, m2, m3 = cross(r1, r2, r3, a1, a2, a3)
            q1, q2, q3 = cross(s1, s2, s3, p1, p2, p3)
            o1, o2, o3 = cross(r1, r2, r3, q1, q2, q3)
            h1, h2, h3 = cross(r1, r2, r3, u1 + v1, u2 + v2, u3 + v3)
            k1, k2, k3 = cross(w1, w2, w3, mu * h1, mu * h2, mu * h3)   # ω × h
            t1 += k1 - mu * m1 + mu * length * o1
            t2 += k2 - mu * m2 + mu * length * o2
            t3 += k3 - mu * m3 + mu * length * o3
            x = s + STATE * k
            put3(out, x + DIRECTION, j, e1, e2, e3)
            put3(out, x + RATE, j, p1, p2, p3)
        return t1, t2, t3

    @inline
    def finish(model, p, n, s, y, j, out, a1, a2, a3):
        """``ν̇ = p + s × (r × ω̇) / l`` with the hub's ``ω̇ = (a₁, a₂, a₃)``."""
        for k in range(n):
            _, length, _, r1, r2, r3, s1, s2, s3, _, _, _ = tank(model, p, s, y, j, k)
            l1, l2, l3 = cross(r1, r2, r3, a1, a2, a3)
            c1, c2, c3 = cross(s1, s2, s3, l1, l2, l3)
            x = s + STATE * k + RATE
            put3(out, x, j, at(out, x, j) + c1 / length, at(out, x + 1, j) + c2 / length,
                 at(out, x + 2, j) + c3 / length)

    @inline
    def project(model, p, n, s, y, j):
        """``s ← s/|s|``, ``ν ← ν − (ν·s) s`` (the step's drift off the constraints)."""
        for k in range(n):
            x = s + STATE * k
            s1, s2, s3 = at(y, x + DIRECTION, j), at(y, x + DIRECTION + 1, j), at(y, x + DIRECTION + 2, j)
            scale = 1.0 / math.sqrt(s1 * s1 + s2 * s2 + s3 * s3)
            s1, s2, s3 = s1 * scale, s2 * scale, s3 * scale
            n1, n2, n3 = at(y, x + RATE, j), at(y, x + RATE + 1, j), at(y, x + RATE + 2, j)
            along = n1 * s1 + n2 * s2 + n3 * s3
            put3(y, x + DIRECTION, j, s1, s2, s3)
            put3(y, x + RATE, j, n1 - along * s1, n2 - along * s2, n3 - along * s3)

    return Actuator(act, momentum, energy, finish=finish, added_inertia=added_inertia, project=project)
