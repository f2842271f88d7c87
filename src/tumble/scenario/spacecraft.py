"""Scenario kind ``"spacecraft"``: a controlled spacecraft (:class:`tumble.spacecraft.Spacecraft`).

A file with a ``[spacecraft]`` table (SI units, body axes; angles of the
orbit in degrees)::

    name = "Slew with four wheels"

    [spacecraft]
    inertia = [[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]]   # total, wheels included
    # or a [spacecraft.hub] table (inertia or moments, mass, com): the hub WITHOUT the wheels,
    # each wheel then with mass, position and transverse_inertia (Spacecraft(hub=...))

    [spacecraft.wheel_pyramid]          # or [[spacecraft.wheels]] tables: axis, inertia, ...
    inertia = 0.02
    max_torque = 0.1

    [[spacecraft.controller]]
    kind = "quaternion_pd"
    natural_frequency = 0.1
    target_euler = { seq = "ZYX", angles = [60.0, 0.0, 0.0] }

    [initial]
    omega = [0.0, 0.0, 0.0]

    [time]
    stop = 200.0
    step = 1.0

    [solver]
    method = "rk4"
    dt = 0.1

The tables and keys are the arguments of :class:`tumble.spacecraft.Spacecraft`
and of its parts (``docs/spacecraft.md`` lists them): actuators, a nutation
damper (``[spacecraft.damper]``, :mod:`tumble.scenario.damper`), environment
(``[spacecraft.magnetic_field]``, ``[spacecraft.residual_dipole]``,
``gravity_gradient``, and the environment sampled along an orbit with its
facet parts: ``[spacecraft.environment]``, ``[spacecraft.solar_pressure]``,
``[spacecraft.drag]``, :mod:`tumble.scenario.environment`), flexible appendages
(``[spacecraft.flexible_modes]``: ``participation`` (m × 3, kg^½ m), ``frequency`` (m, rad/s),
``damping`` (m, ζ; default 0); initial ``eta`` and ``eta_rate``), fuel slosh (``[[spacecraft.slosh]]``, one
table per tank: ``reduced_mass`` (kg), ``length`` (m), ``hinge`` (m, body axes), ``damping`` (1/s; default 0);
initial ``direction`` and ``rate``, 3 per tank), the ``[[spacecraft.controller]]`` laws
(:mod:`tumble.scenario.control`) and the flight software that feeds them an estimate
(``[spacecraft.flight_software]``).
``[initial]``, ``[time]``, ``[solver]``, ``[spacecraft.orbit]`` and the
external torques ``[[torque]]`` (``torque=`` of :func:`tumble.simulate`, on
top of the spacecraft's own environment) are the shared tables
(:mod:`tumble.scenario.tables`, :mod:`tumble.scenario.orbit`,
:mod:`tumble.scenario.torques`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Any, Literal, Protocol, cast

import numpy as np
from pydantic import Field, field_validator, model_validator

from tumble import attitude
from tumble.rigid_body import RigidBody
from tumble.scenario._base import Scenario
from tumble.scenario._errors import ScenarioError, in_file, keyed
from tumble.scenario._run import RUN_KEYS, Run
from tumble.scenario._values import (_Bool, _InertiaOrMoments, _Limit, _Matrix, _Number, _Positive, _Table,
                                     _Quaternion, _Vector)
from tumble.scenario.control import Controller, Regulator
from tumble.scenario.damper import SphericalDamperTable
from tumble.scenario.environment import DragTable, EnvironmentTable, SolarPressureTable
from tumble.scenario.orbit import OrbitTable
from tumble.scenario.tables import Initial, Solver, Time
from tumble.scenario.torques import GravityGradientTorque, Torque, build_torque
from tumble.spacecraft import actuators
from tumble.spacecraft.environment import DipoleField, ResidualDipole
from tumble.spacecraft.flexible_modes import FlexibleModes
from tumble.spacecraft.flight_software import FlightSoftware, Sampling
from tumble.spacecraft.model import Spacecraft
from tumble.spacecraft.slosh import SloshPendulum
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["SpacecraftScenario"]

_MAGIC_SKEW = math.degrees(math.atan(math.sqrt(2.0)))  # deg: the pyramid whose four axes are equally spaced


class _WheelProperties(_Table):
    """The keys of a reaction wheel (:class:`tumble.spacecraft.ReactionWheel`) but its axis: spin inertia
    (kg m²), torque and speed limits (N m, rad/s), friction, and the rotor's mass properties."""

    inertia: _Positive
    max_torque: _Limit = math.inf
    max_speed: _Limit = math.inf
    viscous: _Number = 0.0
    coulomb: _Number = 0.0
    coulomb_speed: _Positive = 1.0
    mass: _Positive | None = None
    position: _Vector | None = None
    transverse_inertia: _Positive | None = None


