"""Spacecraft scenario files: a controlled spacecraft described as data, in TOML.

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
and of its parts (``docs/spacecraft.md`` lists them). Validation reuses
the rules and messages of :mod:`tumble.scenario`: unknown keys are refused,
and every problem is a :class:`tumble.scenario.ScenarioError` naming the
file, the key and the rule.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Literal, Union

import numpy as np
import pydantic
from pydantic import Field, PrivateAttr, field_validator

from tumble.body import RigidBody
from tumble.scenario import (EulerAngles, Initial, ScenarioError, Solver, Time, _blame, _Bool, _describe, _Matrix,
                             _Number, _Positive, _Quaternion, _Table, _toml_problem, _Vector)
from tumble.spacecraft import actuators, control
from tumble.spacecraft.environment import DipoleField
from tumble.spacecraft.model import METHODS, Spacecraft, simulate
from tumble.spacecraft.orbit import Orbit
from tumble.trajectory import Trajectory

__all__ = ["SpacecraftScenario", "load_spacecraft_scenario", "parse_spacecraft_scenario", "run_spacecraft_scenario"]

_Limit = Annotated[float, Field(strict=True, gt=0.0)]  # inf allowed: TOML's inf means "no limit"


class Wheel(_Table):
    axis: _Vector
    inertia: _Positive
    max_torque: _Limit = math.inf
    max_speed: _Limit = math.inf
    viscous: _Number = 0.0
    coulomb: _Number = 0.0
    coulomb_speed: _Positive = 1.0
    mass: _Positive | None = None
    position: _Vector | None = None
    transverse_inertia: _Positive | None = None

    def build(self):
        return actuators.ReactionWheel(**self.model_dump())


class WheelPyramid(_Table):
    """Four identical wheels in a pyramid (:func:`tumble.spacecraft.pyramid_wheels`); ``mass``,
    ``position`` and ``transverse_inertia``, as every other key, apply to each of the four."""

    inertia: _Positive
    skew: _Positive = math.degrees(math.atan(math.sqrt(2.0)))
    max_torque: _Limit = math.inf
    max_speed: _Limit = math.inf
    viscous: _Number = 0.0
    coulomb: _Number = 0.0
    coulomb_speed: _Positive = 1.0
    mass: _Positive | None = None
    position: _Vector | None = None
    transverse_inertia: _Positive | None = None

    def build(self):
        return actuators.pyramid_wheels(**self.model_dump())


class HubTable(_Table):
    """``[spacecraft.hub]``: the hub **without** its wheels (``Spacecraft(hub=RigidBody(...))``):
    ``inertia`` (3×3, kg m², about the hub's centre of mass, body axes) or ``moments`` (its diagonal),
    ``mass`` (kg) and ``com`` (m, body axes; default the origin)."""

    inertia: _Matrix | None = None
    moments: _Vector | None = None
    mass: _Positive
    com: _Vector | None = None

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        if self.inertia is None:
            keys["inertia"] = f"{prefix}.moments"
        return keys

    def build(self) -> RigidBody:
        if (self.inertia is None) == (self.moments is None):
            raise ScenarioError("", [("spacecraft.hub", "give exactly one of inertia or moments")])
        inertia = self.inertia if self.inertia is not None else np.diag(self.moments)
        return RigidBody(inertia, mass=self.mass, com=self.com)


class CMGPyramid(_Table):
    momentum: _Positive
    skew: _Positive = math.degrees(math.atan(math.sqrt(2.0)))
    max_gimbal_rate: _Positive = 1.0
    robust_gain: _Number = 0.01
    robust_decay: _Number = 10.0

    def build(self):
        return actuators.CMGCluster.pyramid(**self.model_dump())


class ThrusterTable(_Table):
    position: _Vector
    direction: _Vector
    force: _Positive

    def build(self):
        return actuators.Thruster(**self.model_dump())


class PWPFTable(_Table):
    gain: _Positive = 4.5
    time_constant: _Positive = 0.85
    on: _Positive = 0.45
    off: _Number = 0.15
    min_on_time: _Number = 0.0

    def build(self):
        return actuators.PWPF(**self.model_dump())


class MagnetorquerTable(_Table):
    max_dipole: _Positive

    def build(self):
        return actuators.Magnetorquers(self.max_dipole)


class OrbitTable(_Table):
    """A circular orbit (``altitude``) or an ellipse (``semi_major_axis``, ``eccentricity``); angles in degrees."""

    altitude: _Number | None = None
    semi_major_axis: _Positive | None = None
    eccentricity: _Number = 0.0
    inclination: _Number = 0.0
    raan: _Number = 0.0
    arg_periapsis: _Number = 0.0
    mean_anomaly: _Number = 0.0

    def build(self) -> Orbit:
        if (self.altitude is None) == (self.semi_major_axis is None):
            raise ScenarioError("", [("spacecraft.orbit", "give exactly one of altitude or semi_major_axis (m)")])
        angles = {k: math.radians(getattr(self, k)) for k in ("inclination", "raan", "arg_periapsis", "mean_anomaly")}
        if self.altitude is not None:
            return Orbit.circular(self.altitude, angles["inclination"], raan=angles["raan"],
                                  arg_latitude=angles["mean_anomaly"] + angles["arg_periapsis"])
        return Orbit(self.semi_major_axis, self.eccentricity, **angles)


class FieldTable(_Table):
    """``model = "dipole"`` (tilted dipole, IGRF-13 2020) or ``uniform = [Bx, By, Bz]`` (T, inertial)."""

    model: Literal["dipole"] | None = None
    uniform: _Vector | None = None

    def build(self):
        if (self.model is None) == (self.uniform is None):
            rule = "give exactly one of model = \"dipole\" or uniform"
            raise ScenarioError("", [("spacecraft.magnetic_field", rule)])
        return DipoleField() if self.model == "dipole" else np.array(self.uniform)


class PDTable(_Table):
    kind: Literal["quaternion_pd"]
    natural_frequency: _Positive
    damping_ratio: _Positive = 1.0 / math.sqrt(2.0)
    target: _Quaternion | None = None
    target_euler: EulerAngles | None = None
    max_rate: _Limit = math.inf
    max_torque: _Limit = math.inf

    def build(self):
        target = (self.target_euler.quaternion() if self.target_euler is not None
                  else (1.0, 0.0, 0.0, 0.0) if self.target is None else self.target)
        return control.QuaternionPD(self.natural_frequency, self.damping_ratio, target=target,
                                    max_rate=self.max_rate, max_torque=self.max_torque)


class RateDampingTable(_Table):
    kind: Literal["rate_damping"]
    time_constant: _Positive
    max_torque: _Limit = math.inf

    def build(self):
        return control.RateDamping(self.time_constant, self.max_torque)


class ConstantTorqueTable(_Table):
    kind: Literal["constant_torque"]
    torque: _Vector

    def build(self):
        return control.ConstantTorque(self.torque)


class BDotTable(_Table):
    kind: Literal["bdot"]
    gain: _Positive

    def build(self):
        return control.BDot(self.gain)


class DumpingTable(_Table):
    kind: Literal["momentum_dumping"]
    gain: _Positive

    def build(self):
        return control.MomentumDumping(self.gain)


_Controller = Annotated[Union[PDTable, RateDampingTable, ConstantTorqueTable, BDotTable, DumpingTable],
                        Field(discriminator="kind")]


class SpacecraftTable(_Table):
    """``[spacecraft]``: mass properties (``inertia`` or ``moments``: the total, wheels included; or a
    ``hub`` table: the hub without the wheels, which then need mass properties), actuators, environment
    and controllers."""

    inertia: _Matrix | None = None
    moments: _Vector | None = None
    hub: HubTable | None = None
    wheels: list[Wheel] = []
    wheel_pyramid: WheelPyramid | None = None
    cmgs: CMGPyramid | None = None
    thrusters: list[ThrusterTable] = []
    pwpf: PWPFTable = PWPFTable()
    magnetorquers: MagnetorquerTable | None = None
    orbit: OrbitTable | None = None
    magnetic_field: FieldTable | None = None
    gravity_gradient: _Bool = False
    controller: list[_Controller] = []
    control_period: _Positive | None = None

    def build(self, source: str) -> Spacecraft:
        given = [key for key in ("inertia", "moments", "hub") if getattr(self, key) is not None]
        if len(given) != 1:
            rule = ("give exactly one of inertia, moments (the total, wheels included) or hub (a [spacecraft.hub] "
                    "table: the hub without the wheels)" + (f"; got {' and '.join(given)}" if given else ""))
            raise ScenarioError(source, [("spacecraft", rule)])
        if self.wheels and self.wheel_pyramid is not None:
            raise ScenarioError(source, [("spacecraft", "give wheels or wheel_pyramid, not both")])
        parts = {}
        for key in ("wheels", "thrusters", "controller"):
            items = []
            for i, entry in enumerate(getattr(self, key)):
                with _blame(source, f"spacecraft.{key}[{i}]", entry.argument_keys(f"spacecraft.{key}[{i}]")):
                    items.append(entry.build())
            parts[key] = items
        for key in ("hub", "wheel_pyramid", "cmgs", "pwpf", "magnetorquers", "orbit", "magnetic_field"):
            entry = getattr(self, key)
            try:
                with _blame(source, f"spacecraft.{key}", entry.argument_keys(f"spacecraft.{key}") if entry else {}):
                    parts[key] = None if entry is None else entry.build()
            except ScenarioError as exc:
                raise ScenarioError(source, list(exc.problems)) from None
        if parts.pop("wheel_pyramid") is not None:
            parts["wheels"] = actuators.pyramid_wheels(**self.wheel_pyramid.model_dump())
        if self.hub is not None:
            self._check_wheel_mass_properties(source)
        inertia = (self.inertia if self.inertia is not None
                   else np.diag(self.moments) if self.moments is not None else None)
        keys = {"inertia": "spacecraft.inertia" if self.inertia is not None else "spacecraft.moments",
                "hub": "spacecraft.hub",
                "control_period": "spacecraft.control_period", "gravity_gradient": "spacecraft.gravity_gradient"}
        with _blame(source, "spacecraft", keys):
            return Spacecraft(inertia=inertia, gravity_gradient=self.gravity_gradient,
                              control_period=self.control_period, **parts)

    def _check_wheel_mass_properties(self, source: str):
        """With a ``hub``, every wheel needs ``mass``, ``position`` and ``transverse_inertia`` (the rule of
        :meth:`tumble.spacecraft.ReactionWheel.part`, reported here against each wheel's key)."""
        tables = ([("spacecraft.wheel_pyramid", self.wheel_pyramid)] if self.wheel_pyramid is not None
                  else [(f"spacecraft.wheels[{i}]", wheel) for i, wheel in enumerate(self.wheels)])
        rule = ("missing required key: with a [spacecraft.hub] (the hub without its wheels) every wheel needs "
                "mass, position and transverse_inertia")
        problems = [(f"{where}.mass", rule) for where, wheel in tables if wheel.mass is None]
        if problems:
            raise ScenarioError(source, problems)


class SpacecraftInitial(Initial):
    """``[initial]``: ``omega``, ``q`` or ``euler`` as in rigid-body scenarios, plus ``wheel_speeds`` (rad/s,
    relative to the hub) and ``gimbal_angles`` (rad)."""

    wheel_speeds: list[_Number] | None = None
    gimbal_angles: list[_Number] | None = None


class SpacecraftSolver(Solver):
    """``[solver]``: ``rk4`` (``dt``) or ``dop853`` (``rtol``, ``atol``; continuous control only)."""

    method: Annotated[str, Field(strict=True)] = "rk4"

    @field_validator("method")
    @classmethod
    def _spacecraft_method(cls, method):
        if method not in METHODS:
            raise ValueError(f"must be one of {', '.join(map(repr, METHODS))} for a spacecraft, got {method!r}")
        return method


class SpacecraftScenario(_Table):
    """A validated spacecraft scenario; :meth:`run` simulates it."""

    name: Annotated[str, Field(strict=True)] | None = None
    description: Annotated[str, Field(strict=True)] | None = None
    spacecraft: SpacecraftTable
    initial: SpacecraftInitial
    time: Time
    solver: SpacecraftSolver = SpacecraftSolver(dt=0.1)

    _source: str = PrivateAttr("<scenario>")

    def run(self, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
        source = self._source
        craft = self.spacecraft.build(source)
        with _blame(source, "initial", {"q": "initial.q", "seq": "initial.euler.seq"}):
            q0 = self.initial.quaternion()
        keys = {"omega0": "initial.omega", "wheel_speeds0": "initial.wheel_speeds",
                "gimbal_angles0": "initial.gimbal_angles", "dt": "solver.dt", "method": "solver.method",
                "rtol": "solver.rtol", "atol": "solver.atol", "t": "time"}
        with _blame(source, "", keys):
            return simulate(craft, self.initial.omega, t=self.time.times(), q0=q0,
                            wheel_speeds0=self.initial.wheel_speeds, gimbal_angles0=self.initial.gimbal_angles,
                            method=self.solver.method, progress=progress, **self.solver.options())


    def target(self) -> np.ndarray | None:
        """The attitude commanded by the scenario's quaternion PD law, if it has one (for figures)."""
        for law in self.spacecraft.controller:
            if isinstance(law, PDTable):
                return law.build().target
        return None

    def figure(self, traj: Trajectory):
        """:func:`tumble.spacecraft.figure.spacecraft_figure` of a run of this scenario, titled with its name."""
        from tumble.spacecraft.figure import spacecraft_figure

        return spacecraft_figure(traj, target=self.target(), title=self.name)


def parse_spacecraft_scenario(text: str, *, source: str = "<string>") -> SpacecraftScenario:
    """Parse and validate a spacecraft scenario from TOML ``text``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, [_toml_problem(exc)]) from None
    try:
        scenario = SpacecraftScenario.model_validate(data)
    except pydantic.ValidationError as exc:
        raise ScenarioError(source, [_describe(_untagged(error)) for error in exc.errors()]) from None
    scenario._source = source
    return scenario


# The ``kind`` values of the controller tables: pydantic puts them in error locations, the file has no such key.
_TAGS = {cls.model_fields["kind"].annotation.__args__[0] for cls in _Controller.__origin__.__args__}


def _untagged(error: dict) -> dict:
    return {**error, "loc": tuple(part for part in error["loc"] if part not in _TAGS)}


def load_spacecraft_scenario(path) -> SpacecraftScenario:
    """Read and validate the spacecraft scenario file ``path`` (UTF-8 TOML)."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(source, [("", f"cannot read the file ({exc.strerror or exc})")]) from None
    return parse_spacecraft_scenario(text, source=source)


def run_spacecraft_scenario(scenario, progress: Callable[[int, int], None] | None = None) -> Trajectory:
    """Simulate a spacecraft scenario (a :class:`SpacecraftScenario` or the path of a file)."""
    if not isinstance(scenario, SpacecraftScenario):
        scenario = load_spacecraft_scenario(scenario)
    return scenario.run(progress=progress)
