"""Compile-time assembly of the controller: the commands of the control laws (:mod:`.laws`), evaluated in the
right-hand side or held by a zero-order hold.

The laws come in three groups, each held at its own sample period (the ``"hold"`` part's parameter block,
:func:`hold_program`) or evaluated continuously (period 0): the torque law (``u_c``), the dipole laws (``m_c``,
summed) and the wheel-torque law (the wheels' direct motor torques). A group of period ``T`` is sampled at the
step ends ``t₀ + k·T`` (within :data:`~tumble.kernels.spacecraft._base.SAMPLE_TOLERANCE` of ``T``) and its
commands are held in the hold's state until its next sample; a set of groups travels as bits
(:data:`~tumble.kernels.spacecraft._layout.TORQUE_LAW`, ``DIPOLE_LAW``, ``WHEEL_LAW``).

Every function here runs once, when Numba compiles the spacecraft model type, and returns compiled (inlined)
functions of the model and one member's state. Which laws a spacecraft has is data: each law is a part whose
field in the model says whether it is present (:func:`tumble.kernels.spacecraft._layout.locator`), read at run
time, so every composition of laws runs the same compiled code.

The motor torques commanded to the wheels directly travel as a ``source`` ``(code, offset, count, values)``,
evaluated once per evaluation of the commands; ``direct(model, t, y, j, i, source)`` is wheel ``i``'s command
(N·m): ``code`` :data:`NO_WHEEL_LAW` (0), :data:`WHEEL_TABLE` (the samples' block at ``offset`` for ``count``
wheels), :data:`WHEEL_PYTHON` (``values[i]`` of the Python law) or :data:`WHEEL_HELD` (held in the state at
``offset + i``).
"""

from __future__ import annotations

import numpy as np

from tumble._vec import cross, matvec_flat
from tumble.kernels.spacecraft import laws, wheels
from tumble.kernels.spacecraft._base import SAMPLE_TOLERANCE, Program, inline
from tumble.kernels.spacecraft._layout import (DIPOLE_LAW, HELD_DIPOLE, HELD_TORQUE, HELD_WHEELS, HOLD_PERIODS, J_RATE,
                                               LAW_GROUPS, PARTS, START, TORQUE_LAW, WHEEL_LAW, locator)

NO_WHEEL_LAW, WHEEL_TABLE, WHEEL_PYTHON, WHEEL_HELD = 0, 1, 2, 3

#: Every law group.
ALL_LAWS = TORQUE_LAW | DIPOLE_LAW | WHEEL_LAW


def hold_program(torque_period: float, dipole_period: float, wheel_period: float, n_wheels: int) -> Program:
    """The ``"hold"`` part: the sample periods (s; 0: continuous) of the torque law, the dipole laws and the
    wheel-torque law, and the held commands (``n_wheels`` motor torques when a wheel-torque law is present)."""
    periods = np.array([torque_period, dipole_period, wheel_period], dtype=np.float64)  # in the order of the bits
    return Program("hold", periods, count=n_wheels, state=HELD_WHEELS + n_wheels)


@inline
def on_clock(t, start, period):
    """True when ``t`` (s) is a sample time ``start + k·period`` of the clock, within ``SAMPLE_TOLERANCE·period``."""
    k = round((t - start) / period)
    return abs(t - start - k * period) <= SAMPLE_TOLERANCE * period


def make_speeds(lane):
    """``speeds(model, y, j, ω) -> array`` of the wheel speeds Ω_i (rad/s; empty without wheels), for Python laws."""
    at = lane.at
    has_wheels, where = locator("wheels")

    @inline
    def speeds(model, y, j, w1, w2, w3):
        if not has_wheels(model):
            return np.empty(0)
        p, n, s, _ = where(model)
        out = np.empty(n)
        for i in range(n):
            b = p + wheels.STRIDE * i
            out[i] = wheels.speed(model.data, b, at(y, s + wheels.MOMENTUM + i, j), w1, w2, w3)
        return out

    return speeds


