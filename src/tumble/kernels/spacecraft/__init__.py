"""The spacecraft as a compiled model (see :mod:`tumble._protocol`): a rigid hub and the parts it carries.

A spacecraft is assembled from *parts*, each a program of one kind of
:data:`PARTS` — an actuator (one file each: :mod:`.wheels`, :mod:`.cmgs`,
:mod:`.thrusters`, :mod:`.magnetorquers`, :mod:`.damper`, :mod:`.flexible_modes`, :mod:`.slosh`), a control law
(:mod:`.laws`), a piece of the environment (:mod:`.environment`) or the
zero-order hold of a sampled controller — made of a parameter block in the one
flat array ``data``, a slice of the state vector and a slice of the
diagnostics, all at named offsets. The composition is data: which parts a
spacecraft has, how many wheels, gyros or thrusters, their parameters, the
control law and its gains, the environment and the external torque program
are numbers in :class:`SpacecraftModel`, whose Numba *type* is the same for
every spacecraft. The right-hand side is compiled once, with every kind of
part behind a runtime test of its presence, and a new composition compiles
nothing.

State vector::

    [q (4), ω (3), then each present part's state slice, in the order of PARTS]

``q`` body → inertial; ``ω`` the hub's rate relative to inertial, rad/s, body
axes. Equations (body axes; Hughes, *Spacecraft Attitude Dynamics*, §7.2;
Markley & Crassidis 2014, §3.3.5)::

    (J_ω + Σ ΔM_k) ω̇ = τ_ext + Σ τ_k − ω × H,      H = J_ω ω + Σ h_k,      q̇ = ½ q ⊗ [0, ω]

where ``J_ω`` is the inertia the hub's rate answers to (the total ``J``, every
rotor counted as a rigid part, less the inertias the parts carry in their own
states: the wheels' spin inertias, the damper sphere, the appendages' ``Σ δ_kδ_kᵀ``), ``h_k`` the angular
momentum part ``k`` carries and ``τ_k`` the torque it exerts on the hub
(``−dh_k/dt`` seen from the hub for internal parts; thrusters and
magnetorquers exert external torques), ``ΔM_k`` the state-dependent inertia a
part adds to the hub's matrix (the slosh pendulums' ``μ g gᵀ``; none: the
precomputed ``J_ω⁻¹`` solves), and ``τ_ext`` the environment's
gravity gradient plus the external torque program of ``torque=``
(:mod:`tumble.torques`). The controller's commands — torque ``u_c`` (N·m),
dipole ``m_c`` (A·m²), motor torques of the wheels — are evaluated in the
right-hand side (continuous control) or, with a ``"hold"`` part, at the
sample times ``t₀ + k·period`` in :func:`tumble._protocol.project` and held
in the state (zero-order hold), each group of laws at its own period
(:mod:`._commands`). The torque command goes to the actuator
``route`` (a kind index of :data:`PARTS`; −1: none).

The diagnostics of one sample (:func:`evaluate`) start with the core block
(``AUX_*``), then each part's.

Inside: :mod:`._layout` says where things are (the kinds, the hub block, the
core diagnostics, each part's packed place), :mod:`._base` what every part
shares (state access, the :class:`~._base.Actuator` interface),
:mod:`._commands` assembles the controller and :mod:`._assembly` the
right-hand side, when Numba compiles the model type (once).
"""

from __future__ import annotations

import collections

import numpy as np
from numba import njit, types
from numba.extending import overload
from numba.np.unsafe.ndarray import to_fixed_tuple

from tumble import _block, _protocol, torques
from tumble.kernels.spacecraft._assembly import assemble as _assemble
from tumble.kernels.spacecraft._base import Program, inline
from tumble.kernels.spacecraft._layout import (ABSENT, AUX_ACTUATOR, AUX_CORE, AUX_DIPOLE_COMMAND, AUX_ENERGY,
                                               AUX_EXTERNAL, AUX_FIELD, AUX_GRAVITY, AUX_MOMENTUM,
                                               AUX_TORQUE_COMMAND, CORE_FIELDS, HELD_WHEELS, HUB_SIZE, PARTS,
                                               Slices, pack, unpack)

