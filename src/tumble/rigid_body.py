"""Rigid bodies: mass, centre of mass, inertia tensor, principal axes, shapes and composites.

Conventions (``docs/conventions.md``): SI units (kg, m, kg·m²). A body is
described in its *reference axes* B (its body axes). ``inertia`` is the 3×3
tensor about the centre of mass in B; ``com`` is the position of the centre
of mass in B (m), or ``None`` when unknown. The principal axes P are the
columns of ``axes = R_BP``, so ``inertia = R_BP diag(moments) R_BPᵀ``.

A rotation ``R`` given to :meth:`RigidBody.placed`, :meth:`Part.placed` or
:meth:`RigidBody.rotated` is a 3×3 proper rotation matrix or a unit
quaternion ``[w, x, y, z]`` (scalar first, Hamilton), converted by the one
quaternion kernel :func:`tumble._quat.qto_matrix`.

Formulas of the shape constructors are those of the table of mass moments of
inertia of homogeneous solids in standard texts, e.g. R. C. Hibbeler,
*Engineering Mechanics: Dynamics* (inside back cover), or the "List of
moments of inertia" (Wikipedia).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._inertia import as_rotation, as_shape, check_inertia, frozen, parallel_axis, principal_axes  # noqa: F401 (re-exported: tumble.rigid_body.principal_axes)
from tumble._validate import ValidationError, as_array, require_positive

__all__ = ["RigidBody", "Part"]

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}

#: The model interface a RigidBody had when it was its own model (before 0.4): each name still answers, for one
#: release, as the body's model (``tumble.as_model(body)``) does, with a DeprecationWarning.
_MODEL_INTERFACE = frozenset({"state_fields", "compile", "initial_states", "outputs", "check_run", "invariants",
                              "batch_size", "torque"})


def _positive_vector(value, name: str) -> np.ndarray:
    """``value`` as a (3,) array whose entries are all > 0."""
    arr = as_shape(value, name, (3,))
    if (arr <= 0.0).any():
        raise ValidationError(f"{name}: each entry must be > 0, got {arr.tolist()}")
    return arr


def _axis_index(axis: str) -> int:
    try:
        return _AXIS_INDEX[axis]
    except (KeyError, TypeError):
        raise ValidationError(f"axis: must be 'x', 'y' or 'z', got {axis!r}") from None


def _axisymmetric(axial: float, transverse: float, axis: str) -> np.ndarray:
    """diag of ``transverse`` with ``axial`` on the symmetry ``axis``."""
    moments = np.full(3, transverse)
    moments[_axis_index(axis)] = axial
    return np.diag(moments)


@dataclass(frozen=True, slots=True, eq=False, kw_only=True)
class Part:
    """A mass element expressed in its parent's axes, ready to be summed by :meth:`RigidBody.composite`.

    ``mass`` (kg, > 0); ``com``, its centre of mass in the parent's axes (m);
    ``inertia``, about ``com`` in the parent's axes (kg·m²), symmetric and
    positive *semi*-definite, so a thin rod or a point mass (zero inertia) is
    a valid part. Made by :meth:`RigidBody.placed`, :meth:`RigidBody.rod`, or
    directly, e.g. a point mass ``Part(mass=m, com=p, inertia=np.zeros((3, 3)))``.
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "mass", require_positive(self.mass, "mass"))
        inertia, _, _ = check_inertia(self.inertia, "inertia", definite=False, check_triangle=False)
        object.__setattr__(self, "com", frozen(as_shape(self.com, "com", (3,))))
        object.__setattr__(self, "inertia", frozen(inertia))

    def placed(self, position: ArrayLike = (0.0, 0.0, 0.0), *, rotation: ArrayLike | None = None) -> Part:
        """This part placed in a new parent: ``com' = p + R com``, ``inertia' = R inertia Rᵀ``.

        ``position`` ``p`` (m) is where this part's origin sits, and
        ``rotation`` ``R`` maps this part's axes to the new parent's axes
        (``v_parent = R v_part``): a 3×3 matrix, a unit quaternion
        ``[w, x, y, z]``, or ``None`` for the identity.
        """
        p = as_shape(position, "position", (3,))
        r = as_rotation(rotation, "rotation")
        return Part(mass=self.mass, com=p + r @ self.com, inertia=r @ self.inertia @ r.T)


