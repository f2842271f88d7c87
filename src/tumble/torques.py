"""Torque models: composable, compiled, body axes.

A torque model gives the external torque on the body, in body axes (N·m), as a
function of time ``t`` (s), attitude ``q`` (body → inertial, scalar first) and
body rate ``omega`` (rad/s, body axes)::

    τ_B = f(t, q, ω)

Models add with ``+``. The built-in models run compiled inside the integrators
(no Python call per step):

=====================  ==========================================================
``ConstantBody(τ)``     ``τ_B = τ`` fixed in the body
``ConstantInertial(τ)`` ``τ_B = R(q)ᵀ τ_N``: fixed in inertial space
``Tabulated(t, τ)``     samples of ``τ(t)`` (body or inertial axes), linear or
                        zero-order-hold interpolation, end values held
``Gravity(m, r, g)``    uniform gravity on a body pivoting about a fixed point:
                        ``τ_B = r_B × m R(q)ᵀ g_N`` (heavy top)
``GravityGradient``     gravity gradient on a body of inertia ``I`` on an orbit:
                        ``τ_B = 3μ/|r|⁵ r_B × (I r_B)``, ``r_B = R(q)ᵀ r_N(t)``
=====================  ==========================================================

Any Python callable ``f(t, q, omega) -> torque`` (body axes) is accepted too,
directly or wrapped as :class:`PythonTorque`. It is called back from the
compiled integrator at Python speed (a few microseconds per call, four calls
per RK4 step, twelve per DOP853 step) and, because it needs the interpreter,
a batch with such a torque runs on one core.

How the models reach the integrators: each model compiles itself to a *torque
program* — a code and a block of float parameters — expressed in the body's
principal axes, where the integrators work; :func:`evaluate` runs a program.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, Union

import numpy as np
from numba import njit, objmode
from numba.extending import overload, register_jitable
from numpy.typing import ArrayLike

from tumble import _callback, _gravity, _quat
from tumble._validate import ValidationError, as_array, increasing_times, readonly, require_positive
from tumble.attitude import rotate_inverse
from tumble._inertia import principal_axes

if TYPE_CHECKING:
    from tumble.rigid_body import RigidBody
    from tumble.spacecraft.orbit import Orbit

__all__ = [
    "TorqueModel",
    "ConstantBody",
    "ConstantInertial",
    "Tabulated",
    "Gravity",
    "GravityGradient",
    "FunctionOfTime",
    "PythonTorque",
    "as_torque_model",
]

# Program codes (the compiled evaluator switches on them).
_CONST_BODY = 1
_CONST_INERTIAL = 2
_TABULATED = 3
_GRAVITY = 4
_GRAVITY_GRADIENT = 5
_PYTHON = 9


class TorqueModel:
    """Base class of torque models; ``a + b`` is the sum of two models.

    Calling a model, ``model(t, q, omega)``, evaluates it in body axes (N·m)
    through the same compiled code the integrators use.
    """

    #: True when evaluating the model calls back into Python.
    needs_python = False

    def terms(self) -> tuple[TorqueModel, ...]:
        """The elementary models whose sum this model is."""
        return (self,)

    def __add__(self, other):
        other = as_torque_model(other)
        if other is None:
            return self
        return Sum(self.terms() + other.terms())

    __radd__ = __add__

    def _params(self, axes: np.ndarray) -> tuple[int, np.ndarray]:
        """(program code, parameters) of this model in the principal axes ``axes`` (R_BP)."""
        raise NotImplementedError

    def __call__(self, t: float, q: ArrayLike, omega: ArrayLike) -> np.ndarray:
        q = as_array(q, "q", tail=(4,))
        omega = as_array(omega, "omega", tail=(3,))
        if q.ndim != 1 or omega.ndim != 1:
            raise ValidationError("q, omega: evaluate a torque model one state at a time")
        codes, params = compile_program(self, np.eye(3), offset=0)
        return np.array(evaluate(float(t), *q, *omega, params[None, :], 0, codes))


class Sum(TorqueModel):
    """Sum of torque models (built by ``+``)."""

    def __init__(self, parts: Iterable[TorqueModel]) -> None:
        self.parts = tuple(parts)
        self.needs_python = any(p.needs_python for p in self.parts)

    def terms(self) -> tuple[TorqueModel, ...]:
        return self.parts

    def __repr__(self):
        return " + ".join(map(repr, self.parts))


class ConstantBody(TorqueModel):
    """A torque fixed in the body: ``τ_B = torque`` (N·m, body axes)."""

    def __init__(self, torque: ArrayLike) -> None:
        self.torque = as_array(torque, "torque", tail=(3,))
        if self.torque.ndim != 1:
            raise ValidationError(f"torque: must have shape (3,), got {self.torque.shape}")

    def _params(self, axes):
        return _CONST_BODY, axes.T @ self.torque

    def __repr__(self):
        return f"ConstantBody({self.torque.tolist()})"


class ConstantInertial(TorqueModel):
    """A torque fixed in inertial space: ``τ_B = R(q)ᵀ τ_N`` (N·m; ``torque`` in inertial axes).

    The inertial angular momentum then grows linearly: ``L_N(t) = L_N(0) + τ_N t``.
    """

    def __init__(self, torque: ArrayLike) -> None:
        self.torque = as_array(torque, "torque", tail=(3,))
        if self.torque.ndim != 1:
            raise ValidationError(f"torque: must have shape (3,), got {self.torque.shape}")

    def _params(self, axes):
        return _CONST_INERTIAL, self.torque.copy()

    def __repr__(self):
        return f"ConstantInertial({self.torque.tolist()})"


class Tabulated(TorqueModel):
    """A torque given by samples ``torque[k]`` at times ``t[k]`` (s, N·m).

    ``frame="body"`` (default) or ``"inertial"`` says in which axes the samples
    are given; ``interpolation="linear"`` (default) or ``"previous"``
    (zero-order hold: the last sample at or before ``t``). Outside
    ``[t[0], t[-1]]`` the end values are held. The integrators do not stop at
    the sample times, so a discontinuous profile ("previous") lowers the
    accuracy of a step that straddles a jump: use output times or a step that
    lands on the jumps when that matters.
    """

    def __init__(self, t: ArrayLike, torque: ArrayLike, *, frame: str = "body", interpolation: str = "linear") -> None:
        t = increasing_times(t, what="sample times")
        torque = as_array(torque, "torque", tail=(3,))
        if torque.shape != (t.size, 3):
            raise ValidationError(f"torque: must have shape (len(t), 3) = ({t.size}, 3), got {torque.shape}")
        if frame not in ("body", "inertial"):
            raise ValidationError(f"frame: must be 'body' or 'inertial', got {frame!r}")
        if interpolation not in ("linear", "previous"):
            raise ValidationError(f"interpolation: must be 'linear' or 'previous', got {interpolation!r}")
        self.t, self.torque, self.frame, self.interpolation = t, torque, frame, interpolation

    def _params(self, axes):
        values = self.torque @ axes if self.frame == "body" else self.torque
        head = [self.t.size, self.frame == "inertial", self.interpolation == "previous"]
        return _TABULATED, np.concatenate([head, self.t, values.ravel()])

    def __repr__(self):
        return f"Tabulated({self.t.size} samples, frame={self.frame!r}, interpolation={self.interpolation!r})"


class Gravity(TorqueModel):
    """Uniform gravity on a body that pivots about a fixed point (a heavy top).

    ``τ_B = r_B × (m R(q)ᵀ g_N)``: ``mass`` (kg), ``com`` the centre of mass
    relative to the pivot in body axes (m), ``g`` the gravitational
    acceleration in inertial axes (m/s², default ``(0, 0, -9.80665)``).
    Simulate such a body with its inertia *about the pivot*
    (``RigidBody.inertia_about(pivot)``), since the pivot is the fixed point.
    """

    def __init__(self, mass: float, com: ArrayLike, g: ArrayLike = (0.0, 0.0, -9.80665)) -> None:
        self.mass = require_positive(mass, "mass")
        self.com = as_array(com, "com", tail=(3,))
        self.g = as_array(g, "g", tail=(3,))
        if self.com.ndim != 1 or self.g.ndim != 1:
            raise ValidationError("com, g: must have shape (3,)")

    def _params(self, axes):
        return _GRAVITY, np.concatenate([axes.T @ (self.mass * self.com), self.g])

    def __repr__(self):
        return f"Gravity(mass={self.mass}, com={self.com.tolist()}, g={self.g.tolist()})"


class GravityGradient(TorqueModel):
    """Gravity-gradient torque on a body on a Kepler orbit about a point mass.

    ``τ_B = (3 μ / |r|⁵) r_B × (I r_B)`` with ``r_B = R(q)ᵀ r_N(t)`` the
    position of the centre of mass in body axes (m), ``r_N(t)`` from the orbit
    (inertial axes, the orbit's epoch at ``t = 0``) and ``I`` the body's
    inertia tensor about its centre of mass, in body axes (kg·m²). Hughes,
    *Spacecraft Attitude Dynamics*, ch. 8; the compiled kernel is
    :func:`tumble.spacecraft.environment.gravity_gradient_torque`.

    orbit   : a :class:`tumble.spacecraft.orbit.Orbit` (anything with an
              ``elements()`` method returning ``[a, e, i, Ω, ω, M₀, μ]``)
    inertia : the simulated body's inertia (a :class:`~tumble.RigidBody` or a
              (3, 3) tensor, kg·m², body axes). The torque model needs it to be a
              complete function ``τ(t, q, ω)``; give the same body you simulate
              (a batch with dispersed inertia needs one model per member).

    The body's orbital motion is prescribed (a fixed Kepler orbit): the
    attitude does not act back on the orbit.
    """

    def __init__(self, orbit: Orbit, inertia: RigidBody | ArrayLike) -> None:
        if not callable(getattr(orbit, "elements", None)):
            raise ValidationError(f"orbit: must be a tumble.spacecraft.orbit.Orbit, got {type(orbit).__name__}")
        self.orbit = orbit
        self.elements = as_array(orbit.elements(), "orbit.elements()", tail=(7,))
        inertia = getattr(inertia, "inertia", inertia)  # a RigidBody, or the tensor itself
        self.inertia = principal_axes(as_array(inertia, "inertia", tail=(3, 3)), "inertia", check_triangle=False)[0]
        if self.inertia.ndim != 2:
            raise ValidationError(f"inertia: must have shape (3, 3), got {self.inertia.shape}")

    def _params(self, axes):
        i = axes.T @ self.inertia @ axes  # in the axes the program is compiled for
        return _GRAVITY_GRADIENT, np.concatenate(
            [self.elements, [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]]
        )

    def __repr__(self):
        return f"GravityGradient({self.orbit!r}, inertia={self.inertia.tolist()})"


class PythonTorque(TorqueModel):
    """Any Python callable ``f(t, q, omega) -> torque`` (body axes, N·m).

    ``q`` is the body → inertial quaternion (scalar first) and ``omega`` the
    body rate (rad/s, body axes), both fresh NumPy arrays. Runs at Python
    speed and on one core (see the module docstring).
    """

    needs_python = True

    def __init__(self, function: Callable[[float, np.ndarray, np.ndarray], ArrayLike]) -> None:
        if not callable(function):
            raise ValidationError(f"torque: must be a torque model or a callable f(t, q, omega), got {function!r}")
        self.function = function
        # registered per process: a copy sent to a Dask worker registers it there (tumble._callback.Callback)
        self.callback = _callback.Callback(function, field="torque", signature="(t, q, omega)",
                                           returns="3 finite numbers (body torque, N·m)")

    def _params(self, axes):
        q_bp = np.array(_quat.qfrom_matrix(readonly(axes)))  # one compiled copy, for a body's or a batch's axes
        return _PYTHON, np.concatenate([[self.callback.slot], axes.ravel(), q_bp])

    def __repr__(self):
        return f"PythonTorque({getattr(self.function, '__name__', self.function)!r})"


class FunctionOfTime(PythonTorque):
    """A torque given by a Python function of time only, ``f(t) -> (3,)`` (N·m).

    ``frame="body"`` (default) or ``"inertial"`` says in which axes ``f``
    returns it. Runs at Python speed; tabulate it (:class:`Tabulated`) for
    compiled speed.
    """

    def __init__(self, function: Callable[[float], ArrayLike], *, frame: str = "body") -> None:
        if not callable(function):
            raise ValidationError(f"function: must be callable f(t) -> torque, got {function!r}")
        if frame not in ("body", "inertial"):
            raise ValidationError(f"frame: must be 'body' or 'inertial', got {frame!r}")
        self.time_function, self.frame = function, frame
        if frame == "body":
            super().__init__(lambda t, q, omega: function(t))
        else:
            super().__init__(lambda t, q, omega: rotate_inverse(q, np.asarray(function(t), dtype=np.float64)))
        self.function.__name__ = getattr(function, "__name__", "f")

    def __repr__(self):
        return f"FunctionOfTime({getattr(self.time_function, '__name__', self.time_function)!r}, frame={self.frame!r})"


#: What a ``torque=`` argument takes: a torque model, a Python function ``f(t, q, omega) -> (3,)`` (N·m, body
#: axes), or None (no torque)
TorqueLike = Union[TorqueModel, Callable[[float, np.ndarray, np.ndarray], ArrayLike], None]


def as_torque_model(torque: TorqueLike) -> TorqueModel | None:
    """``None`` for no torque, a model as is, a callable as :class:`PythonTorque`."""
    if torque is None or isinstance(torque, TorqueModel):
        return torque
    return PythonTorque(torque)


def calls_python(codes: np.ndarray | None) -> bool:
    """True when the torque program ``codes`` (of :func:`compile_program`) calls a Python function."""
    return codes is not None and bool(np.any(np.asarray(codes)[0::2] == _PYTHON))


def program_calls_python(kernel: Any) -> bool:
    """``calls_python`` of a compiled model whose torque program is its field ``codes``."""
    return calls_python(kernel.codes)


def compile_program(model: TorqueModel | None, axes: np.ndarray, offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Compile a model to a torque program in the principal axes ``axes`` (R_BP).

    Returns ``(codes, params)``: ``codes`` holds pairs (code, start) where
    ``start`` indexes the parameter array once it is placed at ``offset`` of
    the integrator's parameter vector.
    """
    codes, blocks = [], []
    start = offset
    for term in () if model is None else model.terms():
        code, block = term._params(np.asarray(axes, dtype=np.float64))
        codes += [code, start]
        blocks.append(np.asarray(block, dtype=np.float64))
        start += blocks[-1].size
    params = np.concatenate(blocks) if blocks else np.zeros(0)
    return np.array(codes, dtype=np.int64), params