class Wheel(_WheelProperties):
    axis: _Vector

    def build(self) -> actuators.ReactionWheel:
        return actuators.ReactionWheel(**self.model_dump())


class WheelPyramid(_WheelProperties):
    """Four identical wheels in a pyramid (:func:`tumble.spacecraft.pyramid_wheels`); ``mass``,
    ``position`` and ``transverse_inertia``, as every other key, apply to each of the four."""

    skew: _Positive = _MAGIC_SKEW

    def build(self) -> list[actuators.ReactionWheel]:
        return actuators.pyramid_wheels(**self.model_dump())


class HubTable(_InertiaOrMoments):
    """``[spacecraft.hub]``: the hub **without** its wheels (``Spacecraft(hub=RigidBody(...))``):
    ``inertia`` (3×3, kg m², about the hub's centre of mass, body axes) or ``moments`` (its diagonal),
    ``mass`` (kg) and ``com`` (m, body axes; default the origin)."""

    inertia: _Matrix | None = None
    moments: _Vector | None = None
    mass: _Positive
    com: _Vector | None = None

    @model_validator(mode="after")
    def _one_description(self):
        if (self.inertia is None) == (self.moments is None):
            raise ValueError("give exactly one of inertia or moments")
        return self

    def build(self) -> RigidBody:
        inertia = self.inertia if self.moments is None else np.diag(self.moments)  # exactly one is given
        return RigidBody(cast(Any, inertia), mass=self.mass, com=self.com)


class CMGPyramid(_Table):
    """Four CMGs in a pyramid (:meth:`tumble.spacecraft.CMGCluster.pyramid`), steered by the
    singularity-robust inverse (``steering = "singularity_robust"``, the default) or by the generalised one
    (``steering = "generalised"``: :meth:`~tumble.spacecraft.CMGCluster.generalised`, whose dither ``dither``
    ε₀, ``dither_frequency`` ω_ε (rad/s) and ``dither_phases`` φ (rad) default to Wie's 0.01, π/2, (0, π/2, π))."""

    momentum: _Positive
    skew: _Positive = _MAGIC_SKEW
    max_gimbal_rate: _Positive = 1.0
    robust_gain: _Number = 0.01
    robust_decay: _Number = 10.0
    steering: Literal["singularity_robust", "generalised"] = "singularity_robust"
    dither: _Number | None = None
    dither_frequency: _Number | None = None
    dither_phases: _Vector | None = None

    @field_validator("dither", "dither_frequency", "dither_phases")
    @classmethod
    def _generalised_only(cls, value, info):
        if value is not None and info.data.get("steering") == "singularity_robust":
            raise ValueError('only with steering = "generalised" (the dither of the generalised SR inverse)')
        return value

    def build(self) -> actuators.CMGCluster:
        dither = {"dither", "dither_frequency", "dither_phases"}
        cluster = actuators.CMGCluster.pyramid(**self.model_dump(exclude={"steering", *dither}))
        if self.steering == "singularity_robust":
            return cluster
        return cluster.generalised(**self.model_dump(include=dither, exclude_none=True))


class ThrusterTable(_Table):
    position: _Vector
    direction: _Vector
    force: _Positive

    def build(self) -> actuators.Thruster:
        return actuators.Thruster(**self.model_dump())


class PWPFTable(_Table):
    gain: _Positive = 4.5
    time_constant: _Positive = 0.85
    on: _Positive = 0.45
    off: _Number = 0.15
    min_on_time: _Number = 0.0

    def build(self) -> actuators.PWPF:
        return actuators.PWPF(**self.model_dump())


class MagnetorquerTable(_Table):
    max_dipole: _Positive

    def build(self) -> actuators.Magnetorquers:
        return actuators.Magnetorquers(cast(Any, self.max_dipole))  # a number or (3,): converted there


class ResidualDipoleTable(_Table):
    """``dipole = [mx, my, mz]``: a constant body dipole, A·m² (torque m × B in the magnetic field)."""

    dipole: _Vector

    def build(self) -> ResidualDipole:
        return ResidualDipole(np.array(self.dipole))


