"""The tables every scenario kind shares: ``[body]``, ``[initial]``, ``[time]``, ``[solver]``.

SI units; ``omega`` in body axes; ``q = [w, x, y, z]`` scalar first, body →
inertial (``docs/scenarios.md``). The ``orbit`` table is in
:mod:`tumble.scenario.orbit`, the ``[[torque]]`` tables in
:mod:`tumble.scenario.torques`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, ClassVar, Literal, Union

import numpy as np
from pydantic import BaseModel, Discriminator, Field, Tag, field_validator

from tumble import attitude, integrate
from tumble._validate import ValidationError
from tumble.rigid_body import RigidBody
from tumble.scenario._errors import ScenarioError
from tumble.scenario._values import (_Axis, _Bool, _Matrix, _Number, _Positive, _Quaternion, _Table, _Text,
                                     _Vector)
from tumble.simulate import SolverOptions

if TYPE_CHECKING:
    from tumble.simulate import Model

__all__ = ["Body", "EulerAngles", "Initial", "MAX_SAMPLES", "ModelState", "Solver", "Time"]

# Most output times a scenario may ask for (10⁷ samples of t, q and ω are
# 640 MB): a guard against a typo such as step = 1e-9 exhausting memory.
MAX_SAMPLES = 10_000_000
# The output times of [time] step reach `stop` when (stop - start)/step is a
# whole number to within this many steps (floating-point rounding of the ratio).
_STEP_ROUNDING = 1e-9


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

    if TYPE_CHECKING:
        shape: str  # each solid's field: the name of its RigidBody constructor

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

_BODY_DESCRIPTIONS = {"inertia": "InertiaBody", "moments": "MomentsBody", "shape": "_Shape"}


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
    return _BODY_DESCRIPTIONS[given[0]] if len(given) == 1 else None


#: ``[body]``: a rigid body, by its tensor, its principal moments or a shape (``.build()`` → RigidBody).
Body = Annotated[
    Union[Annotated[InertiaBody, Tag("InertiaBody")], Annotated[MomentsBody, Tag("MomentsBody")],
          Annotated[_ShapeBody, Tag("_Shape")]],
    Discriminator(_body_kind, custom_error_type="body_description",
                  custom_error_message="give exactly one of inertia, moments or shape"),
]


# --------------------------------------------------------------------------
# [initial]
# --------------------------------------------------------------------------


class EulerAngles(_Table):
    """Euler angles of an attitude, as in :func:`tumble.attitude.from_euler`."""

    seq: _Text
    angles: _Vector
    degrees: _Bool = True

    def quaternion(self) -> np.ndarray:
        return attitude.from_euler(self.seq, self.angles, degrees=self.degrees)


class Initial(_Table):
    """``[initial]``: the body rate ``omega`` (rad/s, body axes) and attitude (``q`` or ``euler``; default
    identity). A kind whose model has more initial state adds its keys in a subclass: key ``x`` is the
    initial value ``x0`` of :func:`tumble.simulate`."""

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

    def state(self) -> dict[str, np.ndarray]:
        """The initial state by name, as keywords of :func:`tumble.simulate`: ``x0`` for each key ``x`` given
        (``q0`` from ``q`` or ``euler``)."""
        values = {f"{key}0": np.array(value) for key, value in self if key not in ("q", "euler") and value is not None}
        return {**values, "q0": self.quaternion()}

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        keys.update({f"{key}0": f"{prefix}.{key}" for key in type(self).model_fields})
        keys.update({key: f"{prefix}.euler.{key}" for key in EulerAngles.model_fields})
        return keys


class ModelState(_Table):
    """The base of an ``[initial]`` table of a model without a body attitude (a robot, a gyroscope): each key
    ``x`` given is the initial state ``x0`` of :func:`tumble.simulate` (or ``x``, where the model's state field
    has no suffix: a gimbaled gyro's ``spin``). A subclass lists the keys of every model of its kind; the
    model built decides which of them it takes (:meth:`state`)."""

    def state(self, model: Model, prefix: str = "initial") -> dict[str, np.ndarray]:
        """The initial state by name, as keywords of :func:`tumble.simulate` for ``model``.

        A key the model has no state field for is refused (a
        :class:`~tumble.scenario.ScenarioError` against ``prefix.key``), naming the keys it takes.
        """
        fields = [f.name for f in model.state_fields()]
        values, problems = {}, []
        for key, value in self:
            if value is None:
                continue
            name = next((name for name in (f"{key}0", key) if name in fields), None)
            if name is None:
                takes = ", ".join(name.removesuffix("0") for name in fields)
                problems.append((f"{prefix}.{key}", f"not an initial state of a {type(model).__name__}, which takes: "
                                                    f"{takes}"))
            else:
                values[name] = np.array(value)
        if problems:
            raise ScenarioError("", problems)
        return values

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        keys.update({f"{key}0": f"{prefix}.{key}" for key in type(self).model_fields})
        return keys


# --------------------------------------------------------------------------
# [time]
# --------------------------------------------------------------------------


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
                # exact while float64 counts every whole number; past float64's range, said so
                count = f"{n:.0f}" if n < 2**53 else f"{n:.3g}" if n < np.inf else "more than 1e308"
                raise ValueError(f"makes {count} output times, more than the limit {MAX_SAMPLES}; use a larger step")
        return step

    def times(self) -> np.ndarray:
        """The output times: ``linspace(start, stop, samples)``, or ``start + k step`` up to ``stop``."""
        if self.samples is not None:
            return _spaced(self.start, self.stop, self.samples)
        step = self.step
        assert step is not None  # the validator gives exactly one of samples and step
        n = int(_step_count(self.start, self.stop, step))  # at most MAX_SAMPLES (the validator)
        end = self.start + n * step
        if not np.isfinite(end):  # n step overflows (start = -1e308): the same sum, from its halves
            end = 2.0 * (0.5 * self.start + (0.5 * step) * n)
        if abs(end - self.stop) <= _STEP_ROUNDING * step:
            end = self.stop  # land exactly on stop despite rounding
        return _spaced(self.start, end, n + 1)


def _step_count(start: float, stop: float, step: float) -> float:
    """Number of whole steps from ``start`` that stay within ``stop`` (to rounding), as a float: it may be
    past any int (``step = 1e-300``; the validator refuses more than :data:`MAX_SAMPLES`)."""
    span = stop - start
    steps = span / step if np.isfinite(span) else stop / step - start / step  # stop - start past 1.8e308
    return float(np.floor(steps + _STEP_ROUNDING))


def _spaced(start: float, stop: float, n: int) -> np.ndarray:
    """``n`` evenly spaced times from ``start`` to ``stop`` (s), ``np.linspace``'s. Where ``stop − start``
    overflows float64 (``start = -1e308, stop = 1e308``), ``start + f (stop − start)`` is summed from the
    halves of the difference, ``(start + f h) + f h`` with ``h = stop/2 − start/2``, which stay finite."""
    if np.isfinite(stop - start):
        return np.linspace(start, stop, n)
    fraction = np.linspace(0.0, 1.0, n)
    half = 0.5 * stop - 0.5 * start
    times = (start + half * fraction) + half * fraction
    times[-1] = stop
    return times


# --------------------------------------------------------------------------
# [solver]
# --------------------------------------------------------------------------


class Solver(_Table):
    """Integration method (one of :data:`tumble.integrate.METHODS`) and its options.

    Adaptive methods take ``rtol``/``atol`` (defaults: those of
    :func:`tumble.simulate`); fixed-step methods need ``dt`` (s). An option the
    method does not use is refused rather than ignored. Whether the kind's model
    provides what the method needs is :func:`tumble.simulate`'s one check,
    reported at ``solver.method``.
    """

    method: _Text = "dop853"
    rtol: _Positive | None = None
    atol: _Positive | None = None
    dt: _Positive | None = Field(default=None, validate_default=True)

    @field_validator("method")
    @classmethod
    def _known_method(cls, method):
        try:
            return integrate.method(method).name
        except ValidationError as error:  # the rule, reported at solver.method
            raise ValueError(error.rule) from None

    @field_validator("rtol", "atol", "dt")
    @classmethod
    def _used_by_method(cls, value, info):
        method = integrate.METHODS.get(info.data.get("method"))
        if method is None:  # the method itself is invalid: reported there
            return value
        reads = [name for name in method.options if name in cls.model_fields]
        if info.field_name == "dt" and "dt" in reads and value is None:
            raise ValueError(f"required by method {method.name!r} (fixed step, s)")
        if value is not None and info.field_name not in reads:
            takes = " and ".join(reads) or "no solver options"
            raise ValueError(f"not used by method {method.name!r}, which takes {takes}")
        return value

    def options(self) -> SolverOptions:
        """The options given, as keyword arguments of :func:`tumble.simulate`."""
        options = SolverOptions()
        if self.rtol is not None:
            options["rtol"] = self.rtol
        if self.atol is not None:
            options["atol"] = self.atol
        if self.dt is not None:
            options["dt"] = self.dt
        return options
