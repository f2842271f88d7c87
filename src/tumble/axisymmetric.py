"""An axisymmetric body integrated in a principal frame that does not spin with it.

For a body with rotational symmetry, every pair of axes perpendicular to the
symmetry axis ``e₃`` is principal, so Euler's equations also hold in a frame
F that follows ``e₃`` but turns about it at its own rate ``Ω₃``
(:func:`tumble.dynamics.euler_frame`)::

    dL/dt|_F + ω_F × L = N,    L = I_t (ω₁e₁ + ω₂e₂) + I_s ω₃ e₃,    ω_F = ω₁e₁ + ω₂e₂ + Ω₃e₃

    I_t ω̇₁ = N₁ − (I_s ω₃ − I_t Ω₃) ω₂,   I_t ω̇₂ = N₂ + (I_s ω₃ − I_t Ω₃) ω₁,   I_s ω̇₃ = N₃

:class:`AxisymmetricBody` integrates in the frame ``Ω₃ = κ ω₃`` (``frame_spin``
κ: 0, the default, is the non-spinning or Resal frame of gyroscope and
projectile analyses; 1 is the body's own axes). Its state is the frame's
attitude ``q_NF``, the body rate ``(ω₁, ω₂, ω₃)`` in F, and the spin angle ψ
of the body about ``e₃`` relative to F (``ψ̇ = (1 − κ) ω₃``); the body's
attitude is recovered as

    q_NB = q_NF ⊗ q_z(ψ) ⊗ q_BP*,     ω_B = R_BP R_z(ψ)ᵀ ω

(``q_z(ψ) = [cos ψ/2, 0, 0, sin ψ/2]``; ``R_BP`` the principal axes of the
body with the symmetry axis third). In the non-spinning frame the fast spin
leaves the attitude equation: ψ grows linearly when the axial torque
vanishes, which every Runge–Kutta method integrates exactly, and the frame
only follows the slow precession and the nutation, whose amplitude sets the
step. Where this pays and where it does not: ``docs/frames.md``.

The compiled kernel is :mod:`tumble.kernels.axisymmetric`; the model runs through
:func:`tumble.simulate` with ``dop853`` or ``rk4`` and any torque of
:mod:`tumble.torques` (body axes, evaluated at the body's attitude and rate).
"""

from __future__ import annotations

import numpy as np

from tumble import attitude, limits, torques
from tumble._validate import ValidationError, as_array
from tumble.rigid_body import RigidBody
from tumble.kernels import axisymmetric as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra

__all__ = ["AXISYMMETRY_RTOL", "AxisymmetricBody"]

#: Two principal moments are taken as equal when they differ by at most this times the largest
#: (``RigidBody.symmetry``). The frame model uses their mean: a residual difference ΔI would move the
#: body's phase by about (ΔI/I) ω t, which this bound keeps at rounding level over long runs.
AXISYMMETRY_RTOL = 1e-12

#: The stack depth from the warnings of :mod:`tumble.limits` to the caller of ``simulate``.
_STACKLEVEL = 4


