"""Compile-time assembly of the spacecraft's right-hand side and discrete updates over every kind of part.

:func:`assemble` runs once per state ``ndim`` when Numba compiles the spacecraft model type: it chains the
actuators' compiled functions (:class:`~tumble.kernels.spacecraft._base.Actuator`) over every kind of part,
each behind its runtime presence test (:func:`~tumble.kernels.spacecraft._layout.locator`), adds the
environment and the controller (:mod:`._commands`), and returns the ``derivative`` and ``sample`` that the
protocol overloads of :mod:`tumble.kernels.spacecraft` call. Which parts a spacecraft has is data: a new
composition runs the same compiled code.
"""

from __future__ import annotations

import functools

from numba import njit

from tumble import _quat, torques
from tumble._vec import cross, matvec_flat, solve_symmetric
from tumble.kernels.spacecraft import (_commands, cmgs, damper, drag, environment, environment_table,
                                      flexible_modes, flight_software, laws, magnetorquers, residual_dipole,
                                      slosh, solar_pressure, thrusters, wheels)
from tumble.kernels.spacecraft._base import (inline, lane, no_added_inertia, no_energy, no_finish, no_momentum,
                                             no_project, no_sample)
from tumble.kernels.spacecraft._layout import (AUX_ACTUATOR, AUX_DIPOLE_COMMAND, AUX_ENERGY, AUX_EXTERNAL, AUX_FIELD,
                                               AUX_GRAVITY, AUX_MOMENTUM, AUX_TORQUE_COMMAND, HELD_TORQUE,
                                               HELD_WHEELS, J,
                                               J_RATE, J_RATE_INV, PARTS, PERIOD, START, locator)

#: The discrete updates due at a step end, besides the law groups due (bits of ``_commands.ALL_LAWS``): a sample
#: time of ``control_period`` (the flight software's estimate), and the parts' own updates (the PWPF triggers).
CONTROL_SAMPLE, PART_UPDATES = 8, 16

#: The actuators (parts that carry momentum or exert torque on the hub), each ``kernel(lane, direct)`` of its
#: state access (:func:`~tumble.kernels.spacecraft._base.lane`) and the motor torques commanded directly to the
#: wheels (:func:`tumble.kernels.spacecraft._commands.make_direct`), in the order their torques are summed.
ACTUATORS = {
    "wheels": wheels.kernel,
    "cmgs": lambda lane, direct: cmgs.kernel(lane),
    "thrusters": lambda lane, direct: thrusters.kernel(lane),
    "magnetorquers": lambda lane, direct: magnetorquers.kernel(lane),
    "damper": lambda lane, direct: damper.kernel(lane),
    "residual_dipole": lambda lane, direct: residual_dipole.kernel(lane),
    "solar_pressure": lambda lane, direct: solar_pressure.kernel(lane),
    "drag": lambda lane, direct: drag.kernel(lane),
    "flexible_modes": lambda lane, direct: flexible_modes.kernel(lane),
    "slosh": lambda lane, direct: slosh.kernel(lane),
}


