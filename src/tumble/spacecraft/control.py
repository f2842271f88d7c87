"""Attitude control laws: quaternion-feedback PD, MRP feedback, rate damping, B-dot, momentum dumping,
wheel motor torques, and any Python function.

A controller is an immutable description; :class:`tumble.spacecraft.Spacecraft`
compiles it into a program of its compiled model (:mod:`tumble.kernels.spacecraft.laws`).
The laws (body axes, SI units):

* :class:`QuaternionPD` (Wie, Weiss & Arapostathis, J. Guidance 12(3), 1989;
  rate limit after Wie & Lu, J. Guidance 18(6), 1995)::

      q_e = q_c* ⊗ q  (w ≥ 0),    ω_c = −C⁻¹K q_e,v  clipped to |ω_c| ≤ max_rate
      u   = C (ω_c − ω) + ω × H,  scaled so that max |u_k| ≤ max_torque

  with ``K = 2ω_n² J`` and ``C = 2ζω_n J``: linearised about the target, each
  axis obeys ``θ̈ + 2ζω_n θ̇ + ω_n² θ = 0`` (``q_e,v ≈ θ/2``).
* :class:`MRPFeedback` (Schaub & Junkins, *Analytical Mechanics of Space Systems*,
  4th ed., 2018, §8; Basilisk's ``mrpFeedback``), regulation to an inertial target::

      σ = MRP of q_e = q_c* ⊗ q (w ≥ 0: the shortest rotation, |σ| ≤ 1)
      u = −K σ − P ω + ω × H                       (without the integral term)
      u = −K σ − P (ω + K_I z) + ω × H,  z = K ∫σ dt + J ω   (with it)

  Both are globally stabilising: ``V = ½ ωᵀJω + 2K ln(1 + σᵀσ) (+ ½ K_I zᵀz)``
  has ``V̇ = −(ω + K_I z)ᵀ P (ω + K_I z)``; the integral term removes the
  steady error under a constant disturbance torque.
* :class:`RateDamping`: ``u = −J ω / τ + ω × H``, so ``ω(t) = ω₀ e^{−t/τ}``.
* :class:`ConstantTorque`: ``u = u₀`` (open loop).
* :class:`BDot`: magnetic dipole ``m = −k Ḃ`` with ``Ḃ = −ω × B`` (the rate of
  change of the body-axes field due to the body's rotation; the slow orbital
  change of the field is left out), so ``τ = m × B = −k (|B|² E − B Bᵀ) ω``
  (Stickler & Alfriend, J. Spacecraft 13(5), 1976).
* :class:`MomentumDumping`: ``m = k (h × B)/|B|²`` with ``h`` the wheels'
  momentum in body axes, giving ``τ = −k h_⊥`` (the part of ``h`` normal to
  ``B``) while the attitude law holds the body (Sidi 1997, §7.5).
* :class:`PythonLaw` (or a plain callable): ``u = law(t, q, omega, wheel_speeds)``,
  any torque command written in Python; it runs at Python speed (a few
  microseconds per call, four calls per RK4 step unless the controller is
  sampled) and a batch with one runs on one core.
* :class:`WheelTorques`: motor torques commanded to the wheels directly, one
  per wheel (N·m): a constant, samples in time, or a Python function.

Every law takes ``period``, its own sample period (s): its command is
computed at ``t₀ + k·period`` and held in between (zero-order hold). The
default None samples it at the spacecraft's ``control_period`` (continuous
without one). The dipole laws add into one dipole command and share one
period (``docs/spacecraft.md``, "Laws at their own rates").

``H`` is the spacecraft's angular momentum in body axes (hub, wheels, gyros,
damper). ``J`` is the inertia the body rate answers to: the total inertia less
the wheels' spin inertias and the damper sphere (see ``docs/spacecraft.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tumble import _callback, attitude
from tumble._validate import ValidationError, as_array, increasing_times, require_positive
from tumble.kernels.spacecraft import laws as _laws
from tumble.kernels.spacecraft._base import Program
from tumble.spacecraft.actuators import _limit

__all__ = ["QuaternionPD", "MRPFeedback", "RateDamping", "ConstantTorque", "BDot", "MomentumDumping", "PythonLaw",
           "WheelTorques", "TORQUE_LAWS", "DIPOLE_LAWS"]


def _period(value) -> float | None:
    """A law's own sample period: None (the spacecraft's ``control_period``) or a finite number > 0, s."""
    if value is None:
        return None
    try:
        return require_positive(value, "period")
    except ValidationError:
        raise ValidationError(f"period: must be None (the spacecraft's control_period) or a finite number > 0 "
                              f"(s), got {value!r}") from None


def _quaternion(value, name: str) -> np.ndarray:
    q = as_array(value, name, tail=(4,))
    if q.shape != (4,) or np.linalg.norm(q) == 0.0:
        raise ValidationError(f"{name}: must be a non-zero quaternion [w, x, y, z], got {q.tolist()}")
    return attitude.normalize(q)


@dataclass(frozen=True)
class QuaternionPD:
    """Quaternion-feedback PD regulator to the attitude ``target`` (body → inertial, scalar first).

    natural_frequency : ω_n, rad/s; damping_ratio : ζ (> 0);
    max_rate : eigen-axis slew rate limit, rad/s (``math.inf``: none);
    max_torque : limit on each component of the commanded torque, N·m (``math.inf``: none);
    period : its sample period, s (None: the spacecraft's ``control_period``).
    """

    natural_frequency: float
    damping_ratio: float = 1.0 / math.sqrt(2.0)
    target: np.ndarray = (1.0, 0.0, 0.0, 0.0)  # type: ignore[assignment]  # array_like: __post_init__ converts
    max_rate: float = math.inf
    max_torque: float = math.inf
    period: float | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "period", _period(self.period))
        set_(self, "natural_frequency", require_positive(self.natural_frequency, "natural_frequency"))
        set_(self, "damping_ratio", require_positive(self.damping_ratio, "damping_ratio"))
        set_(self, "target", _quaternion(self.target, "target"))
        for name in ("max_rate", "max_torque"):
            set_(self, name, _limit(getattr(self, name), name))

    def gains(self, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(K, C)`` = ``(2ω_n² J, 2ζω_n J)`` for the inertia ``J`` (kg·m²)."""
        wn, zeta = self.natural_frequency, self.damping_ratio
        return 2.0 * wn * wn * inertia, 2.0 * zeta * wn * inertia

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        k, c = self.gains(rate_inertia)
        return (_laws.pd_program(c, np.linalg.solve(c, k), self.target, self.max_rate, self.max_torque, 1.0,
                                 np.zeros(3)),)


@dataclass(frozen=True)
class MRPFeedback:
    """MRP feedback regulator to the inertial attitude ``target`` (Schaub & Junkins, §8; Basilisk's
    ``mrpFeedback``): ``u = −K σ − P (ω + K_I z) + ω × H`` (module docstring).

    K : attitude gain, N·m (> 0)
    P : rate gain, N·m·s: a number (> 0) or a symmetric positive-definite (3, 3) matrix, body axes
    Ki : integral gain ``K_I``, 1/(N·m·s) (> 0), or None for no integral term; the integral
        ``∫σ dt`` is a state (``attitude_error_integral``, initial value ``attitude_error_integral0``,
        default 0), integrated continuously also when the controller is sampled
    target : commanded attitude, unit quaternion ``[w, x, y, z]``, body → inertial
    period : its sample period, s (None: the spacecraft's ``control_period``)

    ``J`` (in ``z``) and ``H`` are the spacecraft's: the inertia its rate answers to and its
    angular momentum (hub, wheels, gyros), body axes.
    """

    K: float
    P: object
    Ki: float | None = None
    target: np.ndarray = (1.0, 0.0, 0.0, 0.0)  # type: ignore[assignment]  # array_like: __post_init__ converts
    period: float | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "period", _period(self.period))
        set_(self, "K", require_positive(self.K, "K"))
        p = as_array(self.P, "P")
        if p.shape == ():
            p = require_positive(float(p), "P") * np.eye(3)
        elif p.shape != (3, 3) or not np.allclose(p, p.T, rtol=1e-12, atol=0.0) \
                or not np.all(np.linalg.eigvalsh(0.5 * (p + p.T)) > 0.0):
            raise ValidationError(f"P: must be a number > 0 or a symmetric positive-definite (3, 3) matrix "
                                  f"(N·m·s), got {p.tolist()}")
        p.setflags(write=False)
        set_(self, "P", p)
        if self.Ki is not None:
            set_(self, "Ki", require_positive(self.Ki, "Ki"))
        set_(self, "target", _quaternion(self.target, "target"))

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        mrp = _laws.mrp_program(self.K, self.P, self.target)
        return (mrp,) if self.Ki is None else (mrp, _laws.mrp_integral_program(self.Ki))


