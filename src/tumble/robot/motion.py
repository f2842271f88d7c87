"""A serial chain as a model of the front door (:class:`tumble.simulate.Model`).

``tumble.simulate(chain, q0=..., qd0=..., t=..., torque=...)`` integrates the
equations of motion of a robot arm on a fixed base::

    M(q) q̈ + C(q, q̇) q̇ + g(q) = τ(t, q, q̇),      Ẇ = τ · q̇

from the joint coordinates ``q0`` and rates ``qd0`` (the kernel is
:mod:`tumble.kernels.robot`). ``q`` is the joint vector (rad for a revolute
joint, m for a prismatic one, base to tip), not an attitude quaternion: a
chain has no single attitude, so the :class:`~tumble.Trajectory` has
``q = omega = inertia = None`` and carries the joint motion as extras
(``joint_position``, ``joint_velocity``, ``joint_torque``, ``work``) and the
energy ``E = T + V`` as its total. Gravity is the chain's
(:meth:`tumble.robot.SerialChain.with_gravity` changes it). The joint limits
are not enforced: the model has no joint stops or friction.

:class:`ChainMotion` implements the model interface for
:class:`tumble.robot.SerialChain`, which provides ``dof``, ``joint_names``,
``name`` and the compiled arrays ``_params`` and ``_gravity``.
"""

from __future__ import annotations

import numpy as np

from tumble import _callback, torques
from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _featherstone
from tumble.kernels import robot as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra

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
              "joint coordinates and rates (at Python speed, on one core)")

    def state_fields(self) -> tuple[StateField, ...]:
        n = self.dof
        return (
            StateField("q0", n, f"initial joint coordinates, the joint vector ({n},), not a quaternion: rad "
                                "(revolute) or m (prismatic), base to tip"),
            StateField("qd0", n, f"initial joint rates ({n},), rad/s or m/s (default 0: released at rest)",
                       default=np.zeros(n)),
        )

    def compile(self, torque, t0: float) -> _kernel.RobotModel:
        law, slot, constant = self._torque_law(torque)
        return _kernel.RobotModel(params=self._params, gravity=self._gravity,
                                  law=np.array([law, slot], dtype=np.int64), torque=constant)

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

    def initial_states(self, kernel, values, t0):
        return _kernel.initial_states(values["q0"], values["qd0"])

    def outputs(self, kernel, t, states) -> Outputs:
        """The joint motion at the samples, the applied torques (the law evaluated there: a Python function
        is called once more per sample), the work ``W`` and the energy ``T + V`` (J)."""
        n = self.dof
        q, qd, work = _kernel.split(states, n)
        q, qd = np.ascontiguousarray(q), np.ascontiguousarray(qd)
        tau = np.empty_like(q)
        _kernel.sample_torques(kernel, t, q, qd, tau)
        energies = np.empty((*q.shape[:-1], 2))  # kinetic T = ½ q̇ᵀ M q̇, potential V = −Σ mᵢ g · cᵢ
        _featherstone.energy_batch(kernel.params, q.reshape(-1, n), qd.reshape(-1, n), kernel.gravity,
                                   energies.reshape(-1, 2))
        joint = ("joint",)
        extras = {
            "joint_position": Extra(q, joint, "rad or m", "joint coordinates q, base to tip"),
            "joint_velocity": Extra(qd, joint, "rad/s or m/s", "joint rates dq/dt"),
            "joint_torque": Extra(tau, joint, "N m or N", "joint torques applied at the samples, tau(t, q, dq/dt)"),
            "work": Extra(work, (), "J", "work done by the joint torques since the start, W = int tau . dq/dt dt"),
        }
        names = [str(name) if name is not None else f"joint{k + 1}" for k, name in enumerate(self.joint_names)]
        info = {"joint_names": ", ".join(names),
                **{f"gravity_{axis}": float(g) for axis, g in zip("xyz", kernel.gravity)}}
        if self.name is not None:
            info["robot"] = self.name
        return Outputs(q=None, omega=None, inertia=None, extras=extras,
                       totals={"energy": energies[..., 0] + energies[..., 1]}, info=info)

    def invariants(self, traj) -> dict[str, np.ndarray]:
        """``E − W``, J (n, [N]): the energy ``T + V`` less the work of the joint torques, ``E(0)`` along the
        exact motion under any torque law (gravity is conservative, the joints frictionless)."""
        return {"energy_minus_work": traj.energy - traj.work}