def _unrolled(name, arguments, parts, call, sums=0, routed=False):
    """One inlined function ``name(arguments)`` that runs ``call`` for each of ``parts`` [(kind index,
    (has, where), function)] present, in their order, and returns the ``sums`` values it adds up (none: returns
    nothing). ``call`` names the part's function ``f`` and may use its place ``p, n, s, a`` and ``routed`` (the
    controller's torque command is this part's to deliver).

    Written out as one flat function rather than a chain of closures each calling the previous: Numba's IR
    inliner (0.68) re-runs its passes on, and copies, the whole chain below each link it inlines, so a chain of
    ``N`` parts costs ``N²/2`` parts' compilation. The sums start at 0.0 and add the parts' terms in the same
    order as such a chain, so the result is the same to the bit.
    """
    totals = ", ".join(f"r{i}" for i in range(sums))
    terms = ", ".join(f"b{i}" for i in range(sums))
    lines = [f"def {name}({arguments}):"]
    if sums:
        lines.append(f"    {' = '.join(f'r{i}' for i in range(sums))} = 0.0")
    namespace = {}
    for i, (k, (has, where), function) in enumerate(parts):
        namespace.update({f"has_{i}": has, f"where_{i}": where, f"f_{i}": function})
        lines += [f"    if has_{i}(model):", f"        p, n, s, a = where_{i}(model)"]
        if routed:
            lines.append(f"        routed = model.route == {k}")
        invocation = call.replace("f(", f"f_{i}(")
        if sums:
            lines += [f"        {terms} = {invocation}",
                      f"        {totals} = {', '.join(f'r{j} + b{j}' for j in range(sums))}"]
        else:
            lines.append(f"        {invocation}")
    lines.append(f"    return {totals}" if sums else "    return None")
    exec(compile("\n".join(lines), f"<tumble.kernels.spacecraft {name}>", "exec"), namespace)
    return inline(namespace[name])


def _with(parts, function, absent):
    """``parts`` [(kind index, (has, where), Actuator)] reduced to those whose ``function`` (a field of
    :class:`~tumble.kernels.spacecraft._base.Actuator`) is not ``absent``, with that function."""
    return [(k, located, getattr(part, function)) for k, located, part in parts
            if getattr(part, function) is not absent]


def _sum_momenta(parts):
    """``Σ h_k`` (N·m·s) of the actuators ``parts`` [(kind index, (has, where), Actuator)] present."""
    return _unrolled("momenta", "model, y, j", _with(parts, "momentum", no_momentum), "f(model, p, n, s, y, j)", 3)


def _sum_energies(parts):
    """``Σ T_k`` (J): the kinetic energies of the actuators present (the hub's ``½ ωᵀ J_ω ω`` is added by the
    diagnostics)."""
    return _unrolled("energies", "model, y, j", _with(parts, "energy", no_energy), "f(model, p, n, s, y, j)", 1)


def _sum_torques(parts):
    """``Σ τ_k`` (N·m) of the actuators present, each writing its state derivatives and diagnostics."""
    # Every actuator has an ``act`` (no default to leave out).
    return _unrolled("torques", "model, t, y, j, out, aux, store, w1, w2, w3, cmd", _with(parts, "act", None),
                     "f(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd)", 3, routed=True)


def _sample_all(parts):
    """``(sample, discrete)``: the discrete updates of the actuators present that have some, and
    ``discrete(model)``, True when the spacecraft carries one of them."""
    sampled = _with(parts, "sample", no_sample)
    return (_unrolled("samples", "model, t, y, j", sampled, "f(model, p, n, s, t, y, j)"),
            _any_present(sampled))


def _finish_all(parts):
    """The second phase of the actuators present that have one: each completes its state derivatives in
    ``out`` from the hub's ``ω̇ = (a₁, a₂, a₃)``."""
    return _unrolled("finishes", "model, y, j, out, a1, a2, a3", _with(parts, "finish", no_finish),
                     "f(model, p, n, s, y, j, out, a1, a2, a3)")


def _added_inertia_all(parts):
    """``(added, coupled)``: ``Σ ΔM`` (upper triangle, kg·m²) of the actuators present that add to the hub's
    matrix, and ``coupled(model)``, True when the spacecraft carries one of them."""
    adding = _with(parts, "added_inertia", no_added_inertia)
    return _unrolled("added_inertia", "model, y, j", adding, "f(model, p, n, s, y, j)", 6), _any_present(adding)


def _project_all(parts):
    """The projections of the actuators present that have one: each puts its states back on their
    constraints."""
    return _unrolled("projections", "model, y, j", _with(parts, "project", no_project), "f(model, p, n, s, y, j)")


