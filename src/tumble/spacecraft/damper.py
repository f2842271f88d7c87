"""Energy dissipation on board: a rigid hub with a spherical viscous nutation damper.

The damper is a rigid sphere of moment of inertia ``J`` (about any diameter)
in a concentric spherical cavity at the hub's centre of mass, coupled to the
hub by a viscous fluid film: the torque on the sphere is ``−c (ω_d − ω)``
(``c`` N·m·s) and the hub gets the opposite (the spherical or "Kane"
damper; Hughes, *Spacecraft Attitude Dynamics*, ch. 5; derivations in
``docs/passive_stability.md``). ``ω`` is the hub rate and ``ω_d`` the sphere's,
both relative to inertial space, in hub (body) axes. Euler's equations of
the two bodies, written in body axes (the sphere's inertia is isotropic, so
its inertial derivative seen from the rotating hub adds ``ω × J ω_d``)::

    I ω̇ + ω × (I ω)        = τ_ext + c (ω_d − ω)       (hub)
    J (ω̇_d + ω × ω_d)      = −c (ω_d − ω)               (sphere)
    q̇ = ½ q ⊗ [0, ω]

``I`` is the hub's inertia about the common centre of mass, without the
sphere. Without external torque the total angular momentum
``L = I ω + J ω_d`` is constant in inertial axes, and the kinetic energy
``T = ½ ω·Iω + ½ J |ω_d|²`` falls at the rate ``Ṫ = −c |ω_d − ω|² ≤ 0``:
the body ends in the state of least energy for its ``|L|``, a spin about the
axis of largest moment (the major-axis rule; :mod:`tumble.spacecraft.passive`).

State of the model (:mod:`tumble._protocol` protocol), ``y = [q_w, q_x, q_y,
q_z, ω₁, ω₂, ω₃, ω_d1, ω_d2, ω_d3]``; results come back as a
:class:`tumble.Trajectory` with the sphere's rate in
``extras["damper_omega"]``.

The nutation time constant of a nearly axisymmetric spinner (spin ``Ω``
about the symmetry axis, moments ``I_s`` axial and ``I_t`` transverse) by
the energy-sink method (:func:`energy_sink_time_constant`)::

    1/τ = c J² Ω² (I_t − I_s) I_s / (I_t (c² I_t² + J² Ω² I_s²))

``τ > 0``: the nutation angle grows like ``e^{t/τ}`` (spin about the minor
axis, ``I_s < I_t``, the Explorer 1 case); ``τ < 0``: it decays (major axis).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

from tumble import _protocol, _quat, attitude, integrate, torques
from tumble._validate import ValidationError, as_array, require_positive
from tumble.body import RigidBody
from tumble.trajectory import Extra, Trajectory

__all__ = [
    "DamperModel",
    "SphericalDamper",
    "energy_sink_time_constant",
    "measured_time_constant",
    "nutation_angle",
    "simulate_damped",
    "total_energy",
    "total_momentum_body",
    "total_momentum_inertial",
]

STATE_SIZE = 10
#: The integration methods that take this model (the splitting and exact methods need a rigid body).
METHODS = ("dop853", "rk4", "cf4")


@dataclass(frozen=True)
class SphericalDamper:
    """A spherical viscous nutation damper: sphere inertia ``inertia`` (J, kg·m²), damping ``damping``
    (c, N·m·s)."""

    inertia: float
    damping: float

    def __post_init__(self):
        object.__setattr__(self, "inertia", require_positive(self.inertia, "damper.inertia"))
        object.__setattr__(self, "damping", require_positive(self.damping, "damper.damping"))

    @classmethod
    def tuned(cls, inertia: float, axial: float, transverse: float, spin: float) -> SphericalDamper:
        """The damper of sphere inertia ``inertia`` whose ``c`` maximises the energy-sink rate ``1/|τ|``.

        ``c = J |Ω| I_s / I_t``: the damper's time constant ``J/c`` is then the
        inverse of the nutation rate seen in inertial space, ``Ω I_s/I_t``, and
        ``1/|τ| = J |Ω| |I_t − I_s| / (2 I_t²)``. ``axial``, ``transverse``:
        ``I_s``, ``I_t`` with the sphere locked (kg·m²); ``spin``: ``Ω`` (rad/s).
        """
        inertia = require_positive(inertia, "inertia")
        return cls(inertia, inertia * abs(float(spin)) * require_positive(axial, "axial")
                   / require_positive(transverse, "transverse"))


class DamperModel(NamedTuple):
    """Compiled parameters of a hub with a spherical damper (one body shared by the batch).

    inertia : (9,) hub inertia, body axes, row-major (kg·m²)
    inverse : (9,) its inverse
    damper  : (2,) ``[J, c]``
    params  : (1, n_p) external torque program in body axes
    codes   : int64 torque-program codes, or None without external torque
    """

    inertia: np.ndarray
    inverse: np.ndarray
    damper: np.ndarray
    params: np.ndarray
    codes: np.ndarray | None

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side and the body rate."""
        return frozenset({"rhs", "body_rate"})

    @property
    def calls_python(self) -> bool:
        """True when the torque program calls a Python function (the batch then runs on one core)."""
        return torques.calls_python(self.codes)


