"""What the viewer draws a body as: triangle meshes of boxes and cylinders, and the box of an inertia tensor.

A :class:`Mesh` is a triangle mesh in a solid's own axes (m). A user's
shape is given as :class:`Box` and :class:`Cylinder` pieces placed in the
body's reference axes (the axes of ``RigidBody.com``), as the composite
bodies of :meth:`tumble.RigidBody.composite` are; the viewer draws them about
the centre of mass. Without a shape, a body is drawn as the **uniform box with
the same principal moments** (:func:`equivalent_box`), the honest picture of
an inertia tensor: for a box of mass ``m`` and sides ``a₁, a₂, a₃`` along its
principal axes, ``I₁ = m (a₂² + a₃²)/12`` (and cyclic), so

    aᵢ² = 6 (Iⱼ + Iₖ − Iᵢ) / m,

real wherever the moments satisfy the triangle inequality ``Iⱼ + Iₖ ≥ Iᵢ``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tumble._inertia import as_rotation, as_shape, principal_axes
from tumble._validate import ValidationError, require_positive

__all__ = ["Box", "Cylinder", "Mesh", "body_mesh", "box_mesh", "cylinder_mesh", "ellipsoid_mesh", "equivalent_box",
           "turn_z_to"]

#: Sides of the equivalent box shorter than this fraction of the longest are drawn at it (a body at the
#: edge of the triangle inequality, a flat plate, would otherwise be drawn with no thickness).
MIN_SIDE = 0.02
#: Flat facets around a cylinder.
SECTIONS = 24
_AXES = {"x": 0, "y": 1, "z": 2}


class Mesh(NamedTuple):
    """A triangle mesh: ``vertices`` (V, 3) in m, ``faces`` (F, 3) vertex indices, counter-clockwise seen from
    outside."""

    vertices: np.ndarray
    faces: np.ndarray

    def moved(self, rotation: np.ndarray, position) -> Mesh:
        """The mesh turned by ``rotation`` (3, 3) and then shifted by ``position`` (3,), m: ``v' = R v + p``."""
        return Mesh(self.vertices @ np.asarray(rotation).T + np.asarray(position), self.faces)

    @staticmethod
    def join(meshes: Sequence[Mesh]) -> Mesh:
        """One mesh of several (faces re-indexed)."""
        offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
        return Mesh(np.concatenate([m.vertices for m in meshes]),
                    np.concatenate([m.faces + k for m, k in zip(meshes, offsets)]))


def box_mesh(size) -> Mesh:
    """A box of sides ``size`` (3,), m, centred on the origin, edges along the axes: 8 vertices, 12 triangles."""
    half = 0.5 * np.asarray(size, dtype=np.float64)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64) * half
    faces = np.array([[0, 1, 2], [1, 3, 2], [4, 6, 5], [5, 6, 7],      # x = -, +
                      [0, 4, 1], [1, 4, 5], [2, 3, 6], [3, 7, 6],      # y = -, +
                      [0, 2, 4], [2, 6, 4], [1, 5, 3], [3, 5, 7]])     # z = -, +
    return Mesh(corners, faces)


def cylinder_mesh(radius: float, length: float, sections: int = SECTIONS) -> Mesh:
    """A closed cylinder of ``radius`` and ``length`` (m) along z, centred on the origin."""
    angle = 2.0 * math.pi * np.arange(sections) / sections
    ring = np.stack([radius * np.cos(angle), radius * np.sin(angle), np.zeros(sections)], axis=1)
    bottom, top = ring - [0.0, 0.0, 0.5 * length], ring + [0.0, 0.0, 0.5 * length]
    centres = np.array([[0.0, 0.0, -0.5 * length], [0.0, 0.0, 0.5 * length]])
    k = np.arange(sections)
    nxt = (k + 1) % sections
    side = np.concatenate([np.stack([k, nxt, sections + k], 1), np.stack([nxt, sections + nxt, sections + k], 1)])
    caps = np.concatenate([np.stack([np.full(sections, 2 * sections), nxt, k], 1),
                           np.stack([np.full(sections, 2 * sections + 1), sections + k, sections + nxt], 1)])
    return Mesh(np.concatenate([bottom, top, centres]), np.concatenate([side, caps]))


def turn_z_to(axis) -> np.ndarray:
    """A rotation taking the z axis onto the unit vector ``axis`` (the shortest turn; x to x for z itself)."""
    a = np.asarray(axis, dtype=np.float64)
    z = np.array([0.0, 0.0, 1.0])
    c = float(a @ z)
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross(z, a)
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + k + k @ k / (1.0 + c)   # Rodrigues' formula for unit vectors z → a


@dataclass(frozen=True)
class Box:
    """A box piece of a body's shape: ``size`` (3,) sides, m, centred at ``position`` (m, body reference
    axes), its edges along ``rotation`` (None: the body axes; a 3×3 matrix or unit quaternion, piece → body)."""

    size: object
    position: object = (0.0, 0.0, 0.0)
    rotation: object = None

    def mesh(self) -> Mesh:
        size = as_shape(self.size, "size", (3,))
        if np.any(size <= 0.0):
            raise ValidationError(f"size: every side must be > 0 m, got {size.tolist()}")
        return box_mesh(size).moved(as_rotation(self.rotation, "rotation"), as_shape(self.position, "position", (3,)))


