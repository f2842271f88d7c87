"""Kinematic trees: bodies joined by revolute and prismatic joints, on a fixed or a floating base.

Conventions (``docs/robot.md``): SI units (m, rad, kg, kg·m²). A tree is
given in Featherstone's form (*Rigid Body Dynamics Algorithms*, Springer
2008, §4.1.2): a list of :class:`~tumble.robot.Link` (one joint and the body
it moves) and a parent array ``parents[i] < i`` (−1: the fixed base). The
frames of link i are those of :mod:`tumble.robot.link` with "previous link"
read as "parent link": link frame i = link frame λ(i) · (R_o, p_o) · joint(q_i)
· (R_f, p_f).

*Floating base*: ``links[0]`` with ``joint="floating"`` is a body free in
space (a legged robot in flight, a spacecraft hub). The configuration is
``q = [r (3), quat (4), joints]``: ``r`` the base origin in the world frame
(m), ``quat`` the unit quaternion ``[w, x, y, z]`` of base → world (tumble's
convention); the velocity ``q̇ = [ω (3), v (3), joint rates]``: the base's
angular velocity and the velocity of its origin, both in *base* axes (the
spatial velocity of Featherstone, angular part first). ``τ[0:6]`` is the
wrench ``(n, f)`` on the base, base axes, moment about its origin.

*Mimic joints* (``mimic={i: (j, multiplier, offset)}``) copy the coordinate of
joint j: ``θ_i = multiplier · q_j + offset``. They have no coordinate of their
own, so ``q`` holds the independent coordinates only; the algorithms return
``Gᵀ τ`` and ``Gᵀ M G`` (``θ = G q + offset``), as Pinocchio does.

*Frames*: named frames fixed to a body (URDF links merged by fixed joints,
massless ``base``/``flange``/``tool0``/sensor links): ``Frame(name, body,
rotation, position)``, the pose in the body's link frame (``body = −1``: the
base/world frame). :func:`tumble.robot.frame_poses` and
:func:`tumble.robot.frame_jacobian` use them.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping, Sequence
from typing import Self

import numpy as np
from numpy.typing import ArrayLike

from tumble._inertia import as_rotation, as_shape, frozen, parallel_axis
from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _kernels
from tumble.kernels.featherstone import layout as _columns
from tumble.robot.link import Frame, Link
from tumble.robot.motion import ChainMotion
from tumble.robot.urdf import UrdfRepairWarning, read_urdf

__all__ = ["Frame", "RobotTree", "DEFAULT_GRAVITY"]

DEFAULT_GRAVITY = (0.0, 0.0, -9.81)


class RobotTree(ChainMotion):
    """An immutable, validated kinematic tree of rigid links on a fixed or a floating base.

    ``RobotTree(links, parents, *, gravity=(0, 0, -9.81), name=None, frames=(), mimic=None)``

    ``links``: :class:`Link` in topological order (parents first); ``parents``:
    ``parents[i] < i`` the parent link of link i, −1 for the fixed base; a
    ``links[0]`` with ``joint="floating"`` is a floating base (then every other
    link descends from it). ``gravity``: m/s², world (base) frame. ``frames``:
    :class:`Frame` values; ``mimic``: ``{link index: (copied link index,
    multiplier, offset)}``. Sizes: ``nq`` configuration coordinates, ``nv``
    velocity coordinates (``nq = nv + 1`` with a floating base).
    A tree is a model of :func:`tumble.simulate` (:mod:`tumble.robot.motion`).
    """

    __slots__ = ("_links", "_parents", "_gravity", "_name", "_frames", "_mimic", "_params", "_lower", "_upper",
                 "_no_wrench", "_no_wrenches", "_nq", "_nv", "_floating", "_coordinate_links", "_workspace",
                 "_massless")
    _links: tuple[Link, ...]
    _parents: tuple[int, ...]
    _gravity: np.ndarray  # (3,) m/s², world frame
    _name: str | None
    _frames: tuple[Frame, ...]
    _mimic: dict[int, tuple[int, float, float]]  # {link: (copied link, multiplier, offset)}
    _params: np.ndarray  # (nb, PARAMS): the columns of tumble.kernels.featherstone.layout
    _lower: np.ndarray  # (dof,) read-only
    _upper: np.ndarray
    _no_wrench: np.ndarray  # (6,) zeros
    _no_wrenches: np.ndarray  # (1, 6) zeros
    _nq: int
    _nv: int
    _floating: bool
    _coordinate_links: tuple[int, ...]  # the links of the independent joint coordinates
    _workspace: np.ndarray  # scratch of the single-state entries (tumble.robot.dynamics)
    _massless: tuple[str, ...]  # the joints that move neither mass nor inertia

    def __init__(self, links: Sequence[Link], parents: Sequence[int], *, gravity: ArrayLike = DEFAULT_GRAVITY,
                 name: str | None = None, frames: Sequence[Frame] = (), mimic: Mapping | None = None) -> None:
        links = tuple(links)
        if not links:
            raise ValidationError("links: a robot needs at least one link")
        for k, link in enumerate(links):
            if not isinstance(link, Link):
                raise ValidationError(f"links[{k}]: must be a tumble.robot.Link, got {type(link).__name__}")
        parents = tuple(int(p) for p in parents)
        if len(parents) != len(links):
            raise ValidationError(f"parents: must give one parent per link ({len(links)}), got {len(parents)}")
        floating = links[0].joint == "floating"
        for i, p in enumerate(parents):
            if not -1 <= p < i:
                raise ValidationError(f"parents[{i}]: must be -1 (the base) or a link before it (< {i}), got {p}")
            if i > 0 and links[i].joint == "floating":
                raise ValidationError(f"links[{i}].joint: only links[0] may be 'floating' (the floating base)")
            if floating and i > 0 and p < 0:
                raise ValidationError(f"parents[{i}]: with a floating base every link descends from links[0]")
        mimic = dict(mimic or {})
        coordinate, multiplier, offset = _coordinates(links, mimic, floating)
        set_ = object.__setattr__
        set_(self, "_links", links)
        set_(self, "_parents", parents)
        set_(self, "_gravity", np.array(as_shape(gravity, "gravity", (3,))))
        set_(self, "_name", name)
        set_(self, "_frames", tuple(_frame(f, len(links)) for f in frames))
        set_(self, "_mimic", mimic)
        set_(self, "_floating", floating)
        set_(self, "_params", _pack(links, parents, coordinate, multiplier, offset))
        independent = [i for i in range(len(links)) if i not in mimic and not (floating and i == 0)]
        set_(self, "_coordinate_links", tuple(independent))
        set_(self, "_massless", _massless_joints(links, parents, coordinate, mimic))
        set_(self, "_lower", frozen([links[i].lower for i in independent]))
        set_(self, "_upper", frozen([links[i].upper for i in independent]))
        set_(self, "_no_wrench", np.zeros(6))
        set_(self, "_no_wrenches", np.zeros((1, 6)))
        nv = len(independent) + 6 * floating
        set_(self, "_nv", nv)
        set_(self, "_nq", nv + floating)
        # scratch of the single-state rnea / mass_matrix / forward_dynamics: their compiled code holds the
        # GIL (no nogil) and calls nothing back, so two calls on one model never overlap
        set_(self, "_workspace", _kernels.workspace(len(links), nv))

    @classmethod
    def from_urdf(cls, source: str | os.PathLike[str], *, floating_base: bool = False, mimic: bool = True,
                  check_triangle: bool = True, inertia: str = "check", min_inertia: float = 0.0,
                  gravity: ArrayLike = DEFAULT_GRAVITY) -> RobotTree:
        """A tree from a URDF file (path) or document (a string starting with ``<``); see :mod:`.urdf`.

        ``floating_base=True`` makes the root link a free body (configuration ``[r, quat, joints]``);
        ``mimic=False`` reads ``<mimic>`` joints as independent joints; ``inertia="clip"`` and
        ``min_inertia`` (kg·m²) repair non-physical link inertias (:func:`tumble.robot.urdf.read_urdf`)."""
        d = read_urdf(source, check_triangle=check_triangle, floating_base=floating_base, mimic=mimic,
                      inertia=inertia, min_inertia=min_inertia)
        return cls(d.links, d.parents, gravity=gravity, name=d.name, frames=d.frames, mimic=d.mimic)._warn_massless()

    def _warn_massless(self) -> Self:
        """This robot, after a :class:`~tumble.robot.urdf.UrdfRepairWarning` naming its :attr:`massless_joints`
        when it has any (the readers of robot files call it)."""
        if self._massless:
            warnings.warn(f"{self._name or 'robot'}: joint(s) {list(self._massless)} move no mass or inertia: "
                          "M(q) is singular, so forward dynamics and simulate refuse this robot (torques, gravity "
                          "torques and M(q) are defined; min_inertia gives the links a least inertia)",
                          UrdfRepairWarning, stacklevel=3)
        return self

    # -- data -----------------------------------------------------------------

    @property
    def links(self) -> tuple[Link, ...]:
        """The links, parents first."""
        return self._links

    @property
    def parents(self) -> tuple[int, ...]:
        """``parents[i]``: the parent link of link i (−1: the fixed base or, for the floating base, the world)."""
        return self._parents

    @property
    def floating_base(self) -> bool:
        """True when ``links[0]`` is a floating base."""
        return self._floating

    @property
    def nq(self) -> int:
        """Number of configuration coordinates (7 + joints with a floating base)."""
        return self._nq

    @property
    def nv(self) -> int:
        """Number of velocity coordinates (6 + joints with a floating base)."""
        return self._nv

    @property
    def dof(self) -> int:
        """Number of independent joint coordinates (mimic joints and the floating base excluded)."""
        return len(self._coordinate_links)

    @property
    def joint_names(self) -> tuple[str | None, ...]:
        """Names of the independent joints (one per joint coordinate)."""
        return tuple(self._links[i].name for i in self._coordinate_links)

    @property
    def massless_joints(self) -> tuple[str, ...]:
        """Names of the independent joints that move neither mass nor (for a revolute joint) inertia, with their
        mimic joints: M(q) has a zero row and column for each, for every q (empty for a physical robot)."""
        return self._massless

    @property
    def joint_types(self) -> tuple[str, ...]:
        return tuple(self._links[i].joint for i in self._coordinate_links)

    @property
    def frames(self) -> tuple[Frame, ...]:
        """The named frames (URDF links, merged and massless ones included)."""
        return self._frames

    @property
    def frame_names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self._frames)

    @property
    def mimic(self) -> dict:
        """``{link: (copied link, multiplier, offset)}`` (a copy)."""
        return dict(self._mimic)

    @property
    def gravity(self) -> np.ndarray:
        """(3,) gravitational acceleration in the world (base) frame, m/s² (a copy)."""
        return self._gravity.copy()

    @property
    def name(self) -> str | None:
        return self._name

    @property
    def mass(self) -> float:
        """Total mass, kg."""
        return float(sum(link.mass for link in self._links))

    @property
    def lower(self) -> np.ndarray:
        """(dof,) lower joint limits (rad or m; -inf when unlimited), read-only."""
        return self._lower

    @property
    def upper(self) -> np.ndarray:
        """(dof,) upper joint limits (rad or m; +inf when unlimited), read-only."""
        return self._upper

    @property
    def params(self) -> np.ndarray:
        """(nb, 45) array the compiled algorithms read (columns in :mod:`tumble.kernels.featherstone.layout`), a copy."""
        return self._params.copy()

    def joint_coordinates(self, q: ArrayLike) -> np.ndarray:
        """The joint part ``q[..., nq − dof:]`` of configurations (…, nq) (the floating base's 7 dropped)."""
        q = as_array(q, "q", tail=(self._nq,))
        return q[..., self._nq - self.dof:]

    def within_limits(self, q: ArrayLike) -> np.ndarray | bool:
        """True where ``lower ≤ q ≤ upper`` for every joint; ``q`` of shape (…, nq)."""
        joints = self.joint_coordinates(q)
        ok = np.asarray(((joints >= self._lower) & (joints <= self._upper)).all(axis=-1))
        return bool(ok) if ok.ndim == 0 else ok

    def with_gravity(self, gravity: ArrayLike) -> RobotTree:
        """The same robot under the gravitational acceleration ``gravity`` (3,), m/s², world frame."""
        return RobotTree(self._links, self._parents, gravity=gravity, name=self._name, frames=self._frames,
                         mimic=self._mimic)

    def neutral(self) -> np.ndarray:
        """(nq,) the zero configuration (identity quaternion for a floating base)."""
        q = np.zeros(self._nq)
        if self._floating:
            q[3] = 1.0
        return q

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable: cannot set {name!r}")

    def __reduce__(self):
        """Pickled as what it is built from (links, parents, gravity, name, frames, mimic), so that another
        process (a Dask worker, a resumed sweep) builds the same tree, and the same content digest, without its
        scratch arrays."""
        return _rebuild, (type(self), self._links, self._parents, self._gravity, self._name, self._frames,
                          self._mimic)

    def __repr__(self):
        name = "" if self._name is None else f"{self._name!r}, "
        base = "floating base, " if self._floating else ""
        return (f"{type(self).__name__}({name}{base}{len(self._links)} links, {self.dof} joint coordinates, "
                f"mass={self.mass:.6g} kg)")


def _rebuild(cls: type[RobotTree], links, parents, gravity, name, frames, mimic) -> RobotTree:
    """A tree of class ``cls`` (a subclass too: its own constructor takes other arguments) built by
    :class:`RobotTree`'s constructor, for :meth:`RobotTree.__reduce__`."""
    tree = cls.__new__(cls)
    RobotTree.__init__(tree, links, parents, gravity=gravity, name=name, frames=frames, mimic=mimic)
    return tree


def _frame(frame, nb: int) -> Frame:
    if not isinstance(frame, Frame):
        raise ValidationError(f"frames: must be tumble.robot.Frame values, got {type(frame).__name__}")
    if not -1 <= frame.body < nb:
        raise ValidationError(f"frame {frame.name!r}: body must be -1 (the base) or a link index < {nb}, "
                              f"got {frame.body}")
    return Frame(str(frame.name), int(frame.body), frozen(as_rotation(frame.rotation, f"frame {frame.name!r}")),
                 frozen(as_shape(frame.position, f"frame {frame.name!r}.position", (3,))))


def _coordinates(links, mimic: dict, floating: bool):
    """Velocity index, multiplier and offset of every link's joint variable ``θ_i = k q[c] + offset``."""
    coordinate, multiplier, offset = [], [], []
    index = 6 if floating else 0
    for i, link in enumerate(links):
        if floating and i == 0:
            c, o = 0, 0.0
        elif i in mimic:
            c, o = -1, link.offset
        else:
            c, o = index, link.offset
            index += 1
        coordinate.append(c)
        multiplier.append(1.0)
        offset.append(o)
    for i, spec in mimic.items():
        where = f"mimic[{i}]"
        try:
            j, k, o = spec
            j, k, o = int(j), float(k), float(o)
        except (TypeError, ValueError):
            raise ValidationError(f"{where}: must be (copied link index, multiplier, offset), got {spec!r}") from None
        if not (0 <= i < len(links)) or not (0 <= j < len(links)) or j in mimic or (floating and 0 in (i, j)):
            raise ValidationError(f"{where}: must copy an independent joint (a link index not itself a mimic "
                                  f"joint nor the floating base), got link {i} copying {j}")
        if not (math.isfinite(k) and math.isfinite(o)):
            raise ValidationError(f"{where}: multiplier and offset must be finite, got {k} and {o}")
        coordinate[i], multiplier[i], offset[i] = coordinate[j], k, offset[i] + o
    return coordinate, multiplier, offset


def _massless_joints(links, parents, coordinate, mimic) -> tuple[str, ...]:
    """The names of the independent joints whose coordinate moves nothing: every link it turns or slides (its own
    and its mimic joints' subtrees) has no mass and, for a revolute joint, no inertia, so that ``Mᵢᵢ(q) = 0``."""
    mass = [link.mass for link in links]
    inertia = [bool(link.inertia.any()) for link in links]
    for i in range(len(links) - 1, 0, -1):
        if parents[i] >= 0:
            mass[parents[i]] += mass[i]
            inertia[parents[i]] = inertia[parents[i]] or inertia[i]
    moves: dict[int, bool] = {}
    for i, link in enumerate(links):
        if link.joint != "floating":
            moving = mass[i] > 0.0 or (link.joint == "revolute" and inertia[i])
            moves[coordinate[i]] = moves.get(coordinate[i], False) or moving
    return tuple(str(link.name if link.name is not None else f"links[{i}]") for i, link in enumerate(links)
                 if link.joint != "floating" and i not in mimic and not moves[coordinate[i]])


def _axis_frame(axis) -> np.ndarray:
    """A rotation ``R_a`` with ``R_a e_z = s`` for the unit joint axis ``s``: its columns ``(x, s × x, s)``, ``x``
    the unit part of the basis vector least aligned with ``s`` normal to ``s``. A signed permutation (exact) for
    an axis along ±x, ±y or ±z; the identity for +z."""
    k = int(np.argmin(np.abs(axis)))
    x = -axis[k] * axis
    x[k] += 1.0
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(axis, x), axis])


