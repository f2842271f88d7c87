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

Refused, with the element and the rule named: malformed XML, a kinematic loop
(a link that is the child of two joints, or joints that close a cycle),
``floating`` and ``planar`` joints (use ``floating_base=True`` for a free
root), unknown joint types, missing or unknown parents and children, a
``<mimic>`` of an unknown or mimic joint, negative masses, non-physical
inertias, a joint that moves no mass, bad numbers.

Reference: ROS URDF XML specification, http://wiki.ros.org/urdf/XML.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from defusedxml import DefusedXmlException
from defusedxml import ElementTree

from tumble._files import read_input
from tumble._validate import ValidationError
from tumble._inertia import parallel_axis, principal_axes
from tumble.robot.link import Frame, Link

__all__ = ["UrdfRobot", "read_urdf"]

_MOVING = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
_UNSUPPORTED = {"floating", "planar"}


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
    origin = element.find("origin")
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
    """``(mass, com, inertia about com)`` of a ``<link>`` in its own frame (zeros without ``<inertial>``)."""
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    where = f"{where} <inertial>"
    R, com = _origin(inertial, where)
    mass_el = inertial.find("mass")
    if mass_el is None:
        raise ValidationError(f"{where}: missing <mass>")
    mass = _number(mass_el, "value", f"{where} <mass>")
    if not (math.isfinite(mass) and mass >= 0.0):
        raise ValidationError(f"{where} <mass>: value must be a finite number >= 0 kg, got {mass}")
    el = inertial.find("inertia")
    if el is None:
        raise ValidationError(f"{where}: missing <inertia>")
    w = f"{where} <inertia>"
    ixx, ixy, ixz, iyy, iyz, izz = (_number(el, k, w) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    inertia, _, _ = principal_axes(inertia, w, definite=False, check_triangle=False)
    return mass, com, R @ inertia @ R.T


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
    named ``frames``, ``mimic`` ``{link: (copied link, multiplier, offset)}``, and for the messages of
    :meth:`require_serial` the names of the URDF links of each body and the moving joints hung on each."""

    name: str | None
    links: tuple
    parents: tuple
    frames: tuple
    mimic: dict
    body_links: dict
    children: dict

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
              mimic: bool = True) -> UrdfRobot:
    """The robot described by a URDF file (path) or document (a string starting with ``<``).

    ``mimic=False`` reads ``<mimic>`` joints as independent joints (as Pinocchio's parser does by default)."""
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
    children: dict[str, list] = {}
    parent_of: dict[str, str] = {}
    joint_names = set()
    for el in root.findall("joint"):
        name = el.get("name")
        where = f"joint {name!r}"
        if not name or name in joint_names:
            raise ValidationError(f"{label}: a <joint> has no name or a name used twice ({name!r})")
        joint_names.add(name)
        kind = el.get("type")
        if kind in _UNSUPPORTED:
            raise ValidationError(f"{where}: joint type {kind!r} is not supported (joints are revolute, continuous, "
                                  "prismatic or fixed; for a free root pass floating_base=True)")
        if kind not in _MOVING and kind != "fixed":
            raise ValidationError(f"{where}: unknown joint type {kind!r}; expected one of "
                                  f"{sorted([*_MOVING, 'fixed'])}")
        ends = []
        for tag in ("parent", "child"):
            end = el.find(tag)
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
    return _Builder(links, children, check_triangle, floating_base, mimic).build(root.get("name"), roots[0], label)


class _Builder:
    """Walks the URDF tree from the root (depth first: parents before children), merging fixed joints."""

    def __init__(self, links, children, check_triangle, floating_base, mimic):
        self.links, self.children, self.read_mimic = links, children, mimic
        self.check_triangle, self.floating_base = check_triangle, floating_base
        self.specs, self.parents, self.parts, self.members, self.frames = [], [], [], [], []
        self.mimic_of, self.moving_children = {}, {}

    def build(self, name, root, label) -> UrdfRobot:
        base = -1
        if self.floating_base:
            self._new_body(dict(joint="floating", name=root), -1)
            base = 0
        self.base_link = root
        self._attach(root, base, np.eye(3), np.zeros(3))
        self._walk(root, base, np.eye(3), np.zeros(3), {root})
        if all(s["joint"] == "floating" for s in self.specs):
            raise ValidationError(f"{label}: no revolute, continuous or prismatic joint: nothing moves")
        self._check_moves_mass()
        links = tuple(self._merged(i) for i in range(len(self.specs)))
        index = {s["name"]: i for i, s in enumerate(self.specs) if s["joint"] != "floating"}
        mimic = {}
        for i, (copied, multiplier, offset, where) in self.mimic_of.items():
            if copied not in index or index[copied] in self.mimic_of:
                raise ValidationError(f"{where} <mimic>: joint={copied!r} must name a moving joint that is not "
                                      "itself a mimic joint")
            mimic[i] = (index[copied], multiplier, offset)
        body_links = {-1: root, **{i: m[0] for i, m in enumerate(self.members)}}
        children = {b: [self.specs[j]["name"] for j in js] for b, js in self.moving_children.items()}
        return UrdfRobot(name, links, tuple(self.parents), tuple(self.frames), mimic, body_links, children)

    def _walk(self, link, body, R_link, p_link, seen):
        """Depth first from URDF link ``link`` (fixed to ``body`` at (R_link, p_link)), children in file order."""
        for el in self.children.get(link, []):
            child = el.find("child").get("link")
            where = f"joint {el.get('name')!r}"
            if child in seen:
                raise ValidationError(f"{where}: closes a loop at link {child!r}")
            seen.add(child)
            R, p = _origin(el, where)
            R, p = R_link @ R, p_link + R_link @ p
            if el.get("type") == "fixed":
                self._attach(child, body, R, p)
                self._walk(child, body, R, p, seen)
            else:
                new = self._joint(el, body, R, p, where)
                self._attach(child, new, np.eye(3), np.zeros(3))
                self._walk(child, new, np.eye(3), np.zeros(3), seen)

    def _new_body(self, spec, parent) -> int:
        self.specs.append(spec)
        self.parents.append(parent)
        self.parts.append([])
        self.members.append([])
        return len(self.specs) - 1

    def _attach(self, link, body, R, p):
        """URDF link ``link`` fixed to ``body`` at pose (R, p) in its link frame: a frame, and its mass merged."""
        self.frames.append(Frame(link, body, R, p))
        mass, com, inertia = _inertial(self.links[link], f"link {link!r}")  # checked, also on the fixed base
        if body < 0:
            return
        self.parts[body].append((mass, R @ com + p, R @ inertia @ R.T))
        self.members[body].append(link)

    def _joint(self, el, body, R, p, where) -> int:
        kind = el.get("type")
        axis = _numbers(el.find("axis"), "xyz", 3, "1 0 0", f"{where} <axis>")
        limit = el.find("limit")
        lower, upper = -math.inf, math.inf
        if kind != "continuous" and limit is not None:
            lower = _number(limit, "lower", f"{where} <limit>", 0.0)
            upper = _number(limit, "upper", f"{where} <limit>", 0.0)
        new = self._new_body(dict(joint=_MOVING[kind], axis=axis, origin_position=p, origin_rotation=R,
                                  lower=lower, upper=upper, name=el.get("name")), body)
        self.moving_children.setdefault(body, []).append(new)
        mimic = el.find("mimic")
        if mimic is not None and self.read_mimic:
            copied = mimic.get("joint")
            self.mimic_of[new] = (copied, _number(mimic, "multiplier", f"{where} <mimic>", 1.0),
                                  _number(mimic, "offset", f"{where} <mimic>", 0.0), where)
        return new

    def _check_moves_mass(self):
        """Refuse a joint whose subtree has no mass: it moves nothing, so M(q) is singular for every q."""
        total = [sum(m for m, _, _ in parts) for parts in self.parts]
        for i in range(len(self.specs) - 1, -1, -1):
            if self.parents[i] >= 0:
                total[self.parents[i]] += total[i]
        for i, spec in enumerate(self.specs):
            if spec["joint"] != "floating" and total[i] <= 0.0:
                members = self.members[i]
                merged = f" (with the fixed link(s) {members[1:]} merged into it)" if len(members) > 1 else ""
                raise ValidationError(f"link {members[0]!r} <inertial>: the link moved by joint {spec['name']!r}"
                                      f"{merged} and every link beyond it have no mass (no <inertial>, or <mass "
                                      f"value=\"0\">): the joint would move nothing")

    def _merged(self, i) -> Link:
        """The :class:`Link` of body i carrying the rigid union of its parts (mass, com, inertia about com)::

            m = Σ mₖ,   c = Σ mₖ cₖ / m,   I = Σ [Iₖ + mₖ (|dₖ|² E − dₖ dₖᵀ)],   dₖ = cₖ − c

        (the rule of :meth:`tumble.body.RigidBody.composite`, which needs every mass > 0).
        A broken inertia rule names the URDF links of the body.
        """
        parts, members, spec = self.parts[i], self.members[i], self.specs[i]
        masses = np.array([m for m, _, _ in parts])
        coms = np.array([c for _, c, _ in parts]).reshape(-1, 3)
        mass = masses.sum()
        com = masses @ coms / mass if mass > 0.0 else np.zeros(3)
        inertia = sum((j for _, _, j in parts), np.zeros((3, 3))) + parallel_axis(masses, coms - com)
        merged = f" with the fixed link(s) {members[1:]} merged into it" if len(members) > 1 else ""
        moved = "the floating base" if spec["joint"] == "floating" else f"moved by joint {spec['name']!r}"
        principal_axes(inertia, f"link {members[0]!r} <inertial>{merged} ({moved})",
                       definite=False, check_triangle=self.check_triangle)
        return Link(mass=mass, com=com, inertia=inertia, check_triangle=self.check_triangle, **spec)