__all__ = ["AUX_ACTUATOR", "AUX_DIPOLE_COMMAND", "AUX_ENERGY", "AUX_EXTERNAL", "AUX_FIELD", "AUX_GRAVITY",
           "AUX_MOMENTUM", "AUX_TORQUE_COMMAND", "HELD_WHEELS", "PARTS", "Program", "Slices", "SpacecraftModel",
           "assemble", "evaluate", "initialise", "slices"]

#: The ``store`` flags of the right-hand side (False) and of the diagnostics (True), read from an array so that
#: Numba types both as one runtime boolean and compiles the spacecraft's derivative once for both.
_STORE = np.array([False, True])

#: Kinds that call Python functions (the batch then runs on one core).
_PYTHON = ("python_law", "wheel_python")


class SpacecraftModel(collections.namedtuple("SpacecraftModel", CORE_FIELDS + PARTS)):
    """Compiled parameters of a spacecraft (shared by every member of a batch).

    data        : float64 parameters: the hub block (``J``, ``J_RATE``, ``J_RATE_INV``,
                  ``PERIOD``, ``START``), then each present part's block
    route       : the kind index of the actuator that delivers the torque command, or −1
    size        : length of the state vector
    aux_size    : length of the diagnostics of one sample
    torque_at, torque_terms : the program of ``torque=`` (:func:`tumble.torques.compile_program` in body
                  axes) in ``data``: its parameters, then its ``2 × torque_terms`` codes (as float64) from
                  ``data[torque_at]`` on; no terms without one. In ``data``, not arrays of their own: every
                  array of the model costs a reference count at each call that passes the model
    python_calls : None, or 1 when a control law (``"python_law"``, ``"wheel_python"``) or the torque
                  program calls a Python function. The one part of the composition in the Numba type: a
                  spacecraft without one runs a right-hand side and discrete update compiled without
                  reference counting (they allocate nothing), one with one the same compiled with it, since
                  a Python call allocates its arguments. So the kind compiles twice at most.

    then one int64 field per kind of :data:`PARTS`: :data:`ABSENT` (−1) when the spacecraft has no such part,
    else where the part is, ``(p, n, s, a)`` (:class:`Slices`) packed into one int64 (:func:`pack`). Every
    field has the same type for every spacecraft, so the Numba type is one and a composition is data; the
    layout travels as scalars (the parallel drivers take no tuples; an array of offsets would be read from
    memory at every evaluation).
    """

    __slots__ = ()

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side and the body rate; ``"cuda"``
        without a part that cannot run on a GPU (:attr:`gpu_refusal`)."""
        return frozenset({"rhs", "body_rate", *(() if self.gpu_refusal else ("cuda",))})

    @property
    def gpu_refusal(self) -> str | None:
        """Why this spacecraft cannot run on an NVIDIA GPU (a ValidationError message naming the part), or
        None: a Python control law or torque function, or the flight software, whose MEKF allocates its
        matrices at every sample."""
        if any(getattr(self, kind) != ABSENT for kind in _PYTHON):
            return _protocol.python_on_gpu("controller")
        if torques.calls_python(self.torque_codes):
            return _protocol.python_on_gpu("torque")
        if self.flight_software != ABSENT:
            return ("flight_software: the flight software's MEKF allocates its matrices at every sample, which "
                    "code on the GPU cannot (device='cuda'); use device='cpu'")
        return None

    @property
    def calls_python(self) -> bool:
        """True when a control law or the torque program calls a Python function (the batch then runs on one core)."""
        return any(getattr(self, kind) != ABSENT for kind in _PYTHON) or torques.calls_python(self.torque_codes)

    @property
    def torque_codes(self) -> np.ndarray:
        """The codes of the torque program (pairs (code, start in ``data``), int64; empty without one)."""
        return self.data[self.torque_at:self.torque_at + 2 * self.torque_terms].astype(np.int64)


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
    layout = {}
    for kind in PARTS:
        if kind in by_kind:
            part = by_kind[kind]
            layout[kind] = pack(Slices(p, part.count, s, a))
            blocks.append(np.ravel(part.params))
            p, s, a = p + part.params.size, s + part.state, a + part.aux
    codes, block = torques.compile_program(torque, np.eye(3), offset=p)
    blocks += [block, codes]
    return SpacecraftModel(
        data=np.ascontiguousarray(np.concatenate([np.asarray(b, dtype=np.float64) for b in blocks])),
        route=-1 if route is None else PARTS.index(route), size=s, aux_size=a,
        torque_at=p + block.size, torque_terms=codes.size // 2,
        python_calls=1 if any(kind in by_kind for kind in _PYTHON) or torques.calls_python(codes) else None,
        **{kind: layout.get(kind, ABSENT) for kind in PARTS})


def _python(model) -> bool:
    """Whether the (Numba) model type calls Python functions (its ``python_calls`` field is not None)."""
    return not isinstance(model.types[model.fields.index("python_calls")], types.NoneType)


def slices(model: SpacecraftModel, kind: str) -> Slices | None:
    """Where the part of ``kind`` is in ``model`` (:class:`Slices`), or None when it has none."""
    value = getattr(model, kind)
    return None if value == ABSENT else unpack(value)


# Not inline="always": Numba's overload inliner (0.68) loses the loop accumulators of the parts
# (NumbaIRAssumptionWarning "variable ... is not in scope"); the call costs a few ns per evaluation.
@_protocol.implements(_protocol.rhs, SpacecraftModel)
def _spacecraft_rhs(model, b0, t, Y, OUT):
    derivative, _, _, _, _ = _assemble(Y.ndim, _python(model))
    if Y.ndim == 1:
        def impl(model, b0, t, Y, OUT):
            derivative(model, t, Y, 0, OUT, Y, _STORE[0])
    else:
        def impl(model, b0, t, Y, OUT):
            for j in range(Y.shape[1]):
                derivative(model, t, Y, j, OUT, Y, _STORE[0])
    return impl


def _project(device):
    """The typing function of ``project`` for a spacecraft: ``device``, the variant compiled for a GPU,
    without the flight software (refused there: ``gpu_refusal``)."""

    def typer(model, b0, t, Y):
        _, sense, sample, due, constrain = _assemble(Y.ndim, _python(model), device)
        if Y.ndim == 1:
            normalize, lanes = _protocol.normalize_quaternion, inline(lambda Y: 1)
        else:
            normalize, lanes = _protocol.normalize_quaternions, inline(lambda Y: Y.shape[1])

        def impl(model, b0, t, Y):
            normalize(Y)
            for j in range(lanes(Y)):  # the parts' constraints; the flight software's sensors at their sample times
                constrain(model, Y, j)
                sense(model, t, Y, j)
            updates = due(model, t)  # the laws held at their sample times t₀ + k·period, the parts' updates
            if updates:
                for j in range(lanes(Y)):
                    sample(model, t, Y, j, updates)
        return impl

    return typer


_protocol.implements(_protocol.project, SpacecraftModel)(_project(device=False))
_protocol.implements(_protocol.project, SpacecraftModel, target="cuda")(_project(device=True))


@_protocol.implements(_protocol.state_size, SpacecraftModel)
def _spacecraft_state_size(model):
    return lambda model: model.size


@_protocol.implements(_protocol.body_rate, SpacecraftModel, inline=True)
def _spacecraft_body_rate(model, Y, j):
    return _protocol.rate_at(4, Y)


def _evaluate(model, t, y, aux):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_evaluate, jit_options={"cache": True})
def _evaluate_overload(model, t, y, aux):
    derivative, _, _, _, _ = _assemble(1, _python(model))

    def impl(model, t, y, aux):
        out = np.empty(y.shape[1])
        for k in range(y.shape[0]):
            derivative(model, t[k], y[k], 0, out, aux[k], _STORE[1])

    return impl


def _sample(model, t, y):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_sample, jit_options={"cache": True})
def _sample_overload(model, t, y):
    _, sense, sample, due, _ = _assemble(1, _python(model))

    def impl(model, t, y):
        for j in range(1):  # j an int64, as in the projection: a literal 0 would compile these once more
            sense(model, t, y, j)
            sample(model, t, y, j, due(model, t))

    return impl


@njit(cache=True)
def evaluate(model, t, y, aux):
    """Diagnostics of the samples ``y`` (n, state) at the times ``t`` (n,) into ``aux`` (n, ``model.aux_size``)."""
    _evaluate(model, t, y, aux)


@njit(cache=True)
def initialise(model, t, y):
    """Apply the discrete updates of the start time ``t`` (s) to the state vector ``y``: the sensors' first
    readings, the commands held from the first sample, the PWPF triggers."""
    _sample(model, t, y)


# Blocks behind function pointers (tumble._block): a batch of spacecraft runs the block drivers compiled once per
# method; the assembled right-hand side and discrete updates of a block compile once, in these functions, for every
# method. Two variants, as the kernel type has two (``python_calls``): without and with a Python function.

_PART_KINDS = len(PARTS)  # a global: a compile-time constant, the length of the tuple of the parts' fields


def _pack_flat(model) -> tuple[np.ndarray, np.ndarray]:
    """``(data, ints)``: the spacecraft's ``data`` itself and its int64 fields (``route``, ``size``, ``aux_size``,
    ``torque_at``, ``torque_terms``, then each kind of :data:`PARTS`)."""
    scalars = [model.route, model.size, model.aux_size, model.torque_at, model.torque_terms]
    return model.data, np.array(scalars + [getattr(model, kind) for kind in PARTS], dtype=np.int64)


@njit(cache=True)
def _unpack(data, ints):
    """The :class:`SpacecraftModel` without Python functions whose fields are :func:`_pack_flat`'s."""
    return SpacecraftModel(data, ints[0], ints[1], ints[2], ints[3], ints[4], None,
                           *to_fixed_tuple(ints[5:], _PART_KINDS))


