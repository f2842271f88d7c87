"""The spacecraft as a model for the integrators (see :mod:`tumble._protocol`): compiled equations.

State vector (``n_w`` wheels, ``n_g`` gyros; the thruster block only when
the spacecraft has thrusters)::

    [q (4), ω (3), h (n_w), δ (n_g), W, u_c (3), m_c (3), f (3), y (3), t_on (3)]

``q`` body → inertial; ``ω`` body rate, rad/s, body axes; ``h_i`` the
absolute angular momentum of wheel ``i`` about its axis ``a_i`` (N·m·s,
``h_i = I_s,i (a_i·ω + Ω_i)``, ``Ω_i`` its speed relative to the body);
``δ`` gimbal angles, rad; ``W`` the work done on the wheels by their motors
and bearings, J; ``u_c`` and ``m_c`` the controller's torque (N·m) and
dipole (A·m²) commands held between samples (zero-order hold only); ``f``,
``y``, ``t_on`` the PWPF filter outputs, trigger states (−1, 0, 1) and pulse
start times (s) of the three axes.

Equations (body axes; Hughes, *Spacecraft Attitude Dynamics*, §7.2;
Markley & Crassidis 2014, §3.3.5)::

    J_ω ω̇ = τ − ω × H − Σ a_i ḣ_i − Σ A_i δ̇_i
    H      = J_ω ω + Σ a_i h_i + Σ h_g,i s_i(δ_i)
    ḣ_i    = u_i − c_v Ω_i − c_c tanh(Ω_i / Ω_c)        Ẇ = Σ ḣ_i Ω_i
    q̇      = ½ q ⊗ [0, ω]

``J_ω = J − Σ I_s,i a_i a_iᵀ`` is the total inertia less the wheels' spin
inertias; ``A_i = h_g,i (g_i × s_i)`` is gyro ``i``'s torque column;
``τ`` the external and actuator torques (gravity gradient with the total
inertia ``J``, thrusters, magnetorquers ``m × B``). The command states have
zero derivative: :func:`_protocol.project` refreshes them at the sample times
(zero-order hold); a continuous controller is evaluated in the right-hand
side itself. The PWPF triggers switch in :func:`_protocol.project`, at the
sample times or, with continuous control, after every step.

Components a spacecraft lacks are ``None`` in :class:`SpacecraftModel`
(:mod:`tumble.spacecraft._params`); the overloads below then compile without
them, so they cost nothing.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit, types
from numba.extending import overload

from tumble import _protocol, _quat
from tumble._vec import clip, cross, matvec_flat, solve_symmetric
from tumble.spacecraft._params import (GYRO_STRIDE, ROUTE_MAGNETORQUERS, SAMPLE_TOLERANCE, THRUSTER_STRIDE,
                                       WHEEL_STRIDE, SpacecraftModel)
from tumble.spacecraft.environment import dipole_field, gravity_gradient_torque
from tumble.spacecraft.orbit import orbit_state

def _has(model, name: str) -> bool:
    """True when the field ``name`` of the (Numba) model type is not None."""
    return not isinstance(model.types[model.fields.index(name)], types.NoneType)


@functools.lru_cache(maxsize=None)
def _kernels(model, ndim):
    """Compile-time assembly of the right-hand side for the Numba type ``model`` of a SpacecraftModel.

    Returns ``(derivative, sample)``, which work on lane ``j`` of blocks (state × lanes, C order)
    when ``ndim`` is 2, or on state vectors (``j`` unused) when ``ndim`` is 1:
    ``derivative(model, t, y, j, out, aux, store)`` writes ``dy/dt`` into ``out[:, j]`` (and,
    when ``store``, the diagnostics of :func:`aux_layout` into ``aux[:, j]``);
    ``sample(model, t, y, j, hold)`` applies the discrete updates of the end of a step to
    ``y[:, j]`` in place. Both are inlined into their callers (a call would cost more than
    the equations). Cached per model type and ``ndim``, so that the right-hand side, the
    projection and the diagnostics share their kernels.
    """
    inline = njit(inline="always")
    has_cmg, has_thr = _has(model, "cmg"), _has(model, "thrusters")

    # ---- state access: lane j of a block (state × lanes), or a state vector (ndim 1, j unused) ----
    # scalar reads and writes only: a reshaped or sliced view would cost a helper call and
    # reference counting in every evaluation
    if ndim == 1:
        @inline
        def at(y, i, j):
            return y[i]

        @inline
        def put(y, i, j, value):
            y[i] = value
    else:
        @inline
        def at(y, i, j):
            return y[i, j]

        @inline
        def put(y, i, j, value):
            y[i, j] = value

    @inline
    def put3(y, i, j, v1, v2, v3):
        put(y, i, j, v1)
        put(y, i + 1, j, v2)
        put(y, i + 2, j, v3)

    # ---- environment: field in body axes, gravity-gradient torque ------------------------
    if _has(model, "dipole_field"):
        @inline
        def field(model, d, t, qw, qx, qy, qz):
            r = orbit_state(d[model.o_orbit:model.o_orbit + 7], t)
            b = dipole_field(t, r[0], r[1], r[2], d[model.o_field:model.o_field + 6])
            return _quat.qrotate_inv(qw, qx, qy, qz, b[0], b[1], b[2])
    elif _has(model, "uniform_field"):
        @inline
        def field(model, d, t, qw, qx, qy, qz):
            o = model.o_field
            return _quat.qrotate_inv(qw, qx, qy, qz, d[o], d[o + 1], d[o + 2])
    else:
        @inline
        def field(model, d, t, qw, qx, qy, qz):
            return 0.0, 0.0, 0.0

    if _has(model, "gravity_gradient"):
        @inline
        def gravity(model, d, t, qw, qx, qy, qz):
            o = model.o_orbit
            r = orbit_state(d[o:o + 7], t)
            r1, r2, r3 = _quat.qrotate_inv(qw, qx, qy, qz, r[0], r[1], r[2])
            return gravity_gradient_torque(d[o + 6], r1, r2, r3, d[0], d[4], d[8], d[1], d[2], d[5])
    else:
        @inline
        def gravity(model, d, t, qw, qx, qy, qz):
            return 0.0, 0.0, 0.0

    # ---- control laws ---------------------------------------------------------------------
    if _has(model, "pd"):
        @inline
        def attitude_law(model, d, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            o = model.o_pd
            ew, ex, ey, ez = _quat.qmul(d[o + 18], -d[o + 19], -d[o + 20], -d[o + 21], qw, qx, qy, qz)
            if ew < 0.0:
                ex, ey, ez = -ex, -ey, -ez
            c1, c2, c3 = matvec_flat(d, o + 9, -ex, -ey, -ez)
            rate = math.sqrt(c1 * c1 + c2 * c2 + c3 * c3)
            if rate > d[o + 22]:  # eigen-axis slew at the rate limit (Wie & Lu 1995)
                s = d[o + 22] / rate
                c1, c2, c3 = s * c1, s * c2, s * c3
            g1, g2, g3 = cross(w1, w2, w3, H1, H2, H3)
            u1, u2, u3 = matvec_flat(d, o, c1 - w1, c2 - w2, c3 - w3)
            k = d[o + 24]
            u1, u2, u3 = u1 + k * g1 + d[o + 25], u2 + k * g2 + d[o + 26], u3 + k * g3 + d[o + 27]
            big = max(abs(u1), abs(u2), abs(u3))
            if big > d[o + 23]:  # scale, keeping the direction
                s = d[o + 23] / big
                u1, u2, u3 = s * u1, s * u2, s * u3
            return u1, u2, u3
    else:
        @inline
        def attitude_law(model, d, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            return 0.0, 0.0, 0.0

    if _has(model, "bdot"):
        @inline
        def bdot_law(model, d, w1, w2, w3, b1, b2, b3):
            k = d[model.o_bdot]
            m1, m2, m3 = cross(w1, w2, w3, b1, b2, b3)
            return k * m1, k * m2, k * m3
    else:
        @inline
        def bdot_law(model, d, w1, w2, w3, b1, b2, b3):
            return 0.0, 0.0, 0.0

    if _has(model, "dumping"):
        @inline
        def dumping_law(model, d, h1, h2, h3, b1, b2, b3):
            k = d[model.o_dumping] / (b1 * b1 + b2 * b2 + b3 * b3)
            m1, m2, m3 = cross(h1, h2, h3, b1, b2, b3)
            return k * m1, k * m2, k * m3
    else:
        @inline
        def dumping_law(model, d, h1, h2, h3, b1, b2, b3):
            return 0.0, 0.0, 0.0

    # ---- control moment gyros -------------------------------------------------------------
    if has_cmg:
        @inline
        def cmg_momentum(model, d, y, j):
            o_g = 7 + model.n_wheels
            h1 = h2 = h3 = 0.0
            for i in range(model.n_gyros):
                b = model.o_cmg + 4 + GYRO_STRIDE * i
                cd, sd, h = math.cos(at(y, o_g + i, j)), math.sin(at(y, o_g + i, j)), d[b + 9]
                h1 += h * (cd * d[b + 3] + sd * d[b + 6])
                h2 += h * (cd * d[b + 4] + sd * d[b + 7])
                h3 += h * (cd * d[b + 5] + sd * d[b + 8])
            return h1, h2, h3

        @inline
        def cmg_torque(model, d, y, j, out, u1, u2, u3, aux, store):
            """Steering ``δ̇ = A#(−u)`` with the singularity-robust inverse; returns ``−A δ̇``."""
            o_g, law = 7 + model.n_wheels, model.o_cmg
            m00 = m01 = m02 = m11 = m12 = m22 = 0.0
            for i in range(model.n_gyros):  # A Aᵀ, columns A_i = h (cos δ t0 − sin δ s0)
                b = law + 4 + GYRO_STRIDE * i
                cd, sd, h = math.cos(at(y, o_g + i, j)), math.sin(at(y, o_g + i, j)), d[b + 9]
                x1 = h * (cd * d[b + 6] - sd * d[b + 3])
                x2 = h * (cd * d[b + 7] - sd * d[b + 4])
                x3 = h * (cd * d[b + 8] - sd * d[b + 5])
                m00 += x1 * x1
                m01 += x1 * x2
                m02 += x1 * x3
                m11 += x2 * x2
                m12 += x2 * x3
                m22 += x3 * x3
            hb2 = d[law + 2] * d[law + 2]
            det = (m00 * (m11 * m22 - m12 * m12) - m01 * (m01 * m22 - m12 * m02)
                   + m02 * (m01 * m12 - m11 * m02)) / (hb2 * hb2 * hb2)
            lam = d[law] * math.exp(-d[law + 1] * det) * hb2
            x1, x2, x3 = solve_symmetric(m00 + lam, m01, m02, m11 + lam, m12, m22 + lam, -u1, -u2, -u3)
            t1 = t2 = t3 = 0.0
            nw = model.n_wheels
            for i in range(model.n_gyros):
                b = law + 4 + GYRO_STRIDE * i
                cd, sd, h = math.cos(at(y, o_g + i, j)), math.sin(at(y, o_g + i, j)), d[b + 9]
                a1 = h * (cd * d[b + 6] - sd * d[b + 3])
                a2 = h * (cd * d[b + 7] - sd * d[b + 4])
                a3 = h * (cd * d[b + 8] - sd * d[b + 5])
                rate = clip(a1 * x1 + a2 * x2 + a3 * x3, d[law + 3])
                put(out, o_g + i, j, rate)
                t1 -= a1 * rate
                t2 -= a2 * rate
                t3 -= a3 * rate
                if store:
                    put(aux, 3 * nw + i, j, rate)
            if store:
                put(aux, 3 * nw + model.n_gyros, j, math.sqrt(max(det, 0.0)))
            return t1, t2, t3
    else:
        @inline
        def cmg_momentum(model, d, y, j):
            return 0.0, 0.0, 0.0

        @inline
        def cmg_torque(model, d, y, j, out, u1, u2, u3, aux, store):
            return 0.0, 0.0, 0.0

    # ---- thrusters and their PWPF modulators ----------------------------------------------
    if has_thr:
        @inline
        def thruster_torque(model, d, y, j, out, o_p, u1, u2, u3):
            """Torque of the firing thrusters; writes the PWPF filter rates ``ḟ``."""
            p = model.o_thrusters
            km, tm = d[p], d[p + 1]
            put(out, o_p, j, (km * (u1 / d[p + 5] - at(y, o_p + 3, j)) - at(y, o_p, j)) / tm)
            put(out, o_p + 1, j, (km * (u2 / d[p + 6] - at(y, o_p + 4, j)) - at(y, o_p + 1, j)) / tm)
            put(out, o_p + 2, j, (km * (u3 / d[p + 7] - at(y, o_p + 5, j)) - at(y, o_p + 2, j)) / tm)
            for k in range(6):
                put(out, o_p + 3 + k, j, 0.0)
            t1 = t2 = t3 = 0.0
            for i in range(model.n_thrusters):
                b = p + 8 + THRUSTER_STRIDE * i
                if at(y, o_p + 3 + int(d[b + 3]), j) == d[b + 4]:
                    t1 += d[b]
                    t2 += d[b + 1]
                    t3 += d[b + 2]
            return t1, t2, t3

        @inline
        def trigger(model, d, t, y, j, o_p):
            """Schmitt triggers with a minimum on-time, at a sample time ``t``."""
            p = model.o_thrusters
            for k in range(3):
                f, state, start = at(y, o_p + k, j), at(y, o_p + 3 + k, j), at(y, o_p + 6 + k, j)
                if state == 0.0:
                    if abs(f) > d[p + 2]:
                        put(y, o_p + 3 + k, j, 1.0 if f > 0.0 else -1.0)
                        put(y, o_p + 6 + k, j, t)
                elif state * f < d[p + 3] and t - start >= d[p + 4] * (1.0 - SAMPLE_TOLERANCE):
                    put(y, o_p + 3 + k, j, 0.0)
    else:
        @inline
        def thruster_torque(model, d, y, j, out, o_p, u1, u2, u3):
            return 0.0, 0.0, 0.0

        @inline
        def trigger(model, d, t, y, j, o_p):
            pass

    if _has(model, "magnetorquers"):
        @inline
        def magnetic_torque(model, d, m1, m2, m3, b1, b2, b3):
            o = model.o_dipole
            m1, m2, m3 = clip(m1, d[o]), clip(m2, d[o + 1]), clip(m3, d[o + 2])
            t1, t2, t3 = cross(m1, m2, m3, b1, b2, b3)
            return t1, t2, t3, m1, m2, m3
    else:
        @inline
        def magnetic_torque(model, d, m1, m2, m3, b1, b2, b3):
            return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0

    # ---- momenta and commands -------------------------------------------------------------
    @inline
    def momenta(model, d, y, j):
        """(H, h_wheels): total and wheel angular momentum, body axes, N·m·s."""
        H1, H2, H3 = matvec_flat(d, 9, at(y, 4, j), at(y, 5, j), at(y, 6, j))
        h1 = h2 = h3 = 0.0
        for i in range(model.n_wheels):
            b = model.o_wheels + WHEEL_STRIDE * i
            h1 += d[b] * at(y, 7 + i, j)
            h2 += d[b + 1] * at(y, 7 + i, j)
            h3 += d[b + 2] * at(y, 7 + i, j)
        c1, c2, c3 = cmg_momentum(model, d, y, j)
        return H1 + h1 + c1, H2 + h2 + c2, H3 + h3 + c3, h1, h2, h3

    @inline
    def command(model, d, t, y, j, H1, H2, H3, h1, h2, h3, b1, b2, b3):
        """The controller's torque (N·m) and dipole (A·m²) commands, body axes."""
        u1, u2, u3 = attitude_law(model, d, at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j),
                                  at(y, 4, j), at(y, 5, j), at(y, 6, j), H1, H2, H3)
        m1, m2, m3 = bdot_law(model, d, at(y, 4, j), at(y, 5, j), at(y, 6, j), b1, b2, b3)
        e1, e2, e3 = dumping_law(model, d, h1, h2, h3, b1, b2, b3)
        m1, m2, m3 = m1 + e1, m2 + e2, m3 + e3
        if d[29] == ROUTE_MAGNETORQUERS:  # m = B × u / |B|²: the part of u normal to B
            k = 1.0 / (b1 * b1 + b2 * b2 + b3 * b3)
            e1, e2, e3 = cross(b1, b2, b3, u1, u2, u3)
            m1, m2, m3 = m1 + k * e1, m2 + k * e2, m3 + k * e3
        return u1, u2, u3, m1, m2, m3

    # ---- the right-hand side -----------------------------------------------------------------
    @inline
    def derivative(model, t, y, j, out, aux, store):
        d = model.data
        nw = model.n_wheels
        o_w = 7 + nw + model.n_gyros
        o_c = o_w + 1
        qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
        w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
        H1, H2, H3, h1, h2, h3 = momenta(model, d, y, j)
        b1, b2, b3 = field(model, d, t, qw, qx, qy, qz)
        if d[27] > 0.0:  # zero-order hold: the commands held in the state
            u1, u2, u3 = at(y, o_c, j), at(y, o_c + 1, j), at(y, o_c + 2, j)
            m1, m2, m3 = at(y, o_c + 3, j), at(y, o_c + 4, j), at(y, o_c + 5, j)
        else:
            u1, u2, u3, m1, m2, m3 = command(model, d, t, y, j, H1, H2, H3, h1, h2, h3, b1, b2, b3)
        if store:
            s = 3 * nw + model.n_gyros + (1 if has_cmg else 0) + 12
            put3(aux, s, j, u1, u2, u3)
            put3(aux, s + 3, j, m1, m2, m3)
        t1 = t2 = t3 = 0.0
        power = 0.0
        for i in range(nw):  # reaction wheels
            b = model.o_wheels + WHEEL_STRIDE * i
            a1, a2, a3 = d[b], d[b + 1], d[b + 2]
            speed = at(y, 7 + i, j) / d[b + 3] - (a1 * w1 + a2 * w2 + a3 * w3)
            motor = clip(-(d[b + 9] * u1 + d[b + 10] * u2 + d[b + 11] * u3), d[b + 4])
            saturated = abs(speed) >= d[b + 5] and motor * speed > 0.0
            if saturated:
                motor = 0.0
            hdot = motor - d[b + 6] * speed
            if d[b + 7] != 0.0:  # Coulomb friction, smoothed
                hdot -= d[b + 7] * math.tanh(speed / d[b + 8])
            put(out, 7 + i, j, hdot)
            t1 -= a1 * hdot
            t2 -= a2 * hdot
            t3 -= a3 * hdot
            power += hdot * speed
            if store:
                put(aux, i, j, speed)
                put(aux, nw + i, j, motor)
                put(aux, 2 * nw + i, j, 1.0 if saturated else 0.0)
        c1, c2, c3 = cmg_torque(model, d, y, j, out, u1, u2, u3, aux, store)
        r1, r2, r3 = thruster_torque(model, d, y, j, out, o_c + 6, u1, u2, u3)
        n1, n2, n3, m1, m2, m3 = magnetic_torque(model, d, m1, m2, m3, b1, b2, b3)
        g1, g2, g3 = gravity(model, d, t, qw, qx, qy, qz)
        x1, x2, x3 = t1 + c1 + r1 + n1, t2 + c2 + r2 + n2, t3 + c3 + r3 + n3
        k1, k2, k3 = cross(w1, w2, w3, H1, H2, H3)
        a1, a2, a3 = matvec_flat(d, 18, x1 + g1 - k1, x2 + g2 - k2, x3 + g3 - k3)
        e = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
        put(out, 0, j, 0.5 * e[0])
        put3(out, 1, j, 0.5 * e[1], 0.5 * e[2], 0.5 * e[3])
        put3(out, 4, j, a1, a2, a3)
        put(out, o_w, j, power)
        for k in range(6):
            put(out, o_c + k, j, 0.0)
        if store:
            s = 3 * nw + model.n_gyros + (1 if has_cmg else 0)
            put3(aux, s, j, m1, m2, m3)
            put3(aux, s + 3, j, b1, b2, b3)
            put3(aux, s + 6, j, g1, g2, g3)
            put3(aux, s + 9, j, x1, x2, x3)

    @inline
    def sample(model, t, y, j, hold):
        """Discrete updates at the end of a step: with ``hold`` (a sample time of a zero-order hold),
        the held commands; then the PWPF triggers."""
        d = model.data
        o_c = 8 + model.n_wheels + model.n_gyros
        if hold:
            H1, H2, H3, h1, h2, h3 = momenta(model, d, y, j)
            b1, b2, b3 = field(model, d, t, at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j))
            u1, u2, u3, m1, m2, m3 = command(model, d, t, y, j, H1, H2, H3, h1, h2, h3, b1, b2, b3)
            put3(y, o_c, j, u1, u2, u3)
            put3(y, o_c + 3, j, m1, m2, m3)
        trigger(model, d, t, y, j, o_c + 6)

    return derivative, sample


