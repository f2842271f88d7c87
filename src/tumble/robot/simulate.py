"""Motion of a serial chain under a torque law, integrated by :mod:`tumble.integrate`.

The state of a chain of n joints is ``y = [q, q̇]`` (2n); its right-hand side
is the articulated-body algorithm::

    q̇ = q̇,    q̈ = FD(q, q̇, τ(t, q, q̇))

so every fixed-step and adaptive method of the one integration engine applies
(``rk4``, ``dop853``), with batches of initial states run in parallel. The
chain is a model of the protocol of :mod:`tumble._protocol` (:class:`RobotModel`);
it has no attitude quaternion, so its projection does nothing.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numba import njit, objmode
from numba.extending import overload

from tumble import _protocol, integrate
from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _kernels
from tumble.robot.chain import SerialChain
from tumble.trajectory import write_atomic

__all__ = ["JointTrajectory", "RobotModel", "simulate"]

METHODS = ("rk4", "dop853")
# Torque laws (RobotModel.law).
_ZERO, _CONSTANT, _PYTHON = 0, 1, 2


class RobotModel(NamedTuple):
    """Compiled parameters of a chain for the integrators.

    params : (n, 42) the chain (:mod:`tumble.kernels.featherstone`)
    gravity: (3,) m/s², base frame
    law    : (1,) int64 code of the torque law: zero, constant or a Python function
    torque : (n,) the constant torque (N·m or N)
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
        return int(self.law[0]) == _PYTHON


# A Python torque law is reachable from compiled code while its run is in progress.
_CALLBACK: list = [None]


def _call_python(t, q, qd, out):
    function = _CALLBACK[0]
    tau = np.asarray(function(float(t), q.copy(), qd.copy()), dtype=np.float64)
    if tau.shape != out.shape or not np.isfinite(tau).all():
        name = getattr(function, "__name__", repr(function))
        raise ValidationError(f"torque: the function {name}(t, q, qd) must return {out.shape[0]} finite numbers "
                              f"(N·m or N); at t={t} it returned {tau!r}")
    out[:] = tau


@njit(cache=True)
def _torque(model, t, q, qd, tau):
    """The torque law at (t, q, q̇) into ``tau``."""
    law = model.law[0]
    if law == _ZERO:
        tau[:] = 0.0
    elif law == _CONSTANT:
        tau[:] = model.torque
    else:
        with objmode():
            _call_python(t, q, qd, tau)


@njit(cache=True)
def _derivative(model, t, y, ydot):
    """``ẏ = [q̇, FD(q, q̇, τ(t, q, q̇))]`` of one state vector ``y = [q, q̇]`` (both C-contiguous).

    ``q`` and ``q̇`` are copied out of ``y`` so that the articulated-body
    algorithm runs with the argument types of the batched calls: one compiled
    version serves both (Numba compiles one per array layout).
    """
    n = model.params.shape[0]
    W, X, T = _kernels.aba_scratch(n)
    q, qd = y[:n].copy(), y[n:].copy()
    tau, qdd = np.empty(n), np.empty(n)
    _torque(model, t, q, qd, tau)
    _kernels.aba_one(model.params, q, qd, tau, model.gravity, np.zeros(6), W, X, T, qdd)
    ydot[:n] = qd
    ydot[n:] = qdd


def _is_robot(model):
    return _protocol.is_type(model, RobotModel)


@overload(_protocol.rhs, jit_options={"cache": True})
def _robot_rhs(model, b0, t, Y, OUT):
    if not _is_robot(model):
        return None
    if Y.ndim == 1:
        return lambda model, b0, t, Y, OUT: _derivative(model, t, Y, OUT)

    def impl(model, b0, t, Y, OUT):  # a block: state × lanes
        y, ydot = np.empty(Y.shape[0]), np.empty(Y.shape[0])
        for j in range(Y.shape[1]):
            y[:] = Y[:, j]
            _derivative(model, t, y, ydot)
            OUT[:, j] = ydot

    return impl


@overload(_protocol.project, jit_options={"cache": True})
def _robot_project(model, b0, t, Y):
    if not _is_robot(model):
        return None
    return lambda model, b0, t, Y: None  # joint coordinates live in a vector space


@overload(_protocol.state_size, jit_options={"cache": True})
def _robot_state_size(model):
    if not _is_robot(model):
        return None
    return lambda model: 2 * model.params.shape[0]


