"""Outcomes: what a sweep keeps of each sample's trajectory.

Two kinds of function, both evaluated on a chunk's batched
:class:`~tumble.Trajectory` (arrays with axes ``(time, member, ...)``), so a
whole chunk is reduced at once:

* a **series** ``f(traj) -> (n, m)``: one number per output time and sample
  (its per-time statistics and percentile bands are kept, ``statistics=`` of
  :func:`tumble.sweeps.sweep`);
* an **outcome** ``f(traj) -> (m,)`` or ``(m, ...)``: one value (or array) per
  sample (``outcomes=``).

Built in: the series :class:`PointingError` (the rotation angle from a target
attitude), :class:`NutationAngle` (the angle between a body axis and the
angular momentum) and :class:`Component` (a sampled field or extra); the
reductions of a series :class:`Max`, :class:`Final`, :class:`SettlingTime`
and :class:`CrossingTime`. Any Python callable of the same form works too;
the store records a callable by its module and qualified name. :class:`Final`
and :class:`Max` evaluate a pointwise series (:class:`PointingError`,
:class:`NutationAngle`) at the output times they read only.

Angles are in rad, times in s.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

from tumble import attitude
from tumble._validate import ValidationError, as_array
from tumble.trajectory import Trajectory

__all__ = ["PointingError", "NutationAngle", "Component", "Max", "Final", "SettlingTime", "CrossingTime",
           "describe"]


def describe(function: Callable[[Trajectory], np.ndarray]) -> str:
    """How a sweep's store records an outcome or series: its repr for the built-in ones (their parameters),
    ``module:qualname`` for a Python function."""
    if isinstance(function, (PointingError, NutationAngle, Component, Max, Final, SettlingTime, CrossingTime)):
        return repr(function)
    if not callable(function):
        raise ValidationError(f"outcomes: must be callables f(traj), got {type(function).__name__}")
    return f"{getattr(function, '__module__', '?')}:{getattr(function, '__qualname__', type(function).__name__)}"


@dataclass(frozen=True)
class PointingError:
    """Series: the angle θ = ∠(q_target* ⊗ q) ∈ [0, π] (rad) of the rotation from the target attitude
    ``target`` (unit quaternion [w, x, y, z], body → inertial) to the attitude ``q``
    (:func:`tumble.attitude.relative_angle`, the geodesic distance on SO(3))."""

    target: tuple = (1.0, 0.0, 0.0, 0.0)

    def __post_init__(self):
        q = as_array(self.target, "target", tail=(4,))
        if q.shape != (4,) or np.linalg.norm(q) == 0:
            raise ValidationError(f"target: must be a non-zero quaternion [w, x, y, z], got {q.tolist()}")
        object.__setattr__(self, "target", tuple((q / np.linalg.norm(q)).tolist()))

    def __call__(self, traj: Trajectory) -> np.ndarray:
        return attitude.relative_angle(np.array(self.target), cast(np.ndarray, traj.q))


@dataclass(frozen=True)
class NutationAngle:
    """Series: the angle (rad) between the body axis ``axis`` (body axes) and the system's angular momentum
    ``traj.momentum_body`` (body axes), ``θ = atan2(|a × L|, a · L)``: 0 for a pure spin about ``axis``,
    π/2 when the body turns about an axis across it (a flat spin, for a minor-axis spinner)."""

    axis: tuple = (0.0, 0.0, 1.0)

    def __post_init__(self):
        a = as_array(self.axis, "axis", tail=(3,))
        if a.shape != (3,) or np.linalg.norm(a) == 0:
            raise ValidationError(f"axis: must be a non-zero vector (body axes), got {a.tolist()}")
        object.__setattr__(self, "axis", tuple((a / np.linalg.norm(a)).tolist()))

    def __call__(self, traj: Trajectory) -> np.ndarray:
        from tumble.spacecraft.damper import nutation_angle  # the one implementation

        return nutation_angle(traj, self.axis)


@dataclass(frozen=True)
class Component:
    """Series: a sampled field (``"omega"``, ``"energy"``, ...) or extra (``"wheel_speed"``, ...) of the
    trajectory, with ``index`` picking a component of its trailing axes (e.g. ``index=1`` for ω_y)."""

    name: str
    index: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "index", tuple(np.atleast_1d(self.index).astype(int).tolist())
                           if np.size(self.index) else ())

    def __call__(self, traj: Trajectory) -> np.ndarray:
        try:
            data = getattr(traj, self.name)
        except AttributeError:
            data = None
        if not isinstance(data, np.ndarray) or data.ndim < 2:
            fields = sorted(name for name in ("omega", "q", "energy", "momentum_body", "momentum_inertial")
                            if getattr(traj, name, None) is not None) + sorted(traj.extras)
            raise ValidationError(f"name: the trajectory has no sampled field {self.name!r} (it has "
                                  f"{', '.join(fields)})")
        components = data.shape[2:]
        if len(self.index) != len(components) or any(not -n <= i < n for i, n in
                                                       zip(self.index, components, strict=True)):
            raise ValidationError(f"index: {self.name} has components of shape {components}: give one index "
                                  f"per axis, each in range, got {list(self.index)}")
        return data[(slice(None), slice(None), *self.index)]


def _series_of(of, traj: Trajectory) -> np.ndarray:
    values = np.asarray(of(traj), dtype=np.float64)
    lead = traj.q.shape[:2] if traj.q is not None else traj.energy.shape[:2]
    if values.shape != lead:
        raise ValidationError(f"of: a series must give one value per output time and sample {lead}, "
                              f"got shape {values.shape}")
    return values


#: The series whose value at an output time depends on the state at that time only.
_POINTWISE = (PointingError, NutationAngle)


def _series_at(of, traj: Trajectory, index) -> np.ndarray:
    """The series ``of`` at the output samples ``index`` (:meth:`Trajectory.at`), (len(index), m): a
    pointwise series is evaluated there only (the same numbers, elementwise, for a fraction of the work);
    any other (a drift, a running integral, a user's function) on the whole run, then cut."""
    if isinstance(of, _POINTWISE):
        return _series_of(of, traj.at(index))
    return _series_of(of, traj)[index]


@dataclass(frozen=True)
class Max:
    """Outcome: the largest value of the series ``of`` at output times ``t >= after`` (s)."""

    of: object
    after: float = -np.inf

    def __call__(self, traj: Trajectory) -> np.ndarray:
        keep = np.flatnonzero(traj.t >= self.after)
        if not keep.size:
            raise ValidationError(f"after: no output time at or after {self.after} s (the last is {traj.t[-1]} s)")
        return _series_at(self.of, traj, keep).max(axis=0)


@dataclass(frozen=True)
class Final:
    """Outcome: the value of the series ``of`` at the last output time."""

    of: object

    def __call__(self, traj: Trajectory) -> np.ndarray:
        return _series_at(self.of, traj, [-1])[0]


@dataclass(frozen=True)
class SettlingTime:
    """Outcome: the settling time (s) of the series ``of`` to ``|x| <= below``: the first output time from
    which it stays there to the end of the run; NaN if it is not there at the end."""

    of: object
    below: float

    def __call__(self, traj: Trajectory) -> np.ndarray:
        outside = np.abs(_series_of(self.of, traj)) > self.below
        n = len(traj.t)
        last_out = n - 1 - np.argmax(outside[::-1], axis=0)  # last index outside the band (if any)
        first_in = np.where(outside.any(axis=0), last_out + 1, 0)
        return np.where(first_in < n, traj.t[np.minimum(first_in, n - 1)], np.nan)


@dataclass(frozen=True)
class CrossingTime:
    """Outcome: the first output time (s) at which the series ``of`` is ``>= above``; NaN if it never is."""

    of: object
    above: float

    def __call__(self, traj: Trajectory) -> np.ndarray:
        reached = _series_of(self.of, traj) >= self.above
        return np.where(reached.any(axis=0), traj.t[np.argmax(reached, axis=0)], np.nan)
