"""URDF input: a kinematic tree (or serial chain) from the Unified Robot Description Format.

Parsed with ``defusedxml`` (no entity expansion, no external references: a
robot file is data). Supported: ``revolute``, ``continuous`` (revolute
without limits), ``prismatic`` and ``fixed`` joints; ``<mimic joint
multiplier offset>`` (the joint copies another: ``θ = multiplier · q_joint +
offset``, a constrained coordinate); ``<limit lower upper>`` (kept as the
joint limits); any joint ``<axis>`` (normalised; default ``1 0 0`` as in the
URDF specification); ``<origin xyz rpy>`` with ``R = Rz(yaw) Ry(pitch)
Rx(roll)`` (fixed-axis roll, pitch, yaw); ``<inertial>`` with its own
``<origin>`` (the inertia is about the centre of mass in the axes of that
origin).

Links attached by fixed joints are merged into the moving body they hang from
(mass, centre of mass and inertia combined by the parallel-axis theorem);
those on the root belong to the base. Every URDF link, merged or massless
(ROS-Industrial's ``base``, ``flange``, ``tool0``, sensor frames), becomes a
named :class:`~tumble.robot.Frame` of the body it is fixed to. The root link
is the fixed base, or with ``floating_base=True`` a free body (a legged robot,
a spacecraft).

Inertia tensors that are not positive semi-definite (the data is not
physical) are repaired only by a named rule, and every repair is reported
(:class:`UrdfRepairWarning`, and :attr:`UrdfRobot.repairs`):

* *round-off* (always): a negative principal moment no larger than
  ``_ROUND_OFF`` (1e-14) × the robot's largest inertia entry, such as iCub's
  ``ixz="1.35525e-20"`` on an otherwise zero tensor, is set to zero: at that
  size it is below the float64 resolution of every entry of M(q);
* ``inertia="clip"`` (opt-in): any negative principal moment is set to zero,
  the principal axes kept, which is the nearest positive semi-definite
  tensor in the Frobenius norm (Higham, *Linear Algebra Appl.* 103, 1988):
  TIAGo's 1 mg antennas, Romeo's ``body`` in ``romeo_laas_small``;
* ``min_inertia`` (opt-in, kg·m²; MuJoCo's ``boundinertia``): every moving
  body's principal moments raised to at least this, so that a revolute joint
  that moves only massless links (Romeo's fingers) has a regular M(q).

A joint that moves neither mass nor inertia is loaded: the torques, the
gravity torques and M(q) are defined (M is singular), and
:attr:`tumble.robot.RobotTree.massless_joints` names it; forward dynamics and
``tumble.simulate`` refuse such a robot naming the joint.

Refused, with the element and the rule named: malformed XML, a ``<robot>``
without links, a kinematic loop (a link that is the child of two joints, or
joints that close a cycle), ``floating`` and ``planar`` joints (use
``floating_base=True`` for a free root), unknown joint types, missing or
unknown parents and children, a ``<mimic>`` naming no joint, a fixed joint
or a mimic joint, an element given twice where one is read (``<mass>``,
``<inertia>``, ``<origin>``, ``<axis>``, ...), negative masses, non-physical
inertias (unless repaired as above), a fixed-base robot without a moving
joint (a single body is a floating base: ``floating_base=True``), bad numbers.

Reference: ROS URDF XML specification, http://wiki.ros.org/urdf/XML.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from defusedxml import DefusedXmlException
from defusedxml import ElementTree

from tumble._files import read_input
from tumble._validate import ValidationError, require_non_negative
from tumble._inertia import _DEFINITE_RTOL, parallel_axis, principal_axes
from tumble.robot.link import Frame, Link

__all__ = ["UrdfRepairWarning", "UrdfRobot", "read_urdf"]

_MOVING = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
_UNSUPPORTED = {"floating", "planar"}
_INERTIA_RULES = ("check", "clip")
# A negative principal moment at most this × the robot's largest inertia entry is round-off, set to zero.
_ROUND_OFF = 1e-14


class UrdfRepairWarning(UserWarning):
    """A URDF's non-physical data was repaired by a named rule (:mod:`tumble.robot.urdf`), or a joint moves no
    mass; the message lists each link and what was changed."""


def _child(element, tag: str, where: str):
    """The one ``<tag>`` child of ``element`` (None when absent); two or more are refused (which one counts would
    be a guess: a duplicate ``<mass>`` was taken silently)."""
    found = element.findall(tag)
    if len(found) > 1:
        raise ValidationError(f"{where}: has {len(found)} <{tag}> elements; at most one is allowed")
    return found[0] if found else None


def _numbers(element, attribute: str, count: int, default: str, where: str) -> np.ndarray:
    text = default if element is None else element.get(attribute, default)
    try:
        values = np.array([float(x) for x in text.split()])
    except ValueError:
        values = np.array([])
    if values.shape != (count,) or not np.isfinite(values).all():
        raise ValidationError(f"{where}: attribute {attribute}={text!r} must be {count} finite numbers")
    return values


def _number(element, attribute: str, where: str, default: float | None = None) -> float:
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise ValidationError(f"{where}: missing attribute {attribute!r}")
        return default
    try:
        value = float(text)
    except ValueError:
        raise ValidationError(f"{where}: attribute {attribute}={text!r} must be a number") from None
    if math.isnan(value):
        raise ValidationError(f"{where}: attribute {attribute} must be a number, got nan")
    return value


def _origin(element, where: str) -> tuple[np.ndarray, np.ndarray]:
    """``(R, p)`` of an element's ``<origin xyz rpy>``: ``R = Rz(y) Ry(p) Rx(r)``."""
    origin = _child(element, "origin", where)
    where = f"{where} <origin>"
    p = _numbers(origin, "xyz", 3, "0 0 0", where)
    r, pitch, y = _numbers(origin, "rpy", 3, "0 0 0", where)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(pitch), math.sin(pitch), math.cos(y), math.sin(y)
    R = np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])
    return R, p