def build(body: RigidBody, damper: SphericalDamper, torque=None) -> DamperModel:
    """The :class:`DamperModel` of ``body`` (the hub, without the sphere) with ``damper`` and an external torque."""
    model = torques.as_torque_model(torque)
    if model is not None and model.needs_python:
        raise ValidationError("torque: a hub with a damper takes compiled torque models only, not a Python function")
    codes, params = torques.compile_program(model, np.eye(3), offset=0)
    inertia = np.array(body.inertia, dtype=np.float64)
    return DamperModel(inertia=inertia.ravel().copy(), inverse=np.linalg.inv(inertia).ravel(),
                       damper=np.array([damper.inertia, damper.damping]),
                       params=params[None, :], codes=None if model is None else codes)


def _is_damper(model):
    return _protocol.is_type(model, DamperModel)


@overload(_protocol.rhs, inline="always", jit_options={"cache": True})
def _damper_rhs(model, b0, t, Y, OUT):
    if not _is_damper(model):
        return None
    if isinstance(model.types[4], types.NoneType):

        def torque(model, t, qw, qx, qy, qz, w1, w2, w3):
            return 0.0, 0.0, 0.0

    else:

        def torque(model, t, qw, qx, qy, qz, w1, w2, w3):
            return torques.evaluate_compiled(t, qw, qx, qy, qz, w1, w2, w3, model.params, 0, model.codes)

    torque = njit(inline="always")(torque)

    @njit(inline="always")
    def derivative(model, t, qw, qx, qy, qz, w1, w2, w3, d1, d2, d3):
        I, K = model.inertia, model.inverse
        J, c = model.damper[0], model.damper[1]
        e1, e2, e3 = torque(model, t, qw, qx, qy, qz, w1, w2, w3)
        s1, s2, s3 = d1 - w1, d2 - w2, d3 - w3  # sphere rate relative to the hub
        h1 = I[0] * w1 + I[1] * w2 + I[2] * w3
        h2 = I[3] * w1 + I[4] * w2 + I[5] * w3
        h3 = I[6] * w1 + I[7] * w2 + I[8] * w3
        # I ω̇ = τ + c σ − ω × (I ω)
        r1 = e1 + c * s1 - (w2 * h3 - w3 * h2)
        r2 = e2 + c * s2 - (w3 * h1 - w1 * h3)
        r3 = e3 + c * s3 - (w1 * h2 - w2 * h1)
        a1 = K[0] * r1 + K[1] * r2 + K[2] * r3
        a2 = K[3] * r1 + K[4] * r2 + K[5] * r3
        a3 = K[6] * r1 + K[7] * r2 + K[8] * r3
        # ω̇_d = −(c/J) σ − ω × ω_d
        k = c / J
        b1 = -k * s1 - (w2 * d3 - w3 * d2)
        b2 = -k * s2 - (w3 * d1 - w1 * d3)
        b3 = -k * s3 - (w1 * d2 - w2 * d1)
        q = _quat.qmul(qw, qx, qy, qz, 0.0, w1, w2, w3)
        return 0.5 * q[0], 0.5 * q[1], 0.5 * q[2], 0.5 * q[3], a1, a2, a3, b1, b2, b3

    if Y.ndim == 1:

        def impl(model, b0, t, Y, OUT):
            (OUT[0], OUT[1], OUT[2], OUT[3], OUT[4], OUT[5], OUT[6], OUT[7], OUT[8], OUT[9]) = derivative(
                model, t, Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6], Y[7], Y[8], Y[9])

    else:

        def impl(model, b0, t, Y, OUT):
            for j in range(Y.shape[1]):
                (OUT[0, j], OUT[1, j], OUT[2, j], OUT[3, j], OUT[4, j], OUT[5, j], OUT[6, j], OUT[7, j],
                 OUT[8, j], OUT[9, j]) = derivative(
                    model, t, Y[0, j], Y[1, j], Y[2, j], Y[3, j], Y[4, j], Y[5, j], Y[6, j], Y[7, j], Y[8, j],
                    Y[9, j])

    return impl


