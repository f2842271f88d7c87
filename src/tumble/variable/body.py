"""A body that changes shape: its inertia ``I(t)`` and shape momentum ``A(t)`` as functions of time.

The angular momentum of a deformable body about its centre of mass, in the
axes of a body frame B that moves with it (the trunk of a diver, the hub of a
spacecraft), splits into the part the body would have if it were frozen in
its current shape and the part of the shape change itself::

    L_B = I(t) ω + A(t)

``I(t)`` (kg·m², B axes) is the inertia tensor of the current shape about the
current centre of mass and ``A(t)`` (kg·m²/s, B axes) is the angular momentum
of the motion of the parts relative to B (see :mod:`tumble.variable.human`
for a body made of segments). Both are sampled on a time grid and
interpolated by cubic splines, component by component (scipy's
:class:`~scipy.interpolate.CubicSpline`, not-a-knot end conditions): the
interpolation error is ``O(h⁴)`` for a grid step ``h`` (de Boor, *A Practical
Guide to Splines*, 2001, ch. V: ``‖f − s‖∞ ≤ (5/384) h⁴ ‖f⁗‖∞`` for the
complete spline), so a compiled right-hand side evaluates them without
calling back into Python.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.interpolate import CubicSpline

from tumble._validate import ValidationError, as_array, require_positive
from tumble._inertia import frozen, principal_axes

__all__ = ["VariableBody"]

# I components in the spline channels: xx, yy, zz, xy, xz, yz; then A_x, A_y, A_z.
_ROWS = np.array([0, 1, 2, 0, 0, 1])
_COLS = np.array([0, 1, 2, 1, 2, 2])


class VariableBody:
    """Inertia ``I(t)`` and shape momentum ``A(t)`` of a deformable body, interpolated from samples.

    ``VariableBody(t, inertia, shape_momentum=None, *, check_triangle=True)``

    t : (m,) strictly increasing sample times, s (m ≥ 4: a cubic needs four)
    inertia : (m, 3, 3) inertia tensors about the centre of mass, kg·m², body axes;
        each symmetric, positive definite and obeying the triangle inequality
        ``I₁ + I₂ ≥ I₃`` of its principal moments (the rules of :class:`tumble.RigidBody`;
        refused otherwise, naming the sample and its time)
    shape_momentum : (m, 3) internal angular momentum ``A`` of the shape change,
        kg·m²/s, body axes; ``None`` for zero (a body whose parts do not move
        relative to B, e.g. a rigid body with a prescribed ``I(t)``)
    check_triangle : False accepts samples whose moments break ``I₁ + I₂ ≥ I₃``
        (published data that round across it), as in :class:`tumble.RigidBody`

    The body is defined on ``[t[0], t[-1]]`` only: simulations outside it are
    refused. Between samples ``I`` and ``A`` are cubic splines (error
    ``O(h⁴)``); the splines are checked to stay positive definite at the
    samples only, so sample a shape change finely enough to resolve it.
    """

    __slots__ = ("_t", "_inertia", "_shape_momentum", "_spline")

    def __init__(self, t, inertia, shape_momentum=None, *, check_triangle: bool = True):
        t = as_array(t, "t")
        if t.ndim != 1 or t.size < 4:
            raise ValidationError(f"t: must be a 1-D array of at least 4 sample times, got shape {t.shape}")
        steps = np.diff(t)
        if np.any(steps <= 0.0):
            k = int(np.flatnonzero(steps <= 0.0)[0])
            raise ValidationError(f"t: sample times must be strictly increasing (t[{k + 1}] = {t[k + 1]} "
                                  f"<= t[{k}] = {t[k]})")
        inertia = as_array(inertia, "inertia", tail=(3, 3))
        if inertia.shape != (t.size, 3, 3):
            raise ValidationError(f"inertia: must have shape ({t.size}, 3, 3) (one tensor per sample time), "
                                  f"got {inertia.shape}")
        inertia = _check_tensors(t, inertia, check_triangle)
        if shape_momentum is None:
            shape_momentum = np.zeros((t.size, 3))
        shape_momentum = as_array(shape_momentum, "shape_momentum", tail=(3,))
        if shape_momentum.shape != (t.size, 3):
            raise ValidationError(f"shape_momentum: must have shape ({t.size}, 3), got {shape_momentum.shape}")
        channels = np.concatenate([inertia[:, _ROWS, _COLS], shape_momentum], axis=1)
        self._t = frozen(t)
        self._inertia = frozen(inertia)
        self._shape_momentum = frozen(shape_momentum)
        self._spline = CubicSpline(t, channels, axis=0, bc_type="not-a-knot")

    @classmethod
    def from_functions(cls, inertia: Callable, shape_momentum: Callable | None = None, *,
                       t_span, dt: float, check_triangle: bool = True) -> VariableBody:
        """Sample ``inertia(t) -> (n, 3, 3)`` and ``shape_momentum(t) -> (n, 3)`` (vectorised in ``t``, s).

        The samples lie on a uniform grid of step ≤ ``dt`` (s) over ``t_span = (t0, t1)``;
        the interpolation error scales as ``dt⁴``.
        """
        t = cls.grid(t_span, dt)
        return cls(t, inertia(t), None if shape_momentum is None else shape_momentum(t),
                   check_triangle=check_triangle)

    @staticmethod
    def grid(t_span, dt: float) -> np.ndarray:
        """A uniform grid over ``t_span = (t0, t1)`` (s) with step ≤ ``dt`` (s) and at least 4 points."""
        t0, t1 = (float(x) for x in t_span)
        if not t1 > t0:
            raise ValidationError(f"t_span: must be (t0, t1) with t1 > t0, got {t_span}")
        n = max(4, int(np.ceil((t1 - t0) / require_positive(dt, "dt") - 1e-9)) + 1)
        return np.linspace(t0, t1, n)

    # -- samples -------------------------------------------------------------------

    @property
    def t(self) -> np.ndarray:
        """Sample times (m,), s."""
        return self._t

    @property
    def t_span(self) -> tuple[float, float]:
        """``(t[0], t[-1])``: the interval on which the body is defined, s."""
        return float(self._t[0]), float(self._t[-1])

    @property
    def samples(self) -> tuple[np.ndarray, np.ndarray]:
        """The sampled ``(inertia (m, 3, 3), shape_momentum (m, 3))``."""
        return self._inertia, self._shape_momentum

    # -- interpolants ------------------------------------------------------------------

    def inertia(self, t, nu: int = 0) -> np.ndarray:
        """``I(t)`` (kg·m², body axes) or its ``nu``-th time derivative, by the spline: ``t.shape + (3, 3)``."""
        c = self._evaluate(t, nu)[..., :6]
        out = np.empty(c.shape[:-1] + (3, 3))
        out[..., _ROWS, _COLS] = c
        out[..., _COLS, _ROWS] = c
        return out

    def shape_momentum(self, t, nu: int = 0) -> np.ndarray:
        """``A(t)`` (kg·m²/s, body axes), or its ``nu``-th time derivative; shape ``t.shape + (3,)``."""
        return self._evaluate(t, nu)[..., 6:]

    def _evaluate(self, t, nu):
        t = self.check_times(t)
        return self._spline(t, nu)

    def check_times(self, t) -> np.ndarray:
        """``t`` as a float64 array, refused unless every time lies in :attr:`t_span`."""
        t = as_array(t, "t")
        t0, t1 = self.t_span
        outside = (t < t0) | (t > t1)
        if np.any(outside):
            bad = float(t[outside].flat[0])
            raise ValidationError(f"t: {bad} s lies outside the span [{t0}, {t1}] s on which the body's "
                                  "inertia is given (no extrapolation)")
        return t

    def piecewise(self) -> tuple[np.ndarray, np.ndarray]:
        """The spline as ``(breaks (m,), coefficients (m − 1, 4, 9))`` for compiled code.

        On ``[breaks[k], breaks[k+1]]`` channel ``c`` is
        ``Σₚ coefficients[k, p, c] (t − breaks[k])^(3 − p)``; the channels are
        ``I_xx, I_yy, I_zz, I_xy, I_xz, I_yz, A_x, A_y, A_z``.
        """
        return (np.ascontiguousarray(self._spline.x),
                np.ascontiguousarray(np.transpose(self._spline.c, (1, 0, 2))))

    def __repr__(self) -> str:
        t0, t1 = self.t_span
        return f"VariableBody(t=[{t0:g}, {t1:g}] s, samples={self._t.size})"


def _check_tensors(t, inertia, check_triangle):
    """The rules of :func:`tumble.body.principal_axes` (symmetric, then symmetrised exactly; positive definite;
    the triangle inequality ``I₁ + I₂ ≥ I₃`` that every mass distribution obeys) at every sample; a broken
    rule is refused naming the sample and its time."""
    return principal_axes(inertia, "inertia", check_triangle=check_triangle,
                          member_note=lambda k: f"sample at t = {t[k[0]]} s")[0]
