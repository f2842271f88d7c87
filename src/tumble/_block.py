"""Blocks of bodies behind function pointers: the drivers of a batch compiled once per method, for every kind.

A kind that gives its block functions (:func:`register`) runs its batches and sweeps through one kernel type,
:class:`BlockModel`: its parameters packed as one float64 array ``data`` and one int64 array ``ints``, and the
addresses of its compiled functions, each of one signature for every kind (a block ``Y`` is state × lanes,
C-contiguous; ``data``, ``ints`` the kind's packed parameters)::

    rhs(t, Y, OUT, data, ints)      OUT[:, j] = dy/dt of lane j at (t, Y[:, j])              (RHS)
    project(t, Y, data, ints)       after a step that ends at t: back onto the state manifold (PROJECT)
    body_rate(Y, W, data, ints)     W[:, j] = (ω₁, ω₂, ω₃) of lane j (rad/s, body axes)      (BODY_RATE)

:class:`BlockModel` implements the protocol of :mod:`tumble._protocol` (``rhs``, ``project`` on a block, and
:func:`body_rates`) by calling those functions, so a fixed-step driver (``run_block``, ``run_batch`` of
:mod:`tumble.integrate._fixed`, with a method's scheme) is typed and compiled once for all of them, and a kind
compiles only its own functions, once, for every method. Each rebuilds the kind's kernel NamedTuple from views
of ``data`` and ``ints`` (:func:`matrix_view`) and calls the kind's own ``derivative``: the same arithmetic in
the same order as the inlined path, so results are equal bit for bit. The functions take no member index: a
registered kind's kernel is one for every member of its batch (its own ``rhs`` ignores ``b0``, as the kernels of
those kinds do); a kind whose members have rows of their own (the rigid body's) keeps its own kernel.

Where it does not apply (named in :func:`block_model`): a lone body keeps the right-hand side inlined into its
driver (behind a pointer its step costs +16 … +60 %: the call boundary, five calls a step, which a block of 64
lanes shares), and so do the fused rigid-body kernels (lanes as SIMD lanes in registers) and every kernel
compiled for a GPU (``numba.cuda`` has no first-class functions).

Numba internals this module relies on (checked by ``tests/test__block.py``, which runs a kind through a driver):
``numba.experimental.function_type._get_jit_address`` and ``_get_wrapper_address`` (the compiled code of a
dispatcher's one signature, looked up once per process), and the fields ``jit_addr``, ``c_addr`` and
``py_addr`` of the data model of :class:`numba.types.FunctionType`, which :func:`function_at` fills inside
compiled code (given a dispatcher as an argument, a compiled function looks both addresses up in Python at every
call: 70 µs).
"""

from __future__ import annotations

from typing import Any, Callable, NamedTuple

import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

from tumble import _protocol

_F8, _I8 = types.float64, types.int64
BLOCK, FLOATS, INTS = _F8[:, ::1], _F8[::1], _I8[::1]

#: The one signature of every kind's block right-hand side, projection and body rates.
RHS = types.FunctionType(types.void(_F8, BLOCK, BLOCK, FLOATS, INTS))
PROJECT = types.FunctionType(types.void(_F8, BLOCK, FLOATS, INTS))
BODY_RATE = types.FunctionType(types.void(BLOCK, BLOCK, FLOATS, INTS))
SIGNATURES = (RHS, PROJECT, BODY_RATE)


class BlockModel(NamedTuple):
    """A kernel as data and addresses (the one kernel type of every registered kind's blocks).

    functions : (6,) int64, the compiled code and C wrapper of the kind's rhs, project and body rate
    data      : (d,) float64, the kind's parameters (its ``pack``)
    ints      : (i,) int64, the kind's sizes and codes (its ``pack``)
    """

    functions: np.ndarray
    data: np.ndarray
    ints: np.ndarray


def function_at(ftype):
    """An intrinsic ``at(jit_address, wrapper_address) -> ftype``: the first-class function whose compiled code
    is at those addresses (int64), made inside compiled code as Numba's unboxing of a dispatcher makes it."""

    @intrinsic
    def at(typingctx, jit_address, wrapper_address):
        def codegen(context, builder, signature, args):
            function = cgutils.create_struct_proxy(ftype)(context, builder)
            pointer = context.get_value_type(types.voidptr)
            function.jit_addr = builder.inttoptr(args[0], pointer)  # called with Numba's convention
            function.c_addr = builder.inttoptr(args[1], pointer)
            function.py_addr = pointer(None)
            return function._getvalue()

        return ftype(types.int64, types.int64), codegen

    return at