@dataclass(frozen=True)
class RateDamping:
    """Rate damping ``u = −J ω/τ + ω × H``: every rate decays as ``e^{−t/τ}``; ``time_constant`` τ, s;
    ``period`` its sample period, s (None: the spacecraft's ``control_period``)."""

    time_constant: float
    max_torque: float = math.inf
    period: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "period", _period(self.period))
        object.__setattr__(self, "time_constant", require_positive(self.time_constant, "time_constant"))
        object.__setattr__(self, "max_torque", _limit(self.max_torque, "max_torque"))

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        zero = np.zeros((3, 3))
        return (_laws.pd_program(rate_inertia / self.time_constant, zero, attitude.identity(), math.inf,
                                 self.max_torque, 1.0, np.zeros(3)),)


@dataclass(frozen=True)
class ConstantTorque:
    """An open-loop torque command ``u = torque`` (N·m, body axes), for actuator studies (e.g. the
    pulse train a PWPF modulator makes of a constant command); ``period`` its sample period, s (None: the
    spacecraft's ``control_period``)."""

    torque: np.ndarray
    period: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "period", _period(self.period))
        u = as_array(self.torque, "torque", tail=(3,))
        if u.shape != (3,):
            raise ValidationError(f"torque: must have shape (3,), got {u.shape}")
        object.__setattr__(self, "torque", u)

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        zero = np.zeros((3, 3))
        return (_laws.pd_program(zero, zero, attitude.identity(), math.inf, math.inf, 0.0, self.torque),)


