"""A robot (kinematic tree on a fixed or floating base) as a model for the integrators (see :mod:`tumble._protocol`).

State of a robot with nq configuration and nv velocity coordinates,
``y = [q, q̇, W]`` (nq + nv + 1): the configuration ``q`` (joint coordinates,
rad or m; with a floating base first ``r`` (m, world) and the unit quaternion
``[w, x, y, z]`` base → world), the velocities ``q̇`` (joint rates; with a
floating base first ``ω`` and ``v`` of the base, base axes), and the work
``W`` done by the joint torques since the start (J). Right-hand side::

    q̇_joints = q̇_joints,   ṙ = R(quat) v,   quaṫ = ½ quat ⊗ [0, ω],
    q̈ = FD(q, q̇, τ),    Ẇ = τ · q̇,    τ = τ(t, q, q̇)

with ``FD`` the articulated-body algorithm (Featherstone, *Rigid Body Dynamics
Algorithms*, Springer 2008, Tables 7.1 and 9.6; with mimic joints a CRBA
solve; :mod:`tumble.kernels.featherstone`), which solves ``M(q) q̈ + C(q, q̇)
q̇ + g(q) = τ``. Gravity is conservative and the joints frictionless, so the
energy ``E = T + V`` changes only by the work of the joint torques, ``dE/dt
= τ · q̇``: along the exact motion ``E(t) − W(t) = E(0)``, a power balance
every run can be checked against (:meth:`tumble.robot.RobotTree.invariants`).
The joint torques act on the joints only (none on a floating base).

``project`` renormalises the base quaternion (a fixed base has nothing to
project). The torque law is zero, a constant, or a Python function ``f(t, q,
q̇)`` called through the one registry of Python callbacks,
:mod:`tumble._callback` (then ``calls_python``: the batch runs on one core;
refused on a GPU).

``FD`` runs in the kernel's ``scratch`` (:func:`scratch_size`: the articulated
bodies' spatial quantities, the copies of ``q``, ``q̇``, ``τ`` and ``q̈``, a zero wrench),
which the methods allocate once per run with their workspace, per block on
the CPU and per member on a GPU (:func:`tumble._protocol.scratch`): an
evaluation allocates nothing, so the same right-hand side compiles for an
NVIDIA GPU (``"cuda"``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, objmode
from numba.extending import overload

from tumble import _callback, _protocol
from tumble._quat import qmul, qnorm, qrotate
from tumble.kernels import featherstone as _featherstone

# Torque laws (the first entry of RobotModel.law).
ZERO, CONSTANT, PYTHON = 0, 1, 2


class RobotModel(NamedTuple):
    """Compiled parameters of a robot under a joint-torque law.

    params  : (nb, 45) the tree (columns in :mod:`tumble.kernels.featherstone.layout`)
    sizes   : (2,) int64: nq and nv
    gravity : (3,) gravitational acceleration, m/s², base frame
    law     : (2,) int64: the torque law (``ZERO``, ``CONSTANT`` or ``PYTHON``) and,
              for ``PYTHON``, the function's slot in :mod:`tumble._callback`
    torque  : (dof,) the constant joint torques of ``CONSTANT`` (N·m or N)
    scratch : (:func:`scratch_size`,) where the right-hand side evaluates (one evaluation at a time); the
              methods give each block or GPU thread its own (:func:`tumble._protocol.with_scratch`)
    """

    params: np.ndarray
    sizes: np.ndarray
    gravity: np.ndarray
    law: np.ndarray
    torque: np.ndarray
    scratch: np.ndarray

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side (and a projection); ``"cuda"``
        without a Python torque law."""
        return frozenset({"rhs", *(() if self.calls_python else ("cuda",))})

    @property
    def calls_python(self) -> bool:
        """True when the torque law is a Python function (the batch then runs on one core)."""
        return int(self.law[0]) == PYTHON

    @property
    def gpu_refusal(self) -> str | None:
        """Why this kernel cannot run on an NVIDIA GPU (a ValidationError message), or None: a Python torque law."""
        return _protocol.python_on_gpu("torque") if self.calls_python else None


def scratch_size(nb: int, nv: int) -> int:
    """Length of the scratch of one evaluation for a tree of nb bodies and nv velocity coordinates: the
    single-state workspace of :mod:`tumble.kernels.featherstone` (the bodies' scratch, the forward dynamics'
    matrices, the copies of ``q``, ``q̇`` and ``τ``), then ``q̈`` (nv) and a zero wrench (6)."""
    return _featherstone.workspace_size(nb, nv) + nv + 6


def initial_states(q0: np.ndarray, qd0: np.ndarray) -> np.ndarray:
    """The states ``[q, q̇, W = 0]`` (N, nq + nv + 1) from configurations (N, nq) and velocities (N, nv)."""
    return np.concatenate([q0, qd0, np.zeros((q0.shape[0], 1))], axis=1)


def split(states: np.ndarray, nq: int, nv: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, q̇, W)`` of states (..., nq + nv + 1): views (..., nq), (..., nv) and (...)."""
    return states[..., :nq], states[..., nq:nq + nv], states[..., nq + nv]


@njit(cache=True)
def joint_torque(model, t, q, qd, tau):
    """The joint torques ``τ(t, q, q̇)`` (N·m or N) of the model's law, into ``tau`` (n,)."""
    law = model.law[0]
    if law == ZERO:
        for i in range(tau.shape[0]):
            tau[i] = 0.0
    elif law == CONSTANT:
        for i in range(tau.shape[0]):  # by a loop: a slice assignment compiles a shape-mismatch message formatter
            tau[i] = model.torque[i]
    else:
        _python_law(model, t, q, qd, tau)