_rhs_at, _project_at, _body_rate_at = (function_at(ftype) for ftype in SIGNATURES)


@intrinsic
def matrix_view(typingctx, flat, start, rows, cols):
    """``flat[start:start + rows·cols]`` as a C-contiguous (rows, cols) view of the same memory, made inline.

    (``ndarray.reshape`` calls a C helper of Numba at every call, which LLVM cannot inline: 200–300 ns a step
    when a kernel is rebuilt at every right-hand side.)
    """
    matrix = types.Array(types.float64, 2, "C")

    def codegen(context, builder, signature, args):
        source = make_array(signature.args[0])(context, builder, args[0])
        view = make_array(matrix)(context, builder)
        itemsize = context.get_constant(types.intp, 8)
        populate_array(view, data=builder.gep(source.data, [args[1]]), shape=[args[2], args[3]],
                       strides=[builder.mul(args[3], itemsize), itemsize], itemsize=itemsize,
                       meminfo=source.meminfo, parent=source.parent)
        return impl_ret_borrowed(context, builder, matrix, view._getvalue())

    return matrix(flat, types.intp, types.intp, types.intp), codegen


@intrinsic
def array_view(typingctx, flat, start, shape):
    """``flat[start:start + prod(shape)]`` as a C-contiguous array of ``shape`` (a tuple of integers) sharing
    its memory, made inline as :func:`matrix_view`."""
    ndim = len(shape)
    array = types.Array(types.float64, ndim, "C")

    def codegen(context, builder, signature, args):
        source = make_array(signature.args[0])(context, builder, args[0])
        view = make_array(array)(context, builder)
        itemsize = context.get_constant(types.intp, 8)
        dims = [context.cast(builder, dim, kind, types.intp)
                for dim, kind in zip(cgutils.unpack_tuple(builder, args[2]), signature.args[2])]
        strides = [itemsize]
        for dim in reversed(dims[1:]):
            strides.insert(0, builder.mul(strides[0], dim))
        populate_array(view, data=builder.gep(source.data, [args[1]]), shape=dims, strides=strides,
                       itemsize=itemsize, meminfo=source.meminfo, parent=source.parent)
        return impl_ret_borrowed(context, builder, array, view._getvalue())

    return array(flat, types.intp, shape), codegen


def torque_pieces(kernel) -> tuple[list[np.ndarray], list[int]]:
    """A kernel's torque program (``params`` (rows, p), ``codes`` (c,), or None: none) as flat float pieces and
    the ints ``[rows, p, c, codes…]`` that :func:`torque_views` reads back."""
    rows, width = kernel.params.shape
    codes = () if kernel.codes is None else kernel.codes
    return [kernel.params.ravel()], [rows, width, len(codes), *codes]


@njit(cache=True, inline="always")
def torque_views(data, start, ints, at):
    """``(params, codes)``: the views of a torque program packed by :func:`torque_pieces`, its floats at
    ``data[start:]`` and its ints at ``ints[at:]``."""
    rows, width, count = ints[at], ints[at + 1], ints[at + 2]
    return matrix_view(data, start, rows, width), ints[at + 3:at + 3 + count]


class Kind(NamedTuple):
    """A registered kind: ``pack(kernel) -> (data, ints)`` and ``functions(kernel)``, its block functions for
    that kernel (Python functions of the signatures :data:`SIGNATURES`, compiled on first use)."""

    pack: Callable[[Any], tuple[np.ndarray, np.ndarray]]
    functions: Callable[[Any], tuple[Callable, Callable, Callable | None]]


#: kernel class -> its :class:`Kind` (filled by the kernel modules at import).
_KINDS: dict[type, Kind] = {}
#: Python function -> its compiled dispatcher (a function shared by kinds compiles once).
_COMPILED: dict[Callable, Any] = {}
#: (rhs, project, body rate) -> the addresses of their compiled code (looked up once per process).
_ADDRESSES: dict[tuple, np.ndarray] = {}


def register(cls: type, pack: Callable, rhs: Callable, project: Callable, body_rate: Callable | None) -> None:
    """Register the kernel class ``cls``: its ``pack`` and its block functions (see the module docstring);
    ``body_rate`` None for a kind without (its kernel does not provide ``"body_rate"``, so no method that needs
    it runs the kind: the address is 0)."""
    _KINDS[cls] = Kind(pack, lambda kernel: (rhs, project, body_rate))