@dataclass(frozen=True, eq=False)
class JointTrajectory:
    """Joint motion of a chain sampled at the output times.

    t : (m,) s;  q : (m, [B,] n) rad or m;  qd : (m, [B,] n) rad/s or m/s;
    method : the integrator; info : solver settings and statistics.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    method: str
    joint_names: tuple
    info: dict = field(default_factory=dict)

    def to_xarray(self):
        """An :class:`xarray.Dataset` with variables ``q`` and ``qd`` over (time, [batch,] joint)."""
        import xarray as xr

        dims = ("time", "joint") if self.q.ndim == 2 else ("time", "batch", "joint")
        names = [str(n) for n in self.joint_names]
        ds = xr.Dataset(
            {"q": (dims, self.q, {"units": "rad or m", "long_name": "joint coordinates"}),
             "qd": (dims, self.qd, {"units": "rad/s or m/s", "long_name": "joint velocities"})},
            coords={"time": ("time", self.t, {"units": "s"}), "joint": ("joint", names)},
            attrs={"method": self.method, **{f"solver_{k}": v for k, v in self.info.items()}},
        )
        return ds

    def save(self, path: str | os.PathLike) -> None:
        """Write a NetCDF-4 file atomically (temporary file, then rename)."""
        ds = self.to_xarray()
        write_atomic(path, lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))


def _law(chain: SerialChain, torque):
    """``(code, constant torque)`` of a torque law."""
    n = chain.dof
    if torque is None:
        return _ZERO, np.zeros(n)
    if callable(torque):
        return _PYTHON, np.zeros(n)
    tau = as_array(torque, "torque")
    if tau.shape != (n,):
        raise ValidationError(f"torque: must be None, a callable f(t, q, qd) -> ({n},) or a constant ({n},) "
                              f"(N·m or N); got shape {tau.shape}")
    return _CONSTANT, np.array(tau)


def simulate(chain: SerialChain, q0, qd0, *, t, torque=None, method: str = "rk4", dt: float | None = None,
             rtol: float = 1e-10, atol: float = 1e-12, gravity=None,
             max_steps: int = 10**9) -> JointTrajectory:
    """Integrate ``M(q) q̈ + C(q, q̇) q̇ + g(q) = τ`` from ``(q0, qd0)`` through the output times ``t``.

    ``q0``, ``qd0``: (n,) or a batch (B, n) of initial joint coordinates (rad
    or m) and velocities. ``torque``: ``None`` (no actuation: the chain falls
    under gravity), a constant (n,), or a Python function
    ``f(t, q, qd) -> (n,)`` for any other law (slower: it is called from
    compiled code, on one core). ``method``: ``"rk4"`` (fixed step ``dt``, s) or ``"dop853"``
    (adaptive, ``rtol``/``atol``). ``gravity`` (m/s², base frame) defaults to
    the chain's.
    """
    if not isinstance(chain, SerialChain):
        raise ValidationError(f"chain: must be a SerialChain, got {type(chain).__name__}")
    if method not in METHODS:
        raise ValidationError(f"method: must be one of {METHODS} for a serial chain, got {method!r}")
    t = as_array(t, "t")
    if t.ndim != 1 or t.size < 1 or (np.diff(t) <= 0.0).any():
        raise ValidationError("t: must be a 1-D array of strictly increasing output times (s)")
    n = chain.dof
    q0 = as_array(q0, "q0", tail=(n,))
    qd0 = as_array(qd0, "qd0", tail=(n,))
    if q0.shape != qd0.shape or q0.ndim > 2:
        raise ValidationError(f"qd0: must have the shape of q0 {q0.shape} ((n,) or (B, n)), got {qd0.shape}")
    code, tau = _law(chain, torque)
    g = chain._gravity if gravity is None else as_array(gravity, "gravity", tail=(3,)).reshape(3)
    model = RobotModel(params=chain._params, gravity=np.array(g), law=np.array([code], dtype=np.int64),
                       torque=tau)
    y0 = np.concatenate([np.atleast_2d(q0), np.atleast_2d(qd0)], axis=1)
    if code == _PYTHON:
        _CALLBACK[0] = torque
    try:
        solution = integrate.solve(model, y0, t, method=method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps)
        states, stats = solution.states, solution.statistics()
    finally:
        _CALLBACK[0] = None
    if q0.ndim == 1:
        states = states[:, 0]
    info = {**stats, **({"dt": float(dt)} if method == "rk4" else {"rtol": rtol, "atol": atol})}
    return JointTrajectory(t=t, q=states[..., :n], qd=states[..., n:], method=method,
                           joint_names=chain.joint_names, info=info)
