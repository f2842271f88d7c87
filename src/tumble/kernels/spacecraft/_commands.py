"""Compile-time assembly of the controller: the commands of the control laws present (:mod:`.laws`), evaluated
in the right-hand side or held by a zero-order hold.

Every function here runs when Numba compiles a spacecraft model type and returns compiled (inlined) functions
of the model, its layout ``L`` (:func:`tumble.kernels.spacecraft._layout.loader`) and one member's state.
"""

from __future__ import annotations

import numpy as np

from tumble._vec import cross, matvec_flat
from tumble.kernels.spacecraft import laws, wheels
from tumble.kernels.spacecraft._base import inline
from tumble.kernels.spacecraft._layout import HELD_DIPOLE, HELD_TORQUE, HELD_WHEELS, J_RATE, PARTS, locator

# Absent laws: compiled to nothing (Numba's inliner takes no *args, so one per signature).
no_torque_law = inline(lambda model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3: (0.0, 0.0, 0.0))
no_dipole = inline(lambda model, L, y, j, w1, w2, w3, b1, b2, b3: (0.0, 0.0, 0.0))
no_source = inline(lambda model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3: 0.0)
no_direct = inline(lambda model, t, y, j, i, source: 0.0)


def make_speeds(has, lane):
    """``speeds(model, L, y, j, ω) -> array`` of the wheel speeds Ω_i (rad/s; empty without wheels), for Python laws."""
    at = lane.at
    if not has["wheels"]:
        return inline(lambda model, L, y, j, w1, w2, w3: np.empty(0))
    where = locator(has, "wheels")

    @inline
    def speeds(model, L, y, j, w1, w2, w3):
        p, n, s, _ = where(L)
        out = np.empty(n)
        for i in range(n):
            b = p + wheels.STRIDE * i
            out[i] = wheels.speed(model.data, b, at(y, s + wheels.MOMENTUM + i, j), w1, w2, w3)
        return out

    return speeds


def make_torque_law(has, lane, speeds):
    """``law(model, L, t, y, j, q, ω, H) -> u_c`` (N·m, body axes) of the torque law present (zero without one)."""
    at = lane.at
    if has["pd"]:
        where = locator(has, "pd")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            return laws.pd_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3)
    elif has["mrp"] and has["mrp_integral"]:
        where, where_i = locator(has, "mrp"), locator(has, "mrp_integral")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            pi, _, s, _ = where_i(L)
            d = model.data
            k, ki = d[p + laws.MRP_K], d[pi + laws.MRP_KI]
            # v = K_I z,  z = K ∫σ dt + J_ω ω
            z1, z2, z3 = matvec_flat(d, J_RATE, w1, w2, w3)
            v1 = ki * (k * at(y, s + laws.INTEGRAL, j) + z1)
            v2 = ki * (k * at(y, s + laws.INTEGRAL + 1, j) + z2)
            v3 = ki * (k * at(y, s + laws.INTEGRAL + 2, j) + z3)
            return laws.mrp_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, v1, v2, v3)
    elif has["mrp"]:
        where = locator(has, "mrp")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            return laws.mrp_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, 0.0, 0.0, 0.0)
    elif has["python_law"]:
        where = locator(has, "python_law")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            u = laws.call_python(int(model.data[p + laws.SLOT]), t, qw, qx, qy, qz, w1, w2, w3,
                                 speeds(model, L, y, j, w1, w2, w3), 3)
            return u[0], u[1], u[2]
    else:
        law = no_torque_law
    return law


def make_dipole_law(has, lane):
    """``law(model, L, y, j, ω, B) -> m_c`` (A·m², body axes): the sum of the dipole laws present."""
    bdot = dumping = no_dipole
    if has["bdot"]:
        where_b = locator(has, "bdot")

        @inline
        def bdot(model, L, y, j, w1, w2, w3, b1, b2, b3):
            p, _, _, _ = where_b(L)
            return laws.bdot_dipole(model, p, w1, w2, w3, b1, b2, b3)
    if has["dumping"]:
        where_d, where_w = locator(has, "dumping"), locator(has, "wheels")
        wheel_momentum = wheels.kernel(lane, no_direct).momentum

        @inline
        def dumping(model, L, y, j, w1, w2, w3, b1, b2, b3):
            p, _, _, _ = where_d(L)
            pw, nw, sw, _ = where_w(L)
            h1, h2, h3 = wheel_momentum(model, pw, nw, sw, y, j)
            return laws.dumping_dipole(model, p, h1, h2, h3, b1, b2, b3)

    @inline
    def law(model, L, y, j, w1, w2, w3, b1, b2, b3):
        m1, m2, m3 = bdot(model, L, y, j, w1, w2, w3, b1, b2, b3)
        e1, e2, e3 = dumping(model, L, y, j, w1, w2, w3, b1, b2, b3)
        return m1 + e1, m2 + e2, m3 + e3

    return law