class AxisymmetricBody(Model):
    """An axisymmetric :class:`~tumble.RigidBody` integrated in a principal frame turning at ``κ ω₃`` about its
    symmetry axis (see the module docstring): ``tumble.simulate(AxisymmetricBody(body), omega0, t=..., ...)``.

    body       : a RigidBody with two equal principal moments (to :data:`AXISYMMETRY_RTOL`): an oblate
                 (symmetry axis ``body.axes[:, 2]``), prolate (``body.axes[:, 0]``) or spherical body
                 (``body.axes[:, 2]``); its inertia about the centre of mass, or about the pivot for a top
    frame_spin : κ, the frame's rate about the symmetry axis as a fraction of the body's spin ω₃:
                 0 (default) the non-spinning frame, 1 the body's principal axes

    Initial state: ``omega0`` (3,) body rate, rad/s, body axes (required); ``q0`` (4,) attitude, body →
    inertial (default identity); the frame starts on the body's principal axes (ψ = 0). The
    :class:`~tumble.Trajectory` holds the body's ``q``, ``omega`` (body axes) and ``inertia``, and the
    extras ``frame_attitude`` (``q_NF``) and ``spin_angle`` (ψ, in [−π, π]).
    """

    __slots__ = ("body", "frame_spin", "transverse", "axial", "axes", "q_bp")
    body: RigidBody
    frame_spin: float  # κ
    transverse: float  # I_t, kg·m²
    axial: float  # I_a, kg·m²
    axes: np.ndarray  # (3, 3) R_BP, the symmetry axis third
    q_bp: np.ndarray  # (4,) its quaternion

    def __init__(self, body: RigidBody, *, frame_spin: float = 0.0) -> None:
        if not isinstance(body, RigidBody):
            raise ValidationError(f"body: must be a tumble.RigidBody, got {type(body).__name__}")
        kind = body.symmetry(rtol=AXISYMMETRY_RTOL)
        i1, i2, i3 = body.moments
        if kind == "asymmetric":
            raise ValidationError(
                f"body: must be axisymmetric (two equal principal moments, to {AXISYMMETRY_RTOL:g} of the largest), "
                f"got moments {i1:.6g}, {i2:.6g}, {i3:.6g} kg m^2")
        spin = as_array(frame_spin, "frame_spin")
        if spin.ndim != 0:
            raise ValidationError(f"frame_spin: must be a number, got shape {spin.shape}")
        a = body.axes
        if kind == "prolate":  # symmetry axis first: cycle it to third (det stays +1)
            axes, transverse, axial = a[:, [1, 2, 0]], 0.5 * (i2 + i3), i1
        else:
            axes, transverse, axial = a, 0.5 * (i1 + i2), i3
        set_ = object.__setattr__
        set_(self, "body", body)
        set_(self, "frame_spin", float(spin))
        set_(self, "transverse", float(transverse))
        set_(self, "axial", float(axial))
        set_(self, "axes", np.ascontiguousarray(axes))
        set_(self, "q_bp", attitude.from_matrix(self.axes))

    def __setattr__(self, name, value):
        raise AttributeError(f"AxisymmetricBody is immutable: cannot set {name!r}")

    @property
    def symmetry_axis(self) -> np.ndarray:
        """(3,) the symmetry axis ``e₃`` in body axes."""
        return self.axes[:, 2].copy()

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    def state_fields(self) -> tuple[StateField, ...]:
        return (
            StateField("omega0", 3, "initial body rate, rad/s, body axes"),
            StateField("q0", 4, "initial attitude, unit quaternion [w, x, y, z], body → inertial",
                       default=attitude.identity(), quaternion=True),
        )

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.FrameModel:
        """The compiled model (:class:`tumble.kernels.axisymmetric.FrameModel`) under a torque (body axes)."""
        return _kernel.build(self.transverse, self.axial, self.frame_spin, self.axes,
                             torques.as_torque_model(torque))

    def initial_states(self, kernel: _kernel.FrameModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """``[q_NF, ω, ψ]`` (N, 8): the frame on the principal axes, ``q_NF = q_NB ⊗ q_BP``, ``ω = R_BPᵀ ω_B``, ψ = 0."""
        n = values["omega0"].shape[0]
        y0 = np.zeros((n, _kernel.STATE_SIZE))
        y0[:, :4] = attitude.multiply(values["q0"], self.q_bp)
        y0[:, 4:7] = values["omega0"] @ self.axes
        self._check_limits(y0[:, 4:7])
        return y0

    def outputs(self, kernel: _kernel.FrameModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        q_nf, omega_f, psi = states[..., :4], states[..., 4:7], states[..., 7]
        half = 0.5 * psi
        q_z = np.stack([np.cos(half), np.zeros_like(psi), np.zeros_like(psi), np.sin(half)], axis=-1)
        q = attitude.multiply(attitude.multiply(q_nf, q_z), attitude.conjugate(self.q_bp))
        c, s = np.cos(psi), np.sin(psi)
        omega_p = np.stack([c * omega_f[..., 0] + s * omega_f[..., 1], c * omega_f[..., 1] - s * omega_f[..., 0],
                            omega_f[..., 2]], axis=-1)
        if kernel.codes is not None:  # a torque may have spun the body up: check where it ended
            self._check_limits(omega_p[-1])
        extras = {
            "frame_attitude": Extra(q_nf, ("quaternion",), "1",
                                    "attitude q_NF of the integration frame F (e3 the symmetry axis), F -> inertial"),
            "spin_angle": Extra(psi, (), "rad", "spin angle psi of the body about e3 relative to the frame F, "
                                                "in [-pi, pi]: q_NP = q_NF q_z(psi)"),
        }
        return Outputs(q=q, omega=omega_p @ self.axes.T, inertia=self.body.inertia, extras=extras, totals={},
                       info={"frame_spin": self.frame_spin})

    def _check_limits(self, omega_p):
        """The rigidity checks of :mod:`tumble.limits`, on the rates ``omega_p`` (…, 3) in the frame's principal
        axes turned into the body's (``RigidBody.axes``, ascending moments)."""
        omega = omega_p @ (self.body.axes.T @ self.axes).T
        limits.check_rigid_motion(self.body.moments, omega, self.body.mass, stacklevel=_STACKLEVEL)

    def __repr__(self) -> str:
        return (f"AxisymmetricBody(transverse={self.transverse:.6g} kg m^2, axial={self.axial:.6g} kg m^2, "
                f"frame_spin={self.frame_spin:g})")
