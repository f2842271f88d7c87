"""The spacecraft as a compiled model (see :mod:`tumble._protocol`): a rigid hub and the parts it carries.

A spacecraft is assembled from *parts*, each a program of one kind of
:data:`PARTS` — an actuator (one file each: :mod:`.wheels`, :mod:`.cmgs`,
:mod:`.thrusters`, :mod:`.magnetorquers`, :mod:`.damper`), a control law
(:mod:`.laws`), a piece of the environment (:mod:`.environment`) or the
zero-order hold of a sampled controller — made of a parameter block in the one
flat array ``data``, a slice of the state vector and a slice of the
diagnostics, all at named offsets. :class:`SpacecraftModel` records which
kinds are present in its *type* (a flag field per kind), so that Numba compiles each
combination on its own and a part the spacecraft lacks costs nothing.

State vector::

    [q (4), ω (3), then each present part's state slice, in the order of PARTS]

``q`` body → inertial; ``ω`` the hub's rate relative to inertial, rad/s, body
axes. Equations (body axes; Hughes, *Spacecraft Attitude Dynamics*, §7.2;
Markley & Crassidis 2014, §3.3.5)::

    J_ω ω̇ = τ_ext + Σ τ_k − ω × H,      H = J_ω ω + Σ h_k,      q̇ = ½ q ⊗ [0, ω]

where ``J_ω`` is the inertia the hub's rate answers to (the total ``J``, every
rotor counted as a rigid part, less the inertias the parts carry in their own
states: the wheels' spin inertias, the damper sphere), ``h_k`` the angular
momentum part ``k`` carries and ``τ_k`` the torque it exerts on the hub
(``−dh_k/dt`` seen from the hub for internal parts; thrusters and
magnetorquers exert external torques), and ``τ_ext`` the environment's
gravity gradient plus the external torque program of ``torque=``
(:mod:`tumble.torques`). The controller's commands — torque ``u_c`` (N·m),
dipole ``m_c`` (A·m²), motor torques of the wheels — are evaluated in the
right-hand side (continuous control) or, with a ``"hold"`` part, at the
sample times ``t₀ + k·period`` in :func:`tumble._protocol.project` and held
in the state (zero-order hold). The torque command goes to the actuator
``route`` (a kind index of :data:`PARTS`; −1: none).

The diagnostics of one sample (:func:`evaluate`) start with the core block
(``AUX_*``), then each part's.
"""

from __future__ import annotations

import collections
import functools
from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

from tumble import _protocol, _quat, torques
from tumble._vec import cross, matvec_flat
from tumble.kernels.spacecraft import cmgs, damper, environment, laws, magnetorquers, thrusters, wheels
from tumble.kernels.spacecraft._base import SAMPLE_TOLERANCE, Program, inline, lane, no_sample

__all__ = ["PARTS", "Program", "SpacecraftModel", "assemble", "evaluate", "initialise", "slices"]

#: The kinds of part, in the order of their state slices.
PARTS = ("hold", "wheels", "cmgs", "thrusters", "magnetorquers", "damper", "pd", "mrp", "mrp_integral",
         "python_law", "bdot", "dumping", "wheel_table", "wheel_python", "dipole_field", "uniform_field",
         "gravity_gradient")

#: The actuators (parts that carry momentum or exert torque): their compiled functions for a state access
#: (:func:`~tumble.kernels.spacecraft._base.lane`), given the motor torques commanded directly to the wheels
#: (a function of the wheel-torque law).
ACTUATORS = {
    "wheels": wheels.kernel,
    "cmgs": lambda lane, direct: cmgs.kernel(lane),
    "thrusters": lambda lane, direct: thrusters.kernel(lane),
    "magnetorquers": lambda lane, direct: magnetorquers.kernel(lane),
    "damper": lambda lane, direct: damper.kernel(lane),
}

#: Kinds that call Python functions (the batch then runs on one core).
_PYTHON = ("python_law", "wheel_python")

# The hub's block at the start of data:
J = 0              # J (9), total inertia about the centre of mass, kg·m², row-major
J_RATE = 9         # J_ω (9)
J_RATE_INV = 18    # J_ω⁻¹ (9)
PERIOD = 27        # control period, s (0: continuous)
START = 28         # the control clock's start t₀, s
HUB_SIZE = 29

