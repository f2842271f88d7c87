"""A body that changes shape: its inertia ``I(t)`` and shape momentum ``A(t)``, and its rotation.

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

:class:`VariableBody` is a model of :func:`tumble.simulate`, which solves
the equations of a deformable body in B::

    L_B = I(t) ω + A(t),        dL_B/dt + ω × L_B = τ_B,        q̇ = ½ q ⊗ [0, ω]

(Euler's law ``dL/dt = τ`` for the angular momentum about the centre of mass,
written in the rotating axes of B), as the compiled model of
:mod:`tumble.kernels.variable`: the state holds ``L`` in inertial axes, which
no integrator changes when there is no torque, so ``|L|`` is conserved to
rounding. The rotational energy ``T = ½ ω·Iω`` is *not* conserved: the
muscles (or actuators) that change the shape work on the body at the rate

    dT/dt = −ω·Ȧ − ½ ω·İ ω + ω·τ                (see :func:`shape_power`)

which is why a skater who pulls in the arms (İ < 0, A = 0) spins faster and
has more energy.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import CubicSpline

from tumble import attitude, dynamics, torques
from tumble._inertia import frozen, principal_axes
from tumble._validate import ValidationError, as_array, increasing_times, require_positive
from tumble.kernels import variable as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra, Trajectory

if TYPE_CHECKING:
    from tumble import integrate

__all__ = ["VariableBody", "angular_velocity", "shape_power"]

# I components in the spline channels: xx, yy, zz, xy, xz, yz; then A_x, A_y, A_z.
_ROWS = np.array([0, 1, 2, 0, 0, 1])
_COLS = np.array([0, 1, 2, 1, 2, 2])


class VariableBody(Model):
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

    ``tumble.simulate(body, omega0=..., t=..., q0=..., torque=...)`` integrates
    its rotation (module docstring; ``dop853``, ``rk4`` or ``cf4``); the output
    times must lie in :attr:`t_span`. Initial state: ``omega0`` (3,), the rate of B
    relative to inertial, rad/s, B axes (then ``L_B(t₀) = I(t₀) ω₀ + A(t₀)``),
    required; ``q0`` (4,), the attitude of B, body → inertial (default identity);
    each with an optional leading batch axis (N motions of the same body). The
    :class:`~tumble.Trajectory` holds ``q``, ``omega``, ``inertia`` = ``I(t₀)``,
    the extras ``inertia_t`` ``I(t)`` (n, [N,] 3, 3), ``shape_momentum`` ``A(t)``,
    ``angular_momentum`` ``L_B`` and ``energy_rotational`` ``½ ω·I(t)ω`` (J), and
    the totals ``energy`` = ``½ ω·I(t)ω`` and ``momentum_body`` = ``L_B``.
    """

    __slots__ = ("_t", "_inertia", "_shape_momentum", "_spline")

    def __init__(self, t: ArrayLike, inertia: ArrayLike, shape_momentum: ArrayLike | None = None, *,
                 check_triangle: bool = True) -> None:
        t = increasing_times(t, what="sample times", at_least=4)
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
                       t_span: tuple[float, float], dt: float, check_triangle: bool = True) -> VariableBody:
        """Sample ``inertia(t) -> (n, 3, 3)`` and ``shape_momentum(t) -> (n, 3)`` (vectorised in ``t``, s).

        The samples lie on a uniform grid of step ≤ ``dt`` (s) over ``t_span = (t0, t1)``;
        the interpolation error scales as ``dt⁴``.
        """
        t = cls.grid(t_span, dt)
        return cls(t, inertia(t), None if shape_momentum is None else shape_momentum(t),
                   check_triangle=check_triangle)

    @staticmethod
    def grid(t_span: tuple[float, float], dt: float) -> np.ndarray:
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

    def inertia(self, t: ArrayLike, nu: int = 0) -> np.ndarray:
        """``I(t)`` (kg·m², body axes) or its ``nu``-th time derivative, by the spline: ``t.shape + (3, 3)``."""
        c = self._evaluate(t, nu)[..., :6]
        out = np.empty(c.shape[:-1] + (3, 3))
        out[..., _ROWS, _COLS] = c
        out[..., _COLS, _ROWS] = c
        return out

    def shape_momentum(self, t: ArrayLike, nu: int = 0) -> np.ndarray:
        """``A(t)`` (kg·m²/s, body axes), or its ``nu``-th time derivative; shape ``t.shape + (3,)``."""
        return self._evaluate(t, nu)[..., 6:]

    def _evaluate(self, t, nu):
        t = self.check_times(t)
        return self._spline(t, nu)

    def check_times(self, t: ArrayLike) -> np.ndarray:
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
        return f"{type(self).__name__}(t=[{t0:g}, {t1:g}] s, samples={self._t.size})"

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    attitude_in_state = True  # q = Y[0:4], omega = body_rate: made on the GPU with output="device"

    def state_fields(self) -> tuple[StateField, ...]:
        return (
            StateField("omega0", 3, "initial angular velocity of the body frame B, rad/s, B axes"),
            StateField("q0", 4, "initial attitude of B, unit quaternion [w, x, y, z], B → inertial",
                       default=attitude.identity(), quaternion=True),
        )

    def check_run(self, method: integrate.Method, t: np.ndarray, dt: float | None) -> None:
        """Refuse output times outside :attr:`t_span` (the splines are not extrapolated)."""
        self.check_times(t)

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.VariableModel:
        """The compiled model (:class:`tumble.kernels.variable.VariableModel`) under an external torque (B axes)."""
        return _kernel.build(self, torques.as_torque_model(torque))

    def initial_states(self, kernel: _kernel.VariableModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """``[q, L_N, t₀]`` (N, 8), ``L_N = R(q₀) (I(t₀) ω₀ + A(t₀))``: the state of :mod:`tumble.kernels.variable`."""
        q0 = values["q0"]
        momentum = dynamics.angular_momentum(self.inertia(t0), values["omega0"]) + self.shape_momentum(t0)
        return np.concatenate([q0, attitude.rotate(q0, momentum), np.full((q0.shape[0], 1), t0)], axis=1)

    def outputs(self, kernel: _kernel.VariableModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        q = states[..., :4]
        momentum_body = attitude.rotate_inverse(q, states[..., 4:7])              # (n, N, 3)
        inertia_t = np.broadcast_to(self.inertia(t)[:, None], momentum_body.shape + (3,))
        shape_momentum = np.broadcast_to(self.shape_momentum(t)[:, None], momentum_body.shape)
        omega = angular_velocity(inertia_t, shape_momentum, momentum_body)
        energy = dynamics.kinetic_energy(inertia_t, omega)
        extras = {
            "inertia_t": Extra(inertia_t, ("row", "col"), "kg m2", "inertia tensor I(t) about the centre of mass, "
                               "body axes"),
            "shape_momentum": Extra(shape_momentum, ("vec",), "kg m2 s-1", "angular momentum A(t) of the shape "
                                    "change relative to the body frame, body axes"),
            "angular_momentum": Extra(momentum_body, ("vec",), "kg m2 s-1", "angular momentum L = I(t) omega + "
                                      "A(t) about the centre of mass, body axes"),
            "energy_rotational": Extra(energy, (), "J", "rotational energy 0.5 omega.I(t) omega of the body frozen "
                                       "in its current shape"),
        }
        return Outputs(q=q, omega=omega, inertia=self.inertia(t[0]), extras=extras,
                       totals={"energy": energy, "momentum_body": momentum_body}, info={})

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """Without torque the inertial angular momentum ``R(q) L_B`` (not the energy: the shape change works)."""
        if traj.info.get("torque") != "none":
            return {}
        return {"momentum_inertial": traj.momentum_inertial}


def angular_velocity(inertia: ArrayLike, shape_momentum: ArrayLike, momentum_body: ArrayLike) -> np.ndarray:
    """``ω = I⁻¹ (L_B − A)`` (rad/s, body axes) from ``I`` (…, 3, 3), ``A`` and ``L_B`` (…, 3), broadcast."""
    rhs = np.asarray(momentum_body) - np.asarray(shape_momentum)
    inertia = np.broadcast_to(inertia, rhs.shape + (3,))
    return np.linalg.solve(inertia, rhs[..., None])[..., 0]


def shape_power(body: VariableBody, t: ArrayLike, omega: ArrayLike) -> np.ndarray:
    """Power of the shape change on the rotation, W: ``dT/dt = −ω·Ȧ − ½ ω·İ ω`` (torque-free).

    ``T = ½ ω·Iω`` is the rotational energy of the body frozen in its current
    shape. Derivation: with ``u = L_B − A = I ω`` and ``dL_B/dt = −ω × L_B``
    (no torque), ``T = ½ u·I⁻¹u`` gives
    ``dT/dt = ω·(−ω × L_B − Ȧ) − ½ ω·İ ω = −ω·Ȧ − ½ ω·İ ω``.
    ``t`` (n,) s and ``omega`` (n, [N,] 3) rad/s (body axes) as in a Trajectory.
    """
    t = body.check_times(t)
    omega = np.asarray(omega, dtype=np.float64)
    inertia_rate = body.inertia(t, 1)
    shape_rate = body.shape_momentum(t, 1)
    if omega.ndim == 3:
        inertia_rate, shape_rate = inertia_rate[:, None], shape_rate[:, None]
    return -np.einsum("...i,...i->...", omega, shape_rate) - 0.5 * np.einsum("...i,...ij,...j->...", omega,
                                                                              inertia_rate, omega)


def _check_tensors(t: np.ndarray, inertia: np.ndarray, check_triangle: bool) -> np.ndarray:
    """The rules of :func:`tumble.rigid_body.principal_axes` (symmetric, then symmetrised exactly; positive definite;
    the triangle inequality ``I₁ + I₂ ≥ I₃`` that every mass distribution obeys) at every sample; a broken
    rule is refused naming the sample and its time."""
    return principal_axes(inertia, "inertia", check_triangle=check_triangle,
                          member_note=lambda k: f"sample at t = {t[k[0]]} s")[0]
