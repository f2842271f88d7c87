"""The axisymmetric body in a principal frame that does not turn with it, as a model for the integrators.

State ``y = [q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃, ψ]``: the attitude of the frame F
(``q_NF``, F → inertial), the body rate in F components (rad/s) and the spin
angle ψ of the body's principal axes P about the symmetry axis ``e₃`` of F
(rad), so that ``q_NP = q_NF ⊗ q_z(ψ)`` with ``q_z(ψ) = [cos ψ/2, 0, 0, sin ψ/2]``.
The frame turns at ``ω_F = (ω₁, ω₂, κ ω₃)``, where ``κ`` (``frame_spin``) is 0
for the non-spinning frame and 1 for the body's own axes. Right-hand side
(:func:`tumble.dynamics.euler_frame`)::

    I_t ω̇₁ = N₁ − (I_s − κ I_t) ω₃ ω₂,   I_t ω̇₂ = N₂ + (I_s − κ I_t) ω₃ ω₁,   I_s ω̇₃ = N₃
    q̇_NF = ½ q_NF ⊗ [0, ω₁, ω₂, κ ω₃],    ψ̇ = (1 − κ) ω₃

The torque program is evaluated at the body's state in P (``q_NP``, and the
rate ``ω_P = R_z(ψ)ᵀ ω``) and turned into F: ``N = R_z(ψ) τ_P``. Without a
torque, ψ enters nothing but its own equation, whose right-hand side is
constant: every Runge–Kutta method integrates it exactly. :func:`project`
normalises ``q_NF`` and brings ψ back into [−π, π] after every step, so that
its rounding stays that of an angle below π however many turns the body makes.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, types

from tumble import _protocol, _quat, torques
from tumble.dynamics import euler_frame

STATE_SIZE = 8

_TWO_PI = 2.0 * math.pi


class FrameModel(NamedTuple):
    """Compiled parameters of an axisymmetric body integrated in a principal frame (shared by the batch).

    coefficients : (4,) ``I_s/I_t``, ``1/I_t``, ``1/I_s`` (1/(kg·m²)) and ``κ``, the frame's rate about
                   the symmetry axis as a fraction of the body's spin ω₃
    params       : (1, n_p) torque-program parameters in the body's principal axes P (e₃ the symmetry axis)
    codes        : int64 torque-program codes, or None for a torque-free body
    """

    coefficients: np.ndarray
    params: np.ndarray
    codes: np.ndarray | None

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side; ``"cuda"`` without a Python
        torque function."""
        return frozenset({"rhs", *(() if self.calls_python else ("cuda",))})

    @property
    def calls_python(self) -> bool:
        """True when the torque program calls a Python function (the batch then runs on one core)."""
        return torques.program_calls_python(self)

    @property
    def gpu_refusal(self) -> str | None:
        """Why this kernel cannot run on an NVIDIA GPU (a ValidationError message), or None: a Python torque."""
        return _protocol.python_on_gpu("torque") if self.calls_python else None


def build(transverse: float, axial: float, frame_spin: float, axes: np.ndarray, torque) -> FrameModel:
    """The :class:`FrameModel` of a body of moments ``transverse``, ``axial`` (kg·m²) whose principal axes,
    the symmetry axis third, are the columns of ``axes`` (R_BP), under a torque model (or None)."""
    coefficients = np.array([axial / transverse, 1.0 / transverse, 1.0 / axial, frame_spin])
    if torque is None:
        codes, params = None, np.zeros((1, 0))
    else:
        codes, p = torques.compile_program(torque, axes, offset=0)
        params = np.ascontiguousarray(p[None])
    return FrameModel(coefficients=coefficients, params=params, codes=codes)


@_protocol.implements(_protocol.rhs, FrameModel)
def _frame_rhs(model, b0, t, Y, OUT):
    if isinstance(model.types[2], types.NoneType):  # torque-free: ψ is not needed

        def torque(model, t, qw, qx, qy, qz, w1, w2, w3, psi):
            return 0.0, 0.0, 0.0

    else:

        def torque(model, t, qw, qx, qy, qz, w1, w2, w3, psi):
            # the body's state in P: q_NP = q_NF ⊗ q_z(ψ), ω_P = R_z(ψ)ᵀ ω; the torque back in F
            sh, ch = math.sin(0.5 * psi), math.cos(0.5 * psi)
            c, s = ch * ch - sh * sh, 2.0 * sh * ch
            pw, px, py, pz = _quat.qmul(qw, qx, qy, qz, ch, 0.0, 0.0, sh)
            t1, t2, t3 = torques.evaluate(t, pw, px, py, pz, c * w1 + s * w2, c * w2 - s * w1, w3,
                                          model.params, 0, model.codes)
            return c * t1 - s * t2, s * t1 + c * t2, t3

    torque = njit(inline="always")(torque)

    @njit(inline="always")
    def derivative(model, t, qw, qx, qy, qz, w1, w2, w3, psi):
        k = model.coefficients
        frame3 = k[3] * w3
        n1, n2, n3 = torque(model, t, qw, qx, qy, qz, w1, w2, w3, psi)
        a1, a2, a3 = euler_frame(k[0], k[1], k[2], w1, w2, w3, frame3, n1, n2, n3)
        d = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, frame3)
        return 0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3], a1, a2, a3, w3 - frame3

    return _protocol.rhs_of_eight(derivative, Y)


@njit(cache=True)
def wrap_angle(psi):
    """``psi`` (rad) brought into [−π, π] by whole turns (unchanged when already there)."""
    if abs(psi) <= math.pi:
        return psi
    return psi - _TWO_PI * math.floor(psi / _TWO_PI + 0.5)


@_protocol.implements(_protocol.project, FrameModel)
def _frame_project(model, b0, t, Y):
    if Y.ndim == 1:

        def impl(model, b0, t, Y):
            _protocol.normalize_quaternion(Y)
            Y[7] = wrap_angle(Y[7])

    else:

        def impl(model, b0, t, Y):
            _protocol.normalize_quaternions(Y)
            for j in range(Y.shape[1]):
                Y[7, j] = wrap_angle(Y[7, j])

    return impl


@_protocol.implements(_protocol.state_size, FrameModel)
def _frame_state_size(model):

    def impl(model):
        return STATE_SIZE

    return impl
