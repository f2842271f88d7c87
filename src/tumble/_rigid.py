"""The rigid body as a model for the integrators (see :mod:`tumble._model`).

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
from numba.extending import overload

from tumble import _model, _quat, torques
from tumble.dynamics import euler_principal

STATE_SIZE = 7


class RigidModel(NamedTuple):
    """Compiled parameters of a batch of rigid bodies.

    moments : (N or 1, 3) principal moments, kg·m² (one row shared by all bodies, or one per body)
    params  : (N or 1, n_p) torque-program parameters in each body's principal axes
    codes   : int64 torque-program codes, or None for a torque-free body
    """

    moments: np.ndarray
    params: np.ndarray
    codes: np.ndarray | None


def build(bodies, model) -> RigidModel:
    """The :class:`RigidModel` of a list of RigidBody (one, or one per batch member) under a torque model."""
    rows, codes = [], None
    for body in bodies:
        codes, params = torques.compile_program(model, body.axes, offset=0)
        rows.append(params)
    return RigidModel(
        moments=np.ascontiguousarray([b.moments for b in bodies], dtype=np.float64),
        params=np.ascontiguousarray(rows, dtype=np.float64),
        codes=None if model is None else codes,
    )


def _is_rigid(model):
    return isinstance(model, types.BaseNamedTuple) and model.instance_class is RigidModel


@overload(_model.rhs, jit_options={"cache": True})
def _rigid_rhs(model, b, t, y, out):
    if not _is_rigid(model):
        return None
    if isinstance(model.types[2], types.NoneType):  # torque-free: no torque code at all

        def torque(model, b, t, qw, qx, qy, qz, w1, w2, w3):
            return 0.0, 0.0, 0.0

    else:

        def torque(model, b, t, qw, qx, qy, qz, w1, w2, w3):
            p = model.params[b if model.params.shape[0] > 1 else 0]
            return torques.evaluate(t, qw, qx, qy, qz, w1, w2, w3, p, model.codes)

    torque = njit(torque)

    def impl(model, b, t, y, out):
        m = model.moments[b if model.moments.shape[0] > 1 else 0]
        qw, qx, qy, qz, w1, w2, w3 = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
        t1, t2, t3 = torque(model, b, t, qw, qx, qy, qz, w1, w2, w3)
        d = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
        out[0], out[1], out[2], out[3] = 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]
        out[4], out[5], out[6] = euler_principal(m[0], m[1], m[2], w1, w2, w3, t1, t2, t3)

    return impl


@overload(_model.project, jit_options={"cache": True})
def _rigid_project(model, y):
    if not _is_rigid(model):
        return None

    def impl(model, y):
        _model.normalize_quaternion(y)

    return impl
