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
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from tumble._inertia import as_shape, frozen, parallel_axis
from tumble._validate import ValidationError, as_array
from tumble.kernels import featherstone as _kernels
from tumble.robot.link import Link
from tumble.robot.motion import ChainMotion
from tumble.robot.urdf import links_from_urdf

__all__ = ["SerialChain", "load"]

DEFAULT_GRAVITY = (0.0, 0.0, -9.81)


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
    return Link(joint=joint, axis=(0.0, 0.0, 1.0), origin_position=origin_position,
                origin_rotation=origin_rotation, frame_position=frame_position, frame_rotation=frame_rotation,
                offset=offset, mass=row.get("mass", 0.0), com=row.get("com", (0.0, 0.0, 0.0)),
                inertia=row.get("inertia", np.zeros((3, 3))), lower=lower, upper=upper,
                name=row.get("name", f"joint{k + 1}"), check_triangle=check_triangle)


class SerialChain(ChainMotion):
    """An immutable, validated serial chain of rigid links on a fixed base.

    ``SerialChain(links, *, gravity=(0, 0, -9.81), name=None)``

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

    __slots__ = ("_links", "_gravity", "_name", "_params", "_lower", "_upper", "_no_wrench", "_no_wrenches",
                 "_one_state")

    def __init__(self, links: Sequence[Link], *, gravity=DEFAULT_GRAVITY, name: str | None = None):
        links = tuple(links)
        if not links:
            raise ValidationError("links: a serial chain needs at least one link")
        for k, link in enumerate(links):
            if not isinstance(link, Link):
                raise ValidationError(f"links[{k}]: must be a tumble.robot.Link, got {type(link).__name__}")
        set_ = object.__setattr__
        set_(self, "_links", links)
        set_(self, "_gravity", np.array(as_shape(gravity, "gravity", (3,))))
        set_(self, "_name", name)
        set_(self, "_params", _pack(links))
        set_(self, "_lower", frozen([link.lower for link in links]))
        set_(self, "_upper", frozen([link.upper for link in links]))
        set_(self, "_no_wrench", np.zeros(6))
        set_(self, "_no_wrenches", np.zeros((1, 6)))
        set_(self, "_one_state", (len(links),))  # the shape of one joint array, for the fast path of a call

    # -- constructors ---------------------------------------------------------

    @classmethod
    def from_dh(cls, links: Sequence[Mapping], *, convention: str = "standard", gravity=DEFAULT_GRAVITY,
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
    def from_urdf(cls, source, *, check_triangle: bool = True, gravity=DEFAULT_GRAVITY) -> SerialChain:
        """A chain from a URDF file (path) or document (a string starting with ``<``); see :mod:`.urdf`."""
        name, links = links_from_urdf(source, check_triangle=check_triangle)
        return cls(links, gravity=gravity, name=name)

    # -- data -----------------------------------------------------------------

    @property
    def links(self) -> tuple[Link, ...]:
        """The links, base to tip."""
        return self._links

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return len(self._links)

    @property
    def joint_names(self) -> tuple[str | None, ...]:
        return tuple(link.name for link in self._links)

    @property
    def joint_types(self) -> tuple[str, ...]:
        return tuple(link.joint for link in self._links)

    @property
    def gravity(self) -> np.ndarray:
        """(3,) gravitational acceleration in the base frame, m/s² (a copy)."""
        return self._gravity.copy()

    def with_gravity(self, gravity) -> SerialChain:
        """The same chain under the gravitational acceleration ``gravity`` (3,), m/s², base frame.

        E.g. ``chain.with_gravity((0, 0, -1.62))`` on the Moon, or ``(0, 0, 0)`` to see the
        arm's motion without gravity.
        """
        return SerialChain(self._links, gravity=gravity, name=self._name)

    @property
    def name(self) -> str | None:
        return self._name

    @property
    def lower(self) -> np.ndarray:
        """(n,) lower joint limits (rad or m; -inf when unlimited), read-only."""
        return self._lower

    @property
    def upper(self) -> np.ndarray:
        """(n,) upper joint limits (rad or m; +inf when unlimited), read-only."""
        return self._upper

    @property
    def params(self) -> np.ndarray:
        """(n, 42) array the compiled algorithms read (layout in :mod:`tumble.kernels.featherstone`), a copy."""
        return self._params.copy()

    def within_limits(self, q) -> np.ndarray | bool:
        """True where ``lower ≤ q ≤ upper`` for every joint; ``q`` of shape (…, n)."""
        q = as_array(q, "q", tail=(self.dof,))
        ok = ((q >= self._lower) & (q <= self._upper)).all(axis=-1)
        return bool(ok) if ok.ndim == 0 else ok

    def __setattr__(self, name, value):
        raise AttributeError(f"SerialChain is immutable: cannot set {name!r}")

    def __repr__(self):
        joints = "".join("R" if j == "revolute" else "P" for j in self.joint_types)
        name = "" if self._name is None else f"{self._name!r}, "
        return f"SerialChain({name}{self.dof} joints {joints}, mass={sum(l.mass for l in self._links):.6g} kg)"


def _pack(links: tuple[Link, ...]) -> np.ndarray:
    """The (n, 42) parameter array of :mod:`._kernels`, in canonical frames.

    The link frame's offset (R_f, p_f) of link i−1 is folded into the joint
    origin of joint i, and link i's mass properties are moved from its link
    frame to the canonical frame (origin on joint i's axis):
    ``c' = R_f c + p_f``, ``I_c' = R_f I_c R_fᵀ``, ``I_O = I_c' + m(|c'|² E − c'c'ᵀ)``.
    """
    P = np.zeros((len(links), _kernels.PARAMS))
    prev_R, prev_p = np.eye(3), np.zeros(3)
    for i, link in enumerate(links):
        P[i, 0:9] = (prev_R @ link.origin_rotation).ravel()
        P[i, 9:12] = prev_p + prev_R @ link.origin_position
        P[i, 12:15] = link.axis
        P[i, 15] = _kernels.REVOLUTE if link.joint == "revolute" else _kernels.PRISMATIC
        P[i, 16] = link.offset
        Rf, pf = link.frame_rotation, link.frame_position
        com = Rf @ link.com + pf
        P[i, 17] = link.mass
        P[i, 18:21] = link.mass * com
        P[i, 21:30] = (Rf @ link.inertia @ Rf.T + parallel_axis(link.mass, com)).ravel()
        P[i, 30:39] = Rf.ravel()
        P[i, 39:42] = pf
        prev_R, prev_p = Rf, pf
    return P


_TOML_KEYS = {"name", "convention", "gravity", "check_triangle", "source", "link"}


def load(path) -> SerialChain:
    """A chain from a robot file: a DH table in TOML (``.toml``) or a URDF (``.urdf``, ``.xml``).

    The TOML file holds ``convention`` (``"standard"`` or ``"modified"``),
    optional ``name``, ``gravity``, ``check_triangle`` and ``source`` (a
    credit line), and one ``[[link]]`` table per joint with the keys of
    :meth:`SerialChain.from_dh`. Files are data: nothing in them is executed.
    """
    path = Path(path)
    if path.suffix.lower() in (".urdf", ".xml"):
        return SerialChain.from_urdf(path)
    if path.suffix.lower() != ".toml":
        raise ValidationError(f"robot file: must end in .toml (DH table) or .urdf/.xml, got {path.name!r}")
    try:
        with open(path, "rb") as fh:
            doc = tomllib.load(fh)
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
