"""The model protocol: what an integrator needs from the thing it integrates.

A *model* is an immutable :class:`typing.NamedTuple` of NumPy arrays (its
parameters: one row shared by the whole batch, or one row per body). Its state
is a flat float64 vector whose first four entries are the attitude quaternion
(scalar first). Integrators hold states as structure-of-arrays *blocks*
``Y[i, j]`` = component ``i`` of batch member ``b0 + j``, so that the loop
over the lanes ``j`` compiles to SIMD instructions. A model type provides,
through :func:`numba.extending.overload` of the three generic functions below,
its right-hand side, its projection back onto the state manifold and its
state size::

    rhs(model, b0, t, Y, OUT)    # OUT[:, j] = dy/dt of batch member b0 + j at (t, Y[:, j])
    project(model, b0, t, Y)     # after a step that ends at t: e.g. normalise the quaternion
                                 # Y[0:4, j] of every lane; also the place of discrete updates
    state_size(model)            # length of the state vector, a compile-time constant

where ``Y`` is a block (state × lanes) or the state vector of one body
(``Y[i]``, batch member ``b0``); the overloads specialise on ``Y.ndim``.

Two more functions serve the geometric integrators (:mod:`tumble.integrate`);
a model provides those that apply to it::

    body_rate(model, Y, j)       # (ω₁, ω₂, ω₃) of lane j (rad/s, body axes of the quaternion):
                                 # q̇ = ½ q ⊗ [0, ω]; the Lie-group method (cf4) needs it
    inverse_moments(model, b)    # (1/I₁, 1/I₂, 1/I₃) of batch member b, principal axes (1/(kg·m²)),
                                 # for a torque-free rigid body whose state is [q, ω]; the
                                 # splitting methods need it

A model also tells Python code whether it has an external torque: the
attribute ``torque_free`` (True when it has none) is read by
:func:`tumble.integrate.solve`, which refuses a free-body-only method otherwise.

The integrators call these generic functions; Numba picks the implementation
from the model's type when it compiles the integrator, so each model gets its
own fully inlined integrator, and the compiled code is cached on disk. (Passing
functions as arguments instead would defeat the disk cache, and a run-time
switch on a model code costs 2–3× in the inner loop.) Adding a model is one
module: a NamedTuple, its overloads, and a row in ``docs/architecture.md``.
"""

from __future__ import annotations

import math

from numba import njit, types


def is_type(numba_type, cls) -> bool:
    """True when ``numba_type`` (seen by an overload) is the Numba type of a ``cls`` NamedTuple.

    Models and schemes select their overloads with it.
    """
    return isinstance(numba_type, types.BaseNamedTuple) and numba_type.instance_class is cls


def rhs(model, b0, t, Y, OUT):  # pragma: no cover - replaced by overloads in compiled code
    """``OUT[:, j] = dy/dt`` of batch member ``b0 + j`` of ``model`` at time ``t``, state ``Y[:, j]``."""
    raise NotImplementedError(f"no compiled right-hand side for {type(model).__name__}")


def project(model, b0, t, Y):  # pragma: no cover - replaced by overloads in compiled code
    """After an accepted step that ends at time ``t`` (s): put every lane ``Y[:, j]`` (batch member
    ``b0 + j``) back onto the state manifold, in place.

    It is also where a model applies its discrete-time updates, such as a
    controller sampled at a fixed rate whose command is held in the state
    (zero-order hold): the fixed-step methods land on every output time and
    call ``project`` after each step, so a model whose sample times are
    multiples of ``dt`` sees each of them. (The adaptive ``dop853`` calls it
    after each accepted step too, but its steps do not land on sample times.)
    """
    raise NotImplementedError(f"no compiled projection for {type(model).__name__}")


def state_size(model):  # pragma: no cover - replaced by overloads in compiled code
    """Length of the state vector of ``model`` (a constant, so loops over it unroll)."""
    raise NotImplementedError(f"no compiled state size for {type(model).__name__}")


def body_rate(model, Y, j):  # pragma: no cover - replaced by overloads in compiled code
    """Body angular velocity ``(ω₁, ω₂, ω₃)`` (rad/s) of lane ``j`` of the block ``Y`` (or of the state vector ``Y``).

    It is the rate in the attitude kinematics ``q̇ = ½ q ⊗ [0, ω]`` of the
    quaternion ``Y[0:4]``, in the body axes that quaternion maps to inertial.
    """
    raise NotImplementedError(f"no compiled body rate for {type(model).__name__}")


def inverse_moments(model, b):  # pragma: no cover - replaced by overloads in compiled code
    """``(1/I₁, 1/I₂, 1/I₃)`` (1/(kg·m²)) of batch member ``b`` of a torque-free rigid-body model.

    Only models whose state is ``[q, ω]`` with ``ω`` in principal axes and
    whose motion is torque-free provide it: the splitting methods rely on both.
    """
    raise NotImplementedError(f"{type(model).__name__} is not a torque-free rigid body")


@njit(cache=True)
def quaternion_scale(qw, qx, qy, qz):
    """``1/|q|``: the factor that projects a quaternion back onto the unit sphere.

    This is the projection every attitude model uses: the exact flow keeps
    ``|q| = 1``; a Runge–Kutta step leaves it off by about the local error.
    Projecting after every accepted step keeps it at 1 to rounding without
    changing the order of the method.
    """
    return 1.0 / math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)


@njit(cache=True)
def normalize_quaternions(Y):
    """Normalise the quaternion ``Y[0:4, j]`` of every lane of a block (state × lanes)."""
    for j in range(Y.shape[1]):
        s = quaternion_scale(Y[0, j], Y[1, j], Y[2, j], Y[3, j])
        for i in range(4):
            Y[i, j] *= s


@njit(cache=True)
def normalize_quaternion(y):
    """Normalise the quaternion ``y[0:4]`` of one state vector."""
    s = quaternion_scale(y[0], y[1], y[2], y[3])
    for i in range(4):
        y[i] *= s


# Implementations shared by the models' overloads (each returns the ``impl`` an overload returns).


def quaternion_projection(Y):
    """``project`` for a model whose only constraint is the unit quaternion ``Y[0:4]``: normalise it
    (the state vector, or every lane of a block)."""
    if Y.ndim == 1:
        return lambda model, b0, t, Y: normalize_quaternion(Y)
    return lambda model, b0, t, Y: normalize_quaternions(Y)


def rate_at(offset, Y):
    """``body_rate`` for a model that stores ``(ω₁, ω₂, ω₃)`` at ``Y[offset:offset + 3]``."""
    if Y.ndim == 1:
        return lambda model, Y, j: (Y[offset], Y[offset + 1], Y[offset + 2])
    return lambda model, Y, j: (Y[offset, j], Y[offset + 1, j], Y[offset + 2, j])


def lanewise_rhs(derivative, Y):
    """``rhs`` for a model whose jitted ``derivative(model, t, y, out)`` works on one state vector:
    called on the state itself, or on each lane ``Y[:, j]`` of a block."""
    if Y.ndim == 1:
        return lambda model, b0, t, Y, OUT: derivative(model, t, Y, OUT)

    def impl(model, b0, t, Y, OUT):
        for j in range(Y.shape[1]):
            derivative(model, t, Y[:, j], OUT[:, j])

    return impl