def _is_spacecraft(model):
    return _protocol.is_type(model, SpacecraftModel)


@overload(_protocol.rhs, jit_options={"cache": True})
def _spacecraft_rhs(model, b0, t, Y, OUT):
    if not _is_spacecraft(model):
        return None
    derivative, _ = _kernels(model, Y.ndim)
    if Y.ndim == 1:
        def impl(model, b0, t, Y, OUT):
            derivative(model, t, Y, 0, OUT, Y, False)
    else:
        def impl(model, b0, t, Y, OUT):
            for j in range(Y.shape[1]):
                derivative(model, t, Y, j, OUT, Y, False)
    return impl


@overload(_protocol.project, jit_options={"cache": True})
def _spacecraft_project(model, b0, t, Y):
    if not _is_spacecraft(model):
        return None
    _, sample = _kernels(model, Y.ndim)
    # with continuous control only the PWPF triggers sample after every step: without
    # thrusters the projection is the normalisation alone
    continuous_updates = _has(model, "thrusters")
    if Y.ndim == 1:
        normalize, lanes = _protocol.normalize_quaternion, njit(inline="always")(lambda Y: 1)
    else:
        normalize, lanes = _protocol.normalize_quaternions, njit(inline="always")(lambda Y: Y.shape[1])

    def impl(model, b0, t, Y):
        normalize(Y)
        period = model.data[27]
        if period > 0.0:
            start = model.data[28]
            k = round((t - start) / period)
            if abs(t - start - k * period) <= SAMPLE_TOLERANCE * period:
                for j in range(lanes(Y)):
                    sample(model, t, Y, j, True)
        elif continuous_updates:
            for j in range(lanes(Y)):
                sample(model, t, Y, j, False)
    return impl