def _any_present(parts):
    """``present(model)``: True when the spacecraft carries one of ``parts``."""
    namespace = {f"has_{i}": has for i, (_, (has, _), _) in enumerate(parts)}
    test = " or ".join(f"has_{i}(model)" for i in range(len(parts))) or "False"
    exec(compile(f"def present(model):\n    return {test}\n", "<tumble.kernels.spacecraft present>", "exec"),
         namespace)
    return inline(namespace["present"])


def _environment(python):
    """``field(model, t, q) -> B`` (T, body axes), ``gravity(model, t, q) -> τ_gg`` and
    ``external(model, t, q, ω) -> τ`` (the torque program, its Python terms only in the variant that calls
    Python, ``python``), N·m, body axes. With an environment table the field is its IGRF column and the
    gravity gradient reads its position; without, the dipole or uniform field and the Kepler orbit."""
    program = torques.evaluate if python else torques.evaluate_compiled
    has_dipole, where_dipole = locator("dipole_field")
    has_uniform, where_uniform = locator("uniform_field")
    has_gravity, where_gravity = locator("gravity_gradient")
    has_table, where_table = locator("environment_table")

    @inline
    def field(model, t, qw, qx, qy, qz):
        b1 = b2 = b3 = 0.0
        if has_table(model):
            p, _, _, _ = where_table(model)
            b1, b2, b3 = environment_table.field_body(model.data, p, t, qw, qx, qy, qz)
        elif has_dipole(model):
            p, _, _, _ = where_dipole(model)
            b1, b2, b3 = environment.dipole_body(model, p, t, qw, qx, qy, qz)
        elif has_uniform(model):
            p, _, _, _ = where_uniform(model)
            b1, b2, b3 = environment.uniform_body(model, p, t, qw, qx, qy, qz)
        return b1, b2, b3

    @inline
    def gravity(model, t, qw, qx, qy, qz):
        g1 = g2 = g3 = 0.0
        if has_gravity(model):
            p, _, _, _ = where_gravity(model)
            if has_table(model):
                tp, _, _, _ = where_table(model)
                r1, r2, r3 = environment_table.position_at(model.data, tp, t)
            else:
                r1, r2, r3 = environment.position(model.data, p + environment.ORBIT, t)
            g1, g2, g3 = environment.gravity_gradient(model, p, J, r1, r2, r3, qw, qx, qy, qz)
        return g1, g2, g3

    @inline
    def external(model, t, qw, qx, qy, qz, w1, w2, w3):
        e1 = e2 = e3 = 0.0
        if model.torque_terms > 0:
            d = model.data
            c = model.torque_at
            e1, e2, e3 = program(t, qw, qx, qy, qz, w1, w2, w3, d.reshape((1, d.shape[0])), 0,
                                 d[c:c + 2 * model.torque_terms])
        return e1, e2, e3

    return field, gravity, external


# On a GPU no spacecraft carries flight software (its MEKF allocates; refused: ``SpacecraftModel.gpu_refusal``):
# the laws read the truth, a command acts at once, and no sensor reads.
_truth = inline(lambda model, t, y, j, qw, qx, qy, qz, w1, w2, w3: (qw, qx, qy, qz, w1, w2, w3))
_not_pending = inline(lambda model, y, j, u1, u2, u3, m1, m2, m3: False)


@njit
def _no_sensing(model, t, y, j):
    pass


