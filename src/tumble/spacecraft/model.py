"""``Spacecraft``: a rigid hub with actuators, environment and controller, a model of :func:`tumble.simulate`.

Conventions (``docs/spacecraft.md``): SI units; body axes B are the hub's
reference axes; ``q`` maps body → inertial (scalar first); ``omega`` is the
hub's rate relative to inertial, in body axes. The spacecraft's mass
properties are described in one of two ways:

* ``Spacecraft(inertia=J, ...)``: ``J`` is the **total** inertia about the
  centre of mass, wheels and damper sphere included (each counted as a rigid
  part of the spacecraft, its spin inertia included);
* ``Spacecraft(hub=RigidBody(...), ...)``: the hub **without** the wheels or
  the sphere; each wheel then needs ``mass``, ``position`` and
  ``transverse_inertia`` (the hub a mass), and the total ``J`` is the composite
  of hub and rotors (:meth:`tumble.rigid_body.RigidBody.composite`) plus the
  sphere's ``J_d E`` (it sits at the centre of mass).

Both give the same motion for the same total (tested). Flexible appendages
(``flexible_modes``) are part of either, undeformed. The body rate answers
to ``J_ω = J − Σ I_s a aᵀ − J_d E − Σ δ_k δ_kᵀ`` (the rotors' spin inertias, the
sphere and the appendages' modal participation are carried by their own states). Slosh pendulums (``slosh``)
ride on the hub: ``J`` is then the hub's inertia about its own centre of mass, without the sloshing liquid. The
equations are those of
:mod:`tumble.kernels.spacecraft`, one file per actuator.

One class, one unit (about 800 lines): its checks, its compiled parts, its
initial state and its named outputs each read the same list of parts, and
what each part adds to them is a few lines beside the others.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude, integrate, torques
from tumble._validate import ValidationError, as_array
from tumble.rigid_body import RigidBody
from tumble.kernels import spacecraft as _kernel
from tumble.kernels.spacecraft import _commands
from tumble.kernels.spacecraft import cmgs as _cmgs
from tumble.kernels.spacecraft import drag as _drag
from tumble.kernels.spacecraft import damper as _damper_kernel
from tumble.kernels.spacecraft import flight_software as _fsw_kernel
from tumble.kernels.spacecraft import environment as _environment
from tumble.kernels.spacecraft import flexible_modes as _flexible_modes
from tumble.kernels.spacecraft import laws as _law_kernels
from tumble.kernels.spacecraft import magnetorquers as _magnetorquers
from tumble.kernels.spacecraft import residual_dipole as _residual_dipole
from tumble.kernels.spacecraft import slosh as _slosh
from tumble.kernels.spacecraft import solar_pressure as _solar_pressure
from tumble.kernels.spacecraft import thrusters as _thrusters
from tumble.kernels.spacecraft import wheels as _wheels
from tumble.kernels.spacecraft._base import Program
from tumble.simulate import Model, Outputs, StateField
from tumble.spacecraft.actuators import PWPF, CMGCluster, Magnetorquers, ReactionWheel, Thruster
from tumble.spacecraft.control import DIPOLE_LAWS, TORQUE_LAWS, MomentumDumping, MRPFeedback, PythonLaw, WheelTorques
from tumble.spacecraft.damper import SphericalDamper
from tumble.spacecraft.environment import DipoleField, ResidualDipole
from tumble.spacecraft.environment_table import Environment
from tumble.spacecraft.flexible_modes import FlexibleModes
from tumble.spacecraft.flight_software import FlightSoftware, check_seed
from tumble.spacecraft.flight_software import initial_state as _fsw_initial_state
from tumble.spacecraft.orbit import EARTH_MU, Orbit
from tumble.spacecraft.slosh import SloshPendulum, initial_rods, slosh_program
from tumble.spacecraft.surfaces import Drag, SolarPressure
from tumble.trajectory import Extra, Trajectory

__all__ = ["Spacecraft", "SaturationWarning", "SingularityWarning"]

# A whole number of steps per control period or output interval to this relative tolerance.
_WHOLE = 1e-9
# The stack depth from a warning in outputs() to the caller of tumble.simulate.
_STACKLEVEL = 3
#: A CMG cluster counts as singular when its measure √det(Ā Āᵀ) falls below this (the four-CMG pyramid has 1.09
#: at δ = 0; the slews of the examples stay above 1).
SINGULAR_MEASURE = 1e-2


class SaturationWarning(UserWarning):
    """A reaction wheel reached its speed limit during a simulation (see ``extras['wheel_saturated']``)."""


class SingularityWarning(UserWarning):
    """The CMG cluster was at or near a singular configuration during a simulation (``extras['singularity']``
    below :data:`SINGULAR_MEASURE`): torques along the singular direction could not be delivered there."""


@dataclass(frozen=True)
class Spacecraft(Model):
    """A spacecraft: rigid hub, actuators, environment and controller (all optional but the mass properties).

    inertia : RigidBody or (3, 3) array, kg·m², body axes: the total inertia, wheels and damper sphere included
    hub : RigidBody: the hub without its wheels and damper sphere (give ``inertia`` or ``hub``); it needs a
        mass when there are wheels
    wheels : sequence of :class:`ReactionWheel`
    cmgs : :class:`CMGCluster` or None
    thrusters : sequence of :class:`Thruster`, with ``pwpf`` the modulator of the three axes
    magnetorquers : :class:`Magnetorquers` or None
    damper : :class:`~tumble.spacecraft.damper.SphericalDamper` or None: a viscous nutation damper at the
        centre of mass (initial sphere rate ``damper_omega0``, default ``omega0``)
    orbit : :class:`tumble.spacecraft.orbit.Orbit` or None (needed by the gravity gradient and the dipole field)
    magnetic_field : :class:`~tumble.spacecraft.environment.DipoleField`, a (3,) uniform field in
        inertial axes (T), or None
    gravity_gradient : bool, the gravity-gradient torque of the orbit on the total inertia
    residual_dipole : :class:`~tumble.spacecraft.environment.ResidualDipole` or None: a constant body dipole,
        torque ``m × B`` in ``magnetic_field`` or the environment's field (needed)
    environment : :class:`~tumble.spacecraft.environment_table.Environment` or None: the environment sampled
        along an orbit (Kepler or TLE), whose ``t = 0`` is the simulation's: it replaces ``orbit`` and
        ``magnetic_field`` (the field is its IGRF-14, the gravity gradient reads its position) and is needed by
    solar_pressure : :class:`~tumble.spacecraft.surfaces.SolarPressure` or None: radiation pressure on facets
    drag : :class:`~tumble.spacecraft.surfaces.Drag` or None: aerodynamic drag and lift on facets
    controller : a law or a sequence of laws: at most one torque law (:class:`QuaternionPD`,
        :class:`MRPFeedback`, :class:`RateDamping`, :class:`ConstantTorque`, or a Python callable
        ``u = law(t, q, omega, wheel_speeds)``, i.e. a :class:`PythonLaw`), one of each dipole law
        (:class:`BDot`, :class:`MomentumDumping`) and one :class:`WheelTorques`; a law's ``period`` (s) samples
        it at its own rate (the dipole laws share one; with the torque delivered by the magnetorquers, the
        torque law's too; with flight software, a whole multiple of ``control_period``)
    control_period : None (continuous) or the sample period of a zero-order-hold controller, s: that of every
        law without a ``period`` of its own
    flight_software : :class:`~tumble.spacecraft.flight_software.FlightSoftware` or None: gyro, star tracker
        and direction sensors at their own rates, the MEKF at the control period (needed), the control law fed
        the estimate instead of the truth
    flexible_modes : :class:`~tumble.spacecraft.flexible_modes.FlexibleModes` or None: cantilever modes of
        flexible appendages (hybrid coordinates; the appendages undeformed are in ``inertia`` or ``hub``),
        initial modal coordinates and rates ``eta0``, ``eta_rate0`` (default zero)
    slosh : sequence of :class:`~tumble.spacecraft.slosh.SloshPendulum`: the fuel slosh of each tank as a
        spherical pendulum (``inertia`` the hub's, without the sloshing liquid), initial rod directions
        ``direction0`` and relative rates ``rate0`` (3 per tank, tank by tank; rates default zero)

    The torque command goes to the wheels if there are any, else to the CMGs,
    else to the thrusters (through the PWPF modulators), else to the
    magnetorquers (``m = B × u/|B|²``, the part normal to ``B``). External
    torques (``torque=`` of :func:`tumble.simulate`: :mod:`tumble.torques`
    models or ``f(t, q, omega)``) act on top of the spacecraft's own environment.
    """

    torque = ("external torque on the spacecraft, body axes (N·m): a tumble.torques model or f(t, q, omega), "
              "in addition to its own environment")

    inertia: RigidBody | ArrayLike | None = None
    hub: RigidBody | None = None
    wheels: Sequence[ReactionWheel] = ()
    cmgs: CMGCluster | None = None
    thrusters: Sequence[Thruster] = ()
    pwpf: PWPF = field(default_factory=PWPF)
    magnetorquers: Magnetorquers | None = None
    damper: SphericalDamper | None = None
    orbit: Orbit | None = None
    magnetic_field: object = None
    gravity_gradient: bool = False
    residual_dipole: ResidualDipole | None = None
    environment: Environment | None = None
    solar_pressure: SolarPressure | None = None
    drag: Drag | None = None
    controller: Any = None  # a law, a sequence of laws or None: the tuple of laws once validated
    control_period: float | None = None
    flight_software: FlightSoftware | None = None
    flexible_modes: FlexibleModes | None = None
    slosh: Sequence[SloshPendulum] = ()
    #: The whole spacecraft as one rigid body (total inertia J, mass, centre of mass), derived.
    body: RigidBody = field(init=False, repr=False)

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "wheels", tuple(self.wheels))
        set_(self, "thrusters", tuple(self.thrusters))
        set_(self, "slosh", tuple(self.slosh))
        _check_items(self.wheels, ReactionWheel, "wheels")
        _check_items(self.thrusters, Thruster, "thrusters")
        _check_items(self.slosh, SloshPendulum, "slosh")
        _check_type(self.cmgs, CMGCluster, "cmgs")
        _check_type(self.pwpf, PWPF, "pwpf")
        _check_type(self.magnetorquers, Magnetorquers, "magnetorquers")
        _check_type(self.damper, SphericalDamper, "damper")
        _check_type(self.orbit, Orbit, "orbit")
        _check_type(self.residual_dipole, ResidualDipole, "residual_dipole")
        _check_type(self.environment, Environment, "environment")
        _check_type(self.solar_pressure, SolarPressure, "solar_pressure")
        _check_type(self.drag, Drag, "drag")
        if self.environment is not None:
            for name in ("orbit", "magnetic_field"):
                if getattr(self, name) is not None:
                    raise ValidationError(f"{name}: the environment gives the orbit and the field (IGRF-14); give "
                                          f"the environment or the {name}, not both")
        for name in ("solar_pressure", "drag"):
            if getattr(self, name) is not None and self.environment is None:
                raise ValidationError(f"{name}: needs an environment (the Sun, the shadow, the air along the orbit)")
        set_(self, "body", self._total_body())
        if self.magnetic_field is not None and not isinstance(self.magnetic_field, DipoleField):
            b = as_array(self.magnetic_field, "magnetic_field")
            if b.shape != (3,):
                raise ValidationError(f"magnetic_field: must be a DipoleField or a (3,) uniform field (T), "
                                      f"got shape {b.shape}")
            set_(self, "magnetic_field", b)
        if isinstance(self.magnetic_field, DipoleField) and self.orbit is None:
            raise ValidationError("magnetic_field: a DipoleField needs an orbit (the field depends on the position)")
        if not isinstance(self.gravity_gradient, (bool, np.bool_)):
            raise ValidationError(f"gravity_gradient: must be True or False, got {self.gravity_gradient!r}")
        if self.gravity_gradient and self.orbit is None and self.environment is None:
            raise ValidationError("gravity_gradient: needs an orbit or an environment")
        if self.residual_dipole is not None and not self._has_field:
            raise ValidationError("residual_dipole: needs a magnetic_field (its torque is m × B)")
        set_(self, "controller", self._laws())
        self._thruster_program()  # validates the thruster layout
        if self.control_period is not None:
            value = float(self.control_period)
            if not math.isfinite(value) or value <= 0.0:
                raise ValidationError(f"control_period: must be None (continuous) or a number > 0 (s), got {value}")
            set_(self, "control_period", value)
        self._check_flight_software()
        self._check_flexible_modes()
        self._check_law_periods()

    # -- description -------------------------------------------------------------------

    def _total_body(self) -> RigidBody:
        if (self.inertia is None) == (self.hub is None):
            raise ValidationError("inertia: give exactly one of inertia (total, wheels included) or hub "
                                  "(without the wheels, which then need mass properties)")
        if self.inertia is not None:
            return self.inertia if isinstance(self.inertia, RigidBody) else RigidBody(self.inertia)
        hub = self.hub
        _check_type(hub, RigidBody, "hub")
        assert hub is not None  # exactly one of inertia and hub: checked above
        if self.wheels and hub.mass is None:
            raise ValidationError("hub: needs a mass to be combined with the wheels")
        total = RigidBody.composite([hub] + [w.part() for w in self.wheels]) if self.wheels else hub
        if self.damper is None:
            return total
        return RigidBody(total.inertia + self.damper.inertia * np.eye(3), mass=total.mass, com=total.com)

    def _check_flight_software(self) -> None:
        _check_type(self.flight_software, FlightSoftware, "flight_software")
        if self.flight_software is None:
            return
        if self.control_period is None:
            raise ValidationError("flight_software: needs a control_period (its sensors and filter run at it)")
        self.flight_software.check_clocks(self.control_period)
        if self.flight_software.sees_the_sun and (self.flight_software.sun_direction is None) == (
                self.environment is None):
            raise ValidationError("flight_software: a Sun sensor needs the Sun: a sun_direction or an environment "
                                  "(its Sun and eclipses), not both")
        if self.flight_software.magnetometer_sigma is not None and not self._has_field:
            raise ValidationError("flight_software: a magnetometer needs a magnetic_field")
        if self._torque_law() is None or any(isinstance(law, WheelTorques) for law in self.controller):
            raise ValidationError("flight_software: needs a torque law (QuaternionPD, MRPFeedback, RateDamping, "
                                  "ConstantTorque or a Python law) and no WheelTorques (whose commands it does "
                                  "not delay)")

    def _check_flexible_modes(self) -> None:
        """The modes are :class:`FlexibleModes` and leave ``J_ω`` positive definite."""
        _check_type(self.flexible_modes, FlexibleModes, "flexible_modes")
        if self.flexible_modes is None:
            return
        smallest, largest = np.linalg.eigvalsh(self.rate_inertia)[[0, -1]]
        if smallest <= 1e-12 * abs(largest):
            raise ValidationError(f"flexible_modes: J_ω = J − Σ I_s a aᵀ − J_d E − Σ δ_k δ_kᵀ must be positive "
                                  f"definite (the appendages cannot carry more inertia than the whole body); its "
                                  f"smallest eigenvalue is {smallest:.6g} kg m^2")

    def _check_law_periods(self) -> None:
        """The laws' own periods: with flight software, a whole multiple of ``control_period`` (a law due then
        reads the estimate of its sample time); the dipole laws, and the torque law when the magnetorquers
        deliver its torque, make one dipole command, held at one period."""
        for i, law in enumerate(self.controller):
            if law.period is not None and self.flight_software is not None:
                assert self.control_period is not None  # the flight software needs one: checked before
                ratio = law.period / self.control_period
                if ratio < 1.0 - _WHOLE or abs(ratio - round(ratio)) > _WHOLE * ratio:
                    raise ValidationError(f"controller[{i}].period: with flight software a law's period must be a "
                                          f"whole multiple of control_period = {self.control_period} s (the law "
                                          f"reads the estimate of its sample time), got {law.period} s")
        one_dipole = [(i, law) for i, law in enumerate(self.controller) if isinstance(law, DIPOLE_LAWS) or (
            isinstance(law, TORQUE_LAWS) and self._torque_by_magnetorquers)]
        for i, law in one_dipole[1:]:
            first, period = self._law_period(one_dipole[0][1]), self._law_period(law)
            if period != first:
                k = i if law.period is not None else one_dipole[0][0]
                raise ValidationError(
                    f"controller[{k}].period: the dipole laws, and the torque law when the magnetorquers deliver "
                    f"its torque, make one dipole command held at one period; got {_seconds(first)} and "
                    f"{_seconds(period)}")

    def _law_period(self, law) -> float | None:
        """The sample period of ``law`` (s): its own, else ``control_period``; None: continuous."""
        return self.control_period if law.period is None else law.period

    @property
    def _torque_by_magnetorquers(self) -> bool:
        return self.route == "magnetorquers" and self._torque_law() is not None

    @property
    def _sampled(self) -> bool:
        """Some law is held between samples: a ``control_period`` or a law's own ``period``."""
        return self.control_period is not None or any(law.period is not None for law in self.controller)

    def _group_periods(self) -> tuple[float, float, float]:
        """The sample periods (s; 0: continuous) of the torque law, the dipole laws and the wheel-torque law,
        a group without a law at ``control_period`` (the dipole laws' at the torque law's when the
        magnetorquers deliver its torque)."""

        def period(kinds, default: float) -> float:
            law = next((law for law in self.controller if isinstance(law, kinds)), None)
            return default if law is None else self._law_period(law) or 0.0

        control = self.control_period or 0.0
        torque = period(TORQUE_LAWS, control)
        return torque, period(DIPOLE_LAWS, torque if self._torque_by_magnetorquers else control), period(
            (WheelTorques,), control)

    @property
    def _has_field(self) -> bool:
        """A magnetic field is there: ``magnetic_field`` or the environment's IGRF."""
        return self.magnetic_field is not None or self.environment is not None

    def _laws(self) -> tuple:
        laws = () if self.controller is None else (
            tuple(self.controller) if isinstance(self.controller, (list, tuple)) else (self.controller,))
        kinds = (*TORQUE_LAWS, *DIPOLE_LAWS, WheelTorques)
        laws = tuple(law if isinstance(law, kinds) or not callable(law) else PythonLaw(law) for law in laws)
        for i, law in enumerate(laws):
            if not isinstance(law, kinds):
                raise ValidationError(f"controller: must be one of {', '.join(k.__name__ for k in kinds)} or a "
                                      f"callable law(t, q, omega, wheel_speeds) (or a sequence of them), got "
                                      f"{type(law).__name__} at {i}")
        torque_laws = [law for law in laws if isinstance(law, TORQUE_LAWS)]
        if len(torque_laws) > 1 or any(sum(isinstance(x, kind) for x in laws) > 1
                                       for kind in (*DIPOLE_LAWS, WheelTorques)):
            raise ValidationError("controller: at most one torque law (QuaternionPD, MRPFeedback, RateDamping, "
                                  "ConstantTorque or a Python law), one BDot, one MomentumDumping and one "
                                  "WheelTorques")
        if torque_laws and self.route == "none":
            raise ValidationError(f"controller: {type(torque_laws[0]).__name__} needs an actuator "
                                  "(wheels, cmgs, thrusters or magnetorquers)")
        for law in laws:
            if isinstance(law, DIPOLE_LAWS) and (self.magnetorquers is None or not self._has_field):
                raise ValidationError(f"controller: {type(law).__name__} needs magnetorquers and a magnetic_field")
            if isinstance(law, (MomentumDumping, WheelTorques)) and not self.wheels:
                raise ValidationError(f"controller: {type(law).__name__} needs reaction wheels")
            if isinstance(law, WheelTorques) and law.wheels not in (None, len(self.wheels)):
                raise ValidationError(f"controller: WheelTorques gives {law.wheels} motor torques for "
                                      f"{len(self.wheels)} wheels")
        if self.route == "magnetorquers" and torque_laws and not self._has_field:
            raise ValidationError("controller: torque by magnetorquers needs a magnetic_field")
        return laws

    @property
    def route(self) -> str:
        """Which actuator receives the controller's torque: 'wheels', 'cmgs', 'thrusters', 'magnetorquers', 'none'."""
        for name, present in (("wheels", self.wheels), ("cmgs", self.cmgs), ("thrusters", self.thrusters),
                              ("magnetorquers", self.magnetorquers)):
            if present:
                return name
        return "none"

    @property
    def total_inertia(self) -> np.ndarray:
        """J: inertia of the whole spacecraft about its centre of mass, kg·m², body axes (wheels included)."""
        return self.body.inertia

    @functools.cached_property  # a frozen description: computed once, read-only
    def rate_inertia(self) -> np.ndarray:
        """J_ω = J − Σ I_s a aᵀ − J_d E − Σ δ_k δ_kᵀ: the inertia the body rate answers to, kg·m² (rotor
        spins, the damper sphere and the appendages' modal participation excluded)."""
        j = self.body.inertia.copy()
        for w in self.wheels:
            j -= w.inertia * np.outer(w.axis, w.axis)
        if self.damper is not None:
            j -= self.damper.inertia * np.eye(3)
        if self.flexible_modes is not None:
            j -= self.flexible_modes.inertia
        j.setflags(write=False)
        return j

    @property
    def _law_inertia(self) -> np.ndarray:
        """The inertia the control laws' gains are designed for, kg·m²: ``J_ω`` with the appendages rigid
        (``+ Σ δ_k δ_kᵀ``), the inertia of the rigid-body motion that the modes follow below their
        frequencies."""
        if self.flexible_modes is None:
            return self.rate_inertia
        return self.rate_inertia + self.flexible_modes.inertia

    def _torque_law(self):
        return next((law for law in self.controller if isinstance(law, TORQUE_LAWS)), None)

    # -- the compiled model ------------------------------------------------------------

    @functools.cached_property
    def _programs(self) -> tuple[Program, ...]:
        """The programs of the parts (:mod:`tumble.kernels.spacecraft`), in no particular order."""
        programs = []
        wheel_law = any(isinstance(law, WheelTorques) for law in self.controller)
        if self._sampled:
            programs.append(_commands.hold_program(*self._group_periods(), len(self.wheels) if wheel_law else 0))
        if self.wheels:
            axes = np.array([w.axis for w in self.wheels])
            routed = self.route == "wheels" and self._torque_law() is not None
            spin, max_torque, max_speed, viscous, coulomb, coulomb_speed = (
                np.array([getattr(w, name) for w in self.wheels])
                for name in ("inertia", "max_torque", "max_speed", "viscous", "coulomb", "coulomb_speed"))
            programs.append(_wheels.program(
                axes, spin, max_torque, max_speed, viscous, coulomb, coulomb_speed,
                allocation=np.linalg.pinv(axes.T) if routed else np.zeros_like(axes)))
        programs += [part._program() for part in (self.cmgs, self.magnetorquers, self.damper, self.residual_dipole,
                                                  self.environment, self.solar_pressure, self.drag,
                                                  self.flexible_modes)
                     if part is not None]
        if self.slosh:
            programs.append(slosh_program(self.slosh))
        if self.flight_software is not None:
            assert self.control_period is not None  # checked in __post_init__
            programs.append(self.flight_software._program(self.control_period))
        thrusters = self._thruster_program()
        if thrusters is not None:  # None: no thrusters
            programs.append(thrusters)
        for law in self.controller:
            programs += law._programs(self._law_inertia)
        if isinstance(self.magnetic_field, DipoleField):
            assert self.orbit is not None  # a DipoleField needs an orbit: checked in __post_init__
            programs.append(_environment.dipole_program(self.orbit.elements(), self.magnetic_field.params()))
        elif self.magnetic_field is not None:
            programs.append(_environment.uniform_program(self.magnetic_field))
        if self.gravity_gradient and self.orbit is not None:
            programs.append(_environment.gravity_gradient_program(self.orbit.elements()))
        elif self.gravity_gradient:  # the position from the environment table: only μ is read
            assert self.environment is not None  # checked in __post_init__
            mu = self.environment.orbit.mu if isinstance(self.environment.orbit, Orbit) else EARTH_MU
            programs.append(_environment.gravity_gradient_program(np.r_[np.zeros(6), mu]))
        return tuple(programs)

    def __getstate__(self) -> dict:
        """Pickled without the compiled programs: a Python law's holds its callback slot, a number of this
        process (:mod:`tumble._callback`); the receiving process compiles them again with its own."""
        return {name: value for name, value in self.__dict__.items() if name != "_programs"}

    def _thruster_program(self) -> Program | None:
        """The thrusters' program: each serves the body axis of its largest torque component, with its sign."""
        if not self.thrusters:
            return None
        com = np.zeros(3) if self.body.com is None else self.body.com
        torques_ = np.array([th.torque(com) for th in self.thrusters])
        axis = np.argmax(np.abs(torques_), axis=1)
        sign = np.sign(torques_[np.arange(len(axis)), axis])
        scale = np.zeros(3)
        for k in range(3):
            groups = [torques_[(axis == k) & (sign == s)].sum(axis=0)[k] for s in (1.0, -1.0)]
            if 0.0 in groups:
                raise ValidationError(f"thrusters: the PWPF modulators need thrusters of both signs about each "
                                      f"body axis; none turns the spacecraft {'+-'[groups.index(0.0)]}{'xyz'[k]}")
            scale[k] = 0.5 * (groups[0] - groups[1])
        p = self.pwpf
        return _thrusters.program(torques_, axis.astype(float), sign, gain=p.gain, time_constant=p.time_constant,
                                  on=p.on, off=p.off, min_on_time=p.min_on_time, axis_torque=scale)

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.SpacecraftModel:
        """The compiled model (:class:`tumble.kernels.spacecraft.SpacecraftModel`) under the external ``torque``
        (a :mod:`tumble.torques` model, a callable ``f(t, q, omega)`` or None), control clock at ``t0`` (s)."""
        law = self._torque_law()
        return _kernel.assemble(self.total_inertia, self.rate_inertia, self.control_period or 0.0, float(t0),
                                self._programs, None if law is None or self.route == "none" else self.route,
                                torques.as_torque_model(torque))

    # -- the model interface (tumble.simulate.Model) ---------------------------------------

    attitude_in_state = True  # q = Y[0:4], omega = body_rate: made on the GPU with output="device"

    def state_fields(self) -> tuple[StateField, ...]:
        fields = [
            StateField("omega0", 3, "initial hub rate relative to inertial, rad/s, body axes"),
            StateField("q0", 4, "initial attitude, unit quaternion [w, x, y, z], body → inertial",
                       default=attitude.identity(), quaternion=True),
        ]
        if self.wheels:
            fields.append(StateField("wheel_speeds0", len(self.wheels), "initial wheel speeds relative to the hub, "
                                     "rad/s", default=np.zeros(len(self.wheels))))
        if self.cmgs is not None:
            fields.append(StateField("gimbal_angles0", len(self.cmgs.momentum), "initial CMG gimbal angles, rad",
                                     default=np.zeros(len(self.cmgs.momentum))))
        if self.damper is not None:
            fields.append(StateField("damper_omega0", 3, "initial rate of the damper sphere relative to inertial, "
                                     "rad/s, body axes (default: omega0)", default=lambda values: values["omega0"]))
        if any(isinstance(law, MRPFeedback) and law.Ki is not None for law in self.controller):
            fields.append(StateField("attitude_error_integral0", 3, "initial ∫σ dt of the MRP feedback's "
                                     "integral term, s", default=np.zeros(3)))
        if self.flight_software is not None:
            fields += [
                StateField("q_estimate0", 4, "the flight software's initial attitude estimate, unit quaternion "
                           "[w, x, y, z], body → inertial (default: q0)", default=lambda values: values["q0"],
                           quaternion=True),
                StateField("bias_estimate0", 3, "its initial gyro bias estimate, rad/s, body axes",
                           default=np.zeros(3)),
                StateField("gyro_bias0", 3, "the gyro's true initial bias, rad/s, body axes", default=np.zeros(3)),
                StateField("sensor_seed0", 1, "the seed of the sensors' noise, a whole number in [0, 2**53)",
                           default=np.array([float(self.flight_software.seed)])),
            ]
        if self.flexible_modes is not None:
            m = self.flexible_modes.count
            fields += [StateField("eta0", m, f"initial modal coordinates η ({m}), kg^½·m", default=np.zeros(m)),
                       StateField("eta_rate0", m, f"initial modal rates dη/dt ({m}), kg^½·m/s", default=np.zeros(m))]
        if self.slosh:
            k = 3 * len(self.slosh)
            fields += [StateField("direction0", k, "initial directions of the slosh pendulums' rods from their hinges, "
                                  "body axes, 3 per tank (normalised)"),
                       StateField("rate0", k, "initial angular velocities of the rods relative to the hub, rad/s, "
                                  "body axes, 3 per tank (their components along the rods removed)",
                                  default=np.zeros(k))]
        return tuple(fields)

    def check_run(self, method: integrate.Method, t: np.ndarray, dt: float | None) -> None:
        """A sampled controller needs a fixed-step method (rk4, cf4) whose step divides the control period, each
        law's own period and every output interval, so that steps end on the sample times (where the projection
        updates the held commands). Which methods apply at all is the kernel's to declare (``provides``)."""
        if self.environment is not None:
            self.environment.check_times(t)
        period = self.control_period
        own = [(f"controller[{i}].period", law.period) for i, law in enumerate(self.controller)
               if law.period is not None]
        clocks = ([] if period is None else [("control_period", period)]) + own
        if not clocks:
            return
        if method.adaptive or dt is None:  # dt is None: a method with no step ("exact")
            raise ValidationError(f"method: a sampled controller ({clocks[0][0]} = {clocks[0][1]} s) needs a "
                                  f"fixed-step method ('rk4', 'cf4'), whose steps land on the sample times; got "
                                  f"{method.name!r}")
        for name, clock in clocks:
            ratio = clock / dt
            if abs(ratio - round(ratio)) <= _WHOLE * ratio:
                continue
            if name == "control_period":
                raise ValidationError(f"dt: must divide control_period = {clock} s into whole steps, got dt = {dt} "
                                      f"({ratio:.6g} steps)")
            raise ValidationError(f"{name}: must be a whole number of steps dt = {dt} s (the law's samples fall "
                                  f"on the steps), got {clock} s ({ratio:.6g} steps)")
        if self.flight_software is not None:
            assert period is not None  # the flight software needs a control_period: checked in __post_init__
            for sensor, (sensor_period, _, _) in zip(_fsw_kernel.SENSORS, self.flight_software.clocks(period)):
                ratio = sensor_period / dt
                if sensor_period > 0.0 and (ratio < 1.0 - _WHOLE or abs(ratio - round(ratio)) > _WHOLE * ratio):
                    raise ValidationError(f"dt: must divide the {sensor}'s period {sensor_period} s into whole "
                                          f"steps (its readings fall on the steps), got dt = {dt} ({ratio:.6g} steps)")
        steps = np.diff(t) / dt
        bad = np.abs(steps - np.round(steps)) > _WHOLE * np.maximum(steps, 1.0)
        if bad.any():
            k = int(np.argmax(bad))
            raise ValidationError(f"dt: must divide every output interval into whole steps so that the steps "
                                  f"land on the sample times; t[{k + 1}] − t[{k}] = {t[k + 1] - t[k]} s is "
                                  f"{steps[k]:.6g} steps of {dt} s")

    def step_ends(self, t: np.ndarray, dt: float | None) -> np.ndarray | None:
        """With a flight software whose computation delay ``δ = delay·control_period`` is not a whole number of
        steps ``dt``: the times ``t₀ + k T + δ`` its commands start acting, and with them every sample time
        ``t₀ + k T`` and sensor reading time ``t₀ + m P`` (s), so that steps end on each (between them a step is
        at most ``dt``); else None."""
        fsw, period = self.flight_software, self.control_period
        if fsw is None or period is None or dt is None:
            return None
        lag = fsw.delay * period
        ratio = lag / dt
        if abs(ratio - round(ratio)) <= _WHOLE * max(ratio, 1.0):
            return None
        t0, span = float(t[0]), float(t[-1] - t[0])
        samples = t0 + np.arange(math.floor(span / period) + 1) * period
        ends = [samples, samples + lag]
        for clock in fsw.clocks(period)[:, 0]:
            if clock > 0.0:
                ends.append(t0 + np.arange(math.floor(span / clock) + 1) * clock)
        return np.concatenate(ends)

    def initial_states(self, kernel: Any, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        n = values["omega0"].shape[0]
        y0 = np.zeros((n, kernel.size))
        y0[:, :4] = values["q0"]
        y0[:, 4:7] = values["omega0"]
        where: Callable[[str], Any] = functools.partial(_kernel.slices, kernel)  # each part asked for is there
        if self.wheels:
            w = where("wheels")
            axes = np.array([x.axis for x in self.wheels])
            spin = np.array([x.inertia for x in self.wheels])
            y0[:, w.s + _wheels.MOMENTUM:w.s + _wheels.MOMENTUM + w.n] = spin * (
                values["omega0"] @ axes.T + values["wheel_speeds0"])
        if self.cmgs is not None:
            c = where("cmgs")
            y0[:, c.s:c.s + c.n] = values["gimbal_angles0"]
        if self.damper is not None:
            s = where("damper").s + _damper_kernel.RATE
            y0[:, s:s + 3] = values["damper_omega0"]
        if "attitude_error_integral0" in values:
            s = where("mrp_integral").s + _law_kernels.INTEGRAL
            y0[:, s:s + 3] = values["attitude_error_integral0"]
        if self.flexible_modes is not None:
            f = where("flexible_modes")
            state = _flexible_modes.state_slices(f.n, f.s)
            y0[:, state["modal_coordinate"]] = values["eta0"]
            y0[:, state["modal_rate"]] = values["eta_rate0"]
        if self.slosh:
            rods = _slosh.state_slices(len(self.slosh), where("slosh").s)
            s0, nu0 = initial_rods(values["direction0"], values["rate0"], len(self.slosh))
            y0[:, rods["pendulum_direction"]], y0[:, rods["pendulum_rate"]] = s0, nu0
        if self.flight_software is not None:
            check_seed(values["sensor_seed0"], "sensor_seed0")
            _fsw_initial_state(self.flight_software, values, y0, where("flight_software").s, float(t0))
        for y in y0:
            _kernel.initialise(kernel, float(t0), y)
        return y0

    def outputs(self, kernel: Any, t: np.ndarray, states: np.ndarray) -> Outputs:
        n_t, n_b, _ = states.shape
        aux = np.empty((n_b, n_t, kernel.aux_size))
        for b in range(n_b):
            _kernel.evaluate(kernel, t, np.ascontiguousarray(states[:, b]), aux[b])
        aux = aux.transpose(1, 0, 2)
        q, omega = states[..., 0:4], states[..., 4:7]
        extras = {}

        def add(name, data, dims, units, description):
            extras[name] = Extra(data=data, dims=dims, units=units, description=description)

        def core(offset, size=3):
            return aux[..., offset:offset + size]

        def where(kind: str) -> _kernel.Slices:
            """Where the part of ``kind``, one the spacecraft has, is in the kernel."""
            found = _kernel.slices(kernel, kind)
            assert found is not None, kind
            return found

        if self.wheels:
            w = where("wheels")
            state, diag = _wheels.state_slices(w.n, w.s), _wheels.aux_slices(w.n, w.a)
            add("wheel_speed", aux[..., diag["wheel_speed"]], ("wheel",), "rad/s", "wheel speed relative to the hub")
            add("wheel_momentum", states[..., state["wheel_momentum"]], ("wheel",), "N m s",
                "absolute angular momentum of each wheel about its axis")
            add("wheel_torque", aux[..., diag["wheel_torque"]], ("wheel",), "N m",
                "motor torque on each wheel (after the torque and speed limits)")
            saturated = aux[..., diag["wheel_saturated"]]
            add("wheel_saturated", saturated, ("wheel",), "1", "1 where the wheel is at its speed limit")
            add("wheel_work", states[..., state["wheel_work"]][..., 0], (), "J",
                "work done on the wheels by motors and bearings")
            if saturated.any():
                wheels = sorted(set(np.nonzero(saturated)[-1].tolist()))
                first = t[np.nonzero(saturated.reshape(n_t, -1).any(axis=1))[0][0]]
                warnings.warn(f"reaction wheel(s) {wheels} reached the speed limit (first at t = {first:g} s): the "
                              "commanded torque was not delivered; see extras['wheel_saturated']",
                              SaturationWarning, stacklevel=_STACKLEVEL)
        if self.cmgs is not None:
            c = where("cmgs")
            state, diag = _cmgs.state_slices(c.n, c.s), _cmgs.aux_slices(c.n, c.a)
            add("gimbal_angle", states[..., state["gimbal_angle"]], ("gyro",), "rad", "CMG gimbal angles")
            add("gimbal_rate", aux[..., diag["gimbal_rate"]], ("gyro",), "rad/s", "CMG gimbal rates")
            measure = aux[..., diag["singularity"]][..., 0]
            add("singularity", measure, (), "1",
                "CMG singularity measure sqrt(det(A A^T))/h^3 (0 at a singular configuration)")
            if (measure < SINGULAR_MEASURE).any():
                first = t[np.nonzero((measure < SINGULAR_MEASURE).reshape(n_t, -1).any(axis=1))[0][0]]
                steering = ("the generalised SR inverse steers out of it" if self.cmgs.dither > 0.0 else
                            "the SR inverse cannot leave it along the singular direction; "
                            "CMGCluster.generalised() can")
                warnings.warn(f"the CMG cluster was within {SINGULAR_MEASURE:g} of a singular configuration (first "
                              f"at t = {first:g} s; extras['singularity']): {steering}", SingularityWarning,
                              stacklevel=_STACKLEVEL)
        if self.thrusters:
            th = where("thrusters")
            state = _thrusters.state_slices(th.n, th.s)
            table = kernel.data[th.p + _thrusters.HEAD:th.p + _thrusters.HEAD + th.n * _thrusters.STRIDE].reshape(
                th.n, _thrusters.STRIDE)
            out = states[..., state["pwpf_output"]]
            firing = out[..., table[:, _thrusters.AXIS].astype(int)] == table[:, _thrusters.SIGN]
            add("thruster_firing", firing.astype(float), ("thruster",), "1", "1 while the thruster fires")
            add("pwpf_filter", states[..., state["pwpf_filter"]], ("xyz",), "1", "PWPF filter outputs of the axes")
        if self._torque_law() is not None:
            add("torque_command", core(_kernel.AUX_TORQUE_COMMAND), ("xyz",), "N m",
                "controller torque command, body axes (the held value when the torque law is sampled)")
        if self.magnetorquers is not None:
            m = where("magnetorquers")
            add("dipole_command", core(_kernel.AUX_DIPOLE_COMMAND), ("xyz",), "A m2",
                "controller dipole command before the magnetorquer limits, body axes")
            add("dipole", aux[..., _magnetorquers.aux_slices(m.n, m.a)["dipole"]], ("xyz",), "A m2",
                "magnetorquer dipole (after limits), body axes")
        if self.residual_dipole is not None:
            r = where("residual_dipole")
            add("residual_dipole_torque", aux[..., _residual_dipole.aux_slices(r.n, r.a)["residual_dipole_torque"]],
                ("xyz",), "N m", "torque of the residual dipole m × B, body axes")
        for part, module, name, what in ((self.solar_pressure, _solar_pressure, "solar_pressure_torque",
                                          "solar radiation pressure torque on the facets"),
                                         (self.drag, _drag, "drag_torque", "aerodynamic torque on the facets")):
            if part is not None:
                w = where(name.removesuffix("_torque"))
                add(name, aux[..., module.aux_slices(w.n, w.a)[name]], ("xyz",), "N m", f"{what}, body axes")
        if self._has_field:
            add("magnetic_field", core(_kernel.AUX_FIELD), ("xyz",), "T", "magnetic field, body axes")
        if self.gravity_gradient:
            add("gravity_gradient_torque", core(_kernel.AUX_GRAVITY), ("xyz",), "N m",
                "gravity-gradient torque, body axes")
        if kernel.torque_codes.size:
            add("external_torque", core(_kernel.AUX_EXTERNAL), ("xyz",), "N m",
                "external torque of the torque argument, body axes")
        if self.damper is not None:
            d = where("damper")
            add("damper_omega", states[..., _damper_kernel.state_slices(d.n, d.s)["damper_omega"]], ("body_axis",),
                "rad/s", "angular velocity of the damper sphere relative to inertial, body axes")
        integral = _kernel.slices(kernel, "mrp_integral")
        if integral is not None:
            add("attitude_error_integral",
                states[..., _law_kernels.integral_slices(integral.n, integral.s)["attitude_error_integral"]], ("xyz",),
                "s", "integral of the MRP attitude error of the MRP feedback's integral term")
        if self.flexible_modes is not None:
            f = where("flexible_modes")
            state = _flexible_modes.state_slices(f.n, f.s)
            add("modal_coordinate", states[..., state["modal_coordinate"]], ("mode",), "kg^(1/2) m",
                "modal coordinate eta_k of the appendages (mass-normalised)")
            add("modal_rate", states[..., state["modal_rate"]], ("mode",), "kg^(1/2) m/s", "modal rate deta_k/dt")
        if self.slosh:
            rods = _slosh.state_slices(len(self.slosh), where("slosh").s)
            add("pendulum_direction", states[..., rods["pendulum_direction"]], ("tank", "body_axis"), "1",
                "unit direction of each tank's slosh pendulum from its hinge, body axes")
            add("pendulum_rate", states[..., rods["pendulum_rate"]], ("tank", "body_axis"), "rad/s",
                "angular velocity of each slosh pendulum relative to the hub, body axes")
        if self.flight_software is not None:
            s = where("flight_software").s
            self._estimation_outputs(add, states[..., s:s + _fsw_kernel.STATE], q)
        add("actuator_torque", core(_kernel.AUX_ACTUATOR), ("xyz",), "N m",
            "torque of all parts on the hub, body axes (wheels, gyros, thrusters, magnetorquers, damper, "
            "residual dipole, solar pressure, drag, flexible modes, slosh)")
        momentum_body = core(_kernel.AUX_MOMENTUM)
        energy = core(_kernel.AUX_ENERGY, 1)[..., 0]
        add("total_momentum_inertial", attitude.rotate(q, momentum_body), ("xyz",), "N m s",
            "total angular momentum (hub, wheels, gyro rotors, damper, appendages, slosh), inertial axes")
        add("total_energy", energy, (), "J",
            "kinetic energy of hub, wheels, damper and slosh masses, and the appendages' kinetic and strain energy "
            "(gyro rotors' constant spin energy excluded)")
        info = {} if self.control_period is None else {"control_period": self.control_period}
        return Outputs(q=q, omega=omega, inertia=self.total_inertia, extras=extras,
                       totals={"energy": energy, "momentum_body": momentum_body}, info=info)

    def _estimation_outputs(self, add, fsw: np.ndarray, q: np.ndarray) -> None:
        """The flight software's named outputs from its state slices ``fsw`` (…, STATE) and the true ``q``:
        estimates, knowledge error ``log(q* ⊗ q̂)`` (estimate − truth) with the filter's 3σ, control error
        ``log(q* ⊗ q_c)`` (target − truth), rad, body axes."""
        k = _fsw_kernel
        q_estimate = fsw[..., k.Q_EST:k.Q_EST + 4]
        covariance = fsw[..., k.COVARIANCE:k.COVARIANCE + 36].reshape(*fsw.shape[:-1], 6, 6)
        sigma = np.sqrt(np.diagonal(covariance, axis1=-2, axis2=-1))
        add("q_estimate", q_estimate, ("quaternion",), "1",
            "the flight software's attitude estimate [w, x, y, z], body → inertial, at the last sample")
        add("covariance", covariance, ("error_state", "error_state_column"), "1",
            "the filter's covariance of [δθ, δβ] predicted to the sample, body axes: blocks in rad², rad²/s, "
            "rad²/s²")
        add("bias_estimate", fsw[..., k.BIAS_EST:k.BIAS_EST + 3], ("xyz",), "rad/s", "gyro bias estimate, body axes")
        add("omega_estimate", fsw[..., k.OMEGA_EST:k.OMEGA_EST + 3], ("xyz",), "rad/s",
            "the rate the control law read: gyro rate less the bias estimate, body axes")
        add("gyro_bias", fsw[..., k.GYRO_BIAS:k.GYRO_BIAS + 3], ("xyz",), "rad/s", "the gyro's true bias, body axes")
        used = fsw[..., k.USED:k.USED + len(k.SENSORS)]
        add("sensor_time", np.where(used > k.NEVER, used, np.nan), ("sensor",), "s",
            "the time of each sensor's newest reading the flight software used (gyro, star tracker, Sun sensor, "
            "magnetometer, coarse Sun sensor; NaN: none yet, or no such sensor)")
        add("knowledge_error", attitude.to_rotvec(attitude.multiply(attitude.conjugate(q), q_estimate)), ("xyz",),
            "rad", "estimate − truth: rotation vector of q* ⊗ q_estimate, body axes")
        add("knowledge_error_3sigma", 3.0 * sigma[..., :3], ("xyz",), "rad",
            "the filter's 3σ bound of the attitude error, body axes")
        add("bias_error_3sigma", 3.0 * sigma[..., 3:], ("xyz",), "rad/s", "the filter's 3σ bound of the bias error")
        target = getattr(self._torque_law(), "target", None)
        if target is not None:
            add("control_error", attitude.to_rotvec(attitude.multiply(attitude.conjugate(q), target)), ("xyz",),
                "rad", "target − truth: rotation vector of q* ⊗ q_target, body axes")

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """Without external torque (no ``torque=``, gravity gradient, thrusters, magnetorquers, residual
        dipole, solar pressure or drag): the inertial angular momentum of the whole spacecraft; and, without
        CMGs (whose ideal gimbal servos do work), a damper, damped flexible modes or damped slosh (which
        dissipate), its
        energy less the work done on the wheels by motors and bearings."""
        if (traj.info.get("torque") != "none" or self.gravity_gradient or self.thrusters
                or self.magnetorquers is not None or self.residual_dipole is not None
                or self.solar_pressure is not None or self.drag is not None):
            return {}
        out = {"momentum_inertial": traj.momentum_inertial}
        damped = (self.flexible_modes is not None and bool(np.any(self.flexible_modes.damping))) or any(
            tank.damping > 0.0 for tank in self.slosh)
        if self.cmgs is None and self.damper is None and not damped:
            if self.wheels:
                out["energy_minus_wheel_work"] = traj.energy - traj.wheel_work
            else:
                out["energy"] = traj.energy
        return out


def _seconds(period: float | None) -> str:
    return "continuous" if period is None else f"{period} s"


def _check_type(value, cls, name):
    if value is not None and not isinstance(value, cls):
        raise ValidationError(f"{name}: must be a {cls.__name__} or None, got {type(value).__name__}")


def _check_items(values, cls, name):
    for i, value in enumerate(values):
        if not isinstance(value, cls):
            raise ValidationError(f"{name}[{i}]: must be a {cls.__name__}, got {type(value).__name__}")
