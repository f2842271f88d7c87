"""A segment model of the human body whose joint angles are prescribed functions of time.

The body is a tree of rigid segments; the root (trunk and head) carries the
body frame B: origin at the hip-joint centre, ``x`` to the athlete's right,
``y`` forward, ``z`` up the spine (head), so that in B a somersault is a
rotation about ``x``, a cartwheel about ``y`` and a twist about ``z``. Each
other segment hangs from its parent at a joint, rotated by the joint angles
about fixed joint axes: ``R_joint = R(a₁, θ₁) R(a₂, θ₂) …`` (axes in the
parent's frame, each rotation about the axis as already turned by the ones
before it). With every angle zero the athlete stands straight, arms at the sides.

Kinematics of segment ``i`` relative to B (all vectors in B axes; ``p`` its parent)::

    R_i = R_p R_joint,i                 ω_i = ω_p + R_p Σₖ θ̇ₖ (R(a₁,θ₁)…R(aₖ₋₁,θₖ₋₁)) aₖ
    o_i = o_p + R_p j_i                 ȯ_i = ȯ_p + ω_p × (R_p j_i)          (joint position)
    c_i = o_i + R_i s_i                 ċ_i = ȯ_i + ω_i × (R_i s_i)          (centre of mass)

with ``j_i`` the joint in the parent's frame and ``s_i`` the segment's centre
of mass in its own frame. With the whole-body centre of mass ``C = Σ mᵢcᵢ/M``,
``rᵢ = cᵢ − C`` and the segment inertias ``Jᵢ`` (own axes), the angular
momentum about C of the body turning at ``ω`` (B relative to inertial) is
``Σ [Rᵢ Jᵢ Rᵢᵀ (ω + ωᵢ) + mᵢ rᵢ × (ṙᵢ + ω × rᵢ)] = I(t) ω + A(t)`` with::

    I(t) = Σ [Rᵢ Jᵢ Rᵢᵀ + mᵢ (|rᵢ|² E − rᵢ rᵢᵀ)]          (inertia about C)
    A(t) = Σ [Rᵢ Jᵢ Rᵢᵀ ωᵢ + mᵢ rᵢ × ṙᵢ]                   (shape momentum)

and the kinetic energy is ``½ ω·Iω + ω·A + T_shape``,
``T_shape = ½ Σ [ωᵢ·RᵢJᵢRᵢᵀωᵢ + mᵢ|ṙᵢ|²]`` (the energy of the shape change seen from B).

The default body, :meth:`Human.de_leva`, takes segment masses, centre-of-mass
positions and radii of gyration from P. de Leva, "Adjustments to
Zatsiorsky–Seluyanov's segment inertia parameters", J. Biomech. 29(9) (1996)
1223–1230, Table 4 (male, 73.0 kg, 1.741 m); see ``docs/diver.md``.

A human with a schedule of joint angles is a model of :func:`tumble.simulate`:
``tumble.simulate(human.moving(angles, t_span=(t0, t1)), omega0=..., t=...)``
(:class:`MovingHuman`). A :class:`Human` alone has no motion to simulate.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_positive
from tumble.rigid_body import Part, RigidBody
from tumble.simulate import Outputs
from tumble.trajectory import Extra
from tumble.variable.body import VariableBody

if TYPE_CHECKING:
    from tumble.kernels.variable import VariableModel

__all__ = ["DE_LEVA_MALE", "Human", "Kinematics", "Motion", "MovingHuman", "Segment"]


# -- prescribed joint angles ---------------------------------------------------------


class Motion:
    """A joint angle (rad) as a function of time: a start value, then smooth moves.

    ``Motion(start, moves=())`` with ``moves`` a sequence of ``(t_begin, t_end, target)``
    (s, s, rad), in time order and not overlapping. Each move follows the
    minimum-jerk profile of T. Flash and N. Hogan, J. Neurosci. 5(7) (1985)
    1688–1703: ``θ = θ₀ + (θ₁ − θ₀) σ(u)``, ``σ(u) = 10u³ − 15u⁴ + 6u⁵``,
    ``u = (t − t_begin)/(t_end − t_begin)``, which starts and ends at rest
    with zero acceleration (``θ`` is twice continuously differentiable).
    Any object with vectorised ``angle(t)`` and ``rate(t)`` methods can stand
    in for a Motion; a plain number is a constant angle.
    """

    __slots__ = ("start", "moves")

    def __init__(self, start: float = 0.0, moves: Sequence = ()) -> None:
        self.start = float(as_array(start, "start"))
        checked, previous_end = [], -np.inf
        for k, move in enumerate(moves):
            t0, t1, target = (float(x) for x in as_array(move, f"moves[{k}]", tail=(3,)))
            if not t1 > t0 or t0 < previous_end:
                raise ValidationError(f"moves[{k}]: must be (t_begin, t_end, target) with t_end > t_begin, "
                                      f"starting at or after the previous move's end {previous_end}, "
                                      f"got {(t0, t1, target)}")
            checked.append((t0, t1, target))
            previous_end = t1
        self.moves = tuple(checked)

    def angle(self, t: ArrayLike) -> np.ndarray:
        """The angle at times ``t`` (rad)."""
        t = np.asarray(t, dtype=np.float64)
        out, value = np.full(t.shape, self.start), self.start
        for t0, t1, target in self.moves:
            u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
            out += (target - value) * u**3 * (10.0 - 15.0 * u + 6.0 * u * u)
            value = target
        return out

    def rate(self, t: ArrayLike) -> np.ndarray:
        """The angular rate at times ``t`` (rad/s)."""
        t = np.asarray(t, dtype=np.float64)
        out, value = np.zeros(t.shape), self.start
        for t0, t1, target in self.moves:
            u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
            out += (target - value) / (t1 - t0) * 30.0 * u * u * (1.0 - u) ** 2
            value = target
        return out

    def __repr__(self) -> str:
        return f"Motion(start={self.start!r}, moves={list(self.moves)!r})"


def _profile(value, name):
    if hasattr(value, "angle") and hasattr(value, "rate"):
        return value
    try:
        return Motion(float(value))
    except (TypeError, ValueError, ValidationError):
        raise ValidationError(f"angles[{name!r}]: must be a number (rad) or have angle(t) and rate(t) methods, "
                              f"got {type(value).__name__}") from None


# -- the segment tree ----------------------------------------------------------------


@dataclass(frozen=True)
class Segment:
    """One rigid segment of a :class:`Human`.

    name   : unique name
    parent : name of the segment it hangs from, or None for the root (the body frame B)
    joint  : (3,) joint position in the parent's frame, m (ignored for the root)
    axes   : joint axes, unit vectors in the parent's frame, one per angle, applied in order
    dofs   : names of the joint angles, one per axis (unique in the body)
    part   : mass, centre of mass (relative to the joint) and inertia in the segment's own frame
    """

    name: str
    parent: str | None
    joint: tuple = (0.0, 0.0, 0.0)
    axes: tuple = ()
    dofs: tuple = ()
    part: Part = None  # type: ignore[assignment]  # required: __post_init__ refuses None (it orders the fields)

    def __post_init__(self):
        if not isinstance(self.part, Part):
            raise ValidationError(f"{self.name}.part: must be a tumble.rigid_body.Part, got {type(self.part).__name__}")
        axes = as_array(self.axes, f"{self.name}.axes").reshape(-1, 3) if len(self.axes) else np.zeros((0, 3))
        if np.any(np.abs(np.linalg.norm(axes, axis=1) - 1.0) > 1e-12):
            raise ValidationError(f"{self.name}.axes: must be unit vectors")
        if len(self.dofs) != axes.shape[0]:
            raise ValidationError(f"{self.name}.dofs: must name one angle per axis ({axes.shape[0]}), "
                                  f"got {self.dofs}")
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "joint", as_array(self.joint, f"{self.name}.joint", tail=(3,)))
        object.__setattr__(self, "dofs", tuple(str(d) for d in self.dofs))


class Kinematics(NamedTuple):
    """The state of a :class:`Human`'s shape at the times ``t`` (n,), all in body axes B.

    inertia        : (n, 3, 3) ``I(t)`` about the whole-body centre of mass, kg·m²
    shape_momentum : (n, 3) ``A(t)``, kg·m²/s
    com            : (n, 3) whole-body centre of mass relative to the hip-joint centre, m
    shape_energy   : (n,) ``T_shape``, J
    rotation       : (n, S, 3, 3) segment axes relative to B
    joint          : (n, S, 3) joint positions relative to the hip-joint centre, m
    segment_rate   : (n, S, 3) segment angular velocities relative to B, rad/s
    segment_com    : (n, S, 3) segment centres of mass relative to the hip-joint centre, m
    """

    t: np.ndarray
    inertia: np.ndarray
    shape_momentum: np.ndarray
    com: np.ndarray
    shape_energy: np.ndarray
    rotation: np.ndarray
    joint: np.ndarray
    segment_rate: np.ndarray
    segment_com: np.ndarray


def _axis_rotation(axis, angle):
    """Rodrigues: ``R = E + sin θ [a]× + (1 − cos θ) [a]×²`` for angles (n,), shape (n, 3, 3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


class Human:
    """A tree of :class:`Segment` (root first, each parent before its children) with prescribed joint angles."""

    def __init__(self, segments: Sequence[Segment]) -> None:
        segments = tuple(segments)
        if not segments or segments[0].parent is not None:
            raise ValidationError("segments: the first segment must be the root (parent=None)")
        index: dict[str, int] = {}
        dofs: list[str] = []
        for k, seg in enumerate(segments):
            if not isinstance(seg, Segment):
                raise ValidationError(f"segments[{k}]: must be a Segment, got {type(seg).__name__}")
            if seg.name in index:
                raise ValidationError(f"segments[{k}].name: {seg.name!r} is used twice")
            if k and seg.parent not in index:
                raise ValidationError(f"segments[{k}].parent: {seg.parent!r} must name an earlier segment")
            index[seg.name] = k
            dofs += seg.dofs
        if len(set(dofs)) != len(dofs):
            raise ValidationError(f"segments: joint angle names must be unique, got {dofs}")
        self.segments = segments
        self.dofs = tuple(dofs)
        self._parents: list[int | None] = [None]  # the index of each segment's parent, None for the root
        for seg in segments[1:]:
            assert seg.parent is not None  # an earlier segment: checked above
            self._parents.append(index[seg.parent])

    @classmethod
    def de_leva(cls, mass: float = 73.0, height: float = 1.741) -> Human:
        """The 9-segment diver of :data:`DE_LEVA_MALE`, scaled to ``mass`` (kg) and ``height`` (m)."""
        return cls(_de_leva_segments(require_positive(mass, "mass"), require_positive(height, "height")))

    @property
    def mass(self) -> float:
        """Total mass, kg."""
        return float(sum(s.part.mass for s in self.segments))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.segments)

    def kinematics(self, t: ArrayLike, angles: Mapping | None = None) -> Kinematics:
        """``I(t)``, ``A(t)`` and the segment motion at times ``t`` (s) for the joint ``angles``.

        ``angles`` maps joint-angle names (:attr:`dofs`) to a number (rad), a
        :class:`Motion`, or any object with ``angle(t)``/``rate(t)``; missing
        angles are zero.
        """
        t = np.atleast_1d(as_array(t, "t"))
        profiles = self.profiles(angles)
        n, S = t.size, len(self.segments)
        rot = np.empty((n, S, 3, 3))
        rate = np.empty((n, S, 3))
        joint = np.empty((n, S, 3))
        joint_vel = np.empty((n, S, 3))
        for i, (seg, p) in enumerate(zip(self.segments, self._parents)):
            if p is None:
                rot[:, i], rate[:, i], joint[:, i], joint_vel[:, i] = np.eye(3), 0.0, 0.0, 0.0
                continue
            local = np.broadcast_to(np.eye(3), (n, 3, 3))
            local_rate = np.zeros((n, 3))
            for axis, dof in zip(seg.axes, seg.dofs):
                local_rate = local_rate + profiles[dof].rate(t)[:, None] * (local @ axis)
                local = local @ _axis_rotation(axis, profiles[dof].angle(t))
            arm = rot[:, p] @ seg.joint
            rot[:, i] = rot[:, p] @ local
            rate[:, i] = rate[:, p] + np.einsum("nij,nj->ni", rot[:, p], local_rate)
            joint[:, i] = joint[:, p] + arm
            joint_vel[:, i] = joint_vel[:, p] + np.cross(rate[:, p], arm)
        masses = np.array([s.part.mass for s in self.segments])
        own = np.einsum("nsij,sj->nsi", rot, np.array([s.part.com for s in self.segments]))
        com = joint + own
        com_vel = joint_vel + np.cross(rate, own)
        total = masses.sum()
        centre = np.einsum("s,nsi->ni", masses, com) / total
        r = com - centre[:, None]
        r_dot = com_vel - (np.einsum("s,nsi->ni", masses, com_vel) / total)[:, None]
        inertia_own = rot @ np.array([s.part.inertia for s in self.segments]) @ np.swapaxes(rot, -1, -2)
        sq = np.einsum("nsi,nsi->ns", r, r)
        inertia = (inertia_own.sum(axis=1) + np.einsum("s,ns->n", masses, sq)[:, None, None] * np.eye(3)
                   - np.einsum("s,nsi,nsj->nij", masses, r, r))
        spin = np.einsum("nsij,nsj->nsi", inertia_own, rate)
        shape_momentum = spin.sum(axis=1) + np.einsum("s,nsi->ni", masses, np.cross(r, r_dot))
        shape_energy = 0.5 * (np.einsum("nsi,nsi->n", rate, spin)
                              + np.einsum("s,ns->n", masses, np.einsum("nsi,nsi->ns", r_dot, r_dot)))
        return Kinematics(t, inertia, shape_momentum, centre, shape_energy, rot, joint, rate, com)

    def profiles(self, angles: Mapping | None = None) -> dict:
        """Every joint angle of :attr:`dofs` as an object with ``angle(t)`` and ``rate(t)``.

        ``angles`` maps names to a number (rad), a :class:`Motion` or any such
        object; missing angles are zero; an unknown name is refused.
        """
        angles = {} if angles is None else dict(angles)
        unknown = sorted(set(angles) - set(self.dofs))
        if unknown:
            raise ValidationError(f"angles: unknown joint angles {unknown}; this body has {list(self.dofs)}")
        return {name: _profile(angles.get(name, 0.0), name) for name in self.dofs}

    def moving(self, angles: Mapping | None = None, *, t_span: tuple[float, float], dt: float = 2e-3) -> MovingHuman:
        """This body moving its joints through ``angles`` over ``t_span`` (s): a model of :func:`tumble.simulate`.

        ``I(t)`` and ``A(t)`` are sampled every ``dt`` (s) or less and interpolated
        by cubic splines (error ``O(dt⁴)``; measured in ``docs/diver.md``).
        """
        return MovingHuman(self, angles, t_span=t_span, dt=dt)

    def inertia(self, angles: Mapping | None = None) -> np.ndarray:
        """The inertia (3, 3) about the centre of mass, body axes, kg·m², of the posture ``angles`` (held still)."""
        return self.kinematics([0.0], angles).inertia[0]