@dataclass(frozen=True)
class BDot:
    """B-dot detumbling with magnetorquers: ``m = −k Ḃ = k ω × B``; ``gain`` k in A·m²·s/T; ``period`` its
    sample period, s (None: the spacecraft's ``control_period``)."""

    gain: float
    period: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "period", _period(self.period))
        object.__setattr__(self, "gain", require_positive(self.gain, "gain"))

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        return (_laws.gain_program("bdot", self.gain),)


@dataclass(frozen=True)
class MomentumDumping:
    """Wheel momentum dumping with magnetorquers: ``m = k (h × B)/|B|²``; ``gain`` k in 1/s; ``period`` its
    sample period, s (None: the spacecraft's ``control_period``)."""

    gain: float
    period: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "period", _period(self.period))
        object.__setattr__(self, "gain", require_positive(self.gain, "gain"))

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        return (_laws.gain_program("dumping", self.gain),)


@dataclass(frozen=True, eq=False)
class PythonLaw:
    """A torque command written in Python: ``u = function(t, q, omega, wheel_speeds)``.

    ``t`` (s), ``q`` (unit quaternion, body → inertial), ``omega`` (rad/s, body
    axes) and ``wheel_speeds`` (rad/s relative to the hub, one per wheel; empty
    without wheels) are fresh NumPy arrays; it returns the torque command on
    the hub, 3 numbers (N·m, body axes), delivered by the spacecraft's
    actuators as a compiled law's is. It is called back from the compiled
    integrator through :mod:`tumble._callback`: a few microseconds per call,
    four calls per RK4 step (once per sample when sampled: ``period``, s, or
    the spacecraft's ``control_period`` when None), and a batch runs on one
    core. A plain callable given as a controller is wrapped in this class.
    """

    function: object
    period: float | None = None
    callback: _callback.Callback = field(init=False, repr=False)  # registered per process

    def __post_init__(self):
        object.__setattr__(self, "period", _period(self.period))
        object.__setattr__(self, "callback", _callback.Callback(
            self.function, field="controller", signature="(t, q, omega, wheel_speeds)",
            returns="3 finite numbers (torque command, body axes, N·m)"))

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        return (_laws.python_program("python_law", self.callback.slot),)


