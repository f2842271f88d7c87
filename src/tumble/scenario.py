"""Scenario files: a rigid-body simulation described as data, in TOML.

A scenario gives a body, its initial state, the output times, the solver and
the external torques (SI units; ``omega`` in body axes; ``q`` scalar first,
body → inertial)::

    name = "Tennis racket"

    [body]
    shape = "t_handle"

    [initial]
    omega = [0.001, 10.0, 0.001]      # rad/s, body axes

    [time]
    stop = 20.0                       # s
    step = 0.005                      # s between output times

    [solver]
    method = "dop853"
    rtol = 1e-12
    atol = 1e-12

The schema is documented in ``docs/scenarios.md``. Files are parsed with the
standard library's :mod:`tomllib` and validated by pydantic models that refuse
unknown keys; a scenario is data, never code. Every problem is reported as a
:class:`ScenarioError` naming the file, the key and the rule it breaks, one
line per problem::

    spin.toml: body.inertia: must be positive definite (principal moments ...)

Rules that the library already enforces (a positive-definite inertia, a
positive mass, increasing torque sample times, ...) are not repeated here:
the library's :class:`~tumble.ValidationError` is caught and reported against
the key that fed the offending argument.
"""

from __future__ import annotations

import difflib
import functools
import operator
import re
import tomllib
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, ClassVar, Literal, Union, get_args

import numpy as np
import pydantic
from pydantic import BaseModel, ConfigDict, Discriminator, Field, PrivateAttr, Tag, field_validator

from tumble import attitude, integrate, torques
from tumble._validate import ValidationError
from tumble.body import RigidBody
from tumble.simulate import simulate
from tumble.spacecraft.damper import SphericalDamper, simulate_damped
from tumble.spacecraft.orbit import EARTH_RADIUS, Orbit
from tumble.trajectory import Trajectory

__all__ = ["Problem", "Scenario", "ScenarioError", "load_scenario", "parse_scenario", "run_scenario"]

# Most output times a scenario may ask for (10⁷ samples of t, q and ω are
# 640 MB): a guard against a typo such as step = 1e-9 exhausting memory.
MAX_SAMPLES = 10_000_000
# The output times of [time] step reach `stop` when (stop - start)/step is a
# whole number to within this many steps (floating-point rounding of the ratio).
_STEP_ROUNDING = 1e-9


class ScenarioError(ValidationError):
    """A scenario that cannot be read or breaks a rule.

    ``problems`` holds ``(where, rule)`` pairs: ``where`` is a key path such as
    ``"body.inertia"`` or ``"torque[1].times"``, a TOML position such as
    ``"line 3, column 7"``, or ``""`` for the file as a whole. ``str(error)``
    has one line per problem: ``FILE: WHERE: RULE``.
    """

    def __init__(self, source: str, problems: list[tuple[str, str]]):
        self.source = source
        self.problems = tuple(problems)
        super().__init__("\n".join(f"{source}: {where}: {rule}" if where else f"{source}: {rule}"
                                   for where, rule in self.problems))


# --------------------------------------------------------------------------
# Value types: strict (no "1.5" strings or booleans as numbers), finite.
# --------------------------------------------------------------------------

_Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]  # a TOML integer is accepted too
_Positive = Annotated[_Number, Field(gt=0.0)]
_Vector = Annotated[list[_Number], Field(min_length=3, max_length=3)]
_Matrix = Annotated[list[_Vector], Field(min_length=3, max_length=3)]
_Quaternion = Annotated[list[_Number], Field(min_length=4, max_length=4)]
_Bool = Annotated[bool, Field(strict=True)]
_Axis = Literal["x", "y", "z"]


