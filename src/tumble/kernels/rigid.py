"""The rigid body as a model for the integrators (see :mod:`tumble._protocol`).

State ``y = [q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃]``: the attitude of the principal
axes P (``q_NP``, P → inertial) and the body rate in principal axes (rad/s).
Right-hand side, Euler's equations in principal axes with the kinematics::

    I₁ ω̇₁ = τ₁ + (I₂ − I₃) ω₂ ω₃   (and cyclic),     q̇ = ½ q ⊗ [0, ω]

where ``τ`` is the torque program evaluated in principal axes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types

from tumble import _free_flow, _protocol, torques
from tumble.dynamics import euler_coefficients, rigid_rates

STATE_SIZE = 7


class RigidModel(NamedTuple):
    """Compiled parameters of a batch of rigid bodies.

    coefficients : (6, N or 1) Euler coefficients (``dynamics.euler_coefficients`` of the
                   principal moments), structure of arrays: coefficient ``k`` of body ``b`` is
                   ``coefficients[k, b]`` (one column shared by all bodies, or one per body), so
                   that a block of lanes reads each coefficient as one contiguous vector
    params  : (N or 1, n_p) torque-program parameters in each body's principal axes
    codes   : int64 torque-program codes, or None for a torque-free body
    moments : (N or 1, 3) principal moments, kg·m² (for the exact flow, ``method="exact"``)
    """

    coefficients: np.ndarray
    params: np.ndarray
    codes: np.ndarray | None
    moments: np.ndarray

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): every one; ``"torque_free"`` only without
        a torque program, ``"cuda"`` (and ``"rigid_fields"``, read by the GPU's fused RK4 kernel) only without a
        Python torque function."""
        free = {"torque_free"} if self.codes is None else set()
        gpu = set() if self.calls_python else {"cuda", "rigid_fields"}
        return frozenset({"rhs", "body_rate", "free_flow", *free, *gpu})

    @property
    def calls_python(self) -> bool:
        """True when the torque program calls a Python function (the batch then runs on one core)."""
        return torques.calls_python(self.codes)

    @staticmethod
    def may_call_python(numba_type) -> bool:
        """Whether compiled code of a kernel of the Numba type ``numba_type`` may call a Python function,
        known when a call is typed (:mod:`tumble._protocol`): with a torque program, whose codes are data,
        it may; without one (``codes`` None), never."""
        return not _torque_free(numba_type)

    @property
    def gpu_refusal(self) -> str | None:
        """Why this kernel cannot run on an NVIDIA GPU (a ValidationError message), or None: a Python torque."""
        return _protocol.python_on_gpu("torque") if self.calls_python else None


def build(bodies, model) -> RigidModel:
    """The :class:`RigidModel` of a list of RigidBody (one, or one per batch member) under a torque model."""
    return from_principal(np.stack([b.moments for b in bodies]), np.stack([b.axes for b in bodies]), model)


def from_principal(moments, axes, model) -> RigidModel:
    """The :class:`RigidModel` of bodies given by principal moments (B, 3) and axes R_BP (B, 3, 3).

    ``B`` is 1 (one body shared by the batch) or the batch size. Without a
    torque no per-body work is done beyond the Euler coefficients, so a batch
    of a million bodies with dispersed inertia is set up in milliseconds.
    """
    # a writeable copy: RigidBody.moments is read-only, and Numba would compile every integrator once more
    moments = np.array(moments, dtype=np.float64, order="C")
    coefficients = np.empty((6, moments.shape[0]))
    _coefficients(moments, coefficients)
    if model is None:
        codes, params = None, np.zeros((1, 0))
    else:
        programs = [torques.compile_program(model, a, offset=0) for a in axes]
        codes, params = programs[0][0], np.ascontiguousarray(np.stack([p for _, p in programs]))
    return RigidModel(coefficients=coefficients, params=params, codes=codes, moments=moments)


@njit(cache=True)
def _coefficients(moments, out):
    """``out[:, b]`` = the Euler coefficients of the principal moments ``moments[b]`` (one compiled call)."""
    for b in range(moments.shape[0]):
        out[0, b], out[1, b], out[2, b], out[3, b], out[4, b], out[5, b] = euler_coefficients(
            moments[b, 0], moments[b, 1], moments[b, 2])



def _torque_free(model) -> bool:
    """Whether the Numba type ``model`` of a :class:`RigidModel` has no torque program (``codes`` None): known
    when a call is typed, so that a torque-free body compiles no torque terms at all."""
    return isinstance(model.types[2], types.NoneType)


