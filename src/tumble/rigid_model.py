"""The rigid body as a model of the front door (:class:`tumble.model.Model`).

The integrators work in each body's principal axes P, where Euler's
equations are cheapest (``I₁ω̇₁ = τ₁ + (I₂ − I₃)ω₂ω₃`` and cyclic; the kernel
is :mod:`tumble.kernels.rigid`). The initial state moves into those axes and
the results back::

    q_NP = q_NB ⊗ q_BP,   ω_P = R_BPᵀ ω_B        (in)
    q_NB = q_NP ⊗ q_BP*,  ω_B = R_BP ω_P         (out)

with ``R_BP = body.axes`` (columns: the principal axes in body axes). The
change of axes is exact for a diagonal inertia and costs a few rounding errors
otherwise; the motion does not depend on the body axes chosen (tested).

:class:`RigidBodies` is that model: of one :class:`tumble.RigidBody` (a
value: mass properties only), which :func:`tumble.simulate` turns into its
model, or of a batch with one body per member (a sequence of RigidBody or an
(N, 3, 3) inertia array, validated in one vectorised call).
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Sequence
from typing import cast

import numpy as np
from numba import njit
from numba.extending import register_jitable
from numpy.typing import ArrayLike

from tumble import attitude, limits, torques
from tumble._inertia import principal_axes
from tumble._quat import qmul
from tumble._validate import ValidationError, as_array, readonly
from tumble.kernels import rigid as _kernel
from tumble.rigid_body import RigidBody
from tumble.model import Model, Outputs, StateField

__all__ = ["RigidBodies"]

#: The stack depth from the warnings of :mod:`tumble.limits` to the caller of ``simulate``.
_STACKLEVEL = 4


@functools.cache
def _state_fields() -> tuple[StateField, ...]:
    """The initial state of every rigid model, made once, on the first call: a simulate call reads it (not at
    import: checking the default quaternion calls compiled code, whose loading would slow ``import tumble``)."""
    return (
        StateField("omega0", 3, "initial body rate, rad/s, body axes"),
        StateField("q0", 4, "initial attitude, unit quaternion [w, x, y, z], body → inertial",
                   default=attitude.identity(), quaternion=True),
    )


@register_jitable
def to_principal_axes(q0: np.ndarray, omega0: np.ndarray, q_bp: np.ndarray, axes: np.ndarray, y0: np.ndarray,
                      b: int, j: int) -> None:
    """Member ``b``'s initial state in principal axes from ``q0[b]`` and ``omega0[b]`` in body axes, with
    body ``j``'s ``q_BP`` and ``R_BP``: ``q_NP = q_NB ⊗ q_BP`` into ``y0[b, :4]`` (bit for bit
    :func:`tumble.attitude.multiply`'s product), ``ω_P = R_BPᵀ ω_B`` into ``y0[b, 4:]`` with
    ``ω_i = (R_0i ω_0 + R_1i ω_1) + R_2i ω_2`` in that order. Plain Python until compiled: the GPU's
    set-up (:mod:`tumble._rigid_cuda`) calls it too."""
    w, x, y, z = qmul(q0[b, 0], q0[b, 1], q0[b, 2], q0[b, 3], q_bp[j, 0], q_bp[j, 1], q_bp[j, 2], q_bp[j, 3])
    y0[b, 0], y0[b, 1], y0[b, 2], y0[b, 3] = w, x, y, z
    for i in range(3):
        y0[b, 4 + i] = axes[j, 0, i] * omega0[b, 0] + axes[j, 1, i] * omega0[b, 1] + axes[j, 2, i] * omega0[b, 2]


@register_jitable
def to_body_axes(states: np.ndarray, q_bp: np.ndarray, axes: np.ndarray, q: np.ndarray, omega: np.ndarray,
                 k: int, b: int, j: int) -> None:
    """Member ``b``'s state at output ``k`` from principal to body axes, with body ``j``'s ``q_BP`` and
    ``R_BP``: ``q_NB = q_NP ⊗ q_BP*`` into ``q[k, b]`` (bit for bit :func:`tumble.attitude.multiply`'s
    product), ``ω_B = R_BP ω_P`` into ``omega[k, b]`` with ``ω_i = (R_i0 ω_0 + R_i1 ω_1) + R_i2 ω_2`` in that
    order. Plain Python until compiled, as :func:`to_principal_axes`."""
    w, x, y, z = qmul(states[k, b, 0], states[k, b, 1], states[k, b, 2], states[k, b, 3],
                      q_bp[j, 0], -q_bp[j, 1], -q_bp[j, 2], -q_bp[j, 3])
    q[k, b, 0], q[k, b, 1], q[k, b, 2], q[k, b, 3] = w, x, y, z
    for i in range(3):
        omega[k, b, i] = axes[j, i, 0] * states[k, b, 4] + axes[j, i, 1] * states[k, b, 5] \
            + axes[j, i, 2] * states[k, b, 6]


@njit(cache=True)
def _to_principal_axes(q0, omega0, q_bp, axes, y0):
    """The initial states (N, 7) in principal axes from ``q0`` (N, 4) and ``omega0`` (N, 3) in body axes, in
    one pass (:func:`to_principal_axes`), with ``q_BP`` (B, 4) and ``R_BP`` (B, 3, 3) of B = 1 body or one
    per member."""
    shared = q_bp.shape[0] == 1
    for b in range(y0.shape[0]):
        to_principal_axes(q0, omega0, q_bp, axes, y0, b, 0 if shared else b)


@njit(cache=True)
def _to_body_axes(states, q_bp, axes, q, omega):
    """The states (n, N, 7) in principal axes to body axes, in one pass (:func:`to_body_axes`): ``q`` (n, N, 4)
    and ``omega`` (n, N, 3), with ``q_BP`` (B, 4) and ``R_BP`` (B, 3, 3) of B = 1 body or one per member."""
    shared = q_bp.shape[0] == 1
    for k in range(states.shape[0]):
        for b in range(states.shape[1]):
            to_body_axes(states, q_bp, axes, q, omega, k, b, 0 if shared else b)


class RigidBodies(Model):
    """The rigid-body model: one body, ``simulate(body, omega0, ...)``, or a batch with one body per member,
    ``simulate(bodies, omega0 (N, 3), ...)``; initial state ``omega0`` (and ``q0``), outputs in body axes.

    Made by :meth:`of` from a :class:`tumble.RigidBody`, a sequence of them, or an inertia array (3, 3) or
    (N, 3, 3) (kg·m², body axes), validated with the rules of :class:`tumble.RigidBody`
    (:func:`tumble._inertia.principal_axes`). ``moments`` (B, 3) (kg·m², ascending), ``axes`` R_BP (B, 3, 3)
    and their quaternions ``q_bp`` (B, 4) are those of B = 1 body or one per member; ``inertia`` is the
    tensor in body axes, (3, 3) or (N, 3, 3); ``masses`` (B,) (kg) are None when unknown (they serve the
    rigidity check of :mod:`tumble.limits`).
    """

    __slots__ = ("inertia", "moments", "axes", "q_bp", "masses", "_kind")

    def __init__(self, inertia: np.ndarray, moments: np.ndarray, axes: np.ndarray,
                 masses: np.ndarray | None, *, q_bp: np.ndarray | None = None,
                 kind: str = "RigidBodies") -> None:
        # read-only: the batch's own tensors, which each Trajectory of it shares instead of copying
        self.inertia, self.moments, self.axes, self.masses = readonly(inertia), moments, axes, masses
        self.q_bp = attitude.from_matrix(axes) if q_bp is None else q_bp
        self._kind = kind

    @classmethod
    def of(cls, bodies: RigidBody | Sequence[RigidBody] | ArrayLike) -> RigidBodies:
        """The model of ``bodies``: a RigidBody (its :attr:`kind` is ``"RigidBody"``), a sequence of them, or
        an inertia array (3, 3) or (N, 3, 3)."""
        if isinstance(bodies, RigidBody):
            mass = None if bodies.mass is None else np.array([bodies.mass])
            return cls(bodies.inertia, bodies.moments[None], bodies.axes[None], mass,
                       q_bp=bodies.axes_quaternion[None], kind="RigidBody")
        if isinstance(bodies, Sequence) and bodies and all(isinstance(b, RigidBody) for b in bodies):
            rigid = cast("Sequence[RigidBody]", bodies)
            masses = [b.mass for b in rigid]
            return cls(np.stack([b.inertia for b in rigid]), np.stack([b.moments for b in rigid]),
                       np.stack([b.axes for b in rigid]), None if None in masses else np.array(masses),
                       q_bp=np.stack([b.axes_quaternion for b in rigid]))
        try:
            np.asarray(bodies, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValidationError(f"model: must be a tumble model (RigidBody, FlexibleBody, Spacecraft, SerialChain, "
                                  f"...) or an inertia array (kg m^2, body axes), got {type(bodies).__name__}"
                                  ) from None
        inertia = as_array(bodies, "inertia", tail=(3, 3))
        if inertia.ndim not in (2, 3):
            raise ValidationError(f"inertia: must have shape (3, 3) or (N, 3, 3), got {inertia.shape}")
        inertia, moments, axes = principal_axes(inertia, "inertia")
        if inertia.ndim == 2:
            return cls(inertia, moments[None], axes[None], None)
        return cls(inertia, moments, axes, None)

    @property
    def kind(self) -> str:
        """``"RigidBody"`` for the model of one :class:`tumble.RigidBody`, else ``"RigidBodies"``."""
        return self._kind

    @property
    def batch_size(self) -> int | None:
        return None if self.inertia.ndim == 2 else self.inertia.shape[0]

    def members(self, lo: int, hi: int) -> RigidBodies:
        """The bodies ``lo`` to ``hi − 1`` of the batch (a shared body: itself)."""
        if self.batch_size is None:
            return self
        masses = None if self.masses is None else self.masses[lo:hi]
        return RigidBodies(self.inertia[lo:hi], self.moments[lo:hi], self.axes[lo:hi], masses,
                           q_bp=self.q_bp[lo:hi], kind=self._kind)

    def state_fields(self) -> tuple[StateField, ...]:
        return _state_fields()

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.RigidModel:
        return _kernel.from_principal(self.moments, self.axes, torques.as_torque_model(torque))

    def initial_states(self, kernel: _kernel.RigidModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        y0 = np.empty((values["omega0"].shape[0], _kernel.STATE_SIZE))
        _to_principal_axes(readonly(values["q0"]), readonly(values["omega0"]), readonly(self.q_bp),
                           readonly(self.axes), y0)
        limits.check_rigid_motion(self.moments, y0[:, 4:], self.masses, stacklevel=_STACKLEVEL)
        return y0

    def outputs(self, kernel: _kernel.RigidModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        if kernel.codes is not None:  # a torque may have spun the body up: check where it ended
            limits.check_rigid_motion(self.moments, states[-1, :, 4:], self.masses, stacklevel=_STACKLEVEL)
        q, omega = np.empty(states.shape[:-1] + (4,)), np.empty(states.shape[:-1] + (3,))
        _to_body_axes(states, readonly(self.q_bp), readonly(self.axes), q, omega)
        return Outputs(q=q, omega=omega, inertia=self.inertia, extras={}, totals={}, info={})

    def __repr__(self) -> str:
        return f"RigidBodies(kind={self._kind!r}, batch_size={self.batch_size})"


RigidBody._model_of = RigidBodies.of  # the deprecated model interface of a RigidBody answers as its model


def __getattr__(name: str) -> type[RigidBodies]:
    if name == "RigidMotion":  # deprecated in 0.4: the base of RigidBody and RigidBodies, now RigidBodies alone
        warnings.warn("tumble.rigid.RigidMotion is deprecated: the rigid-body model is "
                      "tumble.rigid_model.RigidBodies (RigidBodies.of(body) for one RigidBody)", DeprecationWarning,
                      stacklevel=2)
        return RigidBodies
    raise AttributeError(f"module 'tumble.rigid_model' has no attribute {name!r}")
