"""Flexible appendages as a part of the hub: ``m`` cantilever modes in hybrid coordinates.

Mode ``k`` has the modal coordinate ``η_k`` (kg^½·m), its rate ``η̇_k``, the
cantilever frequency ``Ω_k`` (rad/s), the damping ratio ``ζ_k`` and the
rotational participation vector ``δ_k`` (kg^½·m, body axes). The
hybrid-coordinate equations of a hub with appendages (Likins, JPL TR
32-1576, 1974; Wie, *Space Vehicle Dynamics and Control*, 2nd ed., 2008;
:mod:`tumble.flexible`), with ``I`` the inertia of the spacecraft with its
appendages undeformed::

    I ω̇ + Σ δ_k η̈_k + ω × (I ω + Σ δ_k η̇_k) = τ
    η̈_k + 2ζ_kΩ_k η̇_k + Ω_k² η_k + δ_k·ω̇ = 0

As a part of the hub (``J_ω ω̇ = τ_ext + Σ τ_k − ω × H``): substituting
``η̈_k = f_k − δ_k·ω̇`` with the modal force ``f_k = −2ζ_kΩ_k η̇_k − Ω_k² η_k``
into the first equation gives ``(I − Σ δ_kδ_kᵀ) ω̇ = τ − Σ δ_k f_k − ω × H``,
so the modes

* take ``Σ δ_kδ_kᵀ`` out of the inertia the hub's rate answers to
  (``J_ω = I − Σ δ_kδ_kᵀ − …``, done where ``J_ω`` is formed);
* carry the momentum ``h = Σ δ_k (δ_k·ω + η̇_k)`` (then ``J_ω ω + h = I ω + Σ δ_k η̇_k``);
* exert on the hub ``τ = −Σ δ_k f_k = Σ δ_k (2ζ_kΩ_k η̇_k + Ω_k² η_k)``;
* carry the energy ``½ Σ (δ_k·ω + η̇_k)² + ½ Σ Ω_k² η_k²`` (with ``½ ωᵀJ_ω ω`` the
  hybrid-coordinate energy ``½ ωᵀIω + Σ (δ_k·ω) η̇_k + ½ Σ (η̇_k² + Ω_k² η_k²)``);
* integrate ``d/dt η_k = η̇_k`` and ``d/dt η̇_k = f_k − δ_k·ω̇``: ``act`` writes ``f_k``,
  ``finish`` subtracts ``δ_k·ω̇`` once the hub's ``ω̇`` is known.

Without external torque ``R(q) H`` is constant and the energy falls at
``Ė = −Σ 2ζ_kΩ_k η̇_k²`` (plus the work of other parts' motors).
"""

from __future__ import annotations

import numpy as np

from tumble.kernels.spacecraft._base import Actuator, Lane, Program, inline

# The block of mode k starts at p + STRIDE·k; within it:
PARTICIPATION = 0   # δ_k (3), kg^½·m, body axes
DAMPING = 3         # 2ζ_kΩ_k, 1/s
STIFFNESS = 4       # Ω_k², 1/s²
STRIDE = 5

# State slice of m modes: η_k at s + k, η̇_k at s + m + k.


def program(participation, frequency, damping) -> Program:
    """The modes' :class:`~tumble.kernels.spacecraft._base.Program`: ``participation`` (m, 3) δ_k (kg^½·m,
    body axes), ``frequency`` (m,) Ω_k (rad/s), ``damping`` (m,) ζ_k."""
    frequency = np.asarray(frequency, dtype=np.float64)
    m = frequency.size
    block = np.zeros((m, STRIDE))
    block[:, PARTICIPATION:PARTICIPATION + 3] = participation
    block[:, DAMPING] = 2.0 * np.asarray(damping) * frequency
    block[:, STIFFNESS] = frequency**2
    return Program("flexible_modes", block.ravel(), count=m, state=2 * m)


def state_slices(n: int, s: int) -> dict[str, slice]:
    """Where the ``n`` modes' states are, their slice starting at ``s`` (the names of
    :class:`tumble.flexible.FlexibleBody`'s outputs)."""
    return {"modal_coordinate": slice(s, s + n), "modal_rate": slice(s + n, s + 2 * n)}


def kernel(lane: Lane) -> Actuator:
    """The modes' :class:`~tumble.kernels.spacecraft._base.Actuator` for the state access ``lane``."""
    at, put = lane.at, lane.put

    @inline
    def coupled_rate(d, b, y, j, rate):
        """``δ_k·ω + η̇_k`` of the mode whose block starts at ``b`` (ω read from the state)."""
        return d[b + PARTICIPATION] * at(y, 4, j) + d[b + PARTICIPATION + 1] * at(y, 5, j) + \
            d[b + PARTICIPATION + 2] * at(y, 6, j) + rate

    @inline
    def momentum(model, p, n, s, y, j):
        """``Σ δ_k (δ_k·ω + η̇_k)``, N·m·s, body axes."""
        d = model.data
        h1 = h2 = h3 = 0.0
        for k in range(n):
            b = p + STRIDE * k
            c = coupled_rate(d, b, y, j, at(y, s + n + k, j))
            h1 += d[b + PARTICIPATION] * c
            h2 += d[b + PARTICIPATION + 1] * c
            h3 += d[b + PARTICIPATION + 2] * c
        return h1, h2, h3

    @inline
    def energy(model, p, n, s, y, j):
        """``½ Σ (δ_k·ω + η̇_k)² + ½ Σ Ω_k² η_k²``, J."""
        d = model.data
        e = 0.0
        for k in range(n):
            b = p + STRIDE * k
            c = coupled_rate(d, b, y, j, at(y, s + n + k, j))
            eta = at(y, s + k, j)
            e += 0.5 * (c * c + d[b + STIFFNESS] * eta * eta)
        return e

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        """``d/dt η_k = η̇_k``, ``f_k`` into the slot of ``d/dt η̇_k`` (completed by ``finish``); returns
        ``−Σ δ_k f_k``."""
        d = model.data
        t1 = t2 = t3 = 0.0
        for k in range(n):
            b = p + STRIDE * k
            rate = at(y, s + n + k, j)
            f = -d[b + DAMPING] * rate - d[b + STIFFNESS] * at(y, s + k, j)
            put(out, s + k, j, rate)
            put(out, s + n + k, j, f)
            t1 -= d[b + PARTICIPATION] * f
            t2 -= d[b + PARTICIPATION + 1] * f
            t3 -= d[b + PARTICIPATION + 2] * f
        return t1, t2, t3

    @inline
    def finish(model, p, n, s, y, j, out, a1, a2, a3):
        """``d/dt η̇_k = f_k − δ_k·ω̇`` with the hub's ``ω̇ = (a₁, a₂, a₃)``."""
        d = model.data
        for k in range(n):
            b = p + STRIDE * k
            put(out, s + n + k, j, at(out, s + n + k, j) - (d[b + PARTICIPATION] * a1 + d[b + PARTICIPATION + 1] * a2
                                                             + d[b + PARTICIPATION + 2] * a3))

    return Actuator(act, momentum, energy, finish=finish)