# The "hold" part's state: u_c (3), m_c (3), then one motor torque per wheel when a wheel-torque law is present.
HELD_TORQUE, HELD_DIPOLE, HELD_WHEELS = 0, 3, 6

# The core block of the diagnostics:
AUX_ENERGY = 0            # kinetic energy of hub and parts, J (1)
AUX_MOMENTUM = 1          # H, N·m·s, body axes (3)
AUX_TORQUE_COMMAND = 4    # u_c, N·m (3)
AUX_DIPOLE_COMMAND = 7    # m_c before the limits, A·m² (3)
AUX_FIELD = 10            # B, T, body axes (3)
AUX_GRAVITY = 13          # gravity-gradient torque, N·m (3)
AUX_ACTUATOR = 16         # Σ τ_k, N·m (3)
AUX_EXTERNAL = 19         # the torque program of torque=, N·m (3)
AUX_CORE = 22


class SpacecraftModel(collections.namedtuple(
        "SpacecraftModel", ("data", "layout", "route", "size", "aux_size", "torque_params", "torque_codes") + PARTS)):
    """Compiled parameters of a spacecraft (shared by every member of a batch).

    data        : float64 parameters: the hub block (``J``, ``J_RATE``, ``J_RATE_INV``,
                  ``PERIOD``, ``START``), then each present part's block
    layout      : int64 (n_parts, 4): ``(p, n, s, a)`` of each present part, in the order of
                  :data:`PARTS`: its parameter offset, count, state offset, diagnostics offset
    route       : the kind index of the actuator that delivers the torque command, or −1
    size        : length of the state vector
    aux_size    : length of the diagnostics of one sample
    torque_params, torque_codes : the program of ``torque=`` (:func:`tumble.torques.compile_program`
                  in body axes, params (1, n)), or None
    then one field per kind of :data:`PARTS`: ``True`` present, ``None`` absent (so the set of parts is
    in the Numba type; the parallel drivers take scalars, None and arrays only, no tuples)
    """

    __slots__ = ()

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side and the body rate."""
        return frozenset({"rhs", "body_rate"})

    @property
    def calls_python(self) -> bool:
        """True when a control law or the torque program calls a Python function (the batch then runs on one core)."""
        return any(getattr(self, kind) for kind in _PYTHON) or torques.calls_python(self.torque_codes)


class Slices(NamedTuple):
    """Where one part is in a compiled model: parameter offset, count, state offset, diagnostics offset."""

    p: int
    n: int
    s: int
    a: int


def assemble(inertia, rate_inertia, period: float, t0: float, programs, route: str | None,
             torque=None) -> SpacecraftModel:
    """The :class:`SpacecraftModel` of a hub (total inertia ``J`` and ``J_ω``, kg·m², body axes) with the parts
    ``programs`` (:class:`~tumble.kernels.spacecraft._base.Program`, at most one of each kind), a control
    ``period`` (s; 0: continuous) whose clock starts at ``t0`` (s), the actuator ``route`` that delivers the
    torque command (a kind, or None) and an external torque model (:mod:`tumble.torques`, or None)."""
    by_kind = {p.kind: p for p in programs}
    if len(by_kind) != len(programs) or not set(by_kind) <= set(PARTS):
        raise ValueError(f"programs: one of each kind of {PARTS}, got {[p.kind for p in programs]}")
    blocks = [np.ravel(inertia), np.ravel(rate_inertia), np.ravel(np.linalg.inv(rate_inertia)), [period, t0]]
    p, s, a = HUB_SIZE, 7, AUX_CORE
    layout = []
    for kind in PARTS:
        if kind in by_kind:
            part = by_kind[kind]
            layout += [p, part.count, s, a]
            blocks.append(np.ravel(part.params))
            p, s, a = p + part.params.size, s + part.state, a + part.aux
    codes, params = None, None
    if torque is not None:
        codes, block = torques.compile_program(torque, np.eye(3), offset=0)
        params = np.ascontiguousarray(block[None, :])
    return SpacecraftModel(
        data=np.ascontiguousarray(np.concatenate([np.asarray(b, dtype=np.float64) for b in blocks])),
        layout=np.array(layout, dtype=np.int64).reshape(-1, 4), route=-1 if route is None else PARTS.index(route),
        size=s, aux_size=a, torque_params=params, torque_codes=codes,
        **{kind: True if kind in by_kind else None for kind in PARTS})


def slices(model: SpacecraftModel, kind: str) -> Slices | None:
    """Where the part of ``kind`` is in ``model`` (:class:`Slices`), or None when it has none."""
    if getattr(model, kind) is None:
        return None
    k = sum(getattr(model, other) is not None for other in PARTS[:PARTS.index(kind)])
    return Slices(*(int(x) for x in model.layout[k]))


# ---------------------------------------------------------------------------------------------------------
# Compile-time assembly
# ---------------------------------------------------------------------------------------------------------


def _present(model) -> dict[str, bool]:
    """The kinds present in the Numba type ``model`` of a SpacecraftModel (its flag fields not None)."""
    return {kind: not isinstance(model.types[model.fields.index(kind)], types.NoneType) for kind in PARTS}


def _locator(has: dict, kind: str):
    """A compiled ``where(L) -> (p, n, s, a)`` of the part ``kind`` in the layout ``L`` of :func:`_loader`."""
    k = 4 * sum(has[other] for other in PARTS[:PARTS.index(kind)])

    @inline
    def where(L):
        return L[k], L[k + 1], L[k + 2], L[k + 3]

    return where


def _loader(has: dict):
    """A compiled ``load(model) -> L``: the layout of the present parts as a flat tuple of ints, read once
    per evaluation (the compiler cannot keep array reads across the stores into the state derivative)."""
    load = inline(lambda model: ())
    for k in range(sum(has.values())):
        load = _load_row(load, k)
    return load


def _load_row(previous, k):
    @inline
    def load(model):
        A = model.layout
        return previous(model) + (A[k, 0], A[k, 1], A[k, 2], A[k, 3])

    return load


# Absent pieces: compiled to nothing (Numba's inliner takes no *args, so one per signature).
_no_momenta = inline(lambda model, L, y, j: (0.0, 0.0, 0.0))
_no_energy = inline(lambda model, L, y, j: 0.0)
_no_torques = inline(lambda model, L, t, y, j, out, aux, store, w1, w2, w3, cmd: (0.0, 0.0, 0.0))
_no_samples = inline(lambda model, L, t, y, j: None)
_no_field = inline(lambda model, L, t, qw, qx, qy, qz: (0.0, 0.0, 0.0))
_no_external = inline(lambda model, L, t, qw, qx, qy, qz, w1, w2, w3: (0.0, 0.0, 0.0))
_no_torque_law = inline(lambda model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3: (0.0, 0.0, 0.0))
_no_dipole = inline(lambda model, L, y, j, w1, w2, w3, b1, b2, b3: (0.0, 0.0, 0.0))
_no_source = inline(lambda model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3: 0.0)
_no_direct = inline(lambda model, t, y, j, i, source: 0.0)
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
        where_field = _locator(has, kind)

        @inline
        def field(model, L, t, qw, qx, qy, qz):
            p, _, _, _ = where_field(L)
            return body_field(model, p, t, qw, qx, qy, qz)
    else:
        field = _no_field

    if has["gravity_gradient"]:
        where_gg = _locator(has, "gravity_gradient")

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


def _wheel_speeds(has, lane):
    """``speeds(model, L, y, j, ω) -> array`` of the wheel speeds Ω_i (rad/s; empty without wheels), for Python laws."""
    at = lane.at
    if not has["wheels"]:
        return inline(lambda model, L, y, j, w1, w2, w3: np.empty(0))
    where = _locator(has, "wheels")

    @inline
    def speeds(model, L, y, j, w1, w2, w3):
        p, n, s, _ = where(L)
        out = np.empty(n)
        for i in range(n):
            b = p + wheels.STRIDE * i
            out[i] = wheels.speed(model.data, b, at(y, s + wheels.MOMENTUM + i, j), w1, w2, w3)
        return out

    return speeds


def _torque_law(has, lane, speeds):
    """``law(model, t, y, j, q, ω, H) -> u_c`` (N·m, body axes) of the torque law present (zero without one)."""
    at = lane.at
    if has["pd"]:
        where = _locator(has, "pd")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            return laws.pd_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3)
    elif has["mrp"] and has["mrp_integral"]:
        where, where_i = _locator(has, "mrp"), _locator(has, "mrp_integral")

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
        where = _locator(has, "mrp")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            return laws.mrp_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, 0.0, 0.0, 0.0)
    elif has["python_law"]:
        where = _locator(has, "python_law")

        @inline
        def law(model, L, t, y, j, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
            p, _, _, _ = where(L)
            u = laws.call_python(int(model.data[p + laws.SLOT]), t, qw, qx, qy, qz, w1, w2, w3,
                                 speeds(model, L, y, j, w1, w2, w3), 3)
            return u[0], u[1], u[2]
    else:
        law = _no_torque_law
    return law


def _dipole_law(has, lane):
    """``law(model, y, j, ω, B) -> m_c`` (A·m², body axes): the sum of the dipole laws present."""
    bdot = dumping = _no_dipole
    if has["bdot"]:
        where_b = _locator(has, "bdot")

        @inline
        def bdot(model, L, y, j, w1, w2, w3, b1, b2, b3):
            p, _, _, _ = where_b(L)
            return laws.bdot_dipole(model, p, w1, w2, w3, b1, b2, b3)
    if has["dumping"]:
        where_d, where_w = _locator(has, "dumping"), _locator(has, "wheels")
        wheel_momentum = wheels.kernel(lane, _no_direct).momentum

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


def _wheel_law(has, speeds):
    """``(source, direct)``: ``source(model, L, t, y, j, q, ω)`` evaluates the motor-torque law once per
    evaluation of the commands, ``direct(model, t, y, j, i, source)`` is wheel ``i``'s command (N·m)."""
    if has["wheel_table"]:
        where, where_w = _locator(has, "wheel_table"), _locator(has, "wheels")

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
        where, where_w = _locator(has, "wheel_python"), _locator(has, "wheels")

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
    return _no_source, _no_direct


