"""URDF input: a serial chain from the Unified Robot Description Format.

Parsed with ``defusedxml`` (no entity expansion, no external references: a
robot file is data). Supported: ``revolute``, ``continuous`` (revolute
without limits), ``prismatic`` and ``fixed`` joints; any joint ``<axis>``
(normalised; default ``1 0 0`` as in the URDF specification); ``<origin
xyz rpy>`` with ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (fixed-axis roll, pitch,
yaw); ``<inertial>`` with its own ``<origin>`` (the inertia is about the
centre of mass in the axes of that origin). Links attached by fixed joints
are merged into the moving link before them (mass, centre of mass and inertia
combined by the parallel-axis theorem); those before the first moving joint
belong to the fixed base. The first link (the root) is the fixed base.

Refused, with the element named: malformed XML, a tree (a link with more than
one child joint), ``floating`` and ``planar`` joints, unknown joint types,
``<mimic>`` (it couples joints; a SerialChain's joints are independent),
missing or unknown parents and children, bad numbers.

Reference: ROS URDF XML specification, http://wiki.ros.org/urdf/XML.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from defusedxml import DefusedXmlException
from defusedxml import ElementTree

from tumble._validate import ValidationError
from tumble._inertia import parallel_axis, principal_axes
from tumble.robot.link import Link

__all__ = ["links_from_urdf"]

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
        path = Path(source)
        return ElementTree.parse(path).getroot(), path.name
    except ElementTree.ParseError as exc:
        raise ValidationError(f"URDF: malformed XML ({exc})") from None
    except DefusedXmlException as exc:
        raise ValidationError(f"URDF: refused unsafe XML ({exc!r})") from None


def links_from_urdf(source, *, check_triangle: bool = True) -> tuple[str | None, list[Link]]:
    """``(robot name, links)`` of the serial chain described by a URDF file or document string."""
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
    for el in root.findall("joint"):
        name = el.get("name")
        where = f"joint {name!r}"
        kind = el.get("type")
        if kind in _UNSUPPORTED:
            raise ValidationError(f"{where}: joint type {kind!r} is not supported (a SerialChain has a fixed base "
                                  "and revolute, continuous, prismatic or fixed joints)")
        if kind not in _MOVING and kind != "fixed":
            raise ValidationError(f"{where}: unknown joint type {kind!r}; expected one of "
                                  f"{sorted([*_MOVING, 'fixed'])}")
        if el.find("mimic") is not None:
            raise ValidationError(f"{where}: <mimic> is not supported (it couples joints; the joints of a "
                                  "SerialChain are independent)")
        ends = []
        for tag in ("parent", "child"):
            end = el.find(tag)
            link = None if end is None else end.get("link")
            if link not in links:
                raise ValidationError(f"{where}: <{tag} link={link!r}> names no <link> of the robot")
            ends.append(link)
        parent, child = ends
        if child in parent_of:
            raise ValidationError(f"link {child!r}: is the child of two joints")
        parent_of[child] = parent
        children.setdefault(parent, []).append(el)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise ValidationError(f"{label}: a chain needs exactly one root link, found {roots}")
    chain = []
    pending_R, pending_p = np.eye(3), np.zeros(3)  # current URDF link frame in the last moving link's frame
    parts: list = []  # (mass, com, inertia) of the current moving link, in its frame
    members: list = []  # names of the URDF links that make it up: its own, then those merged into it
    current = roots[0]
    seen = {current}
    while True:
        joints = children.get(current, [])
        if len(joints) > 1:
            names = [j.get("name") for j in joints]
            raise ValidationError(f"link {current!r}: has {len(joints)} child joints {names}: a tree, not a "
                                  "serial chain")
        if not joints:
            break
        el = joints[0]
        name = el.get("name")
        where = f"joint {name!r}"
        child = el.find("child").get("link")
        if child in seen:
            raise ValidationError(f"{where}: closes a loop at link {child!r}")
        seen.add(child)
        R, p = _origin(el, where)
        R, p = pending_R @ R, pending_p + pending_R @ p
        mass, com, inertia = _inertial(links[child], f"link {child!r}")
        kind = el.get("type")
        if kind == "fixed":
            pending_R, pending_p = R, p
            parts.append((mass, R @ com + p, R @ inertia @ R.T))
            members.append(child)
        else:
            if chain:
                chain[-1] = _merged(chain[-1], parts, members, check_triangle)
            parts, members = [(mass, com, inertia)], [child]
            pending_R, pending_p = np.eye(3), np.zeros(3)
            axis = _numbers(el.find("axis"), "xyz", 3, "1 0 0", f"{where} <axis>")
            limit = el.find("limit")
            lower, upper = -math.inf, math.inf
            if kind != "continuous" and limit is not None:
                lower = _number(limit, "lower", f"{where} <limit>", 0.0)
                upper = _number(limit, "upper", f"{where} <limit>", 0.0)
            chain.append(dict(joint=_MOVING[kind], axis=axis, origin_position=p, origin_rotation=R,
                              lower=lower, upper=upper, name=name))
        current = child
    if not chain:
        raise ValidationError(f"{label}: no revolute, continuous or prismatic joint: nothing moves")
    if sum(m for m, _, _ in parts) <= 0.0:
        # every joint moves the last link, so a massless one makes no joint singular by itself; without it the
        # last joint moves nothing, M(q) is singular for every q and a simulation is NaN
        merged = f" (with the fixed link(s) {members[1:]} merged into it)" if len(members) > 1 else ""
        raise ValidationError(f"link {members[0]!r} <inertial>: the last moving link{merged} has no mass (no "
                              f"<inertial>, or <mass value=\"0\">): joint {chain[-1]['name']!r} would move nothing")
    chain[-1] = _merged(chain[-1], parts, members, check_triangle)
    return root.get("name"), chain


def _merged(spec: dict, parts, members: list[str], check_triangle: bool) -> Link:
    """The :class:`Link` of ``spec`` carrying the rigid union of ``parts`` (mass, com, inertia about com)::

        m = Σ mₖ,   c = Σ mₖ cₖ / m,   I = Σ [Iₖ + mₖ (|dₖ|² E − dₖ dₖᵀ)],   dₖ = cₖ − c

    (the rule of :meth:`tumble.body.RigidBody.composite`, which needs every mass > 0).
    ``members`` names the URDF links of ``parts``; a broken inertia rule names them.
    """
    masses = np.array([m for m, _, _ in parts])
    coms = np.array([c for _, c, _ in parts])
    mass = masses.sum()
    com = masses @ coms / mass if mass > 0.0 else np.zeros(3)
    inertia = sum(i for _, _, i in parts) + parallel_axis(masses, coms - com)
    merged = f" with the fixed link(s) {members[1:]} merged into it" if len(members) > 1 else ""
    principal_axes(inertia, f"link {members[0]!r} <inertial>{merged} (moved by joint {spec['name']!r})",
                   definite=False, check_triangle=check_triangle)
    return Link(mass=mass, com=com, inertia=inertia, check_triangle=check_triangle, **spec)