@njit(cache=True)
def _python_torque(t, qw, qx, qy, qz, w1, w2, w3, P, row, o):
    """Call a PythonTorque: convert the principal-axes state (``q`` normalised here) to body axes and back."""
    s = 1.0 / math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    qw, qx, qy, qz = qw * s, qx * s, qy * s, qz * s
    slot = int(P[row, o])
    r = P[row, o + 1 : o + 10]  # R_BP, row-major
    qb = _quat.qmul(qw, qx, qy, qz, P[row, o + 10], -P[row, o + 11], -P[row, o + 12], -P[row, o + 13])
    q_body = np.array(qb)
    omega_body = np.array(
        (
            r[0] * w1 + r[1] * w2 + r[2] * w3,
            r[3] * w1 + r[4] * w2 + r[5] * w3,
            r[6] * w1 + r[7] * w2 + r[8] * w3,
        )
    )
    tau = np.empty(3)
    with objmode():
        _callback.invoke(slot, t, (q_body, omega_body), tau)
    return (
        r[0] * tau[0] + r[3] * tau[1] + r[6] * tau[2],
        r[1] * tau[0] + r[4] * tau[1] + r[7] * tau[2],
        r[2] * tau[0] + r[5] * tau[1] + r[8] * tau[2],
    )


@register_jitable
def _tabulated(t, P, row, o):
    """Interpolate a Tabulated block at ``t`` (scalar reads only: no array views in the hot loop)."""
    n = int(P[row, o])
    t0 = o + 3  # times at P[row, t0 : t0 + n], values (n, 3) row-major after them
    v0 = t0 + n
    if t <= P[row, t0]:
        k, f = 0, 0.0
    elif t >= P[row, t0 + n - 1]:
        k, f = n - 1, 0.0
    else:
        lo, hi = 0, n - 1  # invariant: times[lo] <= t < times[hi]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if P[row, t0 + mid] <= t:
                lo = mid
            else:
                hi = mid
        k = lo
        f = 0.0 if P[row, o + 2] != 0.0 else (t - P[row, t0 + k]) / (P[row, t0 + k + 1] - P[row, t0 + k])
    i = v0 + 3 * k
    a, b, c = P[row, i], P[row, i + 1], P[row, i + 2]
    if f != 0.0:
        a += f * (P[row, i + 3] - a)
        b += f * (P[row, i + 4] - b)
        c += f * (P[row, i + 5] - c)
    return a, b, c