def assemble(ndim, python, device=False):
    """Compile-time assembly for states of ``ndim``: ``(derivative, sense, sample, due, constrain)``; ``python``:
    the variant for a spacecraft whose control laws call Python (else those laws are left out, and the derivative,
    which then allocates nothing, is compiled without reference counting: the
    runtime tests of the parts split the refcount pairs of the model's arrays over branches that Numba's
    pruner cannot join, and counting them made the RK4 step 5.5 times slower).
    ``derivative(model, t, y, j, out, aux, store)`` writes ``dy/dt`` of the member in lane ``j`` of the block
    ``y`` (or of the state vector ``y``, ``ndim`` 1) into ``out`` and, when ``store``, its diagnostics into
    ``aux``; ``sense(model, t, y, j)`` lets the flight software's sensors whose sample time is the step end ``t``
    read the truth; ``due(model, t)`` the discrete updates due at the step end ``t`` (bits: the law groups
    sampled there, :data:`CONTROL_SAMPLE` at a sample of ``control_period``, :data:`PART_UPDATES` for the parts'
    updates, at the control samples with a ``control_period``, else after every step; 0: none);
    ``sample(model, t, y, j, updates)`` applies those ``updates`` (the held commands, the PWPF triggers);
    ``constrain(model, y, j)`` puts the parts' states back on their constraints (every step end);
    ``device``: the variant compiled for a GPU, without the flight software. Cached, so that the right-hand side,
    the projection and the diagnostics share it."""
    return _assembled(int(ndim), bool(python), bool(device))