def _inertial(link, where: str):
    """``(mass, com, R, inertia)`` of a ``<link>``: the inertia tensor about the centre of mass ``com`` in the axes
    of the ``<inertial> <origin>``, whose rotation to the link frame is ``R`` (zeros without ``<inertial>``).
    Not yet checked for positive semi-definiteness (:meth:`_Builder._physical`)."""
    inertial = _child(link, "inertial", where)
    if inertial is None:
        return 0.0, np.zeros(3), np.eye(3), np.zeros((3, 3))
    where = f"{where} <inertial>"
    R, com = _origin(inertial, where)
    mass_el = _child(inertial, "mass", where)
    if mass_el is None:
        raise ValidationError(f"{where}: missing <mass>")
    mass = _number(mass_el, "value", f"{where} <mass>")
    if not (math.isfinite(mass) and mass >= 0.0):
        raise ValidationError(f"{where} <mass>: value must be a finite number >= 0 kg, got {mass}")
    el = _child(inertial, "inertia", where)
    if el is None:
        raise ValidationError(f"{where}: missing <inertia>")
    w = f"{where} <inertia>"
    ixx, ixy, ixz, iyy, iyz, izz = (_number(el, k, w) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    return mass, com, R, np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def _nearest_semidefinite(inertia: np.ndarray) -> tuple[np.ndarray, float]:
    """``(I', m₁)``: the tensor with its negative principal moments set to zero (the principal axes kept), the
    nearest positive semi-definite tensor in the Frobenius norm, and the smallest principal moment ``m₁`` of
    ``I``. The tensor is scaled to unit largest entry before the eigen-decomposition squares it."""
    scale = float(np.abs(inertia).max())
    moments, axes = np.linalg.eigh(inertia / scale)
    return (axes * (np.maximum(moments, 0.0) * scale)) @ axes.T, float(moments[0] * scale)


def _parse(source):
    try:
        if isinstance(source, str) and source.lstrip().startswith("<"):
            return ElementTree.fromstring(source), "URDF"
        return ElementTree.fromstring(read_input(source)), Path(source).name
    except ElementTree.ParseError as exc:
        raise ValidationError(f"URDF: malformed XML ({exc})") from None
    except DefusedXmlException as exc:
        raise ValidationError(f"URDF: refused unsafe XML ({exc!r})") from None


@dataclass(frozen=True)
class UrdfRobot:
    """What a URDF describes, ready for :class:`~tumble.robot.RobotTree`: ``links`` (parents first), ``parents``,
    named ``frames``, ``mimic`` ``{link: (copied link, multiplier, offset)}``, for the messages of
    :meth:`require_serial` the names of the URDF links of each body and the moving joints hung on each, and
    ``repairs``: one line per repaired inertia tensor (empty when the data was physical)."""

    name: str | None
    links: tuple
    parents: tuple
    frames: tuple
    mimic: dict
    body_links: dict
    children: dict
    repairs: tuple = ()

    def require_serial(self) -> None:
        """Refuse, naming the element, a URDF that is not a serial chain of independent joints."""
        for body, joints in self.children.items():
            if len(joints) > 1:
                raise ValidationError(f"link {self.body_links[body]!r}: has {len(joints)} child joints {joints}: a "
                                      "tree, not a serial chain; load it with tumble.robot.RobotTree.from_urdf")
        for i in self.mimic:
            raise ValidationError(f"joint {self.links[i].name!r}: <mimic> is not supported by a SerialChain (it "
                                  "couples joints); load it with tumble.robot.RobotTree.from_urdf")

    @property
    def serial(self) -> bool:
        return not self.mimic and all(len(j) <= 1 for j in self.children.values()) and \
            self.parents == tuple(range(-1, len(self.links) - 1)) and self.links[0].joint != "floating"


def read_urdf(source: str | os.PathLike[str], *, check_triangle: bool = True, floating_base: bool = False,
              mimic: bool = True, inertia: str = "check", min_inertia: float = 0.0) -> UrdfRobot:
    """The robot described by a URDF file (path) or document (a string starting with ``<``).

    ``mimic=False`` reads ``<mimic>`` joints as independent joints (as Pinocchio's parser does by default).
    ``inertia``: ``"check"`` (round-off repaired, any other non-physical tensor refused) or ``"clip"``
    (negative principal moments set to zero); ``min_inertia`` (kg·m², ≥ 0): the least principal moment of every
    moving body. Each repair is warned (:class:`UrdfRepairWarning`) and listed in ``repairs``."""
    if inertia not in _INERTIA_RULES:
        raise ValidationError(f"inertia: must be one of {_INERTIA_RULES}, got {inertia!r}")
    min_inertia = require_non_negative(min_inertia, "min_inertia")  # kg·m²
    root, label = _parse(source)
    if root.tag != "robot":
        raise ValidationError(f"{label}: the root element must be <robot>, got <{root.tag}>")
    links = {}
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise ValidationError(f"{label}: a <link> has no name")
        if name in links:
            raise ValidationError(f"{label}: link {name!r} is defined twice")
        links[name] = el
    if not links:
        raise ValidationError(f"{label}: <robot> has no <link> element; a robot needs at least one link")
    children: dict[str, list] = {}
    parent_of: dict[str, str] = {}
    joint_types: dict[str, str] = {}
    for el in root.findall("joint"):
        name = el.get("name")
        where = f"joint {name!r}"
        if not name or name in joint_types:
            raise ValidationError(f"{label}: a <joint> has no name or a name used twice ({name!r})")
        kind = el.get("type")
        joint_types[name] = kind
        if kind in _UNSUPPORTED:
            raise ValidationError(f"{where}: joint type {kind!r} is not supported (joints are revolute, continuous, "
                                  "prismatic or fixed; for a free root pass floating_base=True)")
        if kind not in _MOVING and kind != "fixed":
            raise ValidationError(f"{where}: unknown joint type {kind!r}; expected one of "
                                  f"{sorted([*_MOVING, 'fixed'])}")
        ends = []
        for tag in ("parent", "child"):
            end = _child(el, tag, where)
            link = None if end is None else end.get("link")
            if link is None or link not in links:
                raise ValidationError(f"{where}: <{tag} link={link!r}> names no <link> of the robot")
            ends.append(link)
        parent, child = ends
        if child in parent_of:
            raise ValidationError(f"{where}: link {child!r} is the child of two joints (a kinematic loop; a URDF "
                                  "describes a tree)")
        parent_of[child] = parent
        children.setdefault(parent, []).append(el)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        rule = "the joints close a loop" if not roots else "the links are not connected"
        raise ValidationError(f"{label}: a robot needs exactly one root link, found {roots} ({rule})")
    builder = _Builder(links, children, joint_types, check_triangle, floating_base, mimic, inertia == "clip",
                       min_inertia)
    robot = builder.build(root.get("name"), roots[0], label)
    if robot.repairs:
        warnings.warn(f"{label}: non-physical inertia repaired: " + "; ".join(robot.repairs), UrdfRepairWarning,
                      stacklevel=3)
    return robot


class _Builder:
    """Walks the URDF tree from the root (depth first: parents before children), merging fixed joints."""

    def __init__(self, links, children, joint_types, check_triangle, floating_base, mimic, clip, min_inertia):
        self.links, self.children, self.joint_types, self.read_mimic = links, children, joint_types, mimic
        self.check_triangle, self.floating_base, self.clip, self.min_inertia = (check_triangle, floating_base,
                                                                                clip, min_inertia)
        self.specs, self.parents, self.parts, self.members, self.frames = [], [], [], [], []
        self.mimic_of, self.moving_children, self.repairs = {}, {}, []
        self.inertials = {name: _inertial(el, f"link {name!r}") for name, el in links.items()}
        # the robot's inertia scale (kg·m²), against which a negative principal moment is round-off
        self.scale = max(float(np.abs(i[3]).max()) for i in self.inertials.values())

    def build(self, name, root, label) -> UrdfRobot:
        base = -1
        if self.floating_base:
            self._new_body(dict(joint="floating", name=root), -1)
            base = 0
        self.base_link = root
        self._attach(root, base, np.eye(3), np.zeros(3))
        self._walk(root, base)
        if not self.specs:  # a fixed base and no moving joint
            raise ValidationError(f"{label}: no revolute, continuous or prismatic joint: nothing moves on a fixed "
                                  "base (for a single free body, a quadrotor, pass floating_base=True)")
        links = tuple(self._merged(i) for i in range(len(self.specs)))
        mimic = {i: self._mimicked(i, *spec) for i, spec in self.mimic_of.items()}
        body_links = {-1: root, **{i: m[0] for i, m in enumerate(self.members)}}
        children = {b: [self.specs[j]["name"] for j in js] for b, js in self.moving_children.items()}
        return UrdfRobot(name, links, tuple(self.parents), tuple(self.frames), mimic, body_links, children,
                         tuple(self.repairs))

    def _mimicked(self, i, copied, multiplier, offset, where) -> tuple[int, float, float]:
        """``(copied body, multiplier, offset)`` of mimic joint body ``i``; refused naming what ``joint=`` names."""
        index = {s["name"]: k for k, s in enumerate(self.specs) if s["joint"] != "floating"}
        rule = None
        if copied not in self.joint_types:
            rule = ("names no joint of the robot (mimic=False reads the <mimic> joints as independent joints, as "
                    "Pinocchio does by default)")
        elif copied not in index:
            rule = f"names a {self.joint_types[copied]!r} joint; a mimic joint copies a moving joint"
        elif index[copied] in self.mimic_of:
            rule = "names a mimic joint; a mimic joint copies an independent joint"
        if rule is not None:
            raise ValidationError(f"{where} <mimic>: joint={copied!r} {rule}")
        return index[copied], multiplier, offset

    def _walk(self, root, base):
        """Depth first from the root link (on body ``base``), children in file order; iterative, so that a chain
        of any length is read (a 1500-link chain passed Python's recursion limit)."""
        seen = {root}
        stack = [(el, base, np.eye(3), np.zeros(3)) for el in reversed(self.children.get(root, []))]
        while stack:
            el, body, R_link, p_link = stack.pop()
            child = el.find("child").get("link")
            where = f"joint {el.get('name')!r}"
            seen.add(child)
            R, p = _origin(el, where)
            R, p = R_link @ R, p_link + R_link @ p
            if el.get("type") != "fixed":
                body, R, p = self._joint(el, body, R, p, where), np.eye(3), np.zeros(3)
            self._attach(child, body, R, p)
            stack.extend((sub, body, R, p) for sub in reversed(self.children.get(child, [])))
        unreached = [name for name in self.links if name not in seen]
        if unreached:
            raise ValidationError(f"link {unreached[0]!r}: not reached from the root link {root!r} (the joints "
                                  "close a loop)")

    def _new_body(self, spec, parent) -> int:
        self.specs.append(spec)
        self.parents.append(parent)
        self.parts.append([])
        self.members.append([])
        return len(self.specs) - 1

    def _attach(self, link, body, R, p):
        """URDF link ``link`` fixed to ``body`` at pose (R, p) in its link frame: a frame, and its mass merged."""
        self.frames.append(Frame(link, body, R, p))
        mass, com, R_inertial, inertia = self.inertials[link]
        inertia = self._physical(inertia, f"link {link!r} <inertial> <inertia>")  # checked, also on the fixed base
        if body < 0:
            return
        R_inertial = R @ R_inertial
        self.parts[body].append((mass, R @ com + p, R_inertial @ inertia @ R_inertial.T))
        self.members[body].append(link)

    def _physical(self, inertia, where) -> np.ndarray:
        """The tensor checked (:func:`~tumble._inertia.principal_axes`), after the repairs of the module docstring:
        a negative principal moment beyond the rule of ``principal_axes`` is set to zero when it is round-off
        (≤ ``_ROUND_OFF`` × the robot's largest entry) or when ``inertia="clip"``; each repair is recorded."""
        if np.isfinite(inertia).all() and inertia.any():
            repaired, smallest = _nearest_semidefinite(inertia)
            largest = float(np.abs(inertia).max())
            if smallest < -_DEFINITE_RTOL * largest:
                if -smallest <= _ROUND_OFF * self.scale:
                    rule = f"round-off, at most {_ROUND_OFF:g} x the robot's largest entry {self.scale:.6g} kg m^2"
                elif self.clip:
                    rule = "inertia='clip'"
                else:
                    rule = None
                if rule is not None:
                    self.repairs.append(f"{where}: principal moment {smallest:.6g} kg m^2 set to 0 by {rule}")
                    inertia = repaired
        try:
            return principal_axes(inertia, where, definite=False, check_triangle=False)[0]
        except ValidationError as exc:
            if "semi-definite" not in str(exc):
                raise
            raise ValidationError(f"{exc}; inertia='clip' sets its negative principal moments to zero") from None

    def _joint(self, el, body, R, p, where) -> int:
        kind = el.get("type")
        axis = _numbers(_child(el, "axis", where), "xyz", 3, "1 0 0", f"{where} <axis>")
        limit = _child(el, "limit", where)
        lower, upper = -math.inf, math.inf
        if kind != "continuous" and limit is not None:
            lower = _number(limit, "lower", f"{where} <limit>", 0.0)
            upper = _number(limit, "upper", f"{where} <limit>", 0.0)
        new = self._new_body(dict(joint=_MOVING[kind], axis=axis, origin_position=p, origin_rotation=R,
                                  lower=lower, upper=upper, name=el.get("name")), body)
        self.moving_children.setdefault(body, []).append(new)
        mimic = _child(el, "mimic", where)
        if mimic is not None and self.read_mimic:
            copied = mimic.get("joint")
            self.mimic_of[new] = (copied, _number(mimic, "multiplier", f"{where} <mimic>", 1.0),
                                  _number(mimic, "offset", f"{where} <mimic>", 0.0), where)
        return new

    def _merged(self, i) -> Link:
        """The :class:`Link` of body i carrying the rigid union of its parts (mass, com, inertia about com)::

            m = Σ mₖ,   c = Σ mₖ cₖ / m,   I = Σ [Iₖ + mₖ (|dₖ|² E − dₖ dₖᵀ)],   dₖ = cₖ − c

        (the rule of :meth:`tumble.rigid_body.RigidBody.composite`, which needs every mass > 0), its principal moments
        raised to ``min_inertia``. A broken inertia rule names the URDF links of the body.
        """
        parts, members, spec = self.parts[i], self.members[i], self.specs[i]
        masses = np.array([m for m, _, _ in parts])
        coms = np.array([c for _, c, _ in parts]).reshape(-1, 3)
        mass = masses.sum()
        com = masses @ coms / mass if mass > 0.0 else np.zeros(3)
        inertia = sum((j for _, _, j in parts), np.zeros((3, 3))) + parallel_axis(masses, coms - com)
        merged = f" with the fixed link(s) {members[1:]} merged into it" if len(members) > 1 else ""
        moved = "the floating base" if spec["joint"] == "floating" else f"moved by joint {spec['name']!r}"
        where = f"link {members[0]!r} <inertial>{merged} ({moved})"
        if self.min_inertia > 0.0:
            inertia, moments, axes = principal_axes(inertia, where, definite=False, check_triangle=False)
            inertia = (axes * np.maximum(moments, self.min_inertia)) @ axes.T
        principal_axes(inertia, where, definite=False, check_triangle=self.check_triangle)
        return Link(mass=mass, com=com, inertia=inertia, check_triangle=self.check_triangle, **spec)