def make_torque_law(lane, speeds, python):
    """``law(model, t, y, j, q, ω, H) -> u_c`` (N·m, body axes) of the torque law present (zero without one);
    the Python law only in the variant that calls Python (``python``)."""
    at = lane.at
    has_pd, where_pd = locator("pd")
    has_mrp, where_mrp = locator("mrp")
    has_integral, where_integral = locator("mrp_integral")
    has_python, where_python = locator("python_law")

    @inline
    def law(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
        u1 = u2 = u3 = 0.0
        if has_pd(model):
            p, _, _, _ = where_pd(model)
            u1, u2, u3 = laws.pd_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3)
        elif has_mrp(model):
            p, _, _, _ = where_mrp(model)
            v1 = v2 = v3 = 0.0
            if has_integral(model):
                pi, _, s, _ = where_integral(model)
                d = model.data
                k, ki = d[p + laws.MRP_K], d[pi + laws.MRP_KI]
                # v = K_I z,  z = K ∫σ dt + J_ω ω
                z1, z2, z3 = matvec_flat(d, J_RATE, w1, w2, w3)
                v1 = ki * (k * at(y, s + laws.INTEGRAL, j) + z1)
                v2 = ki * (k * at(y, s + laws.INTEGRAL + 1, j) + z2)
                v3 = ki * (k * at(y, s + laws.INTEGRAL + 2, j) + z3)
            u1, u2, u3 = laws.mrp_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, v1, v2, v3)
        return u1, u2, u3

    if not python:
        return law

    @inline
    def law_or_python(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
        if has_python(model):
            p, _, _, _ = where_python(model)
            u = laws.call_python(int(model.data[p + laws.SLOT]), t, qw, qx, qy, qz, w1, w2, w3,
                                 speeds(model, y, j, w1, w2, w3), 3)
            return u[0], u[1], u[2]
        return law(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3)

    return law_or_python


def make_dipole_law(lane):
    """``law(model, y, j, ω, B) -> m_c`` (A·m², body axes): the sum of the dipole laws present."""
    has_bdot, where_bdot = locator("bdot")
    has_dumping, where_dumping = locator("dumping")
    _, where_wheels = locator("wheels")  # momentum dumping needs wheels (Spacecraft checks it)
    wheel_momentum = wheels.kernel(lane, None).momentum

    @inline
    def law(model, y, j, w1, w2, w3, b1, b2, b3):
        m1 = m2 = m3 = 0.0
        if has_bdot(model):
            p, _, _, _ = where_bdot(model)
            m1, m2, m3 = laws.bdot_dipole(model, p, w1, w2, w3, b1, b2, b3)
        e1 = e2 = e3 = 0.0
        if has_dumping(model):
            p, _, _, _ = where_dumping(model)
            pw, nw, sw, _ = where_wheels(model)
            h1, h2, h3 = wheel_momentum(model, pw, nw, sw, y, j)
            e1, e2, e3 = laws.dumping_dipole(model, p, h1, h2, h3, b1, b2, b3)
        return m1 + e1, m2 + e2, m3 + e3

    return law


def make_wheel_law(speeds, python):
    """``source(model, t, y, j, q, ω)``: the motor-torque law of the wheels evaluated once per evaluation of the
    commands (the module docstring); the Python law only in the variant that calls Python (``python``)."""
    has_table, where_table = locator("wheel_table")
    has_python, where_python = locator("wheel_python")
    _, where_wheels = locator("wheels")  # a wheel-torque law needs wheels (Spacecraft checks it)

    @inline
    def source(model, t, y, j, qw, qx, qy, qz, w1, w2, w3):
        if has_table(model):
            p, _, _, _ = where_table(model)
            _, nw, _, _ = where_wheels(model)
            return WHEEL_TABLE, p, nw, model.data
        return NO_WHEEL_LAW, 0, 0, model.data

    if not python:
        return source

    @inline
    def source_or_python(model, t, y, j, qw, qx, qy, qz, w1, w2, w3):
        if has_python(model):
            p, _, _, _ = where_python(model)
            _, nw, _, _ = where_wheels(model)
            return WHEEL_PYTHON, p, nw, laws.call_python(int(model.data[p + laws.SLOT]), t, qw, qx, qy, qz,
                                                         w1, w2, w3, speeds(model, y, j, w1, w2, w3), nw)
        return source(model, t, y, j, qw, qx, qy, qz, w1, w2, w3)

    return source_or_python


def make_direct(lane):
    """``direct(model, t, y, j, i, source)``: the motor torque commanded directly to wheel ``i``, N·m."""
    at = lane.at

    @inline
    def direct(model, t, y, j, i, source):
        code = source[0]
        if code == WHEEL_TABLE:
            return laws.wheel_table(model, source[1], source[2], t, i)
        if code == WHEEL_PYTHON:
            return source[3][i]
        if code == WHEEL_HELD:
            return at(y, source[1] + i, j)
        return 0.0

    return direct


def controller(lane, python):
    """``commands(model, t, y, j, q, ω, H, B, now, u_c, m_c, source) -> (u_c, m_c, source)``: the commands of the
    law groups ``now`` (bits) as the laws give them at ``t`` from ``q``, ``ω``, ``H`` and ``B``, the other groups'
    those given (the held ones); the Python laws only in the variant that calls Python (``python``). With the
    torque command routed to the magnetorquers (``m = B × u/|B|²``, the part of ``u`` normal to ``B``, added to
    the dipole command) the torque and dipole groups share one period (``Spacecraft`` checks it)."""
    speeds = make_speeds(lane)
    torque_law, dipole_law = make_torque_law(lane, speeds, python), make_dipole_law(lane)
    source_now = make_wheel_law(speeds, python)
    magnetorquers_index = PARTS.index("magnetorquers")

    @inline
    def commands(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, b1, b2, b3, now, u1, u2, u3, m1, m2, m3,
                 source):
        if now & TORQUE_LAW:
            u1, u2, u3 = torque_law(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3)
        if now & DIPOLE_LAW:
            m1, m2, m3 = dipole_law(model, y, j, w1, w2, w3, b1, b2, b3)
            if model.route == magnetorquers_index:
                k = 1.0 / (b1 * b1 + b2 * b2 + b3 * b3)
                e1, e2, e3 = cross(b1, b2, b3, u1, u2, u3)
                m1, m2, m3 = m1 + k * e1, m2 + k * e2, m3 + k * e3
        if now & WHEEL_LAW:
            source = source_now(model, t, y, j, qw, qx, qy, qz, w1, w2, w3)
        return u1, u2, u3, m1, m2, m3, source

    return commands


def law_clocks():
    """``(live, due)`` of the law groups under a zero-order hold: ``live(model)`` the groups evaluated in the
    right-hand side (period 0), ``due(model, t)`` those with a sample time at the step end ``t`` (bits)."""
    _, where = locator("hold")

    @inline
    def live(model):
        p, _, _, _ = where(model)
        d = model.data
        bits = 0
        for k in range(LAW_GROUPS):
            if d[p + HOLD_PERIODS + k] == 0.0:
                bits |= 1 << k
        return bits

    @inline
    def due(model, t):
        p, _, _, _ = where(model)
        d = model.data
        bits = 0
        for k in range(LAW_GROUPS):
            period = d[p + HOLD_PERIODS + k]
            if period > 0.0 and on_clock(t, d[START], period):
                bits |= 1 << k
        return bits

    return live, due


def zero_order_hold(lane, direct):
    """``(held, hold)`` of the zero-order hold (the part ``"hold"``): ``held(model, y, j)`` the commands read from
    the state, and ``hold(model, t, y, j, commands...)`` that stores those of the laws (``direct``: their wheel
    commands)."""
    at, put, put3 = lane
    _, where = locator("hold")

    @inline
    def held(model, y, j):
        _, n, s, _ = where(model)
        return (at(y, s + HELD_TORQUE, j), at(y, s + HELD_TORQUE + 1, j), at(y, s + HELD_TORQUE + 2, j),
                at(y, s + HELD_DIPOLE, j), at(y, s + HELD_DIPOLE + 1, j), at(y, s + HELD_DIPOLE + 2, j),
                (WHEEL_HELD if n > 0 else NO_WHEEL_LAW, s + HELD_WHEELS, n, model.data))

    @inline
    def hold(model, t, y, j, u1, u2, u3, m1, m2, m3, source):
        _, n, s, _ = where(model)
        put3(y, s + HELD_TORQUE, j, u1, u2, u3)
        put3(y, s + HELD_DIPOLE, j, m1, m2, m3)
        for i in range(n):
            put(y, s + HELD_WHEELS + i, j, direct(model, t, y, j, i, source))

    return held, hold
