"""Fused fixed steps: a method's whole step on one body's state held in registers.

A kernel that gives its right-hand side on one body's state as a 7-tuple
(``point_rates``, :mod:`tumble._protocol`: state ``[q_NP, ω_P]``, body rate
``ω``, projection ``q ← q/|q|``) lets a fixed-step method write its step as
one function of that tuple, ``point_step(model, r, t, h, y) -> y`` (row ``r`` of
the kernel's parameters). :func:`advance` turns such a step into the
method's ``advance``: one body runs its ``m`` steps in registers; a block runs
one step per pass over its lanes, each lane in registers and the lanes as
SIMD lanes. ``rk4`` (:mod:`._rk4`) and ``cf4`` (:mod:`._liegroup`) run so.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tumble._protocol import members, uniform
from tumble.integrate._fixed import LANES as W  # lanes of a block: the stride of the buffer x


def workspace(model, Y):
    """The scratch of a fused ``advance`` (an overload's implementation): none for one body; for a block,
    the buffer of its lanes at the fixed stride ``W`` and the block's own rows of a non-uniform model."""
    if Y.ndim == 1:
        return lambda scheme, model, b0, Y: ()
    return lambda scheme, model, b0, Y: (np.empty(7 * W),
                                         model if uniform(model) else members(model, b0, b0 + Y.shape[1]))


def counts_references(model) -> bool:
    """Whether the passes over the lanes of ``model`` (the Numba type of a kernel with ``point_rates``) need
    reference counting: when its kind declares that its compiled code may call a Python function, which
    allocates (``may_call_python``, :mod:`tumble._protocol`; the rigid body: with a torque program)."""
    return model.instance_class.may_call_python(model)


def advance(point_step):
    """The typing function of the ``advance`` overload of a method whose step is ``point_step`` (an
    ``inline="always"`` function of a 7-tuple): it returns the implementation for ``Y`` and ``model``.

    A block's lanes are copied into a buffer where component ``i`` of lane ``j`` is ``x[i·W + j]``: with
    a stride known at compile time LLVM sees that the lanes of one pass are independent and vectorises
    the pass (with the block's own run-time stride it does not). Lane ``j`` reads row ``j`` of the
    block's own kernel (:func:`tumble._protocol.members`), or row 0 of a uniform one: indices from 0,
    which LLVM reads as contiguous vectors (from ``b0`` it did not).

    The passes over the lanes are one function, compiled without reference counting for a model whose
    compiled code calls no Python function (:func:`counts_references`), so that the copy compiled on its
    own is vectorised: the step, IR-inlined, binds the model's arrays again in every call, and the
    increments and decrements of their counts, split across the status branches of its helpers' calls,
    were still in the lane loop when LLVM's one ``-O3`` round tried to vectorise it. The process that
    compiles a batch runs that copy (docs/architecture.md): it ran 5× slower than one loading the cached
    code, and now runs as fast. A model whose code may call Python (the rigid body's torque program)
    keeps the counts, since a Python function allocates.
    """

    def lane_steps(model, block, shared, t0, h, m, x, lanes):
        # two loops, so that shared parameters are a broadcast and per-member ones a contiguous load
        for s in range(m):
            t = t0 + s * h
            if shared:
                for j in range(lanes):
                    (x[j], x[W + j], x[2 * W + j], x[3 * W + j], x[4 * W + j], x[5 * W + j], x[6 * W + j]) = (
                        point_step(model, 0, t, h, (x[j], x[W + j], x[2 * W + j], x[3 * W + j], x[4 * W + j],
                                                    x[5 * W + j], x[6 * W + j])))
            else:
                for j in range(lanes):
                    (x[j], x[W + j], x[2 * W + j], x[3 * W + j], x[4 * W + j], x[5 * W + j], x[6 * W + j]) = (
                        point_step(block, j, t, h, (x[j], x[W + j], x[2 * W + j], x[3 * W + j], x[4 * W + j],
                                                    x[5 * W + j], x[6 * W + j])))

    counted = njit(error_model="numpy")(lane_steps)
    counted_not = njit(_nrt=False, error_model="numpy")(lane_steps)

    def typing(Y, model):
        if Y.ndim == 1:

            def one(scheme, model, b0, t0, h, m, Y, work):
                r = 0 if uniform(model) else b0
                y = (Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6])
                for s in range(m):
                    y = point_step(model, r, t0 + s * h, h, y)
                Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6] = y

            return one

        passes = counted if counts_references(model) else counted_not

        def block(scheme, model, b0, t0, h, m, Y, work):
            x, rows = work
            lanes = Y.shape[1]
            for i in range(7):
                for j in range(lanes):
                    x[i * W + j] = Y[i, j]
            passes(model, rows, uniform(model), t0, h, m, x, lanes)
            for i in range(7):
                for j in range(lanes):
                    Y[i, j] = x[i * W + j]

        return block

    return typing