class MovingHuman(VariableBody):
    """A :class:`Human` moving its joints through prescribed angles: a :class:`VariableBody` made from its segments.

    ``MovingHuman(human, angles=None, *, t_span, dt=2e-3)``, or :meth:`Human.moving`:
    ``I(t)`` and ``A(t)`` of :meth:`Human.kinematics` sampled every ``dt`` (s) or
    less over ``t_span`` (s) and interpolated by cubic splines. A model of
    :func:`tumble.simulate` with the initial state of a :class:`VariableBody`
    (``omega0``, ``q0``: the trunk frame B). Its trajectory adds to the extras of a
    VariableBody the prescribed ``joint_angles`` (n, [N,] J, rad, in the order of
    ``human.dofs``) and ``shape_energy`` ``T_shape`` (J), and its total ``energy``
    is the whole kinetic energy about the centre of mass,
    ``½ ω·I ω + ω·A + T_shape`` (module docstring), which the muscles change.
    """

    __slots__ = ("_human", "_angles")

    def __init__(self, human: Human, angles: Mapping | None = None, *, t_span: tuple[float, float],
                 dt: float = 2e-3) -> None:
        if not isinstance(human, Human):
            raise ValidationError(f"human: must be a tumble.variable.Human, got {type(human).__name__}")
        profiles = human.profiles(angles)
        k = human.kinematics(VariableBody.grid(t_span, dt), profiles)
        super().__init__(k.t, k.inertia, k.shape_momentum)
        self._human, self._angles = human, profiles

    @property
    def human(self) -> Human:
        """The segment model."""
        return self._human

    @property
    def angles(self) -> dict:
        """The joint angles, name → object with ``angle(t)`` and ``rate(t)`` (rad, rad/s)."""
        return dict(self._angles)

    def outputs(self, kernel: VariableModel, t: np.ndarray, states: np.ndarray) -> Outputs:
        out = super().outputs(kernel, t, states)
        lead = states.shape[:2]
        joints = np.stack([self._angles[name].angle(t) for name in self._human.dofs], axis=-1)
        shape_energy = np.broadcast_to(self._human.kinematics(t, self._angles).shape_energy[:, None], lead)
        extras = {
            **out.extras,
            "joint_angles": Extra(np.broadcast_to(joints[:, None], lead + joints.shape[-1:]), ("joint",), "rad",
                                  "prescribed joint angles, in the order " + ", ".join(self._human.dofs)),
            "shape_energy": Extra(shape_energy, (), "J", "kinetic energy of the shape change relative to the "
                                  "trunk frame"),
        }
        assert out.omega is not None  # the trunk's rate
        coupling = np.einsum("...i,...i->...", out.omega, out.extras["shape_momentum"].data)   # ω·A
        energy = out.totals["energy"] + coupling + shape_energy
        return out._replace(extras=extras, totals={**out.totals, "energy": energy})


