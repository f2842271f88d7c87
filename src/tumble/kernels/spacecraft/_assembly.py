"""Compile-time assembly of the spacecraft's right-hand side and discrete updates from the parts present.

:func:`assemble` runs when Numba compiles a spacecraft model type (cached per type and state ``ndim``): it
sums the actuators' compiled functions (:class:`~tumble.kernels.spacecraft._base.Actuator`) over the parts
present, adds the environment and the controller (:mod:`._commands`), and returns the inlined
``derivative`` and ``sample`` that the protocol overloads of :mod:`tumble.kernels.spacecraft` call.
"""

from __future__ import annotations

import functools

from numba import njit, types

from tumble import _quat, torques
from tumble._vec import cross, matvec_flat
from tumble.kernels.spacecraft import _commands, cmgs, damper, environment, laws, magnetorquers, thrusters, wheels
from tumble.kernels.spacecraft._base import inline, lane, no_sample
from tumble.kernels.spacecraft._layout import (AUX_ACTUATOR, AUX_DIPOLE_COMMAND, AUX_ENERGY, AUX_EXTERNAL, AUX_FIELD,
                                               AUX_GRAVITY, AUX_MOMENTUM, AUX_TORQUE_COMMAND, HELD_WHEELS, J,
                                               J_RATE, J_RATE_INV, PARTS, loader, locator, present)

#: The actuators (parts that carry momentum or exert torque) and their compiled functions, for a state access
#: (:func:`~tumble.kernels.spacecraft._base.lane`) and the motor torques commanded directly to the wheels (a
#: function of the wheel-torque law, :func:`tumble.kernels.spacecraft._commands.controller`).
ACTUATORS = {
    "wheels": wheels.kernel,
    "cmgs": lambda lane, direct: cmgs.kernel(lane),
    "thrusters": lambda lane, direct: thrusters.kernel(lane),
    "magnetorquers": lambda lane, direct: magnetorquers.kernel(lane),
    "damper": lambda lane, direct: damper.kernel(lane),
}

# Absent pieces: compiled to nothing (Numba's inliner takes no *args, so one per signature).
_no_momenta = inline(lambda model, L, y, j: (0.0, 0.0, 0.0))
_no_energy = inline(lambda model, L, y, j: 0.0)
_no_torques = inline(lambda model, L, t, y, j, out, aux, store, w1, w2, w3, cmd: (0.0, 0.0, 0.0))
_no_samples = inline(lambda model, L, t, y, j: None)
_no_field = inline(lambda model, L, t, qw, qx, qy, qz: (0.0, 0.0, 0.0))
_no_external = inline(lambda model, L, t, qw, qx, qy, qz, w1, w2, w3: (0.0, 0.0, 0.0))
_no_law_rates = inline(lambda model, L, t, y, j, out, qw, qx, qy, qz: None)
_no_hold_rates = inline(lambda model, L, out, j: None)


def _sum_momenta(parts):
    """``Σ h_k`` (N·m·s) of the actuators ``parts`` [(kind index, where, Actuator)]."""
    total = _no_momenta
    for _, where, part in parts:
        total = _add_momentum(total, where, part.momentum)
    return total


def _add_momentum(previous, where, momentum):
    @inline
    def total(model, L, y, j):
        a1, a2, a3 = previous(model, L, y, j)
        p, n, s, _ = where(L)
        b1, b2, b3 = momentum(model, p, n, s, y, j)
        return a1 + b1, a2 + b2, a3 + b3

    return total


def _sum_energies(parts):
    total = _no_energy
    for _, where, part in parts:
        total = _add_energy(total, where, part.energy)
    return total


def _add_energy(previous, where, energy):
    @inline
    def total(model, L, y, j):
        p, n, s, _ = where(L)
        return previous(model, L, y, j) + energy(model, p, n, s, y, j)

    return total


def _sum_torques(parts):
    """``Σ τ_k`` (N·m) of the actuators, each writing its state derivatives and diagnostics."""
    total = _no_torques
    for k, where, part in parts:
        total = _add_torque(total, k, where, part.act)
    return total