def _commands(has, lane):
    """``(commands, direct)``: ``commands(model, L, t, y, j, q, ω, H, B) -> (u_c, m_c, source)`` of the control
    laws as evaluated now, and the wheels' ``direct`` commands for that ``source``."""
    speeds = _wheel_speeds(has, lane)
    torque_law, dipole_law = _torque_law(has, lane, speeds), _dipole_law(has, lane)
    source, direct = _wheel_law(has, speeds)
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


def _held(has, lane, direct):
    """``(commands, direct, hold)`` of a zero-order hold: the held commands read from the state, and
    ``hold(model, L, t, y, j, commands...)`` that stores those of the laws (``direct``: their wheel commands)."""
    at, put, put3 = lane
    where = _locator(has, "hold")
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
        held_direct = _no_direct

    @inline
    def hold(model, L, t, y, j, u1, u2, u3, m1, m2, m3, source):
        _, n, s, _ = where(L)
        put3(y, s + HELD_TORQUE, j, u1, u2, u3)
        put3(y, s + HELD_DIPOLE, j, m1, m2, m3)
        for i in range(n):
            put(y, s + HELD_WHEELS + i, j, direct(model, t, y, j, i, source))

    return commands, held_direct, hold


@functools.lru_cache(maxsize=None)
def _assemble(model, ndim):
    """Compile-time assembly for the Numba type ``model`` of a SpacecraftModel and states of ``ndim``:
    ``(derivative, sample, discrete)``. ``derivative(model, t, y, j, out, aux, store)`` writes ``dy/dt`` of
    the member in lane ``j`` of the block ``y`` (or of the state vector ``y``, ``ndim`` 1) into ``out`` and,
    when ``store``, its diagnostics into ``aux``; ``sample(model, t, y, j)`` applies the discrete updates of
    a sample time (the held commands, the PWPF triggers); ``discrete``: what :func:`tumble._protocol.project`
    must do besides normalising the quaternion (``"hold"``: sample at the sample times; ``"step"``: after
    every step; None). Cached, so that the right-hand side, the projection and the diagnostics share it."""
    has = _present(model)
    load = _loader(has)
    access = lane(ndim)
    at, put, put3 = access
    law_commands, law_direct = _commands(has, access)
    if has["hold"]:
        commands, direct, hold = _held(has, access, law_direct)
        where_hold = _locator(has, "hold")
    else:
        commands, direct = law_commands, law_direct
    actuators = [(PARTS.index(kind), _locator(has, kind), ACTUATORS[kind](access, direct))
                 for kind in ACTUATORS if has[kind]]
    momenta, energies = _sum_momenta(actuators), _sum_energies(actuators)
    torques_on_hub, sample_parts = _sum_torques(actuators), _sample_all(actuators)
    discrete = None if sample_parts is None else "step"
    sample_parts = _no_samples if sample_parts is None else sample_parts
    field, gravity, external = _environment(model, has)

    if has["mrp_integral"]:
        where_mrp, where_int = _locator(has, "mrp"), _locator(has, "mrp_integral")

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

    @inline
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