@njit(cache=True)
def _unpack_calling(data, ints):
    """The :class:`SpacecraftModel` with a Python function (``python_calls`` 1) whose fields are
    :func:`_pack_flat`'s."""
    return SpacecraftModel(data, ints[0], ints[1], ints[2], ints[3], ints[4], 1,
                           *to_fixed_tuple(ints[5:], _PART_KINDS))


def block_rhs(t, Y, OUT, data, ints):
    """The right-hand side of a block of spacecraft (:data:`tumble._block.RHS`)."""
    _protocol.rhs(_unpack(data, ints), 0, t, Y, OUT)


def block_project(t, Y, data, ints):
    """The projection and discrete updates of a block of spacecraft (:data:`tumble._block.PROJECT`)."""
    _protocol.project(_unpack(data, ints), 0, t, Y)


def block_rhs_calling(t, Y, OUT, data, ints):
    """:func:`block_rhs` of a spacecraft with a Python function."""
    _protocol.rhs(_unpack_calling(data, ints), 0, t, Y, OUT)


def block_project_calling(t, Y, data, ints):
    """:func:`block_project` of a spacecraft with a Python function."""
    _protocol.project(_unpack_calling(data, ints), 0, t, Y)


_block.register_variants(
    SpacecraftModel, _pack_flat,
    lambda model: ((block_rhs_calling, block_project_calling, _block.rate_at_4) if model.python_calls
                   else (block_rhs, block_project, _block.rate_at_4)))
