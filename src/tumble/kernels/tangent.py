"""The heavy top in Euler–Poisson variables with its variational (tangent) equations, for Lyapunov exponents.

State ``y = [ω (3), γ (3), δ₁ (6), …, δ_k (6)]`` in the body's principal
axes P: the body rate ``ω`` (rad/s), the upward unit vertical ``γ`` and ``k``
tangent vectors ``δⱼ = (δωⱼ, δγⱼ)``. With the principal moments ``I`` and
``w = m g r`` (N·m, the weight times the centre of mass from the pivot, in P)
the motion and its linearisation are (:mod:`tumble.analytic._integrable`)::

    I ω̇  = (I ω) × ω + γ × w,              γ̇  = γ × ω
    I δω̇ = (I δω) × ω + (I ω) × δω + δγ × w,   δγ̇ = δγ × ω + γ × δω

The flow is divergence-free (``∂ω̇ᵢ/∂ωᵢ = ∂γ̇ᵢ/∂γᵢ = 0``), so the six Lyapunov
exponents sum to zero. The kernel provides the core protocol (``rhs``,
``project``: nothing to project, ``state_size``), on a state vector or a block
of them: :mod:`tumble.measure._lyapunov` runs it through the engine
(:class:`tumble.integrate.Run`) with any method that needs no more.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from tumble import _protocol
from tumble._vec import cross


class TangentModel(NamedTuple):
    """A heavy top in principal axes and the number of tangent vectors carried with it.

    moments : (3,) principal moments about the pivot, kg·m²
    weight  : (3,) ``m g r`` in principal axes, N·m (zero for the Euler top)
    count   : the number ``k`` of tangent vectors (1 to 6)
    """

    moments: np.ndarray
    weight: np.ndarray
    count: int

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): the core protocol only."""
        return frozenset({"rhs"})

    @property
    def calls_python(self) -> bool:
        """Never: the right-hand side is compiled."""
        return False


@njit(cache=True, error_model="numpy")
def derivative(model, t, Y, OUT):
    """``OUT = dy/dt`` of one state vector ``Y = [ω, γ, δ₁, …, δ_k]`` (the equations above)."""
    i1, i2, i3 = model.moments[0], model.moments[1], model.moments[2]
    w1, w2, w3 = model.weight[0], model.weight[1], model.weight[2]
    o1, o2, o3, g1, g2, g3 = Y[0], Y[1], Y[2], Y[3], Y[4], Y[5]
    l1, l2, l3 = i1 * o1, i2 * o2, i3 * o3
    a1, a2, a3 = cross(l1, l2, l3, o1, o2, o3)
    b1, b2, b3 = cross(g1, g2, g3, w1, w2, w3)
    OUT[0], OUT[1], OUT[2] = (a1 + b1) / i1, (a2 + b2) / i2, (a3 + b3) / i3
    OUT[3], OUT[4], OUT[5] = cross(g1, g2, g3, o1, o2, o3)
    for j in range(model.count):
        s = 6 + 6 * j
        d1, d2, d3, e1, e2, e3 = Y[s], Y[s + 1], Y[s + 2], Y[s + 3], Y[s + 4], Y[s + 5]
        a1, a2, a3 = cross(i1 * d1, i2 * d2, i3 * d3, o1, o2, o3)
        b1, b2, b3 = cross(l1, l2, l3, d1, d2, d3)
        c1, c2, c3 = cross(e1, e2, e3, w1, w2, w3)
        OUT[s], OUT[s + 1], OUT[s + 2] = (a1 + b1 + c1) / i1, (a2 + b2 + c2) / i2, (a3 + b3 + c3) / i3
        a1, a2, a3 = cross(e1, e2, e3, o1, o2, o3)
        b1, b2, b3 = cross(g1, g2, g3, d1, d2, d3)
        OUT[s + 3], OUT[s + 4], OUT[s + 5] = a1 + b1, a2 + b2, a3 + b3


@_protocol.implements(_protocol.rhs, TangentModel)
def _tangent_rhs(model, b0, t, Y, OUT):
    return _protocol.lanewise_rhs(derivative, Y)


@_protocol.implements(_protocol.project, TangentModel)
def _tangent_project(model, b0, t, Y):
    return lambda model, b0, t, Y: None  # |γ| = 1 is kept by the flow; projecting would bend the tangents


@_protocol.implements(_protocol.state_size, TangentModel)
def _tangent_state_size(model):
    return lambda model: 6 + 6 * model.count