class FlexibleModesTable(_Table):
    """``[spacecraft.flexible_modes]``: cantilever modes of the appendages
    (:class:`tumble.spacecraft.FlexibleModes`), one entry per mode: ``participation`` δ_k (kg^½ m, body axes), ``frequency`` Ω_k (rad/s), ``damping`` ζ_k
    (default 0)."""

    participation: Annotated[list[_Vector], Field(min_length=1)]
    frequency: list[_Number]
    damping: list[_Number] | None = None

    def build(self) -> FlexibleModes:
        return FlexibleModes(np.array(self.participation), np.array(self.frequency),
                             None if self.damping is None else np.array(self.damping))


class SloshTable(_Table):
    """``[[spacecraft.slosh]]``: the slosh pendulum of one tank (:class:`tumble.spacecraft.SloshPendulum`):
    ``reduced_mass`` μ (kg), ``length`` l (m), ``hinge`` b (m, body axes), ``damping`` d (1/s; default 0)."""

    reduced_mass: _Positive
    length: _Positive
    hinge: _Vector
    damping: _Number = 0.0

    def build(self) -> SloshPendulum:
        return SloshPendulum(**self.model_dump())


class SamplingTable(_Table):
    """A sensor's sampling (:class:`tumble.spacecraft.Sampling`): ``period`` (s; default the control period),
    ``latency`` (s) and ``stream`` (its noise stream's number)."""

    period: _Positive | None = None
    latency: _Number = 0.0
    stream: Annotated[int, Field(strict=True)] | None = None

    def build(self) -> Sampling:
        return Sampling(**self.model_dump())


class FlightSoftwareTable(_Table):
    """``[spacecraft.flight_software]``: a gyro (``gyro_arw``, rad/√s; ``gyro_rrw``, rad/s^1.5) and attitude
    sensors — a star tracker (``star_tracker_sigma``, rad: a number or 3), a fine Sun sensor
    (``sun_sensor_sigma``, rad), a magnetometer (``magnetometer_sigma``, rad), six coarse Sun sensor heads
    (``coarse_sun_sensor_sigma``; the Sun: ``sun_direction``, inertial, or the environment's) —
    each sampled as its ``*_sampling`` table says (``period``, ``latency``, ``stream``), read through the MEKF
    at ``control_period``, the law fed the estimate; ``delay`` (in control periods, in [0, 1]), ``sensor_noise``, ``seed``, and
    the filter's initial ``attitude_sigma0`` (rad) and ``bias_sigma0`` (rad/s)."""

    gyro_arw: _Number
    gyro_rrw: _Number
    star_tracker_sigma: _Positive | _Vector | None = None
    sun_sensor_sigma: _Positive | None = None
    sun_direction: _Vector | None = None
    magnetometer_sigma: _Positive | None = None
    coarse_sun_sensor_sigma: _Positive | None = None
    gyro_sampling: SamplingTable = SamplingTable()
    star_tracker_sampling: SamplingTable = SamplingTable()
    sun_sensor_sampling: SamplingTable = SamplingTable()
    magnetometer_sampling: SamplingTable = SamplingTable()
    coarse_sun_sensor_sampling: SamplingTable = SamplingTable()
    attitude_sigma0: _Positive = 1e-2
    bias_sigma0: _Positive = 1e-4
    delay: _Number = 1.0
    sensor_noise: _Bool = True
    seed: Annotated[int, Field(strict=True)] = 0

    def build(self) -> FlightSoftware:
        values: dict[str, Any] = {name: np.array(value) if isinstance(value, list) else
                                  value.build() if isinstance(value, SamplingTable) else value
                                  for name, value in self}
        return FlightSoftware(**values)


class FieldTable(_Table):
    """``model = "dipole"`` (tilted dipole, IGRF-13 2020) or ``uniform = [Bx, By, Bz]`` (T, inertial)."""

    model: Literal["dipole"] | None = None
    uniform: _Vector | None = None

    @model_validator(mode="after")
    def _one_field(self):
        if (self.model is None) == (self.uniform is None):
            raise ValueError("give exactly one of model = \"dipole\" or uniform")
        return self

    def build(self) -> DipoleField | np.ndarray:
        return DipoleField() if self.model == "dipole" else np.array(self.uniform)


class _Buildable(Protocol):
    """A table that builds a library object (``build``) and maps its arguments to keys (``argument_keys``)."""

    def argument_keys(self, prefix: str) -> dict[str, str]: ...

    def build(self) -> Any: ...


def _built(table: _Buildable, key: str):
    """``table.build()``, a refusal by the library reported against the key behind the argument."""
    with keyed(table.argument_keys(key), key):
        return table.build()