def make_wheel_law(has, speeds):
    """``(source, direct)``: ``source(model, L, t, y, j, q, ω)`` evaluates the motor-torque law once per
    evaluation of the commands, ``direct(model, t, y, j, i, source)`` is wheel ``i``'s command (N·m)."""
    if has["wheel_table"]:
        where, where_w = locator(has, "wheel_table"), locator(has, "wheels")

        @inline
        def source(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3):
            p, _, _, _ = where(L)
            _, nw, _, _ = where_w(L)
            return p, nw

        @inline
        def direct(model, t, y, j, i, source):
            return laws.wheel_table(model, source[0], source[1], t, i)

        return source, direct
    if has["wheel_python"]:
        where, where_w = locator(has, "wheel_python"), locator(has, "wheels")

        @inline
        def source(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3):
            p, _, _, _ = where(L)
            _, nw, _, _ = where_w(L)
            return laws.call_python(int(model.data[p + laws.SLOT]), t, qw, qx, qy, qz, w1, w2, w3,
                                    speeds(model, L, y, j, w1, w2, w3), nw)

        @inline
        def direct(model, t, y, j, i, source):
            return source[i]

        return source, direct
    return no_source, no_direct


def controller(has, lane):
    """``(commands, direct)``: ``commands(model, L, t, y, j, q, ω, H, B) -> (u_c, m_c, source)`` of the control
    laws as evaluated now, and the wheels' ``direct`` commands for that ``source``."""
    speeds = make_speeds(has, lane)
    torque_law, dipole_law = make_torque_law(has, lane, speeds), make_dipole_law(has, lane)
    source, direct = make_wheel_law(has, speeds)
    to_dipole = has["magnetorquers"]
    magnetorquers_index = PARTS.index("magnetorquers")

    @inline
    def commands(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, b1, b2, b3):
        u1, u2, u3 = torque_law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3)
        m1, m2, m3 = dipole_law(model, L, y, j, w1, w2, w3, b1, b2, b3)
        if to_dipole and model.route == magnetorquers_index:  # m = B × u/|B|²: the part of u normal to B
            k = 1.0 / (b1 * b1 + b2 * b2 + b3 * b3)
            e1, e2, e3 = cross(b1, b2, b3, u1, u2, u3)
            m1, m2, m3 = m1 + k * e1, m2 + k * e2, m3 + k * e3
        return u1, u2, u3, m1, m2, m3, source(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3)

    return commands, direct


def zero_order_hold(has, lane, direct):
    """``(commands, direct, hold)`` of a zero-order hold: the held commands read from the state, and
    ``hold(model, L, t, y, j, commands...)`` that stores those of the laws (``direct``: their wheel commands)."""
    at, put, put3 = lane
    where = locator(has, "hold")
    wheel_commands = has["wheel_table"] or has["wheel_python"]

    @inline
    def commands(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, b1, b2, b3):
        _, _, s, _ = where(L)
        return (at(y, s + HELD_TORQUE, j), at(y, s + HELD_TORQUE + 1, j), at(y, s + HELD_TORQUE + 2, j),
                at(y, s + HELD_DIPOLE, j), at(y, s + HELD_DIPOLE + 1, j), at(y, s + HELD_DIPOLE + 2, j),
                s + HELD_WHEELS)

    if wheel_commands:
        held_direct = inline(lambda model, t, y, j, i, source: at(y, source + i, j))
    else:
        held_direct = no_direct

    @inline
    def hold(model, L, t, y, j, u1, u2, u3, m1, m2, m3, source):
        _, n, s, _ = where(L)
        put3(y, s + HELD_TORQUE, j, u1, u2, u3)
        put3(y, s + HELD_DIPOLE, j, m1, m2, m3)
        for i in range(n):
            put(y, s + HELD_WHEELS + i, j, direct(model, t, y, j, i, source))

    return commands, held_direct, hold