def _add_torque(previous, k, where, act):
    @inline
    def total(model, L, t, y, j, out, aux, store, w1, w2, w3, cmd):
        a1, a2, a3 = previous(model, L, t, y, j, out, aux, store, w1, w2, w3, cmd)
        p, n, s, a = where(L)
        b1, b2, b3 = act(model, p, n, s, a, model.route == k, t, y, j, out, aux, store, w1, w2, w3, cmd)
        return a1 + b1, a2 + b2, a3 + b3

    return total


def _sample_all(parts):
    """The discrete updates of the actuators that have some, or None."""
    total = None
    for _, where, part in parts:
        if part.sample is not no_sample:
            total = _add_sample(_no_samples if total is None else total, where, part.sample)
    return total


def _add_sample(previous, where, sample):
    @inline
    def total(model, L, t, y, j):
        previous(model, L, t, y, j)
        p, n, s, _ = where(L)
        sample(model, p, n, s, t, y, j)

    return total


def _environment(model, has):
    """``field(model, L, t, q) -> B`` (T, body axes), ``gravity(model, L, t, q) -> τ_gg`` and
    ``external(model, L, t, q, ω) -> τ`` (the torque program), N·m, body axes."""
    if has["dipole_field"] or has["uniform_field"]:
        kind = "dipole_field" if has["dipole_field"] else "uniform_field"
        body_field = environment.dipole_body if has["dipole_field"] else environment.uniform_body
        where_field = locator(has, kind)

        @inline
        def field(model, L, t, qw, qx, qy, qz):
            p, _, _, _ = where_field(L)
            return body_field(model, p, t, qw, qx, qy, qz)
    else:
        field = _no_field

    if has["gravity_gradient"]:
        where_gg = locator(has, "gravity_gradient")

        @inline
        def gravity(model, L, t, qw, qx, qy, qz):
            p, _, _, _ = where_gg(L)
            return environment.gravity_gradient(model, p, J, t, qw, qx, qy, qz)
    else:
        gravity = _no_field

    if isinstance(model.types[model.fields.index("torque_codes")], types.NoneType):
        external = _no_external
    else:
        @inline
        def external(model, L, t, qw, qx, qy, qz, w1, w2, w3):
            return torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, model.torque_params, 0, model.torque_codes)

    return field, gravity, external