class SpacecraftTable(_InertiaOrMoments):
    """``[spacecraft]``: mass properties (``inertia`` or ``moments``: the total, wheels included; or a
    ``hub`` table: the hub without the wheels and the damper sphere, the wheels then needing mass properties),
    actuators, a nutation ``damper``, environment and controllers."""

    inertia: _Matrix | None = None
    moments: _Vector | None = None
    hub: HubTable | None = None
    wheels: list[Wheel] = []
    wheel_pyramid: WheelPyramid | None = None
    cmgs: CMGPyramid | None = None
    thrusters: list[ThrusterTable] = []
    pwpf: PWPFTable = PWPFTable()
    magnetorquers: MagnetorquerTable | None = None
    damper: SphericalDamperTable | None = None
    orbit: OrbitTable | None = None
    magnetic_field: FieldTable | None = None
    gravity_gradient: _Bool = False
    residual_dipole: ResidualDipoleTable | None = None
    environment: EnvironmentTable | None = None
    solar_pressure: SolarPressureTable | None = None
    drag: DragTable | None = None
    controller: list[Controller] = []
    control_period: _Positive | None = None
    flight_software: FlightSoftwareTable | None = None
    flexible_modes: FlexibleModesTable | None = None
    slosh: list[SloshTable] = []

    @model_validator(mode="after")
    def _one_description(self):
        given = [key for key in ("inertia", "moments", "hub") if getattr(self, key) is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of inertia, moments (the total, wheels included) or hub (a "
                             "[spacecraft.hub] table: the hub without the wheels)"
                             + (f"; got {' and '.join(given)}" if given else ""))
        if self.wheels and self.wheel_pyramid is not None:
            raise ValueError("give wheels or wheel_pyramid, not both")
        return self

    def build(self) -> Spacecraft:
        """The :class:`~tumble.spacecraft.Spacecraft`; a refusal is reported against its key."""
        parts: dict[str, Any] = {  # the keyword arguments of Spacecraft
            key: [_built(entry, f"spacecraft.{key}[{i}]") for i, entry in enumerate(getattr(self, key))]
            for key in ("wheels", "thrusters", "controller", "slosh")}
        for key in ("hub", "wheel_pyramid", "cmgs", "pwpf", "magnetorquers", "damper", "orbit", "magnetic_field",
                    "residual_dipole", "environment", "solar_pressure", "drag", "flight_software", "flexible_modes"):
            entry = getattr(self, key)
            parts[key] = None if entry is None else _built(entry, f"spacecraft.{key}")
        pyramid = parts.pop("wheel_pyramid")
        if pyramid is not None:
            parts["wheels"] = pyramid
        if self.hub is not None:
            self._check_wheel_mass_properties()
        inertia = self.inertia if self.inertia is not None else None if self.moments is None else np.diag(self.moments)
        with keyed(self.argument_keys("spacecraft"), "spacecraft"):
            return Spacecraft(inertia=inertia, gravity_gradient=self.gravity_gradient,
                              control_period=self.control_period, **parts)

    def _check_wheel_mass_properties(self):
        """With a ``hub``, every wheel needs ``mass``, ``position`` and ``transverse_inertia`` (the rule of
        :meth:`tumble.spacecraft.ReactionWheel.part`, reported here against each wheel's key)."""
        tables = ([("spacecraft.wheel_pyramid", self.wheel_pyramid)] if self.wheel_pyramid is not None
                  else [(f"spacecraft.wheels[{i}]", wheel) for i, wheel in enumerate(self.wheels)])
        rule = ("missing required key: with a [spacecraft.hub] (the hub without its wheels) every wheel needs "
                "mass, position and transverse_inertia")
        problems = [(f"{where}.mass", rule) for where, wheel in tables if wheel.mass is None]
        if problems:
            raise ScenarioError("", problems)


class SpacecraftInitial(Initial):
    """``[initial]``: ``omega``, ``q`` or ``euler`` as in every kind, plus ``wheel_speeds`` (rad/s, relative
    to the hub), ``gimbal_angles`` (rad), ``damper_omega`` (the damper sphere's rate relative to inertial,
    rad/s, body axes; default ``omega``) and ``attitude_error_integral`` (∫σ dt of the MRP feedback's
    integral term, s; default 0); with flight software ``q_estimate`` (default ``q``), ``bias_estimate`` and
    ``gyro_bias`` (rad/s, body axes; default 0) and ``sensor_seed`` (its noise seed; default its ``seed``); with
    flexible modes ``eta`` (kg^½ m) and ``eta_rate`` (kg^½ m/s), one per mode (default 0); with slosh
    ``direction`` (the rods' directions, body axes) and ``rate`` (their rates relative to the hub, rad/s;
    default 0), 3 per tank, tank by tank. A key the spacecraft
    has no state for is refused by :func:`tumble.simulate`."""

    wheel_speeds: list[_Number] | None = None
    gimbal_angles: list[_Number] | None = None
    damper_omega: _Vector | None = None
    attitude_error_integral: _Vector | None = None
    q_estimate: _Quaternion | None = None
    bias_estimate: _Vector | None = None
    gyro_bias: _Vector | None = None
    sensor_seed: Annotated[int, Field(strict=True, ge=0)] | None = None
    eta: list[_Number] | None = None
    eta_rate: list[_Number] | None = None
    direction: list[_Number] | None = None
    rate: list[_Number] | None = None


class SpacecraftSolver(Solver):
    """``[solver]``: ``rk4`` (``dt``; the default), ``cf4`` (``dt``) or ``dop853`` (``rtol``, ``atol``;
    continuous control only)."""

    method: Annotated[str, Field(strict=True)] = "rk4"


class SpacecraftScenario(Scenario):
    """A validated spacecraft scenario (``kind = "spacecraft"``, or any file with a ``[spacecraft]`` table):
    the spacecraft, its initial state, times, solver and the external torques ``[[torque]]`` on it
    (:mod:`tumble.scenario.torques`: ``torque=`` of :func:`tumble.simulate`, on top of its own environment)."""

    spacecraft: SpacecraftTable
    initial: SpacecraftInitial
    time: Time
    solver: SpacecraftSolver = SpacecraftSolver(dt=0.1)
    torque: list[Torque] = []

    def build(self) -> Run:
        """Build the spacecraft, its initial state and external torque; a refusal by the library names the key."""
        with in_file(self.source):
            craft = self.spacecraft.build()
            self._check_gravity_gradient_once()
            torque = build_torque(self.torque, craft.body)
            # a law's period the run refuses (a step that does not divide it) is reported against its table
            keys = {**self.initial.argument_keys("initial"), **RUN_KEYS, "controller": "spacecraft.controller"}
            with keyed(keys, "initial"):
                initial = self.initial.state()
            return Run(craft, initial, self.time.times(), self.solver.method, self.solver.options(), torque, keys,
                       self.source)

    def _check_gravity_gradient_once(self):
        """``spacecraft.gravity_gradient = true`` and a ``gravity_gradient`` ``[[torque]]`` would count the
        torque twice."""
        if self.spacecraft.gravity_gradient:
            twice = [(f"torque[{i}].kind", "the gravity gradient is already on: spacecraft.gravity_gradient = "
                                           "true (give one of the two)")
                     for i, entry in enumerate(self.torque) if isinstance(entry, GravityGradientTorque)]
            if twice:
                raise ScenarioError("", twice)

    def target(self) -> np.ndarray | None:
        """The attitude commanded by the scenario's regulator (quaternion PD or MRP feedback), if it has one."""
        for law in self.spacecraft.controller:
            if isinstance(law, Regulator):
                return law.target_quaternion()
        return None

    def figure(self, traj: Trajectory) -> Figure:
        """:func:`tumble.viz.spacecraft.spacecraft_figure` of a run of this scenario, titled with its name."""
        from tumble.viz.spacecraft import spacecraft_figure

        return spacecraft_figure(traj, target=self.target(), title=self.name)

    def rows(self, traj: Trajectory) -> list[tuple[str, str]]:
        """Final rate and angle to the target, wheels (peak speed, saturation), change of the total momentum
        (hub + actuators)."""
        assert traj.q is not None and traj.omega is not None  # the hub's attitude and rate
        rows = [("rate", f"final |omega| {np.linalg.norm(traj.omega[-1]):.3g} rad/s")]
        target = self.target()
        if target is not None:
            angle = np.degrees(attitude.relative_angle(traj.q[-1], attitude.normalize(target)))
            rows.append(("target", f"final angle to the target {angle:.3g} deg"))
        if "wheel_speed" in traj.extras:
            speed = np.abs(traj.extras["wheel_speed"].data)
            saturated = "wheel_saturated" in traj.extras and bool(np.any(traj.extras["wheel_saturated"].data > 0))
            rows.append(("wheels", f"peak speed {speed.max():.4g} rad/s" + (", SATURATED" if saturated else "")))
        if "total_momentum_inertial" in traj.extras:
            h = traj.extras["total_momentum_inertial"].data
            change = np.linalg.norm(h - h[0], axis=-1).max()
            rows.append(("momentum", f"total (hub + actuators), inertial: largest change {change:.3g} N m s"))
        return rows