# -- de Leva (1996), Table 4, male ---------------------------------------------------------------

#: Segment parameters of P. de Leva, J. Biomech. 29(9) (1996) 1223–1230, Table 4, male
#: (mean 73.0 kg, stature 1.741 m): segment length (m), mass fraction of body mass, centre
#: of mass from the proximal end as a fraction of the length (head: from the vertex; foot:
#: from the heel), and radii of gyration as fractions of the length about the
#: medio-lateral (x), antero-posterior (y) and longitudinal (z) axes (Table 4's
#: "sagittal", "transverse" and "longitudinal" columns).
DE_LEVA_MALE = {
    #          length  mass    com     r_x    r_y    r_z
    "head":    (0.2033, 0.0694, 0.5976, 0.362, 0.376, 0.312),
    "trunk":   (0.5319, 0.4346, 0.4486, 0.372, 0.347, 0.191),
    "upper_arm": (0.2817, 0.0271, 0.5772, 0.285, 0.269, 0.158),
    "forearm": (0.2689, 0.0162, 0.4574, 0.276, 0.265, 0.121),
    "hand":    (0.0862, 0.0061, 0.7900, 0.628, 0.513, 0.401),
    "thigh":   (0.4222, 0.1416, 0.4095, 0.329, 0.329, 0.149),
    "shank":   (0.4340, 0.0433, 0.4459, 0.255, 0.249, 0.103),
    "foot":    (0.2581, 0.0137, 0.4415, 0.257, 0.245, 0.124),
}
_STATURE = 1.741
# Geometry not given by de Leva (model choices, scaled with height): half the distance
# between the shoulder-joint centres and between the hip-joint centres, and the
# gap from the top of the trunk (suprasternale) to the bottom of the head (gonion).
_SHOULDER_HALF_WIDTH = 0.18
_HIP_HALF_WIDTH = 0.085
_NECK = 0.08