@dataclass(frozen=True, eq=False)
class WheelTorques:
    """Motor torques commanded to the reaction wheels directly, N·m, one per wheel (in the order of
    ``Spacecraft.wheels``), added to what a torque law allocates to them, then limited as any motor command.

    torques : (n_w,) a constant; (n_t, n_w) samples at the times ``t`` (s, strictly increasing),
        interpolated ``"linear"`` or ``"previous"`` (zero-order hold), the end values held outside; or a
        Python function ``torques(t, q, omega, wheel_speeds) -> (n_w,)`` (Python speed, one core; see
        :class:`PythonLaw`)
    period : its sample period, s (None: the spacecraft's ``control_period``)
    """

    torques: Any  # a function of time, or samples (len(t), n_w) or (n_w,): an array (len(t), n_w) once validated
    t: object = None
    interpolation: str = "linear"
    period: float | None = None
    callback: _callback.Callback | None = field(init=False, repr=False, default=None)  # a function's, per process

    def __post_init__(self):
        object.__setattr__(self, "period", _period(self.period))
        if self.interpolation not in ("linear", "previous"):
            raise ValidationError(f"interpolation: must be 'linear' or 'previous', got {self.interpolation!r}")
        if callable(self.torques):
            if self.t is not None:
                raise ValidationError("t: a function of time needs no sample times")
            object.__setattr__(self, "callback", _callback.Callback(
                self.torques, field="controller", signature="(t, q, omega, wheel_speeds)",
                returns="one finite number per wheel (motor torque, N·m)"))
            return
        values = as_array(self.torques, "torques")
        if self.t is None:
            if values.ndim != 1 or values.size < 1:
                raise ValidationError(f"torques: a constant is one motor torque per wheel, shape (n_w,), "
                                      f"got {values.shape}")
            times, values = np.zeros(1), values[None, :]
        else:
            times = increasing_times(self.t, what="sample times")
            if values.ndim != 2 or values.shape[0] != times.size:
                raise ValidationError(f"torques: must have shape (len(t), n_w) = ({times.size}, n_w), "
                                      f"got {values.shape}")
        object.__setattr__(self, "t", times)
        object.__setattr__(self, "torques", values)

    @property
    def wheels(self) -> int | None:
        """The number of wheels the samples are for (None for a Python function)."""
        return None if self.callback is not None else self.torques.shape[1]

    def _programs(self, rate_inertia) -> tuple[Program, ...]:
        if self.callback is not None:
            return (_laws.python_program("wheel_python", self.callback.slot),)
        return (_laws.wheel_table_program(self.t, self.torques, self.interpolation == "previous"),)


#: The laws that command a torque on the hub (at most one per spacecraft), and those that command a dipole.
TORQUE_LAWS = (QuaternionPD, MRPFeedback, RateDamping, ConstantTorque, PythonLaw)
DIPOLE_LAWS = (BDot, MomentumDumping)
