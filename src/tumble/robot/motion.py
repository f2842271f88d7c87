"""A robot (serial chain or tree, fixed or floating base) as a model of the front door (:class:`tumble.simulate.Model`).

``tumble.simulate(robot, q0=..., qd0=..., t=..., torque=...)`` integrates the
equations of motion of a robot::

    M(q) q̈ + C(q, q̇) q̇ + g(q) = τ(t, q, q̇),      Ẇ = τ · q̇

from the joint coordinates ``q0`` and rates ``qd0`` (the kernel is
:mod:`tumble.kernels.robot`). ``q`` is the joint vector (rad for a revolute
joint, m for a prismatic one), not an attitude quaternion: a robot has no
single attitude, so the :class:`~tumble.Trajectory` has ``q = omega =
inertia = None`` and carries the joint motion as extras (``joint_position``,
``joint_velocity``, ``joint_torque``, ``work``) and the energy ``E = T + V``
as its total. A floating base (a legged robot in flight, a spacecraft hub
carrying an arm) adds the initial values ``base_position0`` (m, world),
``base_q0`` (unit quaternion ``[w, x, y, z]``, base → world), ``base_omega0``
and ``base_velocity0`` (rad/s and m/s, base axes) and the extras
``base_position``, ``base_attitude``, ``base_omega``, ``base_velocity`` and
the centroidal momentum ``angular_momentum`` (about the centre of mass) and
``linear_momentum``, world axes, which stay constant without gravity.
Gravity is the robot's (:meth:`tumble.robot.RobotTree.with_gravity` changes
it). The joint limits are not enforced (no joint stops or friction): the
extra ``beyond_limits`` says, per sample, whether a joint has left its range.

:class:`ChainMotion` implements the model interface for
:class:`tumble.robot.RobotTree`, which provides ``nq``, ``nv``, ``dof``,
``joint_names``, ``massless_joints``, ``name``, the limits and the compiled
arrays ``_params`` and ``_gravity``.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from tumble import _callback, torques
from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _featherstone
from tumble.kernels import robot as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory

__all__ = ["ChainMotion"]


class _TorqueFunction:
    """A Python joint-torque law ``f(t, q, qd) -> (n,)`` (N·m or N), registered with the one registry of
    Python callbacks (:mod:`tumble._callback`) for as long as this object lives (a run)."""

    __slots__ = ("function", "slot", "__weakref__")

    def __init__(self, function, dof: int):
        self.function = function
        self.slot = _callback.register(self, function, field="torque", signature="(t, q, qd)",
                                       returns=f"{dof} finite numbers (joint torques, N·m or N)")


class ChainMotion(Model):
    """The model interface of a serial chain: initial state ``q0``, ``qd0``; outputs the joint motion and its energy."""

    __slots__ = ()

    torque = ("joint torques and forces, one per joint, N·m (revolute) or N (prismatic): None (the arm moves "
              "under gravity alone), a constant (n,), or a Python function f(t, q, qd) -> (n,) of the time (s), "
              "joint coordinates and rates (at Python speed, on one core); with a floating base q and qd are the "
              "whole configuration [base position, base quaternion, joints] (7 + n,) and velocity [base omega, "
              "base velocity, joint rates] (6 + n,)")

    # -- what the tree provides (tumble.robot.RobotTree) -----------------------
    _params: np.ndarray  # (nb, 45): the columns of tumble.kernels.featherstone.layout
    _gravity: np.ndarray  # (3,) m/s², world frame

    @property
    @abc.abstractmethod
    def nq(self) -> int: ...

    @property
    @abc.abstractmethod
    def nv(self) -> int: ...

    @property
    @abc.abstractmethod
    def dof(self) -> int: ...

    @property
    @abc.abstractmethod
    def floating_base(self) -> bool: ...

    @property
    @abc.abstractmethod
    def joint_names(self) -> tuple[str | None, ...]: ...

    @property
    @abc.abstractmethod
    def name(self) -> str | None: ...

    @property
    @abc.abstractmethod
    def massless_joints(self) -> tuple[str, ...]: ...

    @property
    @abc.abstractmethod
    def lower(self) -> np.ndarray: ...

    @property
    @abc.abstractmethod
    def upper(self) -> np.ndarray: ...

    # -- the model interface (tumble.simulate.Model) ----------------------------

    def state_fields(self) -> tuple[StateField, ...]:
        n = self.dof
        joints = (
            StateField("q0", n, f"initial joint coordinates, the joint vector ({n},), not a quaternion: rad "
                                "(revolute) or m (prismatic), base to tip",
                       default=np.zeros(0) if n == 0 else None),  # a single free body has no joint
            StateField("qd0", n, f"initial joint rates ({n},), rad/s or m/s (default 0: released at rest)",
                       default=np.zeros(n)),
        )
        if not self.floating_base:
            return joints
        return joints + (
            StateField("base_position0", 3, "initial origin of the floating base, m, world frame (default 0)",
                       default=np.zeros(3)),
            StateField("base_q0", 4, "initial attitude of the floating base, unit quaternion [w, x, y, z], base -> "
                                     "world (default identity)", default=np.array([1.0, 0.0, 0.0, 0.0]),
                       quaternion=True),
            StateField("base_omega0", 3, "initial angular velocity of the floating base, rad/s, base axes "
                                         "(default 0)", default=np.zeros(3)),
            StateField("base_velocity0", 3, "initial velocity of the floating base's origin, m/s, base axes "
                                            "(default 0)", default=np.zeros(3)),
        )

    def compile(self, torque: ArrayLike | Callable[[float, np.ndarray, np.ndarray], ArrayLike] | None,
                t0: float) -> _kernel.RobotModel:
        if self.massless_joints:
            raise ValidationError(f"model: joint(s) {list(self.massless_joints)} move no mass or inertia, so M(q) "
                                  "is singular and the motion undefined (load the URDF with min_inertia > 0 to give "
                                  "the links a least inertia)")
        law, slot, constant = self._torque_law(torque)
        return _kernel.RobotModel(params=self._params, sizes=np.array([self.nq, self.nv], dtype=np.int64),
                                  gravity=self._gravity, law=np.array([law, slot], dtype=np.int64),
                                  torque=constant, scratch=np.empty(_kernel.scratch_size(len(self._params), self.nv)))

    def _torque_law(self, torque) -> tuple[int, int, np.ndarray]:
        """``(law, callback slot, constant torque)`` of the ``torque`` argument."""
        n = self.dof
        if torque is None:
            return _kernel.ZERO, 0, np.zeros(n)
        if isinstance(torque, torques.TorqueModel):
            raise ValidationError(f"torque: a {type(self).__name__} takes joint torques (N·m or N, one per joint), "
                                  f"not a body torque model such as {torque!r}")
        if callable(torque):
            return _kernel.PYTHON, _TorqueFunction(torque, n).slot, np.zeros(n)
        tau = as_array(torque, "torque")
        if tau.shape != (n,):
            raise ValidationError(f"torque: must be None, a callable f(t, q, qd) -> ({n},) or a constant ({n},) "
                                  f"(N·m or N); got shape {tau.shape}")
        return _kernel.CONSTANT, 0, np.array(tau)

    def initial_states(self, kernel: _kernel.RobotModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        if not self.floating_base:
            return _kernel.initial_states(values["q0"], values["qd0"])
        q = np.concatenate([values["base_position0"], values["base_q0"], values["q0"]], axis=-1)
        qd = np.concatenate([values["base_omega0"], values["base_velocity0"], values["qd0"]], axis=-1)
        return _kernel.initial_states(q, qd)

    def outputs(self, kernel: _kernel.RobotModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        """The joint motion at the samples, the applied torques (the law evaluated there: a Python function
        is called once more per sample), the work ``W`` and the energy ``T + V`` (J)."""
        n, nq, nv = self.dof, self.nq, self.nv
        q_all, qd_all, work = _kernel.split(states, nq, nv)
        q_all, qd_all = np.ascontiguousarray(q_all), np.ascontiguousarray(qd_all)
        q, qd = np.ascontiguousarray(q_all[..., nq - n:]), np.ascontiguousarray(qd_all[..., nv - n:])
        tau = np.empty_like(q)
        _kernel.sample_torques(kernel, t, q_all, qd_all, tau)
        energies = np.empty((*q.shape[:-1], 2))  # kinetic T = ½ q̇ᵀ M q̇, potential V = −Σ mᵢ g · cᵢ
        _featherstone.energy_batch(kernel.params, q_all.reshape(-1, nq), qd_all.reshape(-1, nv), kernel.gravity,
                                   energies.reshape(-1, 2))
        joint = ("joint",)
        outside = (q < self.lower) | (q > self.upper)
        extras = {
            "joint_position": Extra(q, joint, "rad or m", "joint coordinates q, base to tip"),
            "joint_velocity": Extra(qd, joint, "rad/s or m/s", "joint rates dq/dt"),
            "joint_torque": Extra(tau, joint, "N m or N", "joint torques applied at the samples, tau(t, q, dq/dt)"),
            "work": Extra(work, (), "J", "work done by the joint torques since the start, W = int tau . dq/dt dt"),
            "beyond_limits": Extra(np.asarray(outside.any(axis=-1), dtype=np.float64), (), "1",
                                   "1 where a joint is beyond its limits (not enforced: no joint stops), else 0"),
        }
        if self.floating_base:
            extras.update(self._base_extras(q_all, qd_all))
        names = [str(name) if name is not None else f"joint{k + 1}" for k, name in enumerate(self.joint_names)]
        info = {"joint_names": ", ".join(names),
                **{f"gravity_{axis}": float(g) for axis, g in zip("xyz", kernel.gravity)}}
        if self.name is not None:
            info["robot"] = self.name
        return Outputs(q=None, omega=None, inertia=None, extras=extras,
                       totals={"energy": energies[..., 0] + energies[..., 1]}, info=info)

    def _base_extras(self, q, qd) -> dict:
        """The floating base's motion and the centroidal momentum (world axes) at every sample (compiled:
        :func:`tumble.kernels.featherstone.centroidal_momentum_batch`)."""
        h = np.empty((*q.shape[:-1], 6))
        _featherstone.centroidal_momentum_batch(self._params, q.reshape(-1, self.nq), qd.reshape(-1, self.nv),
                                                h.reshape(-1, 6))
        vector = ("xyz",)
        return {
            "base_position": Extra(q[..., 0:3], vector, "m", "origin of the floating base, world frame"),
            "base_attitude": Extra(q[..., 3:7], ("wxyz",), "1", "unit quaternion [w, x, y, z], base -> world"),
            "base_omega": Extra(qd[..., 0:3], vector, "rad/s", "angular velocity of the base, base axes"),
            "base_velocity": Extra(qd[..., 3:6], vector, "m/s", "velocity of the base's origin, base axes"),
            "angular_momentum": Extra(h[..., 0:3], vector, "N m s",
                                      "total angular momentum about the centre of mass, world axes"),
            "linear_momentum": Extra(h[..., 3:6], vector, "N s", "total linear momentum, world axes"),
        }

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """``E − W``, J (n, [N]): the energy ``T + V`` less the work of the joint torques, ``E(0)`` along the
        exact motion under any torque law (gravity is conservative, the joints frictionless)."""
        return {"energy_minus_work": traj.energy - traj.work}