@functools.lru_cache(maxsize=None)
def _assembled(ndim, python, device):
    """:func:`assemble`, cached on its arguments normalised (``assemble(1, False)`` and ``assemble(1, False,
    False)`` are one assembly: a second would compile every function of the spacecraft again)."""
    access = lane(ndim)
    at, put, put3 = access
    direct = _commands.make_direct(access)
    commands = _commands.controller(access, python)
    held, hold = _commands.zero_order_hold(access, direct)
    live, laws_due = _commands.law_clocks()
    has_hold, where_hold = locator("hold")
    has_integral, where_integral = locator("mrp_integral")
    _, where_mrp = locator("mrp")
    actuators = [(PARTS.index(kind), locator(kind), ACTUATORS[kind](access, direct)) for kind in ACTUATORS]
    momenta, energies = _sum_momenta(actuators), _sum_energies(actuators)
    torques_on_hub = _sum_torques(actuators)
    sample_parts, discrete = _sample_all(actuators)
    finish_parts = _finish_all(actuators)
    added_inertia, coupled = _added_inertia_all(actuators)
    project_parts = _project_all(actuators)
    field, gravity, external = _environment(python)
    has_fsw, where_fsw = locator("flight_software")
    has_table, where_table = locator("environment_table")
    fsw_sense, fsw_step, fsw_pend, fsw_due = flight_software.kernel(access)

    @inline
    def controller_commands(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, b1, b2, b3):
        """The commands in force: those of the sampled law groups held from their last sample time, the
        others' now."""
        if has_hold(model):
            u1, u2, u3, m1, m2, m3, source = held(model, y, j)
            return commands(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, b1, b2, b3, live(model),
                            u1, u2, u3, m1, m2, m3, source)
        return commands(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, b1, b2, b3, _commands.ALL_LAWS,
                        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, (_commands.NO_WHEEL_LAW, 0, 0, model.data))

    @inline
    def law_rates(model, t, y, j, out, qw, qx, qy, qz):
        """d/dt ∫σ dt = σ, continuous also under a zero-order hold."""
        if has_integral(model):
            p, _, _, _ = where_mrp(model)
            _, _, s, _ = where_integral(model)
            s1, s2, s3 = laws.attitude_error(model, p, qw, qx, qy, qz)
            put3(out, s + laws.INTEGRAL, j, s1, s2, s3)

    @inline
    def hold_rates(model, out, j):
        if has_hold(model):
            _, n, s, _ = where_hold(model)
            for i in range(HELD_WHEELS + n):
                put(out, s + i, j, 0.0)
        if has_fsw(model):  # the flight software's state changes only at the samples
            _, _, s, _ = where_fsw(model)
            for i in range(flight_software.STATE):
                put(out, s + i, j, 0.0)

    @inline
    def hub_rate(model, y, j, r1, r2, r3):
        """``ω̇`` (rad/s²) of the hub's ``(J_ω + Σ ΔM) ω̇ = r``: with the precomputed ``J_ω⁻¹`` unless a part
        adds to the matrix."""
        d = model.data
        if coupled(model):
            m00, m01, m02, m11, m12, m22 = added_inertia(model, y, j)
            return solve_symmetric(d[J_RATE] + m00, d[J_RATE + 1] + m01, d[J_RATE + 2] + m02, d[J_RATE + 4] + m11,
                                   d[J_RATE + 5] + m12, d[J_RATE + 8] + m22, r1, r2, r3)
        return matvec_flat(d, J_RATE_INV, r1, r2, r3)

    # Not inlined: one compiled function that the right-hand side and the diagnostics
    # (:func:`tumble.kernels.spacecraft.evaluate`) share, so that the model type compiles it once.
    @njit(_nrt=python)
    def derivative(model, t, y, j, out, aux, store):
        d = model.data
        qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
        w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
        H1, H2, H3 = matvec_flat(d, J_RATE, w1, w2, w3)
        h1, h2, h3 = momenta(model, y, j)
        H1, H2, H3 = H1 + h1, H2 + h2, H3 + h3
        b1, b2, b3 = field(model, t, qw, qx, qy, qz)
        u1, u2, u3, m1, m2, m3, source = controller_commands(model, t, y, j, qw, qx, qy, qz, w1, w2, w3,
                                                             H1, H2, H3, b1, b2, b3)
        x1, x2, x3 = torques_on_hub(model, t, y, j, out, aux, store, w1, w2, w3,
                                    (u1, u2, u3, m1, m2, m3, b1, b2, b3, source))
        g1, g2, g3 = gravity(model, t, qw, qx, qy, qz)
        e1, e2, e3 = external(model, t, qw, qx, qy, qz, w1, w2, w3)
        k1, k2, k3 = cross(w1, w2, w3, H1, H2, H3)
        a1, a2, a3 = hub_rate(model, y, j, x1 + g1 + e1 - k1, x2 + g2 + e2 - k2, x3 + g3 + e3 - k3)
        r = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
        put(out, 0, j, 0.5 * r[0])
        put3(out, 1, j, 0.5 * r[1], 0.5 * r[2], 0.5 * r[3])
        put3(out, 4, j, a1, a2, a3)
        finish_parts(model, y, j, out, a1, a2, a3)
        law_rates(model, t, y, j, out, qw, qx, qy, qz)
        hold_rates(model, out, j)
        if store:
            c1, c2, c3 = matvec_flat(d, J_RATE, w1, w2, w3)
            put(aux, AUX_ENERGY, j, 0.5 * (w1 * c1 + w2 * c2 + w3 * c3) + energies(model, y, j))
            put3(aux, AUX_MOMENTUM, j, H1, H2, H3)
            put3(aux, AUX_TORQUE_COMMAND, j, u1, u2, u3)
            put3(aux, AUX_DIPOLE_COMMAND, j, m1, m2, m3)
            put3(aux, AUX_FIELD, j, b1, b2, b3)
            put3(aux, AUX_GRAVITY, j, g1, g2, g3)
            put3(aux, AUX_ACTUATOR, j, x1, x2, x3)
            put3(aux, AUX_EXTERNAL, j, e1, e2, e3)

    # Counted: the flight software's filter allocates its matrices; the sensors read once per step, the
    # filter once per sample time, not per evaluation of the right-hand side.
    @inline
    def sun(model, p, t):
        """The Sun's direction (inertial, unit) and the fraction of it seen at ``t``: the environment table's, or
        the flight software's fixed ``sun_direction``, always seen."""
        d = model.data
        if has_table(model):
            tp, _, _, _ = where_table(model)
            row, f = environment_table.interval(d, tp, t)
            s1, s2, s3 = environment_table.direction(d, row, f, environment_table.SUN_DIRECTION)
            return s1, s2, s3, environment_table.linear(d, row, f, environment_table.SHADOW)
        o = p + flight_software.SUN_DIRECTION
        return d[o], d[o + 1], d[o + 2], 1.0

    if device:
        sense, estimate, pending = _no_sensing, _truth, _not_pending
    else:
        @njit
        def sense(model, t, y, j):
            """The flight software's sensors whose sample time is the step end ``t`` read the truth, and a pending
            command whose delay ends at ``t`` goes to the hold."""
            if has_fsw(model):
                p, _, s, _ = where_fsw(model)
                b1, b2, b3 = field(model, t, at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j))
                s1, s2, s3, light = sun(model, p, t)
                fsw_sense(model, p, s, t, y, j, b1, b2, b3, s1, s2, s3, light)
                if fsw_due(model, p, t):  # the command computed one delay ago starts acting
                    _, _, held_at, _ = where_hold(model)
                    for i in range(6):
                        put(y, held_at + HELD_TORQUE + i, j, at(y, s + flight_software.PENDING + i, j))

        @inline
        def estimate(model, t, y, j, qw, qx, qy, qz, w1, w2, w3):
            """What the laws read at a sample: the flight software's estimate, or the truth without one."""
            if has_fsw(model):
                p, _, s, _ = where_fsw(model)
                qw, qx, qy, qz, w1, w2, w3 = fsw_step(model, p, s, model.data[PERIOD], t, y, j)
            return qw, qx, qy, qz, w1, w2, w3

        @inline
        def pending(model, y, j, u1, u2, u3, m1, m2, m3):
            """Whether the command waits for the flight software's computation delay (the held stays)."""
            if has_fsw(model):
                p, _, s, _ = where_fsw(model)
                return fsw_pend(model, p, s, y, j, u1, u2, u3, m1, m2, m3)
            return False

    @inline
    def due(model, t):
        d = model.data
        bits = 0
        if d[PERIOD] > 0.0:
            if _commands.on_clock(t, d[START], d[PERIOD]):
                bits = CONTROL_SAMPLE | PART_UPDATES
        elif discrete(model):  # parts with discrete states update after every step
            bits = PART_UPDATES
        if has_hold(model):
            bits |= laws_due(model, t)
        return bits

    @njit
    def sample(model, t, y, j, updates):
        if updates & (CONTROL_SAMPLE | _commands.ALL_LAWS):
            qw, qx, qy, qz = at(y, 0, j), at(y, 1, j), at(y, 2, j), at(y, 3, j)
            w1, w2, w3 = at(y, 4, j), at(y, 5, j), at(y, 6, j)
            b1, b2, b3 = field(model, t, qw, qx, qy, qz)
            if updates & CONTROL_SAMPLE:  # the laws due read the estimate (their periods: multiples of control's)
                qw, qx, qy, qz, w1, w2, w3 = estimate(model, t, y, j, qw, qx, qy, qz, w1, w2, w3)
            H1, H2, H3 = matvec_flat(model.data, J_RATE, w1, w2, w3)
            h1, h2, h3 = momenta(model, y, j)
            u1, u2, u3, m1, m2, m3, source = held(model, y, j)
            u1, u2, u3, m1, m2, m3, source = commands(model, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1 + h1, H2 + h2,
                                                      H3 + h3, b1, b2, b3, updates & _commands.ALL_LAWS,
                                                      u1, u2, u3, m1, m2, m3, source)
            if updates & CONTROL_SAMPLE and pending(model, y, j, u1, u2, u3, m1, m2, m3):  # acts after the delay
                u1, u2, u3, m1, m2, m3, source = held(model, y, j)
            hold(model, t, y, j, u1, u2, u3, m1, m2, m3, source)
        if updates & PART_UPDATES:
            sample_parts(model, t, y, j)

    @njit
    def constrain(model, y, j):
        project_parts(model, y, j)

    return derivative, sense, sample, due, constrain
