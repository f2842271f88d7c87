"""A rigid hub with flexible appendages (solar panels, antennas): the hybrid-coordinate model.

The elastic deformation of the appendages is a sum of ``m`` cantilever modes
(the appendage clamped to a hub held still) with modal coordinates ``ηₖ``
(mass-normalised: kg^½·m), frequencies ``Ωₖ`` (rad/s), damping ratios
``ζₖ`` and rotational participation vectors ``δₖ`` (kg^½·m, body axes: the
angular momentum about the centre of mass that a unit modal rate carries).
With ``I`` the inertia of the undeformed spacecraft (hub and appendages,
kg·m², body axes), the equations of motion are the hybrid-coordinate
equations (Likins, JPL TR 32-1576, 1974; Wie, *Space Vehicle Dynamics and
Control*, 2nd ed., AIAA 2008)::

    h   = I ω + Σₖ δₖ η̇ₖ                                   (total angular momentum, body axes)
    ḣ + ω × h = τ,  i.e.  I ω̇ + Σₖ δₖ η̈ₖ + ω × (I ω + Σₖ δₖ η̇ₖ) = τ
    η̈ₖ + 2ζₖΩₖ η̇ₖ + Ωₖ² ηₖ + δₖ · ω̇ = 0

with ``q̇ = ½ q ⊗ [0, ω]`` for the attitude of the body axes (those of the
undeformed hub).

**Derivation and what is linearised.** They are the Euler–Poincaré equations
of the Lagrangian ``ℒ = ½ ω·Iω + Σₖ (δₖ·ω) η̇ₖ + ½ Σₖ η̇ₖ² − ½ Σₖ Ωₖ² ηₖ²``
with the Rayleigh dissipation ``ℛ = Σₖ ζₖΩₖ η̇ₖ²``:
``d/dt ∂ℒ/∂ω + ω × ∂ℒ/∂ω = τ`` and ``d/dt ∂ℒ/∂η̇ₖ − ∂ℒ/∂ηₖ = −∂ℛ/∂η̇ₖ``.
What is linearised is the Lagrangian: the exact kinetic energy of the
deforming body is truncated at total degree two in ``(ω, η, η̇)``, keeping
``½ ω·Iω``, ``(δₖ·ω) η̇ₖ`` and ``½ η̇ₖ²`` and dropping the ``O(η)`` change of
the inertia (``ω² η``), the Coriolis coupling of the modes (``ω η η̇``) and
centrifugal stiffening (``ω² η²``), all of degree three or four. The
equations are then taken from the truncated ``ℒ`` without further
approximation, so the full ``ω × h`` term stays: ``h`` is the angular
momentum of the model, the inertial momentum ``R(q) h`` is an exact
invariant of the torque-free motion, and the energy

    E = ½ ω·Iω + Σₖ (δₖ·ω) η̇ₖ + ½ Σₖ (η̇ₖ² + Ωₖ² ηₖ²),   Ė = ω·τ − Σₖ 2ζₖΩₖ η̇ₖ²

is conserved without damping and torque and decreases monotonically with
damping. The model is valid for slow rotation, ``|ω| ≪ Ωₖ``.

**Frequencies with the hub free.** About a non-rotating hub (``ω × h`` is of
second order), ``ω̇ = −I⁻¹ Σ δₖ η̈ₖ`` and the modes obey
``(1 − Dᵀ I⁻¹ D) η̈ + diag(Ωₖ²) η = 0`` with ``D = [δ₁ … δ_m]``: the
unconstrained (free-free) frequencies are the roots of
``det(diag(Ωₖ²) − σ² (1 − Dᵀ I⁻¹ D)) = 0``; for one mode
``σ = Ω / √(1 − δᵀ I⁻¹ δ)``, above the cantilever
frequency ``Ω``. :meth:`FlexibleBody.free_frequencies`.

A :class:`FlexibleBody` is a model of :func:`tumble.simulate` (its compiled
right-hand side: :mod:`tumble.kernels.flexible`); the trajectory's totals are
``E`` and ``h``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude, dynamics, torques
from tumble._moved import moved
from tumble._validate import ValidationError, as_array, require_positive
from tumble.rigid_body import RigidBody
from tumble.kernels import flexible as _kernel
from tumble.simulate import Model, Outputs, StateField
from tumble.trajectory import Extra, Trajectory

__all__ = ["Mode", "FlexibleBody", "energy", "momentum_body", "slew_torque"]

__getattr__ = moved(__name__, {"demo_flexible": "tumble.viz.flexible", "slew_figure": "tumble.viz.flexible"})


@dataclass(frozen=True)
class Mode:
    """One cantilever mode of an appendage.

    frequency     : ``Ω`` (rad/s), natural frequency with the hub held still, > 0
    damping       : ``ζ``, damping ratio, ≥ 0
    participation : ``δ`` (3,), rotational participation vector (kg^½·m, body axes)
    """

    frequency: float
    damping: float
    participation: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "frequency", require_positive(self.frequency, "frequency"))
        damping = float(self.damping)
        if not math.isfinite(damping) or damping < 0.0:
            raise ValidationError(f"damping: must be a finite damping ratio >= 0, got {damping}")
        object.__setattr__(self, "damping", damping)
        delta = as_array(self.participation, "participation", tail=(3,))
        if delta.ndim != 1:
            raise ValidationError(f"participation: must have shape (3,), got {delta.shape}")
        delta = delta.copy()  # frozen below: never the caller's array
        delta.setflags(write=False)
        object.__setattr__(self, "participation", delta)


@dataclass(frozen=True)
class FlexibleBody(Model):
    """A hub with flexible appendages: the undeformed body and its modes; a model of :func:`tumble.simulate`.

    body  : RigidBody (or (3, 3) inertia, kg·m², body axes): the whole spacecraft with its
            appendages undeformed, about its centre of mass (``I`` in the equations)
    modes : sequence of :class:`Mode`, at least one

    Refused unless ``I − Σₖ δₖδₖᵀ`` (the inertia of what stays rigid) is positive
    definite: the appendages cannot carry more inertia than the whole body.

    ``tumble.simulate(fbody, omega0=..., t=..., q0=..., eta0=..., eta_rate0=..., torque=...)``
    integrates the equations of the module docstring (``dop853``, ``rk4`` or ``cf4``).
    Initial state: ``omega0`` (3,) hub rate, rad/s, body axes (required); ``q0`` (4,) hub
    attitude, body → inertial (default identity); ``eta0``, ``eta_rate0`` (m,) modal
    coordinates (kg^½·m) and rates (kg^½·m/s), default zero; each with an optional leading
    batch axis. The :class:`~tumble.Trajectory` holds ``q``, ``omega`` of the hub,
    ``inertia`` = the undeformed ``I``, the extras ``modal_coordinate`` and ``modal_rate``
    (n, [N,] m), and the totals of the whole spacecraft: ``energy`` ``E`` (:func:`energy`)
    and ``momentum_body`` ``h`` (:func:`momentum_body`).
    """

    body: RigidBody
    modes: tuple[Mode, ...]

    torque = "external torque on the hub, body axes (N·m): a tumble.torques model or f(t, q, omega)"

    def __post_init__(self):
        body = self.body if isinstance(self.body, RigidBody) else RigidBody(self.body)
        modes = tuple(self.modes) if isinstance(self.modes, Sequence) else (self.modes,)
        if not modes or not all(isinstance(m, Mode) for m in modes):
            raise ValidationError("modes: must be a non-empty sequence of tumble.flexible.Mode")
        object.__setattr__(self, "body", body)
        object.__setattr__(self, "modes", modes)
        smallest, largest = np.linalg.eigvalsh(self.hub_inertia)[[0, -1]]
        if smallest <= 1e-12 * abs(largest):
            raise ValidationError(
                "modes: I - sum(delta_k delta_k^T) must be positive definite (the appendages cannot carry more "
                f"inertia than the whole body); its smallest eigenvalue is {smallest:.6g} kg m^2"
            )

    @property
    def participation(self) -> np.ndarray:
        """``D`` (3, m): the participation vectors ``δₖ`` as columns (kg^½·m, body axes)."""
        return np.stack([m.participation for m in self.modes], axis=1)

    @property
    def frequencies(self) -> np.ndarray:
        """(m,) cantilever frequencies ``Ωₖ`` (rad/s)."""
        return np.array([m.frequency for m in self.modes])

    @property
    def damping_ratios(self) -> np.ndarray:
        """(m,) damping ratios ``ζₖ``."""
        return np.array([m.damping for m in self.modes])

    @property
    def hub_inertia(self) -> np.ndarray:
        """``I − D Dᵀ`` (3, 3), kg·m²: the inertia the hub shows when the modes are free to lag."""
        D = self.participation
        return self.body.inertia - D @ D.T

    def free_frequencies(self) -> np.ndarray:
        """(m,) undamped frequencies (rad/s) of the modes with the hub free and not rotating, ascending.

        The roots ``σ`` of ``det(diag(Ωₖ²) − σ² (1 − Dᵀ I⁻¹ D)) = 0`` (module docstring);
        ``Ω/√(1 − δᵀI⁻¹δ)`` for one mode.
        """
        from scipy.linalg import eigh

        D = self.participation
        modal_mass = np.eye(D.shape[1]) - D.T @ np.linalg.solve(self.body.inertia, D)
        return np.sqrt(eigh(np.diag(self.frequencies**2), modal_mass, eigvals_only=True))

    # -- the model interface (tumble.simulate.Model) ----------------------------------

    attitude_in_state = True  # q = Y[0:4], omega = body_rate: made on the GPU with output="device"

    def state_fields(self) -> tuple[StateField, ...]:
        m = len(self.modes)
        return (
            StateField("omega0", 3, "initial hub rate, rad/s, body axes"),
            StateField("q0", 4, "initial hub attitude, unit quaternion [w, x, y, z], body → inertial",
                       default=attitude.identity(), quaternion=True),
            StateField("eta0", m, f"initial modal coordinates η ({m}), kg^½·m", default=np.zeros(m)),
            StateField("eta_rate0", m, f"initial modal rates dη/dt ({m}), kg^½·m/s", default=np.zeros(m)),
        )

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.FlexibleModel:
        """The compiled model (:class:`tumble.kernels.flexible.FlexibleModel`) under a torque on the hub (body axes)."""
        codes, params = torques.compile_program(torques.as_torque_model(torque), np.eye(3), offset=0)
        w = self.frequencies
        return _kernel.FlexibleModel(
            inertia=np.ascontiguousarray(self.body.inertia),
            inverse_hub=np.linalg.inv(self.hub_inertia),
            participation=np.ascontiguousarray(self.participation.T),
            damping=2.0 * self.damping_ratios * w,
            stiffness=w**2,
            params=params[None, :],
            codes=codes,
        )

    def initial_states(self, kernel: _kernel.FlexibleModel, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """``[q, ω, η, η̇]`` (N, 7 + 2m): the state of :mod:`tumble.kernels.flexible`."""
        return np.concatenate([values["q0"], values["omega0"], values["eta0"], values["eta_rate0"]], axis=1)

    def outputs(self, kernel: _kernel.FlexibleModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        m = len(self.modes)
        omega, eta, rate = states[..., 4:7], states[..., 7:7 + m], states[..., 7 + m:]
        extras = {
            "modal_coordinate": Extra(eta, ("mode",), "kg^(1/2) m",
                                      "modal coordinate eta_k of the appendages (mass-normalised)"),
            "modal_rate": Extra(rate, ("mode",), "kg^(1/2) m/s", "modal rate deta_k/dt"),
        }
        totals = {"energy": _energy(self, omega, eta, rate), "momentum_body": _momentum(self, omega, rate)}
        return Outputs(q=states[..., :4], omega=omega, inertia=self.body.inertia, extras=extras, totals=totals,
                       info={"modes": m})

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """Without torque the inertial momentum ``R(q) h``; without damping too, the energy ``E``."""
        if traj.info.get("torque") != "none":
            return {}
        kept = {"momentum_inertial": traj.momentum_inertial}
        if not np.any(self.damping_ratios):
            kept["energy"] = traj.energy
        return kept


def _momentum(fbody: FlexibleBody, omega, rate) -> np.ndarray:
    """``h = I ω + Σₖ δₖ η̇ₖ`` (N·m·s, body axes) from ω (…, 3) and η̇ (…, m)."""
    return dynamics.angular_momentum(fbody.body.inertia, omega) + np.einsum("ik,...k->...i", fbody.participation, rate)


def _energy(fbody: FlexibleBody, omega, eta, rate) -> np.ndarray:
    """``E`` (J) from ω (…, 3), η and η̇ (…, m): see :func:`energy`."""
    coupling = np.einsum("...i,ik,...k->...", omega, fbody.participation, rate)
    modal = 0.5 * np.sum(rate**2 + fbody.frequencies**2 * eta**2, axis=-1)
    return dynamics.kinetic_energy(fbody.body.inertia, omega) + coupling + modal


def momentum_body(fbody: FlexibleBody, trajectory: Trajectory) -> np.ndarray:
    """Total angular momentum ``h = I ω + Σₖ δₖ η̇ₖ`` (N·m·s, body axes) along a trajectory, (n, [N,] 3).

    ``trajectory.momentum_body`` of a run of ``fbody`` holds the same numbers.
    """
    return _momentum(fbody, trajectory.omega, trajectory.modal_rate)


def energy(fbody: FlexibleBody, trajectory: Trajectory) -> np.ndarray:
    """Total energy ``½ ω·Iω + Σₖ (δₖ·ω) η̇ₖ + ½ Σₖ (η̇ₖ² + Ωₖ² ηₖ²)`` (J) along a trajectory, (n, [N]).

    ``trajectory.energy`` of a run of ``fbody`` holds the same numbers.
    """
    return _energy(fbody, trajectory.omega, trajectory.modal_coordinate, trajectory.modal_rate)


def slew_torque(axis: ArrayLike, angle: float, *, duration: float, inertia: float, ramp: float = 0.0,
                start: float = 0.0) -> torques.Tabulated:
    """Rest-to-rest bang-bang torque that turns a rigid body by ``angle`` (rad) about ``axis`` in ``duration`` (s).

    ``τ(t) = u a(t) axis`` (N·m, body axes) with ``a`` = +1 on the first half and −1 on the
    second, each switch a linear ramp of ``ramp`` s (0: instantaneous; ramps keep the torque
    continuous, which the integrators prefer), zero outside ``[start, start + duration]``.
    The peak ``u = inertia · angle / ∫₀ᵀ (T − s) a(s) ds`` (Cauchy's formula for the angle
    of ``inertia · θ̈ = u a``; ``u = 4 inertia angle / T²`` without ramps), with ``inertia``
    the moment about ``axis`` (kg·m²). ``axis`` should be a principal axis of the rigid body
    for the slew to be a rotation about it. The profile is piecewise linear: put its knots
    (``.t`` of the result) among the output times, so that no step straddles a kink (an
    adaptive step across one loses about three digits).
    """
    axis = as_array(axis, "axis", tail=(3,))
    norm = float(np.linalg.norm(axis))
    if axis.ndim != 1 or norm == 0.0:
        raise ValidationError(f"axis: must be a non-zero vector of shape (3,), got {axis.tolist()}")
    T = require_positive(duration, "duration")
    inertia = require_positive(inertia, "inertia")
    ramp = float(ramp)
    if not 0.0 <= ramp < T / 4:
        raise ValidationError(f"ramp: must be in [0, duration/4) = [0, {T / 4}), got {ramp}")
    r = max(ramp, 1e-9 * T)  # a zero ramp is a jump: two samples 1e-9 T apart
    knots = np.array([0.0, r, T / 2 - r, T / 2 + r, T - r, T])
    shape = np.array([0.0, 1.0, 1.0, -1.0, -1.0, 0.0])
    # ∫ (T − s) a(s) ds, exact by Simpson's rule on each linear piece (the integrand is quadratic)
    mid = 0.5 * (knots[1:] + knots[:-1])
    f0, f1, fm = (T - knots[:-1]) * shape[:-1], (T - knots[1:]) * shape[1:], (T - mid) * 0.5 * (shape[1:] + shape[:-1])
    moment = float(np.sum(np.diff(knots) / 6.0 * (f0 + 4.0 * fm + f1)))
    peak = inertia * float(angle) / moment
    return torques.Tabulated(start + knots, np.outer(shape * peak, axis / norm))


#: The demo spacecraft: 3000 kg·m² about the slew axis z, a solar array with two modes about z.
DEMO_BODY = FlexibleBody(
    body=RigidBody(np.diag([2000.0, 1500.0, 3000.0])),
    modes=(Mode(frequency=2 * math.pi * 0.2, damping=0.003, participation=np.array([0.0, 0.0, 25.0])),
           Mode(frequency=2 * math.pi * 1.1, damping=0.005, participation=np.array([0.0, 0.0, 8.0]))),
)


def slew_angle(q: np.ndarray) -> np.ndarray:
    """Rotation angle about z (rad) of attitudes ``q`` that are rotations about z (the demo slew)."""
    return 2.0 * np.arctan2(q[..., 3], q[..., 0])