@overload(_protocol.project, inline="always", jit_options={"cache": True})
def _damper_project(model, b0, t, Y):
    if not _is_damper(model):
        return None
    return _protocol.quaternion_projection(Y)


@overload(_protocol.state_size, jit_options={"cache": True})
def _damper_state_size(model):
    if not _is_damper(model):
        return None
    return lambda model: STATE_SIZE


@overload(_protocol.body_rate, inline="always", jit_options={"cache": True})
def _damper_body_rate(model, Y, j):
    if not _is_damper(model):
        return None
    return _protocol.rate_at(4, Y)


def simulate_damped(body: RigidBody, damper: SphericalDamper, omega0, *, t, q0=None, damper_omega0=None,
                    method: str = "dop853", rtol: float = 1e-10, atol: float = 1e-12, dt: float | None = None,
                    torque=None, max_steps: int = 10**9,
                    progress: Callable[[int, int], None] | None = None) -> Trajectory:
    """Integrate a hub ``body`` with a spherical damper through the output times ``t`` (s).

    ``omega0`` (3,) or (N, 3): hub rate, rad/s, body axes; ``damper_omega0``:
    the sphere's rate relative to inertial, body axes (default: ``omega0``,
    the sphere turning with the hub); ``q0``: body → inertial, scalar first
    (default identity); ``torque``: an external compiled torque model (body
    axes). Methods and options as in :func:`tumble.simulate` (``dop853``,
    ``rk4``, ``cf4``; ``progress(done, total)`` as there). Returns a
    :class:`tumble.Trajectory` of the hub with ``extras["damper_omega"]``
    (n, [N,] 3); use :func:`total_momentum_inertial` and
    :func:`total_energy` for the invariants of hub and sphere together.
    """
    if not isinstance(body, RigidBody):
        raise ValidationError(f"body: must be a RigidBody (the hub, without the damper), got {type(body).__name__}")
    if not isinstance(damper, SphericalDamper):
        raise ValidationError(f"damper: must be a SphericalDamper, got {type(damper).__name__}")
    if method not in METHODS:
        raise ValidationError(f"method: a hub with a damper integrates with one of {', '.join(map(repr, METHODS))} "
                              f"(the others need a rigid body), got {method!r}")
    integrate.check_options(method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps)
    times = as_array(t, "t")
    if times.ndim != 1 or times.size < 1 or np.any(np.diff(times) <= 0.0):
        raise ValidationError("t: must be a 1-D array of strictly increasing output times")
    omega0 = as_array(omega0, "omega0", tail=(3,))
    if omega0.ndim > 2:
        raise ValidationError(f"omega0: must have shape (3,) or (N, 3), got {omega0.shape}")
    batch = omega0.shape[:-1]
    damper_omega0 = omega0 if damper_omega0 is None else as_array(damper_omega0, "damper_omega0", tail=(3,))
    q0 = attitude.identity() if q0 is None else as_array(q0, "q0", tail=(4,))
    if np.any(np.linalg.norm(q0, axis=-1) == 0.0):
        raise ValidationError("q0: must be a non-zero quaternion [w, x, y, z]")
    n = omega0.shape[0] if batch else 1
    y0 = np.empty((n, STATE_SIZE))
    try:
        y0[:, :4] = attitude.normalize(np.broadcast_to(q0, (n, 4)))
        y0[:, 4:7] = omega0
        y0[:, 7:] = damper_omega0
    except ValueError:
        raise ValidationError(f"q0, damper_omega0: must broadcast to the batch of omega0 {omega0.shape}") from None
    model = build(body, damper, torque)
    solution = integrate.solve(model, y0, times, method=method, dt=dt, rtol=rtol, atol=atol,
                                    max_steps=max_steps, progress=progress)
    states, stats = solution.states, solution.statistics()
    if not batch:
        states = states[:, 0]
    info = {"torque": repr(torques.as_torque_model(torque)) if torque is not None else "none",
            "damper_inertia": damper.inertia, "damper_damping": damper.damping, **stats}
    info.update({"rtol": float(rtol), "atol": float(atol)} if method == "dop853" else {"dt": float(dt)})
    extras = {"damper_omega": Extra(states[..., 7:], ("body_axis",), "rad/s",
                                    "angular velocity of the damper sphere relative to inertial, body axes")}
    return Trajectory(t=times, q=states[..., :4], omega=states[..., 4:7], inertia=body.inertia, method=method,
                      info=info, extras=extras)