@register_jitable
def evaluate_compiled(t: float, qw: float, qx: float, qy: float, qz: float, w1: float, w2: float, w3: float,
                      P: np.ndarray, row: int, codes: np.ndarray) -> tuple[float, float, float]:
    """The compiled terms of the torque program in row ``row`` of ``P`` (all but Python callbacks):
    the torque (N·m) in the axes it was compiled for.

    ``q`` (normalised here) maps those axes to inertial axes, ``omega`` is
    expressed in them. A plain function compiled into its callers, the CPU
    integrators (through :func:`evaluate`) and the CUDA kernel of
    :mod:`tumble.integrate._cuda` alike.
    """
    # Runge–Kutta stage states are off the unit sphere by about the local error:
    # rotate by q/|q| so that the torque does not depend on the body axes chosen.
    s = 1.0 / math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    qw, qx, qy, qz = qw * s, qx * s, qy * s, qz * s
    t1 = t2 = t3 = 0.0
    for k in range(0, codes.shape[0], 2):
        code, o = int(codes[k]), int(codes[k + 1])  # codes may be held as float64 (a spacecraft's data)
        if code == _CONST_BODY:
            a, b, c = P[row, o], P[row, o + 1], P[row, o + 2]
        elif code == _CONST_INERTIAL:
            a, b, c = _quat.qrotate_inv(qw, qx, qy, qz, P[row, o], P[row, o + 1], P[row, o + 2])
        elif code == _TABULATED:
            a, b, c = _tabulated(t, P, row, o)
            if P[row, o + 1] != 0.0:
                a, b, c = _quat.qrotate_inv(qw, qx, qy, qz, a, b, c)
        elif code == _GRAVITY:
            # τ = (m r) × g_body with g_body = R(q)ᵀ g_N
            gx, gy, gz = _quat.qrotate_inv(qw, qx, qy, qz, P[row, o + 3], P[row, o + 4], P[row, o + 5])
            rx, ry, rz = P[row, o], P[row, o + 1], P[row, o + 2]
            a, b, c = ry * gz - rz * gy, rz * gx - rx * gz, rx * gy - ry * gx
        elif code == _GRAVITY_GRADIENT:
            # orbit position (inertial), into the program's axes, then 3μ/r⁵ r × (I r)
            rx, ry, rz, _, _, _ = _gravity.kepler_state(
                P[row, o], P[row, o + 1], P[row, o + 2], P[row, o + 3], P[row, o + 4], P[row, o + 5],
                P[row, o + 6], t,
            )
            rx, ry, rz = _quat.qrotate_inv(qw, qx, qy, qz, rx, ry, rz)
            a, b, c = _gravity.gravity_gradient_torque(
                P[row, o + 6], rx, ry, rz, P[row, o + 7], P[row, o + 8], P[row, o + 9], P[row, o + 10],
                P[row, o + 11], P[row, o + 12],
            )
        else:  # a Python callback: see evaluate
            continue
        t1 += a
        t2 += b
        t3 += c
    return t1, t2, t3


