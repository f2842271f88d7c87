"""What every part of the compiled spacecraft shares: lane access to the state, the actuator interface.

``at(y, i, j)`` and ``put(y, i, j, v)`` (a :class:`Lane`) read and write
component ``i`` of one member's state: ``y[i]`` when ``y`` is the state vector
of one body, ``y[i, j]`` when ``y`` is a block (state × lanes) and ``j`` the
lane. A part that reads or writes states is written once, in a function of the
:class:`Lane` (``kernel(lane)``), and compiled for both. Scalar reads and
writes only: a row view would cost reference counting in every evaluation of
the right-hand side.

An actuator (or any part that carries angular momentum: wheels, gyros, a
damper, flexible modes, slosh pendulums) is an :class:`Actuator` of up to seven compiled functions with one
signature each; :mod:`tumble.kernels.spacecraft` sums them over the parts present.
Every function receives the compiled model and the part's place in it: ``p``
the offset of its parameter block in ``model.data``, ``n`` its count (wheels,
gyros, thrusters), ``s`` the offset of its state slice, ``a`` that of its
diagnostics (see :data:`tumble.kernels.spacecraft.PARTS`)::

    momentum(model, p, n, s, y, j) -> (h₁, h₂, h₃)
        the angular momentum the part carries, N·m·s, body axes (its share of H)
    energy(model, p, n, s, y, j) -> T
        its kinetic energy, J
    act(model, p, n, s, a, routed, t, y, j, out, aux, store, w₁, w₂, w₃, cmd) -> (τ₁, τ₂, τ₃)
        writes the derivatives of its states into ``out`` (and, when ``store``,
        its diagnostics into ``aux``); returns the torque it exerts on the hub,
        N·m, body axes: ``−dh/dt`` seen from the hub for a part whose momentum
        ``h`` is in ``H`` (an external torque for thrusters and magnetorquers).
        ``routed``: the controller's torque command is this part's to deliver;
        ``cmd = (u₁, u₂, u₃, m₁, m₂, m₃, b₁, b₂, b₃, source)``: torque command
        (N·m), dipole command (A·m²) and magnetic field (T), body axes, and
        what the wheel-torque law left for the wheels' direct commands
    finish(model, p, n, s, y, j, out, a₁, a₂, a₃)
        completes the derivatives of its states in ``out`` once the hub's
        ``ω̇ = (a₁, a₂, a₃)`` (rad/s², body axes) is known, for a part whose
        states respond to the hub's acceleration (the flexible modes'
        ``η̈_k = f_k − δ_k·ω̇``): ``act`` contributes first, ``finish`` follows
        the hub's solve, as Basilisk's ``updateContributions`` and
        ``computeDerivatives``
    sample(model, p, n, s, t, y, j)
        its discrete updates at the end of a step that ends at ``t`` (in place)
    added_inertia(model, p, n, s, y, j) -> (m₀₀, m₀₁, m₀₂, m₁₁, m₁₂, m₂₂)
        a state-dependent, symmetric contribution ``ΔM`` (kg·m², upper triangle) to
        the hub's matrix, for a part whose states' accelerations carry the hub's
        ``ω̇`` back into the torque it exerts (the slosh pendulums' ``μ g gᵀ``; Basilisk's
        effectors add their ``matrixD`` terms to the hub's back-substitution so):
        the hub then solves ``(J_ω + Σ ΔM) ω̇ = rhs`` (a closed-form 3×3 solve),
        without such a part present with the precomputed ``J_ω⁻¹``
    project(model, p, n, s, y, j)
        puts its states back on their constraints at every step end (in place; the
        slosh rods' ``|s| = 1``, ``ν·s = 0``), as the quaternion is normalised there

The right-hand side calls, in order: every ``momentum`` (to form ``H``), every
``act`` (the torques on the hub), every ``added_inertia``, the hub's solve for
``ω̇``, every ``finish``.
"""

from __future__ import annotations

import functools
from typing import Callable, NamedTuple

import numpy as np
from numba import njit

#: IR-level inlining: the parts are small and called in the innermost loop (a call costs more than they do).
inline = njit(inline="always")

#: A step end counts as a sample time of a clock (the control period, a law's own period) when within this
#: fraction of the clock's period of a whole number of periods after the start.
SAMPLE_TOLERANCE = 1e-9


class Lane(NamedTuple):
    """``at(y, i, j)``, ``put(y, i, j, v)`` and ``put3(y, i, j, v₁, v₂, v₃)`` for states of one ``ndim``."""

    at: Callable
    put: Callable
    put3: Callable


@functools.lru_cache(maxsize=None)
def lane(ndim: int) -> Lane:
    """The :class:`Lane` access for state vectors (``ndim`` 1, ``j`` unused) or blocks (``ndim`` 2).

    Plain compiled closures, one set per ``ndim``, which LLVM inlines: not inlined in Numba's IR (``inline``),
    where each of their ~200 call sites would cost a run of Numba's passes over a copy of the function
    (a sixth of the spacecraft's compile time), and not an ``overload`` dispatching on ``y.ndim``, whose
    inlined calls Numba's IR inliner (0.68) drops when an argument is a conditional expression.
    """
    if ndim == 1:
        @njit
        def at(y, i, j):
            return y[i]

        @njit
        def put(y, i, j, value):
            y[i] = value
    else:
        @njit
        def at(y, i, j):
            return y[i, j]

        @njit
        def put(y, i, j, value):
            y[i, j] = value

    @njit
    def put3(y, i, j, v1, v2, v3):
        put(y, i, j, v1)
        put(y, i + 1, j, v2)
        put(y, i + 2, j, v3)

    return Lane(at, put, put3)


@inline
def no_momentum(model, p, n, s, y, j):
    return 0.0, 0.0, 0.0


@inline
def no_energy(model, p, n, s, y, j):
    return 0.0


@inline
def no_sample(model, p, n, s, t, y, j):
    pass


@inline
def no_finish(model, p, n, s, y, j, out, a1, a2, a3):
    pass


@inline
def no_added_inertia(model, p, n, s, y, j):
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


@inline
def no_project(model, p, n, s, y, j):
    pass


class Actuator(NamedTuple):
    """The compiled functions of one part (see the module docstring); absent ones do nothing."""

    act: Callable
    momentum: Callable = no_momentum
    energy: Callable = no_energy
    sample: Callable = no_sample
    finish: Callable = no_finish
    added_inertia: Callable = no_added_inertia
    project: Callable = no_project


class Program(NamedTuple):
    """One part of a spacecraft, compiled: its kind (a name of :data:`tumble.kernels.spacecraft.PARTS`),
    its parameter block, its count (wheels, gyros, thrusters) and the sizes of its state and diagnostics."""

    kind: str
    params: np.ndarray
    count: int = 0
    state: int = 0
    aux: int = 0