@njit(cache=True)
def _call_python_law(model, t, q, qd, tau):
    """``tau = f(t, q, q̇)``: the law's Python function, called through :mod:`tumble._callback`."""
    slot = model.law[1]
    with objmode():
        _callback.invoke(slot, t, (q, qd), tau)


def _python_law(model, t, q, qd, tau):  # pragma: no cover - replaced by the overloads in compiled code
    """``tau = f(t, q, q̇)``, the law's Python function. Compiled per target: on the CPU it calls the function;
    on an NVIDIA GPU it does nothing, since a Python law is refused before a launch (``gpu_refusal``), so that
    the right-hand side compiles for the GPU."""
    raise NotImplementedError("compiled code only")


@overload(_python_law, target="cpu", jit_options={"cache": True})
def _python_law_cpu(model, t, q, qd, tau):
    return lambda model, t, q, qd, tau: _call_python_law(model, t, q, qd, tau)


@overload(_python_law, target="cuda")
def _python_law_gpu(model, t, q, qd, tau):
    return lambda model, t, q, qd, tau: None


@njit(cache=True)
def sample_torques(model, t, Q, QD, TAU):
    """``TAU[k, b] = τ(t[k], Q[k, b], QD[k, b])``: the applied joint torques at the output samples (time, member, joint)."""
    for k in range(Q.shape[0]):
        for b in range(Q.shape[1]):
            joint_torque(model, t[k], Q[k, b], QD[k, b], TAU[k, b])


@njit(cache=True)
def _derivative(model, t, y, ydot):
    """``ẏ = [q̇ (configuration rates), FD(q, q̇, τ), τ · q̇]`` of one state vector ``y = [q, q̇, W]``, in the
    kernel's scratch.

    ``q`` and ``q̇`` are copied out of ``y`` (which may be a lane of a block)
    so that the forward dynamics always sees contiguous arrays: one compiled
    version of it serves every call.
    """
    nq, nv = model.sizes[0], model.sizes[1]
    fl = nq - nv
    P, S = model.params, model.scratch
    W, X, T, M, zero = _featherstone.fd_views(P, S, nv)
    o = _featherstone.state_offset(P, nv)  # q, q̇, τ, then q̈
    q, qd = _featherstone.state_copy(y[:nq], S, o), _featherstone.state_copy(y[nq:nq + nv], S, o + nq)
    tau, qdd = S[o + nq + nv:o + nq + 2 * nv], S[o + nq + 2 * nv:o + nq + 3 * nv]
    no_wrench = S[o + nq + 3 * nv:o + nq + 3 * nv + 6]  # on the last body
    for i in range(6):
        no_wrench[i] = 0.0
    for i in range(6 * fl):  # no joint torque on a floating base
        tau[i] = 0.0
    joint_torque(model, t, q, qd, tau[6 * fl:])
    _featherstone.forward_one(P, q, qd, tau, model.gravity, no_wrench, W, X, T, M, zero, qdd)
    power = 0.0
    for i in range(nv):
        ydot[nq + i] = qdd[i]
        power += tau[i] * qd[i]
    for i in range(6 * fl, nv):
        ydot[i + fl] = qd[i]
    if fl == 1:  # ṙ = R(quat) v, quaṫ = ½ quat ⊗ [0, ω]
        vx, vy, vz = qrotate(q[3], q[4], q[5], q[6], qd[3], qd[4], qd[5])
        ydot[0], ydot[1], ydot[2] = vx, vy, vz
        dw, dx, dy, dz = qmul(q[3], q[4], q[5], q[6], 0.0, qd[0], qd[1], qd[2])
        ydot[3], ydot[4], ydot[5], ydot[6] = 0.5 * dw, 0.5 * dx, 0.5 * dy, 0.5 * dz
    ydot[nq + nv] = power


@njit(cache=True)
def _normalise_base(model, y):
    """Renormalise the floating base's quaternion ``y[3:7]`` (nothing on a fixed base)."""
    if model.sizes[0] > model.sizes[1]:
        n = qnorm(y[3], y[4], y[5], y[6])
        for k in range(3, 7):
            y[k] /= n


@_protocol.implements(_protocol.rhs, RobotModel)
def _robot_rhs(model, b0, t, Y, OUT):
    return _protocol.lanewise_rhs(_derivative, Y)


@_protocol.implements(_protocol.project, RobotModel)
def _robot_project(model, b0, t, Y):
    if Y.ndim == 1:
        return lambda model, b0, t, Y: _normalise_base(model, Y)

    def impl(model, b0, t, Y):
        for j in range(Y.shape[1]):
            _normalise_base(model, Y[:, j])

    return impl


@_protocol.implements(_protocol.state_size, RobotModel)
def _robot_state_size(model):
    return lambda model: model.sizes[0] + model.sizes[1] + 1


@_protocol.implements(_protocol.scratch, RobotModel)
def _robot_scratch(model, Y):
    return lambda model, Y: np.empty(model.scratch.shape[0])


@_protocol.implements(_protocol.with_scratch, RobotModel, inline=True)
def _robot_with_scratch(model, S):
    return lambda model, S: RobotModel(model.params, model.sizes, model.gravity, model.law, model.torque, S)