class _Table(BaseModel):
    """A TOML table: unknown keys are refused, values are immutable once validated."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    #: Library argument name → key of this table, where the two differ.
    renamed: ClassVar[dict[str, str]] = {}

    def argument_keys(self, prefix: str) -> dict[str, str]:
        """Map each library argument this table feeds to its full key path under ``prefix``."""
        keys = {name: f"{prefix}.{name}" for name in type(self).model_fields}
        keys.update({arg: f"{prefix}.{key}" for arg, key in self.renamed.items()})
        return keys


# --------------------------------------------------------------------------
# [body]: exactly one of inertia, moments or shape
# --------------------------------------------------------------------------


class InertiaBody(_Table):
    """``inertia``: the 3×3 tensor about the centre of mass, kg m², body axes."""

    inertia: _Matrix
    mass: _Number | None = None
    check_triangle: _Bool = True

    def build(self) -> RigidBody:
        return RigidBody(self.inertia, mass=self.mass, check_triangle=self.check_triangle)


class MomentsBody(_Table):
    """``moments``: principal moments about the body x, y, z axes, kg m² (inertia = diag(moments))."""

    moments: _Vector
    mass: _Number | None = None
    check_triangle: _Bool = True
    renamed: ClassVar[dict[str, str]] = {"inertia": "moments"}

    def build(self) -> RigidBody:
        return RigidBody(np.diag(self.moments), mass=self.mass, check_triangle=self.check_triangle)


class _Shape(_Table):
    """A homogeneous solid: its keys are the arguments of ``RigidBody.<shape>(...)``."""

    def build(self) -> RigidBody:
        constructor = getattr(RigidBody, self.shape)
        return constructor(**self.model_dump(exclude={"shape"}, exclude_none=True))


class SphereBody(_Shape):
    shape: Literal["sphere"]
    mass: _Number
    radius: _Number


class HollowSphereBody(_Shape):
    shape: Literal["hollow_sphere"]
    mass: _Number
    radius: _Number


class CylinderBody(_Shape):
    shape: Literal["cylinder"]
    mass: _Number
    radius: _Number
    length: _Number
    axis: _Axis | None = None


class HollowCylinderBody(_Shape):
    shape: Literal["hollow_cylinder"]
    mass: _Number
    inner_radius: _Number
    outer_radius: _Number
    length: _Number
    axis: _Axis | None = None


class BoxBody(_Shape):
    shape: Literal["box"]
    mass: _Number
    size: _Vector


class EllipsoidBody(_Shape):
    shape: Literal["ellipsoid"]
    mass: _Number
    semi_axes: _Vector


class PointMassesBody(_Shape):
    shape: Literal["point_masses"]
    masses: Annotated[list[_Number], Field(min_length=1)]
    positions: Annotated[list[_Vector], Field(min_length=1)]
    check_triangle: _Bool | None = None


class THandleBody(_Shape):
    shape: Literal["t_handle"]
    handle_mass: _Number | None = None
    handle_length: _Number | None = None
    bar_mass: _Number | None = None
    bar_length: _Number | None = None
    radius: _Number | None = None


_ShapeBody = Annotated[
    Union[SphereBody, HollowSphereBody, CylinderBody, HollowCylinderBody, BoxBody, EllipsoidBody,
          PointMassesBody, THandleBody],
    Field(discriminator="shape"),
]

_BODY_DESCRIPTIONS = ("inertia", "moments", "shape")


def _body_kind(table) -> str | None:
    """The class of a [body] table: ``"InertiaBody"``, ``"MomentsBody"`` or ``"_Shape"`` (any shape).

    ``None`` (refused) unless exactly one of ``inertia``, ``moments``, ``shape``
    is given. Anything but a table is sent to :class:`InertiaBody`, whose
    validation then says "must be a table".
    """
    if isinstance(table, BaseModel):
        table = table.model_dump()
    if not isinstance(table, dict):
        return "InertiaBody"
    given = [key for key in _BODY_DESCRIPTIONS if key in table]
    if len(given) != 1:
        return None
    return {"inertia": "InertiaBody", "moments": "MomentsBody", "shape": "_Shape"}[given[0]]


_Body = Annotated[
    Union[Annotated[InertiaBody, Tag("InertiaBody")], Annotated[MomentsBody, Tag("MomentsBody")],
          Annotated[_ShapeBody, Tag("_Shape")]],
    Discriminator(_body_kind, custom_error_type="body_description",
                  custom_error_message="give exactly one of inertia, moments or shape"),
]


# --------------------------------------------------------------------------
# [initial], [time], [solver], [[torque]]
# --------------------------------------------------------------------------


class EulerAngles(_Table):
    """Euler angles of the initial attitude, as in :func:`tumble.attitude.from_euler`."""

    seq: Annotated[str, Field(strict=True)]
    angles: _Vector
    degrees: _Bool = True

    def quaternion(self) -> np.ndarray:
        return attitude.from_euler(self.seq, self.angles, degrees=self.degrees)


class Initial(_Table):
    """Initial body rate ``omega`` (rad/s, body axes) and attitude (``q`` or ``euler``; default identity)."""

    omega: _Vector
    q: _Quaternion | None = None
    euler: EulerAngles | None = None

    @field_validator("euler")
    @classmethod
    def _one_attitude(cls, euler, info):
        if euler is not None and info.data.get("q") is not None:
            raise ValueError("give the initial attitude as q or as euler, not both")
        return euler

    def quaternion(self) -> np.ndarray:
        """``q0``: unit quaternion ``[w, x, y, z]``, body → inertial (``q`` is normalised)."""
        if self.euler is not None:
            return self.euler.quaternion()
        return attitude.identity() if self.q is None else attitude.normalize(self.q)


class Time(_Table):
    """Output times, s: ``samples`` evenly spaced from ``start`` to ``stop``, or every ``step``."""

    start: _Number = 0.0
    stop: _Number
    samples: Annotated[int, Field(strict=True, ge=2, le=MAX_SAMPLES)] | None = None
    step: _Positive | None = Field(None, validate_default=True)

    @field_validator("stop")
    @classmethod
    def _after_start(cls, stop, info):
        start = info.data.get("start")
        if start is not None and not stop > start:
            raise ValueError(f"must be greater than start = {start} s, got {stop}")
        return stop

    @field_validator("step")
    @classmethod
    def _samples_or_step(cls, step, info):
        if "samples" not in info.data:  # samples itself is invalid: reported there
            return step
        if (info.data["samples"] is None) == (step is None):
            raise ValueError("give exactly one of samples (number of output times) or step (s between them)")
        if step is not None and {"start", "stop"} <= info.data.keys():
            n = _step_count(info.data["start"], info.data["stop"], step) + 1
            if n > MAX_SAMPLES:
                raise ValueError(f"makes {n} output times, more than the limit {MAX_SAMPLES}; use a larger step")
        return step

    def times(self) -> np.ndarray:
        """The output times: ``linspace(start, stop, samples)``, or ``start + k step`` up to ``stop``."""
        if self.samples is not None:
            return np.linspace(self.start, self.stop, self.samples)
        n = _step_count(self.start, self.stop, self.step)
        end = self.start + n * self.step
        if abs(end - self.stop) <= _STEP_ROUNDING * self.step:
            end = self.stop  # land exactly on stop despite rounding
        return np.linspace(self.start, end, n + 1)


def _step_count(start: float, stop: float, step: float) -> int:
    """Number of whole steps from ``start`` that stay within ``stop`` (to rounding)."""
    return int(np.floor((stop - start) / step + _STEP_ROUNDING))


class Solver(_Table):
    """Integration method (one of :data:`tumble.integrate.METHODS`) and its options.

    Adaptive methods take ``rtol``/``atol`` (defaults: those of
    :func:`tumble.simulate`); fixed-step methods need ``dt`` (s). An option the
    method does not use is refused rather than ignored.
    """

    method: Annotated[str, Field(strict=True)] = "dop853"
    rtol: _Positive | None = None
    atol: _Positive | None = None
    dt: _Positive | None = Field(None, validate_default=True)

    @field_validator("method")
    @classmethod
    def _known_method(cls, method):
        if method not in integrate.METHODS:
            raise ValueError(f"must be one of {', '.join(map(repr, integrate.METHODS))}, got {method!r}")
        return method

    @field_validator("rtol", "atol", "dt")
    @classmethod
    def _used_by_method(cls, value, info):
        method = integrate.METHODS.get(info.data.get("method"))
        if method is None:  # the method itself is invalid: reported there
            return value
        fixed_step = method.stepper and not method.adaptive
        if info.field_name == "dt" and fixed_step and value is None:
            raise ValueError(f"required by method {method.name!r} (fixed step, s)")
        used = fixed_step if info.field_name == "dt" else method.adaptive
        if value is not None and not used:
            uses = "rtol and atol" if method.adaptive else "dt" if fixed_step else "no solver options"
            raise ValueError(f"not used by method {method.name!r}, which takes {uses}")
        return value

    def options(self) -> dict[str, float]:
        """The options given, as keyword arguments of :func:`tumble.simulate`."""
        return self.model_dump(include={"rtol", "atol", "dt"}, exclude_none=True)


class ConstantBodyTorque(_Table):
    """``value``: a torque fixed in the body, N m, body axes."""

    kind: Literal["constant_body"]
    value: _Vector
    renamed: ClassVar[dict[str, str]] = {"torque": "value"}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.ConstantBody(self.value)


class ConstantInertialTorque(_Table):
    """``value``: a torque fixed in inertial space, N m, inertial axes."""

    kind: Literal["constant_inertial"]
    value: _Vector
    renamed: ClassVar[dict[str, str]] = {"torque": "value"}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.ConstantInertial(self.value)


class TabulatedTorque(_Table):
    """Torque samples ``values`` (N m) at ``times`` (s), as :class:`tumble.torques.Tabulated`."""

    kind: Literal["tabulated"]
    times: Annotated[list[_Number], Field(min_length=1)]
    values: Annotated[list[_Vector], Field(min_length=1)]
    frame: Literal["body", "inertial"] | None = None
    interpolation: Literal["linear", "previous"] | None = None
    renamed: ClassVar[dict[str, str]] = {"t": "times", "torque": "values"}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        options = self.model_dump(include={"frame", "interpolation"}, exclude_none=True)
        return torques.Tabulated(self.times, self.values, **options)


class GravityTorque(_Table):
    """Uniform gravity on a body pivoting about a fixed point, as :class:`tumble.torques.Gravity`:
    ``mass`` (kg), ``com`` (m, centre of mass relative to the pivot, body axes), ``g`` (m/s², inertial)."""

    kind: Literal["gravity"]
    mass: _Positive
    com: _Vector
    g: _Vector | None = None

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.Gravity(self.mass, self.com, *([] if self.g is None else [self.g]))


class OrbitTable(_Table):
    """A Kepler orbit, as :class:`tumble.spacecraft.orbit.Orbit`: ``altitude`` (m above the Earth's
    equatorial radius, 6378137 m) or ``semi_major_axis`` (m); ``eccentricity``; angles ``inclination``,
    ``raan``, ``arg_periapsis``, ``mean_anomaly`` (at t = 0) in degrees (or rad with ``degrees = false``);
    ``mu`` (m³/s², default the Earth's)."""

    altitude: _Number | None = None
    semi_major_axis: _Positive | None = Field(None, validate_default=True)
    eccentricity: _Number = 0.0
    inclination: _Number = 0.0
    raan: _Number = 0.0
    arg_periapsis: _Number = 0.0
    mean_anomaly: _Number = 0.0
    degrees: _Bool = True
    mu: _Positive | None = None

    @field_validator("semi_major_axis")
    @classmethod
    def _one_size(cls, semi_major_axis, info):
        if "altitude" in info.data and (info.data["altitude"] is None) == (semi_major_axis is None):
            raise ValueError("give exactly one of altitude (m above 6378137 m) or semi_major_axis (m)")
        return semi_major_axis

    def build(self) -> Orbit:
        a = self.semi_major_axis if self.altitude is None else EARTH_RADIUS + self.altitude
        angle = np.radians if self.degrees else float
        options = {} if self.mu is None else {"mu": self.mu}
        return Orbit(semi_major_axis=a, eccentricity=self.eccentricity, inclination=angle(self.inclination),
                     raan=angle(self.raan), arg_periapsis=angle(self.arg_periapsis),
                     mean_anomaly=angle(self.mean_anomaly), **options)


class GravityGradientTorque(_Table):
    """Gravity gradient on the body on the Kepler orbit ``orbit``, as :class:`tumble.torques.GravityGradient`
    (the body's own inertia; the orbit's t = 0 at the scenario's t = 0)."""

    kind: Literal["gravity_gradient"]
    orbit: OrbitTable

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        keys.update(self.orbit.argument_keys(f"{prefix}.orbit"))
        keys["semi_major_axis"] = f"{prefix}.orbit." + ("altitude" if self.orbit.altitude is not None
                                                        else "semi_major_axis")
        return keys

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.GravityGradient(self.orbit.build(), body)


_Torque = Annotated[Union[ConstantBodyTorque, ConstantInertialTorque, TabulatedTorque, GravityTorque,
                          GravityGradientTorque],
                    Field(discriminator="kind")]


class DamperTable(_Table):
    """A spherical viscous nutation damper in the body (:mod:`tumble.spacecraft.damper`): sphere ``inertia``
    J (kg m²), ``damping`` c (N m s), initial sphere rate ``omega`` (rad/s, body axes; default: the body's)."""

    inertia: _Positive
    damping: _Positive
    omega: _Vector | None = None

    def build(self) -> SphericalDamper:
        return SphericalDamper(self.inertia, self.damping)


# --------------------------------------------------------------------------
# The scenario
# --------------------------------------------------------------------------


# Where simulate()'s arguments come from in a scenario.
_SIMULATE_KEYS = {
    "omega0": "initial.omega", "q0": "initial", "t": "time", "method": "solver.method",
    "rtol": "solver.rtol", "atol": "solver.atol", "dt": "solver.dt", "torque": "torque",
}


@dataclass(frozen=True)
class Problem:
    """A scenario turned into the arguments of :func:`tumble.simulate`.

    ``omega0`` rad/s in body axes; ``q0`` unit quaternion ``[w, x, y, z]``,
    body → inertial; ``t`` output times, s; ``options`` the solver options
    given in the file (``rtol``, ``atol``, ``dt``); ``torque`` a torque model
    or ``None`` (torque-free); ``source`` the file, for error messages;
    ``damper`` a nutation damper in the body and ``damper_omega0`` its initial
    rate (rad/s, body axes; ``None``: the body's), or ``None``.
    """

    body: RigidBody
    omega0: np.ndarray
    q0: np.ndarray
    t: np.ndarray
    method: str
    options: dict[str, float]
    torque: torques.TorqueModel | None
    source: str = "<scenario>"
    damper: SphericalDamper | None = None
    damper_omega0: np.ndarray | None = None

    def simulate(self, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
        """Run :func:`tumble.simulate` (or, with a damper, :func:`tumble.spacecraft.damper.simulate_damped`);
        an argument it refuses is reported against its scenario key."""
        with _blame(self.source, "", {**_SIMULATE_KEYS, "damper_omega0": "damper.omega"}):
            if self.damper is not None:
                return simulate_damped(self.body, self.damper, self.omega0, q0=self.q0, t=self.t,
                                       damper_omega0=self.damper_omega0, method=self.method, torque=self.torque,
                                       progress=progress, **self.options)
            return simulate(self.body, self.omega0, q0=self.q0, t=self.t, method=self.method,
                            torque=self.torque, progress=progress, **self.options)


class Scenario(_Table):
    """A validated scenario (see ``docs/scenarios.md``); :meth:`build` makes the simulation's inputs."""

    name: Annotated[str, Field(strict=True)] | None = None
    description: Annotated[str, Field(strict=True)] | None = None
    body: _Body
    initial: Initial
    time: Time
    solver: Solver = Solver()
    torque: list[_Torque] = []
    damper: DamperTable | None = None

    _source: str = PrivateAttr("<scenario>")

    @property
    def source(self) -> str:
        """Where the scenario came from (its file name), as error messages give it."""
        return self._source

    def build(self) -> Problem:
        """Build the body, initial state, times and torque model.

        Raises :class:`ScenarioError` naming the key behind any argument the
        library refuses (e.g. ``body.moments`` for moments that break the
        triangle inequality).
        """
        with _blame(self.source, "body", self.body.argument_keys("body")):
            body = self.body.build()
        attitude_keys = {"q": "initial.q", "seq": "initial.euler.seq", "angles": "initial.euler.angles"}
        with _blame(self.source, "initial", attitude_keys):
            q0 = self.initial.quaternion()
        models = []
        for i, entry in enumerate(self.torque):
            with _blame(self.source, f"torque[{i}]", entry.argument_keys(f"torque[{i}]")):
                models.append(entry.build(body))
        return Problem(
            body=body,
            omega0=np.array(self.initial.omega),
            q0=q0,
            t=self.time.times(),
            method=self.solver.method,
            options=self.solver.options(),
            torque=functools.reduce(operator.add, models) if models else None,
            source=self.source,
            damper=None if self.damper is None else self.damper.build(),
            damper_omega0=None if self.damper is None or self.damper.omega is None else np.array(self.damper.omega),
        )


@contextmanager
def _blame(source: str, fallback: str, keys: Mapping[str, str]) -> Iterator[None]:
    """Re-raise the library's ``ValidationError("argument: rule")`` against the key behind ``argument``.

    Messages whose argument is not in ``keys`` are reported whole against ``fallback``.
    """
    try:
        yield
    except ScenarioError:
        raise
    except ValidationError as exc:
        argument, sep, rule = str(exc).partition(": ")
        where, rule = (keys[argument], rule) if sep and argument in keys else (fallback, str(exc))
        raise ScenarioError(source, [(where, rule)]) from exc


def parse_scenario(text: str, *, source: str = "<string>") -> Scenario:
    """Parse and validate a scenario from TOML ``text``; ``source`` names it in error messages."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, [_toml_problem(exc)]) from None
    try:
        scenario = Scenario.model_validate(data)
    except pydantic.ValidationError as exc:
        raise ScenarioError(source, [_describe(error) for error in exc.errors()]) from None
    scenario._source = source
    return scenario


def load_scenario(path) -> Scenario:
    """Read and validate the scenario file ``path`` (UTF-8 TOML); raises :class:`ScenarioError`."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(source, [("", f"cannot read the file ({exc.strerror or exc})")]) from None
    except UnicodeDecodeError as exc:
        rule = f"not UTF-8 text, as TOML requires ({exc.reason} at byte {exc.start})"
        raise ScenarioError(source, [("", rule)]) from None
    return parse_scenario(text, source=source)


def run_scenario(scenario, *, progress: Callable[[int, int], None] | None = None) -> Trajectory:
    """Simulate a scenario (a :class:`Scenario`, or the path of a scenario file).

    ``progress(done, total)`` is passed to :func:`tumble.simulate`. Bad input
    raises :class:`ScenarioError` before the integration starts; a failure of
    the integrator raises :class:`tumble.SolverError`.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    return scenario.build().simulate(progress=progress)


# --------------------------------------------------------------------------
# Error messages: file, key, rule
# --------------------------------------------------------------------------

_TOML_POSITION = re.compile(r"\s*\(at (line \d+, column \d+|end of document)\)$")

_TYPE_RULES = {
    "float_type": "must be a number",
    "int_type": "must be an integer",
    "bool_type": "must be true or false",
    "string_type": "must be a string",
    "list_type": "must be an array",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "finite_number": "must be finite",
}
_BOUND_RULES = {"greater_than": (">", "gt"), "greater_than_equal": (">=", "ge"), "less_than_equal": ("<=", "le")}


def _toml_problem(exc: tomllib.TOMLDecodeError) -> tuple[str, str]:
    """``(position, rule)`` of a TOML syntax error."""
    message = str(exc)
    match = _TOML_POSITION.search(message)
    where = match.group(1) if match else ""
    return where, f"invalid TOML: {message[:match.start()] if match else message}"


def _describe(error: Mapping) -> tuple[str, str]:
    """``(key path, rule)`` of one pydantic error, in the words of a TOML file."""
    path, table = _locate(error["loc"])
    kind, ctx, got = error["type"], error.get("ctx") or {}, error.get("input")
    if kind == "missing":
        rule = "missing required key"
    elif kind == "extra_forbidden":
        rule = "unknown key" + _hint(str(path[-1]), table)
    elif kind in ("union_tag_not_found", "union_tag_invalid"):  # the key choosing a table's kind
        tag_key = ctx["discriminator"].strip("'")
        path.append(tag_key)
        rule = ("missing required key" if kind == "union_tag_not_found"
                else f"must be one of {ctx['expected_tags']}, got {_short(got[tag_key])}")
    elif kind in _TYPE_RULES:
        rule = f"{_TYPE_RULES[kind]}, got {_short(got)}"
    elif kind in ("too_short", "too_long"):
        bound = "at least" if kind == "too_short" else "at most"
        limit = ctx.get("min_length", ctx.get("max_length"))
        rule = f"must have {bound} {limit} entries, got {ctx['actual_length']}"
    elif kind in _BOUND_RULES:
        sign, limit = _BOUND_RULES[kind]
        rule = f"must be {sign} {ctx[limit]}, got {_short(got)}"
    elif kind == "literal_error":
        rule = f"must be {ctx['expected']}, got {_short(got)}"
    elif kind == "value_error":
        rule = str(ctx["error"])
    else:
        rule = error["msg"]
    return _dotted(path), rule


def _locate(loc: tuple) -> tuple[list, type[_Table] | None]:
    """Split a pydantic error location into the file's key path and the table holding its last key.

    Locations include the tags of union members (``"_Shape"``, ``"box"``,
    ``"tabulated"``: see :func:`_tags`), which are not keys of the file.
    """
    path, candidates, table = [], [Scenario], None
    for part in loc:
        if isinstance(part, int):  # an index into an array
            path.append(part)
            continue
        tagged = [cls for cls in candidates if part in _tags(cls)]
        if tagged:  # a union tag narrows down the table
            candidates = tagged
            continue
        path.append(part)
        table = candidates[0] if len(candidates) == 1 else None
        field = table.model_fields.get(part) if table is not None else None
        candidates = _tables_in(field.annotation) if field is not None else []
    return path, table


def _tags(cls: type[_Table]) -> set[str]:
    """Union tags that select ``cls``: its own and its bases' class names, its ``shape``/``kind`` value."""
    tags = {base.__name__ for base in cls.__mro__ if issubclass(base, _Table)}
    for key in ("shape", "kind"):
        if key in cls.model_fields:
            tags.update(get_args(cls.model_fields[key].annotation))
    return tags


def _tables_in(annotation) -> list[type[_Table]]:
    """The table classes an annotation can hold (through Optional, list, Union, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, _Table):
        return [annotation]
    return [cls for arg in get_args(annotation) for cls in _tables_in(arg)]


def _hint(key: str, table: type[_Table] | None) -> str:
    """" (did you mean ...?)" or the keys the table takes."""
    if table is None:
        return ""
    keys = list(table.model_fields)
    close = difflib.get_close_matches(key, keys, n=1, cutoff=0.75)
    return f" (did you mean {close[0]!r}?)" if close else f" (this table takes: {', '.join(keys)})"


def _dotted(path: list) -> str:
    """``["body", "inertia", 1, 2]`` → ``"body.inertia[1][2]"``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


def _short(value, limit: int = 40) -> str:
    """``repr(value)``, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