@functools.lru_cache(maxsize=None)
def assemble(model, ndim):
    """Compile-time assembly for the Numba type ``model`` of a SpacecraftModel and states of ``ndim``:
    ``(derivative, sample, discrete)``. ``derivative(model, t, y, j, out, aux, store)`` writes ``dy/dt`` of
    the member in lane ``j`` of the block ``y`` (or of the state vector ``y``, ``ndim`` 1) into ``out`` and,
    when ``store``, its diagnostics into ``aux``; ``sample(model, t, y, j)`` applies the discrete updates of
    a sample time (the held commands, the PWPF triggers); ``discrete``: what :func:`tumble._protocol.project`
    must do besides normalising the quaternion (``"hold"``: sample at the sample times; ``"step"``: after
    every step; None). Cached, so that the right-hand side, the projection and the diagnostics share it."""
    has = present(model)
    load = loader(model)
    access = lane(ndim)
    at, put, put3 = access
    law_commands, law_direct = _commands.controller(has, access)
    if has["hold"]:
        commands, direct, hold = _commands.zero_order_hold(has, access, law_direct)
        where_hold = locator(has, "hold")
    else:
        commands, direct = law_commands, law_direct
    actuators = [(PARTS.index(kind), locator(has, kind), ACTUATORS[kind](access, direct))
                 for kind in ACTUATORS if has[kind]]
    momenta, energies = _sum_momenta(actuators), _sum_energies(actuators)
    torques_on_hub, sample_parts = _sum_torques(actuators), _sample_all(actuators)
    discrete = None if sample_parts is None else "step"
    sample_parts = _no_samples if sample_parts is None else sample_parts
    field, gravity, external = _environment(model, has)

    if has["mrp_integral"]:
        where_mrp, where_int = locator(has, "mrp"), locator(has, "mrp_integral")

        @inline
        def law_rates(model, L, t, y, j, out, qw, qx, qy, qz):
            """d/dt ∫σ dt = σ, continuous also under a zero-order hold."""
            p, _, _, _ = where_mrp(L)
            _, _, s, _ = where_int(L)
            s1, s2, s3 = laws.attitude_error(model, p, qw, qx, qy, qz)
            put3(out, s + laws.INTEGRAL, j, s1, s2, s3)
    else:
        law_rates = _no_law_rates

    if has["hold"]:
        @inline
        def hold_rates(model, L, out, j):
            _, n, s, _ = where_hold(L)
            for i in range(HELD_WHEELS + n):
                put(out, s + i, j, 0.0)
    else:
        hold_rates = _no_hold_rates

    # Not inlined: one compiled function that the right-hand side and the diagnostics
    # (:func:`tumble.kernels.spacecraft.evaluate`) share, so that a model type compiles it once.
    @njit
    def derivative(model, t, y, j, out, aux, store):
        d = model.data
        L = load(model)
        qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
        w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
        H1, H2, H3 = matvec_flat(d, J_RATE, w1, w2, w3)
        h1, h2, h3 = momenta(model, L, y, j)
        H1, H2, H3 = H1 + h1, H2 + h2, H3 + h3
        b1, b2, b3 = field(model, L, t, qw, qx, qy, qz)
        u1, u2, u3, m1, m2, m3, source = commands(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3,
                                                  b1, b2, b3)
        x1, x2, x3 = torques_on_hub(model, L, t, y, j, out, aux, store, w1, w2, w3,
                                    (u1, u2, u3, m1, m2, m3, b1, b2, b3, source))
        g1, g2, g3 = gravity(model, L, t, qw, qx, qy, qz)
        e1, e2, e3 = external(model, L, t, qw, qx, qy, qz, w1, w2, w3)
        k1, k2, k3 = cross(w1, w2, w3, H1, H2, H3)
        a1, a2, a3 = matvec_flat(d, J_RATE_INV, x1 + g1 + e1 - k1, x2 + g2 + e2 - k2, x3 + g3 + e3 - k3)
        r = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
        put(out, 0, j, 0.5 * r[0])
        put3(out, 1, j, 0.5 * r[1], 0.5 * r[2], 0.5 * r[3])
        put3(out, 4, j, a1, a2, a3)
        law_rates(model, L, t, y, j, out, qw, qx, qy, qz)
        hold_rates(model, L, out, j)
        if store:
            c1, c2, c3 = matvec_flat(d, J_RATE, w1, w2, w3)
            put(aux, AUX_ENERGY, j, 0.5 * (w1 * c1 + w2 * c2 + w3 * c3) + energies(model, L, y, j))
            put3(aux, AUX_MOMENTUM, j, H1, H2, H3)
            put3(aux, AUX_TORQUE_COMMAND, j, u1, u2, u3)
            put3(aux, AUX_DIPOLE_COMMAND, j, m1, m2, m3)
            put3(aux, AUX_FIELD, j, b1, b2, b3)
            put3(aux, AUX_GRAVITY, j, g1, g2, g3)
            put3(aux, AUX_ACTUATOR, j, x1, x2, x3)
            put3(aux, AUX_EXTERNAL, j, e1, e2, e3)

    if has["hold"]:
        @inline
        def sample(model, t, y, j):
            L = load(model)
            qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
            w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
            H1, H2, H3 = matvec_flat(model.data, J_RATE, w1, w2, w3)
            h1, h2, h3 = momenta(model, L, y, j)
            b1, b2, b3 = field(model, L, t, qw, qx, qy, qz)
            u1, u2, u3, m1, m2, m3, source = law_commands(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3,
                                                          H1 + h1, H2 + h2, H3 + h3, b1, b2, b3)
            hold(model, L, t, y, j, u1, u2, u3, m1, m2, m3, source)
            sample_parts(model, L, t, y, j)

        discrete = "hold"
    else:
        @inline
        def sample(model, t, y, j):
            sample_parts(model, load(model), t, y, j)
    return derivative, sample, discrete