class RigidBody:
    """Immutable, validated mass properties of a rigid body: a value, which :func:`tumble.simulate` turns into
    its model (:func:`tumble.as_model`: :class:`tumble.rigid_model.RigidBodies`).

    ``RigidBody(inertia, *, mass=None, com=None, check_triangle=True, name=None)``

    ``inertia`` is the 3×3 tensor about the centre of mass in the body's
    reference axes (kg·m²); ``mass`` (kg) and ``com``, the centre of mass in
    the reference axes (m), are ``None`` when unknown. Refused with
    :class:`~tumble.ValidationError` unless: inertia has shape (3, 3), is
    finite, symmetric (max |I − Iᵀ| ≤ 1e-12 max |I|; then symmetrized
    exactly), positive definite (smallest principal moment > 1e-14 × the
    largest) and, unless ``check_triangle=False`` (for data such as
    published robot link inertias that break it), its principal moments
    satisfy ``I₁ + I₂ ≥ I₃ (1 − 1e-9)``; mass is finite and > 0; com is
    finite with shape (3,).

    Arrays are stored read-only. Two bodies are equal when inertia, mass and
    com are equal (the ``name`` is a label and is not compared).
    """

    __slots__ = ("_inertia", "_moments", "_axes", "_mass", "_com", "_check_triangle", "_name", "_q_bp")
    _inertia: np.ndarray
    _moments: np.ndarray
    _axes: np.ndarray
    _mass: float | None
    _com: np.ndarray | None
    _check_triangle: bool
    _name: str | None
    _q_bp: np.ndarray | None

    #: How a body becomes its model, registered by :mod:`tumble.rigid_model` (the model builds on this value): what the
    #: deprecated model interface (:data:`_MODEL_INTERFACE`) answers with.
    _model_of: ClassVar[Callable[[RigidBody], Any] | None] = None

    def __init__(self, inertia: ArrayLike, *, mass: float | None = None, com: ArrayLike | None = None,
                 check_triangle: bool = True, name: str | None = None) -> None:
        inertia, moments, axes = check_inertia(inertia, "inertia", definite=True, check_triangle=check_triangle)
        set_ = object.__setattr__
        set_(self, "_inertia", frozen(inertia))
        set_(self, "_moments", frozen(moments))
        set_(self, "_axes", frozen(axes))
        set_(self, "_mass", None if mass is None else require_positive(mass, "mass"))
        set_(self, "_com", None if com is None else frozen(as_shape(com, "com", (3,))))
        set_(self, "_check_triangle", bool(check_triangle))
        set_(self, "_name", name)
        set_(self, "_q_bp", None)  # the quaternion of R_BP, made on first use (the first simulation)

    # -- data ---------------------------------------------------------------

    @property
    def inertia(self) -> np.ndarray:
        """(3, 3) inertia tensor about the centre of mass in body axes (kg·m²), read-only."""
        return self._inertia

    @property
    def moments(self) -> np.ndarray:
        """(3,) principal moments of inertia ``I₁ ≤ I₂ ≤ I₃`` (kg·m²), read-only."""
        return self._moments

    @property
    def axes(self) -> np.ndarray:
        """(3, 3) ``R_BP``: column i is principal axis i in body axes; det +1, read-only.

        ``inertia = axes @ diag(moments) @ axes.T`` to rounding. Deterministic:
        each column's largest-magnitude component is positive, except that
        the third column is flipped when needed for det +1.
        """
        return self._axes

    @property
    def axes_quaternion(self) -> np.ndarray:
        """(4,) the unit quaternion ``q_BP`` ``[w, x, y, z]`` of :attr:`axes` (principal → body axes), read-only."""
        q_bp = self._q_bp
        if q_bp is None:
            q_bp = frozen(attitude.from_matrix(self._axes))
            object.__setattr__(self, "_q_bp", q_bp)
        return q_bp

    @property
    def mass(self) -> float | None:
        """Mass (kg), or ``None`` when unknown."""
        return self._mass

    @property
    def com(self) -> np.ndarray | None:
        """(3,) centre of mass in body axes (m), read-only, or ``None`` when unknown."""
        return self._com

    @property
    def name(self) -> str | None:
        """Optional label."""
        return self._name

    def symmetry(self, *, rtol: float = 1e-9) -> str:
        """Kind of body from its moments, two being equal when they differ by ≤ ``rtol`` × ``I₃``.

        ``"spherical"`` (I₁ = I₂ = I₃), ``"oblate"`` symmetric top (I₁ = I₂ < I₃,
        symmetry axis ``axes[:, 2]``), ``"prolate"`` symmetric top
        (I₁ < I₂ = I₃, symmetry axis ``axes[:, 0]``) or ``"asymmetric"``.
        """
        i1, i2, i3 = self._moments
        low, high = i2 - i1 <= rtol * i3, i3 - i2 <= rtol * i3
        if low and high:
            return "spherical"
        if low:
            return "oblate"
        if high:
            return "prolate"
        return "asymmetric"

    # -- changes of description ---------------------------------------------

    def principal(self) -> RigidBody:
        """The same body described in its principal axes: ``inertia = diag(moments)``, ``com_P = axesᵀ com``."""
        com = None if self._com is None else self._axes.T @ self._com
        return RigidBody(
            np.diag(self._moments), mass=self._mass, com=com, check_triangle=self._check_triangle, name=self._name
        )

    def rotated(self, rotation: ArrayLike) -> RigidBody:
        """The same body described in axes rotated by ``R``.

        ``R`` maps new-axes components to old-axes components
        (``v_old = R v_new``; the new axes are the old ones rotated by ``R``),
        so ``I_new = Rᵀ I_old R`` and ``com_new = Rᵀ com_old``. ``rotation``
        is a 3×3 proper rotation matrix or a unit quaternion ``[w, x, y, z]``.
        """
        r = as_rotation(rotation, "rotation")
        com = None if self._com is None else r.T @ self._com
        return RigidBody(
            r.T @ self._inertia @ r, mass=self._mass, com=com, check_triangle=self._check_triangle, name=self._name
        )

    def inertia_about(self, point: ArrayLike) -> np.ndarray:
        """(3, 3) inertia about ``point`` (m, body axes), in body axes (kg·m²).

        Parallel-axis theorem: ``I_P = I + m (|d|² E − d dᵀ)``, ``d = com − point``.
        Needs ``mass`` and ``com``.
        """
        if self._mass is None or self._com is None:
            raise ValidationError(
                f"inertia_about: needs the body's mass and com (mass={self._mass}, com={self._com})"
            )
        point = as_shape(point, "point", (3,))
        return self._inertia + parallel_axis(self._mass, self._com - point)

    # -- composites ---------------------------------------------------------

    def placed(self, position: ArrayLike = (0.0, 0.0, 0.0), *, rotation: ArrayLike | None = None) -> Part:
        """This body as a :class:`Part` of a composite, its reference origin at ``position``.

        ``position`` (m) is in the composite's axes; ``rotation`` ``R`` maps
        this body's axes to the composite's (``v_composite = R v_body``): a
        3×3 matrix, a unit quaternion ``[w, x, y, z]`` or ``None``
        (identity). The part's centre of mass sits at ``position + R com``
        (``com=None`` is read as the reference origin) and its inertia is
        ``R inertia Rᵀ``. The body must have a mass.
        """
        if self._mass is None:
            raise ValidationError("mass: a body placed as a part of a composite needs a mass (got mass=None)")
        com = np.zeros(3) if self._com is None else self._com
        return Part(mass=self._mass, com=com, inertia=self._inertia).placed(position, rotation=rotation)

    @classmethod
    def composite(cls, parts: Iterable[Part | RigidBody], *, check_triangle: bool = True,
                  name: str | None = None) -> RigidBody:
        """Rigid union of parts (:class:`Part`, or a body placed at the origin).

        ``m = Σ mₖ``; ``c = Σ mₖ cₖ / m``;
        ``I = Σ [Iₖ + mₖ (|dₖ|² E − dₖ dₖᵀ)]``, ``dₖ = cₖ − c``, where ``cₖ``
        and ``Iₖ`` are part k's centre of mass and inertia in the composite's
        axes (``Iₖ = Rₖ I_k,own Rₖᵀ``, see :meth:`placed`). The result's
        ``com`` is ``c`` and its ``inertia`` is about ``c``, both in the
        composite's axes; it must be positive definite.
        """
        parts = list(parts)
        if not parts:
            raise ValidationError("parts: a composite needs at least one part")
        for k, part in enumerate(parts):
            if isinstance(part, RigidBody):
                parts[k] = part.placed()
            elif not isinstance(part, Part):
                raise ValidationError(f"parts[{k}]: must be a Part or a RigidBody, got {type(part).__name__}")
        masses = np.array([p.mass for p in parts])
        coms = np.array([p.com for p in parts])
        mass = masses.sum()
        com = masses @ coms / mass
        inertia = sum(p.inertia for p in parts) + parallel_axis(masses, coms - com)
        return cls(inertia, mass=mass, com=com, check_triangle=check_triangle, name=name)

    # -- shapes ---------------------------------------------------------------

    @classmethod
    def sphere(cls, *, mass: float, radius: float) -> RigidBody:
        """Solid uniform sphere centred on the origin: ``I = (2/5) m r²`` about every axis."""
        m, r = require_positive(mass, "mass"), require_positive(radius, "radius")
        return cls(np.eye(3) * (0.4 * m * r * r), mass=m, com=np.zeros(3))

    @classmethod
    def hollow_sphere(cls, *, mass: float, radius: float) -> RigidBody:
        """Thin uniform spherical shell centred on the origin: ``I = (2/3) m r²`` about every axis."""
        m, r = require_positive(mass, "mass"), require_positive(radius, "radius")
        return cls(np.eye(3) * (2.0 / 3.0 * m * r * r), mass=m, com=np.zeros(3))

    @classmethod
    def cylinder(cls, *, mass: float, radius: float, length: float, axis: str = "z") -> RigidBody:
        """Solid uniform circular cylinder centred on the origin, its axis along ``axis``.

        Axial ``m r²/2``; transverse ``m (3 r² + L²)/12``.
        """
        m, r = require_positive(mass, "mass"), require_positive(radius, "radius")
        L = require_positive(length, "length")
        inertia = _axisymmetric(m * r * r / 2.0, m * (3.0 * r * r + L * L) / 12.0, axis)
        return cls(inertia, mass=m, com=np.zeros(3))

    @classmethod
    def hollow_cylinder(cls, *, mass: float, inner_radius: float, outer_radius: float, length: float,
                        axis: str = "z") -> RigidBody:
        """Thick-walled uniform tube centred on the origin, its axis along ``axis``.

        Axial ``m (r₁² + r₂²)/2``; transverse ``m (3 (r₁² + r₂²) + L²)/12``.
        ``inner_radius = 0`` is the solid cylinder; ``inner_radius =
        outer_radius`` the thin shell (axial ``m r²``, transverse ``m (6 r² + L²)/12``).
        """
        m, L = require_positive(mass, "mass"), require_positive(length, "length")
        r2 = require_positive(outer_radius, "outer_radius")
        r1 = float(as_shape(inner_radius, "inner_radius", ()))
        if not 0.0 <= r1 <= r2:
            raise ValidationError(f"inner_radius: must satisfy 0 <= inner_radius <= outer_radius = {r2}, got {r1}")
        s = r1 * r1 + r2 * r2
        return cls(_axisymmetric(m * s / 2.0, m * (3.0 * s + L * L) / 12.0, axis), mass=m, com=np.zeros(3))

    @classmethod
    def box(cls, *, mass: float, size: ArrayLike) -> RigidBody:
        """Solid uniform cuboid centred on the origin, edges ``size = (a, b, c)`` (m) along x, y, z.

        ``Ixx = m (b² + c²)/12``, ``Iyy = m (a² + c²)/12``, ``Izz = m (a² + b²)/12``.
        """
        m = require_positive(mass, "mass")
        sq = _positive_vector(size, "size") ** 2
        return cls(np.diag(m * (sq.sum() - sq) / 12.0), mass=m, com=np.zeros(3))

    @classmethod
    def ellipsoid(cls, *, mass: float, semi_axes: ArrayLike) -> RigidBody:
        """Solid uniform ellipsoid centred on the origin, semi-axes ``(a, b, c)`` (m) along x, y, z.

        ``Ixx = m (b² + c²)/5``, ``Iyy = m (a² + c²)/5``, ``Izz = m (a² + b²)/5``.
        """
        m = require_positive(mass, "mass")
        sq = _positive_vector(semi_axes, "semi_axes") ** 2
        return cls(np.diag(m * (sq.sum() - sq) / 5.0), mass=m, com=np.zeros(3))

    @classmethod
    def rod(cls, *, mass: float, length: float, axis: str = "z") -> Part:
        """Thin uniform rod centred on the origin along ``axis``, as a :class:`Part`.

        Transverse ``m L²/12``; zero about its own axis. Because that makes
        its inertia singular, a rod is not a :class:`RigidBody` on its own:
        it returns a :class:`Part` (place it with :meth:`Part.placed`) to be
        combined by :meth:`composite`, whose result must be positive definite.
        """
        m, L = require_positive(mass, "mass"), require_positive(length, "length")
        return Part(mass=m, com=np.zeros(3), inertia=_axisymmetric(0.0, m * L * L / 12.0, axis))

    @classmethod
    def point_masses(cls, masses: ArrayLike, positions: ArrayLike, *, check_triangle: bool = True) -> RigidBody:
        """Rigid cloud of point masses ``mₖ`` (kg) at ``positions`` ``rₖ`` (m), shape (n,) and (n, 3).

        ``com = Σ mₖ rₖ / Σ mₖ``; ``inertia = Σ mₖ (|dₖ|² E − dₖ dₖᵀ)``,
        ``dₖ = rₖ − com`` (about the centre of mass). At least three
        non-collinear points are needed for a positive definite inertia.
        """
        masses = as_array(masses, "masses")
        positions = as_array(positions, "positions", tail=(3,))
        if masses.ndim != 1 or positions.shape != (masses.size, 3):
            raise ValidationError(
                f"positions: must have shape (n, 3) for masses of shape (n,), "
                f"got {positions.shape} and {masses.shape}"
            )
        if (masses <= 0.0).any():
            raise ValidationError(f"masses: each must be > 0, got {masses.tolist()}")
        mass = masses.sum()
        com = masses @ positions / mass
        return cls(parallel_axis(masses, positions - com), mass=mass, com=com, check_triangle=check_triangle)

    @classmethod
    def t_handle(
        cls,
        *,
        handle_mass: float = 0.03,
        handle_length: float = 0.08,
        bar_mass: float = 0.02,
        bar_length: float = 0.08,
        radius: float = 0.004,
    ) -> RigidBody:
        """T-handle ("wing nut") of the Dzhanibekov / tennis-racket demonstration.

        A solid cylinder handle along x from the origin to ``handle_length``
        and a solid cylinder cross bar along y centred on the handle's end,
        both of ``radius`` (m). The defaults (8 cm handle and bar, 50 g) give
        moments ≈ (1.10, 3.55, 4.61)e-5 kg·m² about x, y, z: clearly distinct,
        with y (along the bar) the unstable intermediate axis.
        """
        for value, field in [
            (handle_mass, "handle_mass"),
            (handle_length, "handle_length"),
            (bar_mass, "bar_mass"),
            (bar_length, "bar_length"),
        ]:
            require_positive(value, field)
        handle = cls.cylinder(mass=handle_mass, radius=radius, length=handle_length, axis="x")
        bar = cls.cylinder(mass=bar_mass, radius=radius, length=bar_length, axis="y")
        parts = [handle.placed((0.5 * handle_length, 0.0, 0.0)), bar.placed((handle_length, 0.0, 0.0))]
        return cls.composite(parts, name="t_handle")

    # -- protocol -------------------------------------------------------------

    def __setattr__(self, name, value):
        raise AttributeError(f"RigidBody is immutable: cannot set {name!r}")

    def __delattr__(self, name):
        raise AttributeError(f"RigidBody is immutable: cannot delete {name!r}")

    def __getattr__(self, name: str) -> Any:
        """The deprecated model interface of :data:`_MODEL_INTERFACE`, answered by the body's model."""
        model_of = RigidBody._model_of
        if name not in _MODEL_INTERFACE or model_of is None:
            raise AttributeError(f"'RigidBody' object has no attribute {name!r}")
        warnings.warn(f"RigidBody.{name} is deprecated: a RigidBody is a value, and tumble.as_model(body) is its "
                      f"model; use tumble.as_model(body).{name}", DeprecationWarning, stacklevel=2)
        return getattr(model_of(self), name)

    def __reduce__(self):
        return (_rebuild, (self._inertia, self._mass, self._com, self._check_triangle, self._name))

    def __eq__(self, other):
        if not isinstance(other, RigidBody):
            return NotImplemented
        same_com = (self._com is None and other._com is None) or (
            self._com is not None and other._com is not None and np.array_equal(self._com, other._com)
        )
        return np.array_equal(self._inertia, other._inertia) and self._mass == other._mass and same_com

    def __hash__(self):
        return hash((self._moments.tobytes(), self._mass))

    def __repr__(self):
        moments = ", ".join(f"{m:.6g}" for m in self._moments)
        mass = "None" if self._mass is None else f"{self._mass:.6g} kg"
        name = "" if self._name is None else f", name={self._name!r}"
        return f"RigidBody(moments=[{moments}] kg m^2, mass={mass}{name})"


def _rebuild(inertia, mass, com, check_triangle, name):
    """Unpickle a :class:`RigidBody` (re-validated, so a stored body is still checked)."""
    return RigidBody(inertia, mass=mass, com=com, check_triangle=check_triangle, name=name)