def _damper_rate(traj: Trajectory) -> np.ndarray:
    if "damper_omega" not in traj.extras:
        raise ValidationError("traj: has no extras['damper_omega'] (not a simulate_damped result)")
    return traj.extras["damper_omega"].data


def total_momentum_body(traj: Trajectory, damper: SphericalDamper) -> np.ndarray:
    """``L = I ω + J ω_d`` (N·m·s) in body axes, (n, [N,] 3)."""
    return traj.momentum_body + damper.inertia * _damper_rate(traj)


def total_momentum_inertial(traj: Trajectory, damper: SphericalDamper) -> np.ndarray:
    """``L_N = R(q) (I ω + J ω_d)`` (N·m·s), inertial axes, (n, [N,] 3): constant without external torque."""
    return attitude.rotate(traj.q, total_momentum_body(traj, damper))


def total_energy(traj: Trajectory, damper: SphericalDamper) -> np.ndarray:
    """``T = ½ ω·Iω + ½ J |ω_d|²`` (J), (n, [N]): non-increasing without external torque."""
    w_d = _damper_rate(traj)
    return traj.energy + 0.5 * damper.inertia * np.sum(w_d * w_d, axis=-1)


def nutation_angle(traj: Trajectory, damper: SphericalDamper, axis) -> np.ndarray:
    """Angle (rad) between the body axis ``axis`` (body axes) and the total angular momentum, (n, [N])."""
    a = as_array(axis, "axis", tail=(3,))
    if a.shape != (3,) or not np.linalg.norm(a) > 0.0:
        raise ValidationError(f"axis: must be a non-zero vector of shape (3,), got {a.tolist()}")
    L = total_momentum_body(traj, damper)
    cos = (L @ a) / (np.linalg.norm(L, axis=-1) * np.linalg.norm(a))
    sin = np.linalg.norm(np.cross(L, a), axis=-1) / (np.linalg.norm(L, axis=-1) * np.linalg.norm(a))
    return np.arctan2(sin, cos)


def energy_sink_time_constant(axial: float, transverse: float, damper: SphericalDamper, spin: float) -> float:
    """Nutation time constant ``τ`` (s) of an axisymmetric spinner with a spherical damper, energy-sink estimate.

    ``axial``, ``transverse``: ``I_s``, ``I_t`` of the whole body with the
    sphere locked (hub + ``J``), kg·m²; ``spin``: ``Ω`` (rad/s). For small
    nutation angle ``θ``, ``θ ∝ e^{t/τ}`` with (derivation in
    ``docs/passive_stability.md``)::

        1/τ = c J² Ω² (I_t − I_s) I_s / (I_t (c² I_t² + J² Ω² I_s²))

    Valid for ``J ≪ I_s, I_t`` (the damper does not change the nutation
    frequency) and a quasi-steady damper (``J/c`` short against ``|τ|``).
    Positive for a minor-axis spin (nutation grows), negative for a
    major-axis spin (it decays), infinite for ``I_s = I_t``.
    """
    i_s, i_t = require_positive(axial, "axial"), require_positive(transverse, "transverse")
    spin = float(spin)
    j, c = damper.inertia, damper.damping
    rate = c * j * j * spin * spin * (i_t - i_s) * i_s / (i_t * (c * c * i_t * i_t + j * j * spin * spin * i_s * i_s))
    return math.inf if rate == 0.0 else 1.0 / rate


def measured_time_constant(t, angle, *, window: tuple[float, float]) -> float:
    """Time constant ``τ`` (s) of an exponential ``angle ∝ e^{t/τ}``, fitted to the samples in ``window``.

    Least-squares line through ``ln angle`` against ``t`` over the samples
    with ``low ≤ angle ≤ high`` (``window = (low, high)``, rad): the
    small-angle phase where the energy-sink estimate applies. ``τ < 0`` for a
    decaying angle. Needs at least 3 such samples.
    """
    t = as_array(t, "t")
    angle = as_array(angle, "angle")
    low, high = (float(w) for w in window)
    if not 0.0 < low < high:
        raise ValidationError(f"window: must be (low, high) with 0 < low < high, got {window}")
    inside = (angle >= low) & (angle <= high)
    if np.count_nonzero(inside) < 3:
        raise ValidationError(f"angle: fewer than 3 samples between {low} and {high} rad to fit")
    return float(1.0 / np.polyfit(t[inside], np.log(angle[inside]), 1)[0])
