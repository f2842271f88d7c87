"""A link of a serial chain: one joint and the rigid body it moves.

Conventions (``docs/robot.md``): SI units (m, rad, kg, kg·m²). Frame 0 is the
fixed base; link frame i is attached to link i, the body moved by joint i
(i = 1…n, stored 0-based). Each :class:`Link` gives

* the pose of its *joint frame* (before motion) in the previous link frame:
  ``origin_position`` p_o and ``origin_rotation`` R_o (columns: joint axes in
  the previous link axes, ``v_prev = R_o v_joint + p_o``);
* the joint: ``"revolute"`` (rotation ``θ = q + offset`` about ``axis``) or
  ``"prismatic"`` (translation ``d = q + offset`` along ``axis``), ``axis``
  a unit vector in the joint frame (any direction, including negative ones);
* the pose of the *link frame* in the moved joint frame, ``frame_position``
  p_f and ``frame_rotation`` R_f (identity for URDF and modified DH; the
  ``Tz(d) Tx(a) Rx(α)`` of standard DH);
* its mass (kg, ≥ 0), centre of mass ``com`` (m) and inertia tensor about the
  centre of mass (kg·m², 3×3), both in the link frame.

So link frame i = link frame i−1 · (R_o, p_o) · joint(q_i) · (R_f, p_f).
The chain readers (:mod:`tumble.robot.chain` for DH tables,
:mod:`tumble.robot.urdf`) build links; :class:`tumble.robot.SerialChain`
strings them together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tumble._inertia import as_rotation, as_shape, frozen, principal_axes
from tumble._validate import ValidationError

__all__ = ["JOINT_TYPES", "Frame", "Link"]

JOINT_TYPES = ("revolute", "prismatic", "floating")  # "floating": the free base of a RobotTree only
# A joint axis is normalised; one shorter than this (m or 1) is refused as undefined.
_MIN_AXIS_NORM = 1e-9


class Frame(NamedTuple):
    """A named frame fixed to body ``body`` (−1: the base): ``rotation`` (3, 3) maps frame axes to the body's link
    axes, ``position`` (3,) is its origin in the link frame (m)."""

    name: str
    body: int
    rotation: np.ndarray
    position: np.ndarray


@dataclass(frozen=True, slots=True, eq=False, kw_only=True)
class Link:
    """One joint and the rigid link it moves (see the module docstring for the frames).

    ``inertia`` must be symmetric and positive semi-definite (a massless or
    slender link is allowed; the chain's mass matrix must still be positive
    definite), with principal moments that satisfy the triangle inequality
    unless ``check_triangle=False`` (published link inertias sometimes break
    it): the rules of :func:`tumble.rigid_body.principal_axes`. ``lower`` ≤
    ``upper`` are the joint limits (rad or m, on ``q``; ±inf when unlimited).
    """

    # The array fields take array_like values (the tuple defaults) and hold read-only float64 arrays once
    # __post_init__ has converted them: a conversion mypy does not follow, hence the ignores.
    joint: str = "revolute"
    axis: np.ndarray = (0.0, 0.0, 1.0)  # type: ignore[assignment]
    origin_position: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    origin_rotation: np.ndarray | None = None
    frame_position: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    frame_rotation: np.ndarray | None = None
    offset: float = 0.0
    mass: float = 0.0
    com: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    inertia: np.ndarray = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # type: ignore[assignment]
    lower: float = -math.inf
    upper: float = math.inf
    name: str | None = None
    check_triangle: bool = True

    def __post_init__(self):
        where = "link" if self.name is None else f"link {self.name!r}"
        set_ = object.__setattr__
        if self.joint not in JOINT_TYPES:
            raise ValidationError(f"{where}.joint: must be one of {JOINT_TYPES}, got {self.joint!r}")
        axis = as_shape(self.axis, f"{where}.axis", (3,))
        # scaled before squaring: the norm of (1e200, 1e200, 0) overflowed to inf and the axis became zero
        largest = float(np.abs(axis).max())
        scaled = axis / largest if largest > 0.0 else axis
        if largest * float(np.linalg.norm(scaled)) < _MIN_AXIS_NORM:
            raise ValidationError(f"{where}.axis: must be a non-zero vector, got {axis.tolist()}")
        set_(self, "axis", frozen(scaled / np.linalg.norm(scaled)))
        for field in ("origin", "frame"):
            set_(self, f"{field}_position", frozen(as_shape(getattr(self, f"{field}_position"),
                                                              f"{where}.{field}_position", (3,))))
            set_(self, f"{field}_rotation", frozen(as_rotation(getattr(self, f"{field}_rotation"),
                                                                 f"{where}.{field}_rotation")))
        set_(self, "offset", float(as_shape(self.offset, f"{where}.offset", ())))
        mass = float(as_shape(self.mass, f"{where}.mass", ()))
        if mass < 0.0:
            raise ValidationError(f"{where}.mass: must be >= 0 kg, got {mass}")
        set_(self, "mass", mass)
        set_(self, "com", frozen(as_shape(self.com, f"{where}.com", (3,))))
        inertia = as_shape(self.inertia, f"{where}.inertia", (3, 3))
        inertia, _, _ = principal_axes(inertia, f"{where}.inertia", definite=False,
                                       check_triangle=self.check_triangle)
        set_(self, "inertia", frozen(inertia))
        lower, upper = float(self.lower), float(self.upper)
        if math.isnan(lower) or math.isnan(upper) or lower > upper:
            raise ValidationError(f"{where}.lower/upper: must satisfy lower <= upper, got {lower} and {upper}")
        set_(self, "lower", lower)
        set_(self, "upper", upper)
