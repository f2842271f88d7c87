"""Classical fourth-order Runge–Kutta with a fixed step that lands on every output time.

The steps are those of :func:`tumble.integrate._fixed.landing_steps`: never
longer than the requested ``dt``, ending exactly on each output time. The
quaternion is normalised after every step.

Tableau (Kutta 1901)::

    k₁ = f(t, y)            k₂ = f(t + h/2, y + h k₁/2)
    k₃ = f(t + h/2, y + h k₂/2)   k₄ = f(t + h, y + h k₃)
    y ← y + h (k₁ + 2k₂ + 2k₃ + k₄)/6
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba.extending import register_jitable

from tumble import _protocol
from tumble._protocol import project, rhs, state_size
from tumble.integrate import _fixed

ORDER = 4


# Not inline="always": numba-cuda (0.68) binds the arguments of an IR-inlined register_jitable
# as omitted ones on a real GPU (the CUDA simulator does not compile); LLVM inlines it anyway.
@register_jitable
def weighted_sum(h, k1, k2, k3, k4):
    """``h (k₁ + 2k₂ + 2k₃ + k₄)/6``: the RK4 increment from the four stage slopes (scalars or arrays).

    The one place of the tableau's weights, used by the CPU step below, the
    torque kicks of :mod:`._exactsplit` and the GPU step of :mod:`._cuda`.
    """
    return h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


class RK4(NamedTuple):
    """The classical Runge–Kutta scheme (no parameters)."""


SCHEME = RK4()



@_protocol.implements(_fixed.workspace, RK4)
def _rk4_workspace(scheme, model, Y):
    return lambda scheme, model, Y: (np.empty_like(Y), np.empty_like(Y), np.empty_like(Y), np.empty_like(Y),
                                     np.empty_like(Y))


@_protocol.implements(_fixed.advance, RK4, inline=True)
def _rk4_advance(scheme, model, b0, t0, h, m, Y, work):

    def impl(scheme, model, b0, t0, h, m, Y, work):
        k1, k2, k3, k4, tmp = work
        # flat views: each stage update is one loop over state × lanes (contiguous, vectorised)
        y_, k1_, k2_, k3_, k4_, tmp_ = Y.ravel(), k1.ravel(), k2.ravel(), k3.ravel(), k4.ravel(), tmp.ravel()
        # a compile-time constant for one body, so LLVM unrolls the stage loops
        size = state_size(model) if Y.ndim == 1 else Y.size
        for s in range(m):
            t = t0 + s * h
            rhs(model, b0, t, Y, k1)
            for i in range(size):
                tmp_[i] = y_[i] + 0.5 * h * k1_[i]
            rhs(model, b0, t + 0.5 * h, tmp, k2)
            for i in range(size):
                tmp_[i] = y_[i] + 0.5 * h * k2_[i]
            rhs(model, b0, t + 0.5 * h, tmp, k3)
            for i in range(size):
                tmp_[i] = y_[i] + h * k3_[i]
            rhs(model, b0, t + h, tmp, k4)
            for i in range(size):
                y_[i] += weighted_sum(h, k1_[i], k2_[i], k3_[i], k4_[i])
            project(model, b0, t + h, Y)

    return impl