@overload(_protocol.state_size, jit_options={"cache": True})
def _spacecraft_state_size(model):
    if not _is_spacecraft(model):
        return None
    extra = 9 if _has(model, "thrusters") else 0

    def impl(model):
        return 14 + model.n_wheels + model.n_gyros + extra

    return impl


@overload(_protocol.body_rate, inline="always", jit_options={"cache": True})
def _spacecraft_body_rate(model, Y, j):
    if not _is_spacecraft(model):
        return None
    return _protocol.rate_at(4, Y)


def _evaluate(model, t, y, aux):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_evaluate, jit_options={"cache": True})
def _evaluate_overload(model, t, y, aux):
    derivative, _ = _kernels(model, 1)

    def impl(model, t, y, aux):
        out = np.empty(y.shape[1])
        for k in range(y.shape[0]):
            derivative(model, t[k], y[k], 0, out, aux[k], True)

    return impl


def _sample(model, t, y):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_sample, jit_options={"cache": True})
def _sample_overload(model, t, y):
    _, sample = _kernels(model, 1)
    return lambda model, t, y: sample(model, t, y, 0, True)


@njit(cache=True)
def evaluate(model, t, y, aux):
    """Diagnostics of the samples ``y`` (n, state) at the times ``t`` (n,) into ``aux`` (n, aux size)."""
    _evaluate(model, t, y, aux)


@njit(cache=True)
def initialise(model, t, y):
    """Apply the discrete updates of the start time ``t`` to the state vector ``y`` (held commands, triggers)."""
    _sample(model, t, y)
