"""Serial chains: a fixed base and links in a row, from Denavit–Hartenberg tables, URDF or robot files.

Conventions (``docs/robot.md``): SI units (m, rad, kg, kg·m²); the frames of
a link are those of :mod:`tumble.robot.link`:
link frame i = link frame i−1 · (R_o, p_o) · joint(q_i) · (R_f, p_f).

Standard DH (Denavit & Hartenberg 1955; Spong, Hutchinson & Vidyasagar,
*Robot Modeling and Control*, 2006, §3.2)::

    ᶦ⁻¹Tᵢ = Rz(θᵢ) Tz(dᵢ) Tx(aᵢ) Rx(αᵢ)

and modified DH (Craig, *Introduction to Robotics*, 3rd ed. 2005, eq. 3.6),
where the row of joint i holds the ``a`` and ``α`` of link i−1::

    ᶦ⁻¹Tᵢ = Rx(α_{i−1}) Tx(a_{i−1}) Rz(θᵢ) Tz(dᵢ)

with ``θᵢ = qᵢ + theta`` (revolute) or ``dᵢ = qᵢ + d`` (prismatic).
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from tumble._files import read_input
from tumble._inertia import as_shape
from tumble._validate import ValidationError, as_array
from tumble.robot.link import Frame, Link
from tumble.robot.tree import DEFAULT_GRAVITY, RobotTree
from tumble.robot.urdf import read_urdf

__all__ = ["SerialChain", "load"]


def _rx(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rz(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


_DH_KEYS = {"joint", "a", "alpha", "d", "theta", "mass", "com", "inertia", "limits", "name"}


def _dh_link(row: Mapping, k: int, modified: bool, check_triangle: bool) -> Link:
    """The :class:`Link` of row ``k`` of a DH table (see :meth:`SerialChain.from_dh`)."""
    where = f"links[{k}]"
    if not isinstance(row, Mapping):
        raise ValidationError(f"{where}: must be a table of DH parameters, got {type(row).__name__}")
    unknown = sorted(set(row) - _DH_KEYS)
    if unknown:
        raise ValidationError(f"{where}: unknown key(s) {unknown}; allowed: {sorted(_DH_KEYS)}")
    joint = row.get("joint", "revolute")
    a, alpha, d, theta = (float(as_shape(row.get(key, 0.0), f"{where}.{key}", ())) for key in
                          ("a", "alpha", "d", "theta"))
    limits = as_array(row.get("limits", (-math.inf, math.inf)), f"{where}.limits", finite=False)
    if limits.shape != (2,) or np.isnan(limits).any():
        raise ValidationError(f"{where}.limits: must be [lower, upper] (rad or m), got {limits.tolist()}")
    lower, upper = limits
    prismatic = joint == "prismatic"
    # the joint variable enters as θ = q + theta (revolute) or d = q + d (prismatic)
    fixed_z = _rz(theta) if prismatic else np.eye(3)
    offset = d if prismatic else theta
    slide = np.zeros(3) if prismatic else np.array([0.0, 0.0, d])
    if modified:  # Rx(α) Tx(a) [Rz(θ)] J [Tz(d)]
        origin_rotation = _rx(alpha) @ fixed_z
        origin_position = np.array([a, 0.0, 0.0])
        frame_rotation, frame_position = np.eye(3), slide
    else:  # [Rz(θ)] J [Tz(d)] Tx(a) Rx(α)
        origin_rotation, origin_position = fixed_z, np.zeros(3)
        frame_rotation = _rx(alpha)
        frame_position = slide + np.array([a, 0.0, 0.0])
    return Link(joint=joint, axis=np.array([0.0, 0.0, 1.0]), origin_position=origin_position,
                origin_rotation=origin_rotation, frame_position=frame_position, frame_rotation=frame_rotation,
                offset=offset, mass=row.get("mass", 0.0), com=row.get("com", (0.0, 0.0, 0.0)),
                inertia=row.get("inertia", np.zeros((3, 3))), lower=lower, upper=upper,
                name=row.get("name", f"joint{k + 1}"), check_triangle=check_triangle)


class SerialChain(RobotTree):
    """An immutable, validated serial chain of rigid links on a fixed base: the tree whose parents are
    ``λ(i) = i − 1`` (:class:`~tumble.robot.RobotTree`).

    ``SerialChain(links, *, gravity=(0, 0, -9.81), name=None, frames=())``

    ``links`` is a sequence of :class:`Link` (base to tip); ``gravity`` is the
    gravitational acceleration in the base frame (m/s²), part of the model as
    in Pinocchio and MuJoCo: the default of every algorithm of
    :mod:`tumble.robot` and the gravity of ``tumble.simulate(chain, ...)``
    (:meth:`with_gravity` gives the same chain under another). Built also by
    :meth:`from_dh`, :meth:`from_urdf` and :func:`load`. The chain's arrays
    for the compiled algorithms are built once, here.

    A chain is a model of :func:`tumble.simulate` (:class:`~tumble.robot.motion.ChainMotion`)::

        tumble.simulate(chain, q0=q0, qd0=qd0, t=t, torque=None)

    with ``q0`` the initial joint vector (rad or m, not a quaternion) and
    ``qd0`` the joint rates (rad/s or m/s, default 0).
    """

    __slots__ = ()

    def __init__(self, links: Sequence[Link], *, gravity: ArrayLike = DEFAULT_GRAVITY, name: str | None = None,
                 frames: Sequence[Frame] = ()) -> None:
        links = tuple(links)
        for k, link in enumerate(links):
            if isinstance(link, Link) and link.joint == "floating":
                raise ValidationError(f"links[{k}].joint: a SerialChain has a fixed base; a floating base is a "
                                      "RobotTree")
        super().__init__(links, range(-1, len(links) - 1), gravity=gravity, name=name, frames=frames)

    # -- constructors ---------------------------------------------------------

    @classmethod
    def from_dh(cls, links: Sequence[Mapping], *, convention: str = "standard", gravity: ArrayLike = DEFAULT_GRAVITY,
                name: str | None = None, check_triangle: bool = True) -> SerialChain:
        """A chain from a Denavit–Hartenberg table, one mapping per joint (base to tip).

        Keys (all optional): ``joint`` (``"revolute"``, default, or
        ``"prismatic"``), ``a`` (m), ``alpha`` (rad), ``d`` (m), ``theta``
        (rad): for a revolute joint ``theta`` is the offset (``θ = q +
        theta``) and ``d`` fixed; for a prismatic joint ``d`` is the offset and
        ``theta`` fixed. ``mass`` (kg), ``com`` (m) and ``inertia`` (3×3,
        kg·m², about the centre of mass) in the DH link frame; ``limits``
        ``[lower, upper]``; ``name``. ``convention``: ``"standard"`` (frame i
        at the distal end of link i) or ``"modified"`` (Craig: frame i on
        joint i; the row of joint i holds ``a`` and ``alpha`` of link i−1).
        """
        if convention not in ("standard", "modified"):
            raise ValidationError(f"convention: must be 'standard' or 'modified', got {convention!r}")
        if isinstance(links, Mapping) or not isinstance(links, Sequence):
            raise ValidationError(f"links: must be a list of DH rows, got {type(links).__name__}")
        rows = [_dh_link(row, k, convention == "modified", check_triangle) for k, row in enumerate(links)]
        return cls(rows, gravity=gravity, name=name)

    @classmethod
    def from_urdf(  # type: ignore[override]  # a chain has no floating base and no mimic joints to ask for
            cls, source: str | os.PathLike[str], *, check_triangle: bool = True, inertia: str = "check",
            min_inertia: float = 0.0, gravity: ArrayLike = DEFAULT_GRAVITY) -> SerialChain:
        """A chain from a URDF file (path) or document (a string starting with ``<``); see :mod:`.urdf`.

        Refused when the URDF describes a tree or has mimic joints (use :meth:`RobotTree.from_urdf`)."""
        description = read_urdf(source, check_triangle=check_triangle, inertia=inertia, min_inertia=min_inertia)
        description.require_serial()
        return cls(description.links, gravity=gravity, name=description.name,
                   frames=description.frames)._warn_massless()

    def with_gravity(self, gravity: ArrayLike) -> SerialChain:
        """The same chain under the gravitational acceleration ``gravity`` (3,), m/s², base frame.

        E.g. ``chain.with_gravity((0, 0, -1.62))`` on the Moon, or ``(0, 0, 0)`` to see the
        arm's motion without gravity.
        """
        return SerialChain(self._links, gravity=gravity, name=self._name, frames=self._frames)

    def __repr__(self):
        joints = "".join("R" if j == "revolute" else "P" for j in self.joint_types)
        name = "" if self._name is None else f"{self._name!r}, "
        return f"SerialChain({name}{self.dof} joints {joints}, mass={self.mass:.6g} kg)"


_TOML_KEYS = {"name", "convention", "gravity", "check_triangle", "source", "link"}


def load(path: str | os.PathLike[str], *, inertia: str = "check", min_inertia: float = 0.0) -> RobotTree:
    """A robot from a robot file: a DH table in TOML (``.toml``) or a URDF (``.urdf``, ``.xml``).

    A URDF gives a :class:`SerialChain` when it describes a serial chain
    without mimic joints, else a :class:`~tumble.robot.RobotTree`
    (:func:`tumble.robot.urdf.read_urdf`, which ``inertia`` and
    ``min_inertia`` are passed to).

    The TOML file holds ``convention`` (``"standard"`` or ``"modified"``),
    optional ``name``, ``gravity``, ``check_triangle`` and ``source`` (a
    credit line), and one ``[[link]]`` table per joint with the keys of
    :meth:`SerialChain.from_dh`. Files are data: nothing in them is executed.
    """
    path = Path(path)
    if path.suffix.lower() in (".urdf", ".xml"):
        d = read_urdf(path, inertia=inertia, min_inertia=min_inertia)
        if d.serial:
            return SerialChain(d.links, name=d.name, frames=d.frames)._warn_massless()
        return RobotTree(d.links, d.parents, name=d.name, frames=d.frames, mimic=d.mimic)._warn_massless()
    if path.suffix.lower() != ".toml":
        raise ValidationError(f"robot file: must end in .toml (DH table) or .urdf/.xml, got {path.name!r}")
    try:
        doc = tomllib.loads(read_input(path).decode("utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ValidationError(f"{path.name}: malformed TOML ({exc})") from None
    unknown = sorted(set(doc) - _TOML_KEYS)
    if unknown:
        raise ValidationError(f"{path.name}: unknown key(s) {unknown}; allowed: {sorted(_TOML_KEYS)}")
    if "link" not in doc:
        raise ValidationError(f"{path.name}: needs at least one [[link]] table")
    check_triangle = doc.get("check_triangle", True)
    if not isinstance(check_triangle, bool):
        raise ValidationError(f"{path.name}: check_triangle must be true or false, got {check_triangle!r}")
    return SerialChain.from_dh(doc["link"], convention=doc.get("convention", "standard"),
                               gravity=doc.get("gravity", DEFAULT_GRAVITY), name=doc.get("name", path.stem),
                               check_triangle=check_triangle)