def _add_python_terms(t1, t2, t3, t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):  # pragma: no cover
    """``(t1, t2, t3)`` plus the torque (N·m) of each Python callback of the torque program in row ``row``
    of ``P``, added in the program's order.

    Compiled per target: on the CPU it calls each callback; on an NVIDIA GPU
    (``numba.cuda``) a program has no Python terms, since
    :mod:`tumble.integrate._cuda` refuses one before it launches, and nothing is
    added, so that every kernel that evaluates a torque program compiles for the GPU.
    """
    raise NotImplementedError("compiled code only")


@overload(_add_python_terms, target="cpu", jit_options={"cache": True})
def _add_python_terms_cpu(t1, t2, t3, t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):
    def impl(t1, t2, t3, t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):
        for k in range(0, codes.shape[0], 2):
            if int(codes[k]) == _PYTHON:
                a, b, c = _python_torque(t, qw, qx, qy, qz, w1, w2, w3, P, row, int(codes[k + 1]))
                t1 += a
                t2 += b
                t3 += c
        return t1, t2, t3

    return impl


@overload(_add_python_terms, target="cuda")
def _add_python_terms_gpu(t1, t2, t3, t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):
    return lambda t1, t2, t3, t, qw, qx, qy, qz, w1, w2, w3, P, row, codes: (t1, t2, t3)


@njit(cache=True)
def evaluate(t: float, qw: float, qx: float, qy: float, qz: float, w1: float, w2: float, w3: float, P: np.ndarray,
             row: int, codes: np.ndarray) -> tuple[float, float, float]:
    """Run the torque program in row ``row`` of ``P``: the torque (N·m) in the axes it was compiled for.

    The compiled terms (:func:`evaluate_compiled`), then the Python callbacks (:func:`_add_python_terms`).
    """
    t1, t2, t3 = evaluate_compiled(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes)
    return _add_python_terms(t1, t2, t3, t, qw, qx, qy, qz, w1, w2, w3, P, row, codes)