def _is_spacecraft(model):
    return _protocol.is_type(model, SpacecraftModel)


# Not inline="always": Numba's overload inliner (0.68) loses the loop accumulators of the parts
# (NumbaIRAssumptionWarning "variable ... is not in scope"); the call costs a few ns per evaluation.
@overload(_protocol.rhs, jit_options={"cache": True})
def _spacecraft_rhs(model, b0, t, Y, OUT):
    if not _is_spacecraft(model):
        return None
    derivative, _, _ = _assemble(model, Y.ndim)
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
    _, sample, discrete = _assemble(model, Y.ndim)
    if Y.ndim == 1:
        normalize, lanes = _protocol.normalize_quaternion, inline(lambda Y: 1)
    else:
        normalize, lanes = _protocol.normalize_quaternions, inline(lambda Y: Y.shape[1])
    if discrete == "hold":
        def impl(model, b0, t, Y):
            normalize(Y)
            period, start = model.data[PERIOD], model.data[START]
            k = round((t - start) / period)
            if abs(t - start - k * period) <= SAMPLE_TOLERANCE * period:
                for j in range(lanes(Y)):
                    sample(model, t, Y, j)
    elif discrete == "step":
        def impl(model, b0, t, Y):
            normalize(Y)
            for j in range(lanes(Y)):
                sample(model, t, Y, j)
    else:
        def impl(model, b0, t, Y):
            normalize(Y)
    return impl