def _pack(links, parents, coordinate, multiplier, offset) -> np.ndarray:
    """The (nb, 45) parameter array of :mod:`._kernels`, in canonical frames.

    Canonical body frame i = link frame i · (R_f, p_f)⁻¹ · R_a: origin on joint
    i's axis, and that axis along z (``R_a``: :func:`_axis_frame`; the identity
    for the floating base), so that the compiled algorithms only turn about or
    slide along z. In it the link's user frame is ``(R_f', p_f') = (R_aᵀ R_f,
    R_aᵀ p_f)``; the joint origin of joint i, ``(R_o, p_o)`` in link λ(i)'s
    frame, becomes ``(R_f'λ R_o R_a, p_f'λ + R_f'λ p_o)``, and link i's mass
    properties move to the canonical frame: ``c' = R_f' c + p_f'``, ``I_c' =
    R_f' I_c R_f'ᵀ``, ``I_O = I_c' + m(|c'|² E − c'c'ᵀ)``.
    """
    c = _columns
    P = np.zeros((len(links), c.PARAMS))
    kinds = {"revolute": c.REVOLUTE, "prismatic": c.PRISMATIC, "floating": c.FREE}
    turn = [np.eye(3) if link.joint == "floating" else _axis_frame(link.axis) for link in links]
    user_R = [Ra.T @ link.frame_rotation for Ra, link in zip(turn, links)]
    user_p = [Ra.T @ link.frame_position for Ra, link in zip(turn, links)]
    for i, link in enumerate(links):
        par = parents[i]
        prev_R, prev_p = (np.eye(3), np.zeros(3)) if par < 0 else (user_R[par], user_p[par])
        P[i, c.JOINT_FRAME:c.JOINT_FRAME + 9] = (prev_R @ link.origin_rotation @ turn[i]).ravel()
        P[i, c.JOINT_FRAME + c.ORIGIN:c.JOINT_FRAME + 12] = prev_p + prev_R @ link.origin_position
        P[i, c.AXIS:c.AXIS + 3] = (0.0, 0.0, 1.0)
        P[i, c.JOINT_TYPE] = kinds[link.joint]
        P[i, c.OFFSET] = offset[i]
        Rf, pf = user_R[i], user_p[i]
        com = Rf @ link.com + pf
        P[i, c.MASS] = link.mass
        P[i, c.FIRST_MOMENT:c.FIRST_MOMENT + 3] = link.mass * com
        P[i, c.INERTIA:c.INERTIA + 9] = (Rf @ link.inertia @ Rf.T + parallel_axis(link.mass, com)).ravel()
        P[i, c.USER_FRAME:c.USER_FRAME + 9] = Rf.ravel()
        P[i, c.USER_FRAME + c.ORIGIN:c.USER_FRAME + 12] = pf
        P[i, c.PARENT] = par
        P[i, c.COORDINATE] = coordinate[i]
        P[i, c.MULTIPLIER] = multiplier[i]
    return P