def _de_leva_segments(mass, height):
    """The 9 segments: trunk+head (root), upper arms, forearm+hand, thighs, shank+foot (toes pointed)."""
    k = height / _STATURE

    def piece(name, top):
        """A de Leva segment hanging down from ``top`` (z), as a Part in its parent's axes (cm, J)."""
        length, fraction, com, *radii = DE_LEVA_MALE[name]
        length *= k
        m = fraction * mass
        inertia = np.diag(m * (np.array(radii) * length) ** 2)
        return Part(mass=m, com=np.array([0.0, 0.0, top - com * length]), inertia=inertia), length

    trunk, trunk_length = piece("trunk", DE_LEVA_MALE["trunk"][0] * k)   # from hip (z = 0) to suprasternale
    head, _ = piece("head", trunk_length + _NECK * k + DE_LEVA_MALE["head"][0] * k)
    upper_arm, upper_length = piece("upper_arm", 0.0)
    forearm, forearm_length = piece("forearm", 0.0)
    hand, _ = piece("hand", -forearm_length)
    thigh, thigh_length = piece("thigh", 0.0)
    shank, shank_length = piece("shank", 0.0)
    foot, _ = piece("foot", -shank_length)

    def merged(*parts):
        body = RigidBody.composite(parts)
        return Part(mass=body.mass, com=body.com, inertia=body.inertia)

    torso, forearm_hand, shank_foot = merged(trunk, head), merged(forearm, hand), merged(shank, foot)
    shoulder_z = trunk_length
    segments = [Segment("torso", None, part=torso)]
    for side, sign in (("left", -1.0), ("right", 1.0)):
        out = (0.0, -sign, 0.0)   # abduction axis: +y for the left limb (at x < 0), -y for the right
        segments += [
            Segment(f"{side}_upper_arm", "torso", (sign * _SHOULDER_HALF_WIDTH * k, 0.0, shoulder_z),
                    ((1.0, 0.0, 0.0), out), (f"{side}_shoulder_flexion", f"{side}_shoulder_abduction"), upper_arm),
            Segment(f"{side}_forearm", f"{side}_upper_arm", (0.0, 0.0, -upper_length), ((1.0, 0.0, 0.0),),
                    (f"{side}_elbow_flexion",), forearm_hand),
            Segment(f"{side}_thigh", "torso", (sign * _HIP_HALF_WIDTH * k, 0.0, 0.0), ((1.0, 0.0, 0.0), out),
                    (f"{side}_hip_flexion", f"{side}_hip_abduction"), thigh),
            Segment(f"{side}_shank", f"{side}_thigh", (0.0, 0.0, -thigh_length), ((-1.0, 0.0, 0.0),),
                    (f"{side}_knee_flexion",), shank_foot),
        ]
    return segments