@dataclass(frozen=True)
class Cylinder:
    """A solid cylinder piece of a body's shape: ``radius`` and ``length`` (m) along body ``axis`` ("x", "y",
    "z" or a vector), centred at ``position`` (m, body reference axes)."""

    radius: float
    length: float
    axis: object = "z"
    position: object = (0.0, 0.0, 0.0)

    def mesh(self) -> Mesh:
        radius, length = require_positive(self.radius, "radius"), require_positive(self.length, "length")
        if isinstance(self.axis, str):
            if self.axis not in _AXES:
                raise ValidationError(f"axis: must be 'x', 'y', 'z' or a vector, got {self.axis!r}")
            axis = np.eye(3)[_AXES[self.axis]]
        else:
            axis = as_shape(self.axis, "axis", (3,))
            norm = float(np.linalg.norm(axis))
            if norm == 0.0:
                raise ValidationError("axis: must be a non-zero vector")
            axis = axis / norm
        return cylinder_mesh(radius, length).moved(turn_z_to(axis), as_shape(self.position, "position", (3,)))


def equivalent_box(moments, mass: float) -> np.ndarray:
    """Sides (3,), m, of the uniform box of ``mass`` (kg) with the principal ``moments`` (3,), kg·m²:
    ``aᵢ = √(6 (Iⱼ + Iₖ − Iᵢ)/m)``, each at least :data:`MIN_SIDE` × the longest."""
    i1, i2, i3 = np.asarray(moments, dtype=np.float64)
    squares = 6.0 / mass * np.array([i2 + i3 - i1, i1 + i3 - i2, i1 + i2 - i3])
    sides = np.sqrt(np.maximum(squares, 0.0))
    return np.maximum(sides, MIN_SIDE * sides.max())


def body_mesh(inertia, *, mass: float | None = None, com=None, shape=None) -> tuple[Mesh, str]:
    """The mesh of a body in its axes about the centre of mass, and a sentence saying what it is.

    ``shape``: a :class:`Box`, a :class:`Cylinder` or a sequence of them in the body's reference axes (drawn
    about ``com``, m, when given); None: the equivalent box of ``inertia`` (3, 3), kg·m², body axes, for
    ``mass`` (kg; 1 kg when unknown: then the proportions are the inertia's, the size is not).
    """
    if shape is not None:
        pieces = list(shape) if isinstance(shape, (list, tuple)) else [shape]
        for k, piece in enumerate(pieces):
            if not isinstance(piece, (Box, Cylinder)):
                raise ValidationError(f"shape[{k}]: must be a tumble.viz.viewer.Box or Cylinder, "
                                      f"got {type(piece).__name__}")
        mesh = Mesh.join([piece.mesh() for piece in pieces])
        centre = np.zeros(3) if com is None else np.asarray(com, dtype=np.float64)
        return Mesh(mesh.vertices - centre, mesh.faces), "the body's shape"
    _, moments, axes = principal_axes(inertia, "inertia", check_triangle=False)
    sides = equivalent_box(moments, 1.0 if mass is None else mass)
    mesh = box_mesh(sides).moved(axes, np.zeros(3))
    note = "the uniform box with the body's principal moments" + (
        "" if mass is not None else " (for 1 kg: its proportions are the inertia's, its size is not)")
    return mesh, note


def ellipsoid_mesh(semi_axes, rings: int = 16, sections: int = SECTIONS) -> Mesh:
    """A closed ellipsoid of ``semi_axes`` (3,) along x, y, z, centred on the origin (latitude-longitude grid)."""
    polar = np.linspace(0.0, math.pi, rings + 1)[1:-1]
    azimuth = 2.0 * math.pi * np.arange(sections) / sections
    sin_p, cos_p = np.sin(polar)[:, None], np.cos(polar)[:, None]
    ring = np.stack([sin_p * np.cos(azimuth), sin_p * np.sin(azimuth), np.repeat(cos_p, sections, axis=1)], -1)
    vertices = np.concatenate([[[0.0, 0.0, 1.0]], ring.reshape(-1, 3), [[0.0, 0.0, -1.0]]])
    k = np.arange(sections)
    nxt = (k + 1) % sections
    faces = [np.stack([np.zeros(sections, int), 1 + k, 1 + nxt], 1)]
    for r in range(rings - 2):
        a, b = 1 + r * sections, 1 + (r + 1) * sections
        faces += [np.stack([a + k, b + k, a + nxt], 1), np.stack([a + nxt, b + k, b + nxt], 1)]
    last, bottom = 1 + (rings - 2) * sections, len(vertices) - 1
    faces.append(np.stack([np.full(sections, bottom), last + nxt, last + k], 1))
    return Mesh(vertices * np.asarray(semi_axes, dtype=np.float64), np.concatenate(faces))