@_protocol.implements(_protocol.point_rates, RigidModel, inline=True)
def _rigid_point_rates(model, b, t, y):
    if _torque_free(model):  # no torque code at all

        def torque(model, b, t, qw, qx, qy, qz, w1, w2, w3):
            return None

    else:

        def torque(model, b, t, qw, qx, qy, qz, w1, w2, w3):
            return torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, model.params, b, model.codes)

    torque = njit(inline="always")(torque)

    def impl(model, b, t, y):
        # b is the member's row, 0 for all of a uniform model (see _rigid_uniform): lanes b, b+1, ...
        # read contiguous coefficients (structure of arrays), or one broadcast; scalar reads only (a
        # column view would cost reference counting in the inner loop)
        c = model.coefficients
        r = b
        qw, qx, qy, qz, w1, w2, w3 = y
        return rigid_rates(c[0, r], c[1, r], c[2, r], c[3, r], c[4, r], c[5, r], qw, qx, qy, qz, w1, w2, w3,
                           torque(model, b, t, qw, qx, qy, qz, w1, w2, w3))

    return impl


@_protocol.implements(_protocol.uniform, RigidModel, inline=True)
def _rigid_uniform(model):
    # one body for all (from_principal gives the coefficients and a torque program's parameters
    # the same number of rows: 1, or one per body; a torque-free model has one empty row)
    return lambda model: model.coefficients.shape[1] == 1


@_protocol.implements(_protocol.members, RigidModel)
def _rigid_members(model, b0, b1):

    def impl(model, b0, b1):
        c = np.ascontiguousarray(model.coefficients[:, b0:b1])
        params = np.ascontiguousarray(model.params[b0:b1]) if model.params.shape[0] > 1 else model.params
        return RigidModel(c, params, model.codes, np.ascontiguousarray(model.moments[b0:b1]))

    return impl


@_protocol.implements(_protocol.rhs, RigidModel, inline=True)
def _rigid_rhs(model, b0, t, Y, OUT):
    if Y.ndim == 1:  # one body: the state vector itself

        def impl(model, b0, t, Y, OUT):
            OUT[0], OUT[1], OUT[2], OUT[3], OUT[4], OUT[5], OUT[6] = _protocol.point_rates(
                model, b0 * (model.coefficients.shape[1] > 1), t, (Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6]))

    else:  # a block: state × lanes

        def impl(model, b0, t, Y, OUT):
            per_body = model.coefficients.shape[1] > 1  # not uniform: row b0 + j (see _rigid_uniform)
            for j in range(Y.shape[1]):
                (OUT[0, j], OUT[1, j], OUT[2, j], OUT[3, j], OUT[4, j], OUT[5, j], OUT[6, j]) = _protocol.point_rates(
                    model, (b0 + j) * per_body, t, (Y[0, j], Y[1, j], Y[2, j], Y[3, j], Y[4, j], Y[5, j], Y[6, j]))

    return impl


@_protocol.implements(_protocol.project, RigidModel, inline=True)
def _rigid_project(model, b0, t, Y):
    return _protocol.quaternion_projection(Y)


@_protocol.implements(_protocol.state_size, RigidModel)
def _rigid_state_size(model):

    def impl(model):
        return STATE_SIZE

    return impl


@_protocol.implements(_protocol.body_rate, RigidModel, inline=True)
def _rigid_body_rate(model, Y, j):
    return _protocol.rate_at(4, Y)


@_protocol.implements(_protocol.inverse_moments, RigidModel, inline=True)
def _rigid_inverse_moments(model, b):
    if not _torque_free(model):
        return None  # with a torque program, the body is not free: no splitting

    def impl(model, b):
        c = model.coefficients
        r = b * (c.shape[1] > 1)
        return c[3, r], c[4, r], c[5, r]

    return impl


@_protocol.implements(_protocol.free_setup, RigidModel, inline=True)
def _rigid_free_setup(model, b, x):

    def impl(model, b, x):
        r = b * (model.moments.shape[0] > 1)
        return _free_flow._setup(model.moments[r, 0], model.moments[r, 1], model.moments[r, 2],
                                 x[4], x[5], x[6], x[0], x[1], x[2], x[3])

    return impl


@_protocol.implements(_protocol.free_evaluate, RigidModel, inline=True)
def _rigid_free_evaluate(model, motion, tau):

    def impl(model, motion, tau):
        w1, w2, w3, qw, qx, qy, qz = _free_flow._evaluate(motion, tau)
        return qw, qx, qy, qz, w1, w2, w3

    return impl


@_protocol.implements(_protocol.torque_acceleration, RigidModel, inline=True)
def _rigid_torque_acceleration(model, b, t, x, w1, w2, w3):
    if _torque_free(model):
        return lambda model, b, t, x, w1, w2, w3: (0.0, 0.0, 0.0)

    def impl(model, b, t, x, w1, w2, w3):
        c = model.coefficients
        r = b * (c.shape[1] > 1)
        t1, t2, t3 = torques.evaluate(t, x[0], x[1], x[2], x[3], w1, w2, w3, model.params,
                                      b * (model.params.shape[0] > 1), model.codes)
        return c[3, r] * t1, c[4, r] * t2, c[5, r] * t3

    return impl


@_protocol.implements(_protocol.torque_free, RigidModel, inline=True)
def _rigid_torque_free(model):
    free = _torque_free(model)
    return lambda model: free