def register_variants(cls: type, pack: Callable, functions: Callable) -> None:
    """Register the kernel class ``cls`` whose block functions depend on the kernel: ``functions(kernel) ->
    (rhs, project, body_rate)`` (a spacecraft with Python control laws keeps reference counts)."""
    _KINDS[cls] = Kind(pack, functions)


def compiled(function: Callable, ftype) -> Any:
    """The dispatcher of ``function`` compiled now with the signature of ``ftype`` (once per process; cached on
    disk), with NumPy's error model as the drivers."""
    if function not in _COMPILED:
        _COMPILED[function] = njit(ftype.signature, cache=True, error_model="numpy")(function)
    return _COMPILED[function]


def addresses(functions: tuple[Callable, Callable, Callable | None]) -> np.ndarray:
    """``[rhs's code, its C wrapper, project's …, body rate's …]`` (int64) of a kind's block ``functions``,
    compiled and looked up once per process."""
    if functions not in _ADDRESSES:
        from numba.experimental.function_type import _get_jit_address, _get_wrapper_address

        found = []
        for function, ftype in zip(functions, SIGNATURES):
            if function is None:
                found += [0, 0]
                continue
            dispatcher = compiled(function, ftype)
            found += [lookup(dispatcher, ftype.signature) for lookup in (_get_jit_address, _get_wrapper_address)]
        _ADDRESSES[functions] = np.array(found, dtype=np.int64)
    return _ADDRESSES[functions]


def block_model(kernel) -> Any:
    """The kernel a batch runs: the :class:`BlockModel` of a registered kind, else ``kernel`` itself (its
    overloads inlined into every driver: the kinds not registered — the fused rigid bodies, the robot … —
    and every lone body, which the drivers run on its state vector)."""
    kind = _KINDS.get(type(kernel))
    if kind is None:
        return kernel
    data, ints = kind.pack(kernel)
    return BlockModel(addresses(kind.functions(kernel)), np.ascontiguousarray(data, dtype=np.float64),
                      np.ascontiguousarray(ints, dtype=np.int64))


# The protocol of BlockModel: each a call of the kind's function (blocks only; a lone body never runs it).


def body_rates(model, Y, W):  # pragma: no cover - replaced by overloads in compiled code
    """``W[:, j] = body_rate(model, Y, j)`` for every lane ``j`` of the block ``Y`` (or the state vector ``Y``,
    ``W`` then (3,)): the stage rates of the Lie-group method."""
    raise NotImplementedError("compiled code only")


@_protocol.implements(_protocol.rhs, BlockModel, inline=True)
def _block_rhs(model, b0, t, Y, OUT):
    def impl(model, b0, t, Y, OUT):
        f = model.functions
        _rhs_at(f[0], f[1])(t, Y, OUT, model.data, model.ints)

    return impl


@_protocol.implements(_protocol.project, BlockModel, inline=True)
def _block_project(model, b0, t, Y):
    def impl(model, b0, t, Y):
        f = model.functions
        _project_at(f[2], f[3])(t, Y, model.data, model.ints)

    return impl


@_protocol.implements(_protocol.state_size, BlockModel)
def _block_state_size(model):
    # never reached: a block's loops run over Y.size (the drivers read state_size for a lone body only)
    return lambda model: -1


@_protocol.implements(body_rates, BlockModel, inline=True)
def _block_body_rates(model, Y, W):
    def impl(model, Y, W):
        f = model.functions
        _body_rate_at(f[4], f[5])(Y, W, model.data, model.ints)

    return impl


# Block functions shared by kinds.


def quaternion_project(t, Y, data, ints):
    """``project`` of a kind whose only constraint is the unit quaternion ``Y[0:4]``."""
    _protocol.normalize_quaternions(Y)


@njit(cache=True, inline="always")
def lane_rates(model, Y, W):
    """``W[:, j] = body_rate(model, Y, j)``, the body rate (rad/s, body axes) of every lane ``j`` of the block
    ``Y``, by the kind's own ``body_rate``: the body of a kind's ``BODY_RATE`` function after its ``unpack``."""
    for j in range(Y.shape[1]):
        W[0, j], W[1, j], W[2, j] = _protocol.body_rate(model, Y, j)


def rate_at_4(Y, W, data, ints):
    """``body_rate`` of a kind that stores ``(ω₁, ω₂, ω₃)`` at ``Y[4:7]``."""
    for j in range(Y.shape[1]):
        W[0, j], W[1, j], W[2, j] = Y[4, j], Y[5, j], Y[6, j]
