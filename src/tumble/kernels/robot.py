"""A serial chain (robot arm on a fixed base) as a model for the integrators (see :mod:`tumble._protocol`).

State of a chain of n joints, ``y = [q, q̇, W]`` (2n + 1): the joint
coordinates ``q`` (rad for a revolute joint, m for a prismatic one, base to
tip), their rates ``q̇`` (rad/s or m/s), and the work ``W`` done on the chain by
the joint torques since the start (J). Right-hand side::

    q̇ = q̇,    q̈ = FD(q, q̇, τ),    Ẇ = τ · q̇,    τ = τ(t, q, q̇)

with ``FD`` the articulated-body algorithm (Featherstone, *Rigid Body Dynamics
Algorithms*, Springer 2008, Table 7.1; :mod:`tumble.kernels.featherstone`),
which solves ``M(q) q̈ + C(q, q̇) q̇ + g(q) = τ``. Gravity is conservative and
the joints frictionless, so the energy ``E = T + V`` changes only by the
work of the joint torques, ``dE/dt = τ · q̇``: along the exact motion
``E(t) − W(t) = E(0)``, a power balance every run can be checked against
(:meth:`tumble.robot.SerialChain.invariants`).

The joint coordinates live in a vector space (no quaternion), so
``project`` does nothing and the chain provides a right-hand side only:
``rk4`` and ``dop853`` apply. The torque law is zero, a constant, or a Python
function ``f(t, q, q̇)`` called through the one registry of Python callbacks,
:mod:`tumble._callback` (then ``calls_python``: the batch runs on one core).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, objmode

from tumble import _callback, _protocol
from tumble.kernels import featherstone as _featherstone

# Torque laws (the first entry of RobotModel.law).
ZERO, CONSTANT, PYTHON = 0, 1, 2


class RobotModel(NamedTuple):
    """Compiled parameters of a serial chain under a joint-torque law.

    params  : (n, 42) the chain (layout in :mod:`tumble.kernels.featherstone`)
    gravity : (3,) gravitational acceleration, m/s², base frame
    law     : (2,) int64: the torque law (``ZERO``, ``CONSTANT`` or ``PYTHON``) and,
              for ``PYTHON``, the function's slot in :mod:`tumble._callback`
    torque  : (n,) the constant joint torques of ``CONSTANT`` (N·m or N)
    """

    params: np.ndarray
    gravity: np.ndarray
    law: np.ndarray
    torque: np.ndarray

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side (joint coordinates, no attitude)."""
        return frozenset({"rhs"})

    @property
    def calls_python(self) -> bool:
        """True when the torque law is a Python function (the batch then runs on one core)."""
        return int(self.law[0]) == PYTHON


def initial_states(q0: np.ndarray, qd0: np.ndarray) -> np.ndarray:
    """The states ``[q, q̇, W = 0]`` (N, 2n + 1) from joint coordinates and rates (N, n)."""
    return np.concatenate([q0, qd0, np.zeros((q0.shape[0], 1))], axis=1)


def split(states: np.ndarray, dof: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, q̇, W)`` of states (..., 2n + 1): views (..., n), (..., n) and (...)."""
    return states[..., :dof], states[..., dof:2 * dof], states[..., 2 * dof]


@njit(cache=True)
def joint_torque(model, t, q, qd, tau):
    """The joint torques ``τ(t, q, q̇)`` (N·m or N) of the model's law, into ``tau`` (n,)."""
    law = model.law[0]
    if law == ZERO:
        tau[:] = 0.0
    elif law == CONSTANT:
        tau[:] = model.torque
    else:
        slot = model.law[1]
        with objmode():
            _callback.invoke(slot, t, (q, qd), tau)


@njit(cache=True)
def sample_torques(model, t, Q, QD, TAU):
    """``TAU[k, b] = τ(t[k], Q[k, b], QD[k, b])``: the applied joint torques at the output samples (time, member, joint)."""
    for k in range(Q.shape[0]):
        for b in range(Q.shape[1]):
            joint_torque(model, t[k], Q[k, b], QD[k, b], TAU[k, b])


@njit(cache=True)
def _derivative(model, t, y, ydot):
    """``ẏ = [q̇, FD(q, q̇, τ), τ · q̇]`` of one state vector ``y = [q, q̇, W]``.

    ``q`` and ``q̇`` are copied out of ``y`` (which may be a lane of a block)
    so that the articulated-body algorithm always sees contiguous arrays: one
    compiled version of it serves every call.
    """
    n = model.params.shape[0]
    W, X, T = _featherstone.aba_scratch(n)
    q, qd = y[:n].copy(), y[n:2 * n].copy()
    tau, qdd = np.empty(n), np.empty(n)
    joint_torque(model, t, q, qd, tau)
    _featherstone.aba_one(model.params, q, qd, tau, model.gravity, np.zeros(6), W, X, T, qdd)
    power = 0.0
    for i in range(n):
        ydot[i] = qd[i]
        ydot[n + i] = qdd[i]
        power += tau[i] * qd[i]
    ydot[2 * n] = power



@_protocol.implements(_protocol.rhs, RobotModel)
def _robot_rhs(model, b0, t, Y, OUT):
    return _protocol.lanewise_rhs(_derivative, Y)


@_protocol.implements(_protocol.project, RobotModel)
def _robot_project(model, b0, t, Y):
    return lambda model, b0, t, Y: None  # joint coordinates and work live in a vector space


@_protocol.implements(_protocol.state_size, RobotModel)
def _robot_state_size(model):
    return lambda model: 2 * model.params.shape[0] + 1