@overload(_protocol.state_size, jit_options={"cache": True})
def _spacecraft_state_size(model):
    if not _is_spacecraft(model):
        return None
    return lambda model: model.size


@overload(_protocol.body_rate, inline="always", jit_options={"cache": True})
def _spacecraft_body_rate(model, Y, j):
    if not _is_spacecraft(model):
        return None
    return _protocol.rate_at(4, Y)


def _evaluate(model, t, y, aux):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_evaluate, jit_options={"cache": True})
def _evaluate_overload(model, t, y, aux):
    derivative, _, _ = _assemble(model, 1)

    def impl(model, t, y, aux):
        out = np.empty(y.shape[1])
        for k in range(y.shape[0]):
            derivative(model, t[k], y[k], 0, out, aux[k], True)

    return impl


def _sample(model, t, y):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_sample, jit_options={"cache": True})
def _sample_overload(model, t, y):
    _, sample, _ = _assemble(model, 1)
    return lambda model, t, y: sample(model, t, y, 0)


@njit(cache=True)
def evaluate(model, t, y, aux):
    """Diagnostics of the samples ``y`` (n, state) at the times ``t`` (n,) into ``aux`` (n, ``model.aux_size``)."""
    _evaluate(model, t, y, aux)


@njit(cache=True)
def initialise(model, t, y):
    """Apply the discrete updates of the start time ``t`` (s) to the state vector ``y``: the commands held
    from the first sample, the PWPF triggers."""
    _sample(model, t, y)
