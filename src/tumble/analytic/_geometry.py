"""Geometry of torque-free motion: polhodes, separatrices and the herpolhode (Poinsot's construction).

In principal axes (moments ``I₁ ≤ I₂ ≤ I₃``, kg·m²) the body rate ``ω`` (rad/s)
of a torque-free body keeps its kinetic energy ``T`` (J) and the magnitude
``L = |L|`` (N·m·s) of its angular momentum, so it moves on the intersection of

    the energy ellipsoid    I₁ω₁² + I₂ω₂² + I₃ω₃² = 2T
    the momentum ellipsoid  I₁²ω₁² + I₂²ω₂² + I₃²ω₃² = L²

a closed curve, the *polhode* (Landau & Lifshitz, *Mechanics*, §37; Goldstein,
*Classical Mechanics*, §5.6). ``L²`` lies between ``2T I₁`` and ``2T I₃``. For
``L² > 2T I₂`` the polhode circles the axis of largest moment (``"major"``),
for ``L² < 2T I₂`` the axis of smallest moment (``"minor"``); ``L² = 2T I₂``
is the *separatrix*, two ellipses crossing at the intermediate axis.

Subtracting ``Iᵢ`` times the first equation from the second gives
``Σⱼ Iⱼ (Iⱼ − Iᵢ) ωⱼ² = Δᵢ``, ``Δᵢ = L² − 2T Iᵢ``. For the circled axis ``c``
and the other two ``j, k`` (cyclic) it is an ellipse in ``(ω_j, ω_k)``, which
parametrises the polhode exactly,

    ω_j = A_j cos θ,   ω_k = ± A_k sin θ,   A_i² = Δ_c / (I_i (I_i − I_c)),
    I_c |I_c − I₂| ω_c² = |Δ₂| + I_o |I_o − I₂| ω_o²     (o: the axis other than c and 2),

with ``ω_c`` of sign ``s = ±1``, the side of the polhode; the last line is
the equation ``i = 2``, a sum of non-negative terms, so ``ω_c`` keeps its
accuracy up to the separatrix. ``θ`` is the Jacobi amplitude of the elliptic
solution (up to a quarter turn), and the sign of ``ω_k`` is chosen so that
``θ`` increases along the motion.

Poinsot: the energy ellipsoid, fixed to the body, rolls without slipping on
the *invariable plane*, perpendicular to the inertial angular momentum ``L_I``
at distance ``2T/|L|`` from the centre, since ``ω·L = 2T``. The point of
contact is ``ω``; its path on the plane is the *herpolhode*.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

from tumble._validate import ValidationError, as_array, require_count, require_positive
from tumble.analytic._free import free_parameters
from tumble.attitude import rotate
from tumble.rigid_body import RigidBody
from tumble.trajectory import Trajectory

__all__ = ["Polhode", "Herpolhode", "polhode", "polhode_through", "polhode_family", "separatrix", "herpolhode"]

# 2T I₁ ≤ L² ≤ 2T I₃ is accepted up to this relative excess (rounding of T and
# |L| computed from a rate along the first or third principal axis).
_LEVEL_RTOL = 1e-12
_DEFAULT_POINTS = 361


@dataclass(frozen=True, eq=False)
class Polhode:
    """A polhode: its points and the motion it belongs to (:func:`polhode_through`, :func:`polhode_family`).

    ``points`` (n, 3): body rates in principal axes (rad/s), a closed curve
    (first point = last) in the direction of the motion; ``momentum``: ``|L|``
    (N·m·s); ``axis``: index (0 or 2) of the principal axis it circles
    (``axis = 2``: regime ``"major"``, ``axis = 0``: ``"minor"``); ``sign``:
    the sign of the rate about that axis.
    """

    points: np.ndarray
    momentum: float
    axis: int
    sign: int

    @property
    def regime(self) -> str:
        """``"major"`` (circles the axis of largest moment) or ``"minor"`` (smallest)."""
        return "major" if self.axis == 2 else "minor"


@dataclass(frozen=True, eq=False)
class Herpolhode:
    """The path of the body rate on the invariable plane (inertial axes).

    ``points`` (n, 2): in-plane coordinates of ``ω_I`` along ``basis`` (rad/s);
    ``omega_inertial`` (n, 3): the body rate in inertial axes, ``ω_I = R(q) ω_B``
    (rad/s); ``normal`` (3,): ``L_I/|L_I|`` at the first sample; ``height``:
    ``2T/|L|`` (rad/s) at the first sample, the distance of the plane from the
    origin; ``basis`` (2, 3): orthonormal in-plane axes, with
    ``basis[0] × basis[1] = normal``. So ``ω_I ≈ height·normal + points @ basis``.
    """

    points: np.ndarray
    omega_inertial: np.ndarray
    normal: np.ndarray
    height: float
    basis: np.ndarray


def _moments(body: RigidBody) -> np.ndarray:
    if not isinstance(body, RigidBody):
        raise ValidationError(f"body: must be a RigidBody, got {type(body).__name__}")
    moments = body.moments
    if moments[0] == moments[2]:
        raise ValidationError(
            "body: a spherical body (I1 = I2 = I3) has no polhodes: every rotation is steady, omega is constant"
        )
    return moments


def _omega_principal(body: RigidBody, omega) -> np.ndarray:
    """``ω_P = R_BPᵀ ω_B`` (rad/s) for one non-zero body rate ``omega`` of shape (3,) in body axes."""
    omega = as_array(omega, "omega", tail=(3,))
    if omega.shape != (3,):
        raise ValidationError(f"omega: must have shape (3,), got {omega.shape}")
    if not omega.any():
        raise ValidationError("omega: must be non-zero (a body at rest does not move)")
    return body.axes.T @ omega


def _levels(moments: np.ndarray, energy: float, momentum: float) -> np.ndarray:
    """``Δᵢ = L² − 2T Iᵢ`` (3,), with ``2T I₁ ≤ L² ≤ 2T I₃`` checked (to ``_LEVEL_RTOL``) and ``L²`` clipped into it."""
    energy = require_positive(energy, "energy")
    l2 = require_positive(momentum, "momentum") ** 2
    low, high = 2.0 * energy * moments[0], 2.0 * energy * moments[2]
    if not low * (1.0 - _LEVEL_RTOL) <= l2 <= high * (1.0 + _LEVEL_RTOL):
        raise ValidationError(
            f"momentum: |L|^2 = {l2:.6g} must lie between 2 T I1 = {low:.6g} and 2 T I3 = {high:.6g} "
            f"(T = {energy:.6g} J)"
        )
    return min(max(l2, low), high) - 2.0 * energy * moments


def _levels_of_rates(moments: np.ndarray, omega_p: np.ndarray) -> np.ndarray:
    """``Δᵢ = L² − 2T Iᵢ = Σⱼ Iⱼ (Iⱼ − Iᵢ) ωⱼ²`` (3,) from rates in principal axes: Δ₁ ≥ 0 ≥ Δ₃ without cancellation."""
    terms = moments * omega_p**2
    return (moments[None, :] - moments[:, None]) @ terms


def _circled_axis(moments: np.ndarray, levels: np.ndarray) -> int:
    """Index of the principal axis the polhode circles: 2 when ``Δ₂ ≥ 0`` (and ``I₂ < I₃``), else 0."""
    return 2 if levels[1] >= 0.0 and moments[1] < moments[2] else 0


def _curve(moments, levels, c, sign, theta) -> np.ndarray:
    """Polhode points (len(theta), 3) circling axis ``c`` on side ``sign``, at the angles ``theta``.

    ``levels`` are the ``Δᵢ = L² − 2T Iᵢ``. With ``j, k`` the axes after ``c``
    (cyclic): ``ω_j = A_j cos θ``, ``ω_k = s·d·A_k sin θ``,
    ``A_i² = Δ_c / (I_i (I_i − I_c))``, and ``d = sign(I_c − I_j)`` because
    ``I_k ω̇_k = (I_c − I_j) ω_c ω_j``: ``θ`` grows along the motion. The
    circled rate follows from ``Σᵢ Iᵢ (Iᵢ − I₂) ωᵢ² = Δ₂`` as a sum of
    non-negative terms, ``I_c |I_c − I₂| ω_c² = |Δ₂| + I_o |I_o − I₂| ω_o²``
    (``o`` the axis other than ``c`` and the intermediate one), exact to
    rounding up to the separatrix. Indices here are 0-based.
    """
    j, k = (c + 1) % 3, (c + 2) % 3
    others = moments[[j, k]]
    a_j, a_k = np.sqrt(np.maximum(levels[c] / (others * (others - moments[c])), 0.0))
    points = np.empty((theta.size, 3))
    points[:, j] = a_j * np.cos(theta)
    points[:, k] = sign * np.sign(moments[c] - moments[j]) * a_k * np.sin(theta)
    o = 2 - c
    numerator = abs(levels[1]) + moments[o] * abs(moments[o] - moments[1]) * points[:, o] ** 2
    points[:, c] = sign * np.sqrt(numerator / (moments[c] * abs(moments[c] - moments[1])))
    return points


def _amplitude(moments: np.ndarray, c: int, sign: int, omega_p: np.ndarray) -> float:
    """The angle ``θ`` of :func:`_curve` at the point ``omega_p`` (principal axes) of its polhode.

    ``tan θ = s·d·(ω_k/A_k)/(ω_j/A_j)``, where the ratio
    ``A_j/A_k = √(I_k (I_k − I_c) / (I_j (I_j − I_c)))`` does not depend on
    ``L² − 2T I_c``: ``θ`` keeps full accuracy next to the axis.
    """
    j, k = (c + 1) % 3, (c + 2) % 3
    direction = np.sign(moments[c] - moments[j])
    scale_j = np.sqrt(abs(moments[j] * (moments[j] - moments[c])))
    scale_k = np.sqrt(abs(moments[k] * (moments[k] - moments[c])))
    return float(np.arctan2(sign * direction * omega_p[k] * scale_k, omega_p[j] * scale_j))


def _circled(params) -> int:
    """Principal axis (0-based) circled by the polhode of a motion of :func:`free_parameters`."""
    return 0 if params.regime in ("minor", "prolate") else 2


def _side(sign) -> int:
    if sign not in (1, -1):
        raise ValidationError(f"sign: must be +1 or -1, got {sign!r}")
    return int(sign)


def _angles(n: int) -> np.ndarray:
    theta = np.linspace(0.0, 2.0 * np.pi, n)
    theta[-1] = 0.0  # closed: the last point is exactly the first
    return theta


def polhode(body: RigidBody, energy: float, momentum: float, *, n: int = _DEFAULT_POINTS, sign: int = 1) -> np.ndarray:
    """Points of the polhode of kinetic energy ``T`` and angular momentum ``|L|``: (n, 3), principal axes, rad/s.

    The closed curve ``Σ Iᵢ ωᵢ² = 2T``, ``Σ Iᵢ² ωᵢ² = L²`` (first point = last,
    in the direction of the motion), on the side ``sign`` (±1, the sign of the
    rate about the circled axis: the third principal axis when
    ``L² ≥ 2T I₂``, the first otherwise). ``energy`` in J, ``momentum`` in
    N·m·s, with ``2T I₁ ≤ L² ≤ 2T I₃``. On the separatrix ``L² = 2T I₂`` of an
    asymmetric body it is the closed loop made of the halves of the two
    :func:`separatrix` ellipses on that side. At ``L² = 2T I₁`` or ``2T I₃`` it
    collapses to a point on the axis (a steady rotation). Parametrisation: the
    module docstring. A spherical body has none (refused).
    """
    moments = _moments(body)
    levels = _levels(moments, energy, momentum)
    return _curve(moments, levels, _circled_axis(moments, levels), _side(sign), _angles(require_count(n, "n", 3)))


def polhode_through(body: RigidBody, omega, *, n: int = _DEFAULT_POINTS) -> Polhode:
    """The polhode of the torque-free motion whose body rate is ``omega`` (3,) (rad/s, body axes).

    ``T``, ``|L|`` and the regime come from :func:`free_parameters`; the side
    is the sign of the rate about the circled axis (+1 when it is 0: on the
    separatrix). The curve starts at ``ω`` itself (``points[0]`` is ``ω`` in
    principal axes, to rounding) and runs in the direction of the motion;
    points in principal axes, rad/s. A steady rotation (``ω × Iω = 0``
    exactly: ``ω`` along a principal axis, or in the plane of two equal
    moments) has a polhode of one point: ``n`` copies of ``ω``.
    """
    moments = _moments(body)
    omega_p = _omega_principal(body, omega)
    params = free_parameters(moments, omega_p)
    c = _circled(params)
    sign = -1 if omega_p[c] < 0.0 else 1
    theta = _amplitude(moments, c, sign, omega_p) + _angles(require_count(n, "n", 3))
    if not np.cross(omega_p, moments * omega_p).any():
        return Polhode(np.tile(omega_p, (theta.size, 1)), float(params.momentum), c, sign)
    points = _curve(moments, _levels_of_rates(moments, omega_p), c, sign, theta)
    return Polhode(points, float(params.momentum), c, sign)  # one body: |L| a number


def polhode_family(body: RigidBody, energy: float, n_curves: int = 5, *, n: int = _DEFAULT_POINTS) -> list[Polhode]:
    """A family of polhodes of kinetic energy ``T`` (J), for drawing: ``n_curves`` levels about each stable axis.

    About each axis that polhodes circle (the first and the third for an
    asymmetric body; the symmetry axis only for a symmetric top), the levels
    have semi-axes ``A_j`` evenly spaced in ``(0, A_j,separatrix)``, i.e.
    ``L² − 2T I_c = (L²_sep − 2T I_c) f²``, ``f = i/(n_curves + 1)``,
    ``i = 1 … n_curves``, with ``L²_sep = 2T I₂``; each level gives two
    curves (``sign = ±1``). Ordered by ``|L|``, then ``sign``.
    """
    moments = _moments(body)
    energy = require_positive(energy, "energy")
    n_curves, theta = require_count(n_curves, "n_curves", 1), _angles(require_count(n, "n", 3))
    fractions = np.arange(1, n_curves + 1) / (n_curves + 1)
    separatrix_l2 = 2.0 * energy * moments[1]
    curves = []
    for c in (0, 2):
        if moments[c] == moments[1]:
            continue  # a symmetric top: polhodes circle only the symmetry axis
        axis_l2 = 2.0 * energy * moments[c]
        for l2 in axis_l2 + (separatrix_l2 - axis_l2) * fractions**2:
            levels = l2 - 2.0 * energy * moments
            curves += [Polhode(_curve(moments, levels, c, s, theta), float(np.sqrt(l2)), c, s) for s in (1, -1)]
    return sorted(curves, key=lambda p: (p.momentum, -p.sign))


def separatrix(body: RigidBody, energy: float, *, n: int = _DEFAULT_POINTS) -> np.ndarray:
    """The separatrix ``L² = 2T I₂`` on the energy ellipsoid of ``T`` (J): (2, n, 3), principal axes, rad/s.

    Asymmetric body: the two ellipses, in the planes
    ``√(I₁(I₂ − I₁)) ω₁ = ±√(I₃(I₃ − I₂)) ω₃`` through the intermediate axis,

        ω = √(2T) (u₁ sin θ, cos θ / √I₂, ±u₃ sin θ),
        u₁ = √((I₃ − I₂)/(I₁ (I₃ − I₁))),   u₃ = √((I₂ − I₁)/(I₃ (I₃ − I₁))),

    which cross at ``±√(2T/I₂) e₂``. They separate the polhodes that circle
    the first axis from those that circle the third. Symmetric top: shape
    (1, n, 3), the circle of steady rotations about the transverse axes
    (``ω₃ = 0`` for an oblate top, ``ω₁ = 0`` for a prolate one). Closed
    curves (first point = last). A spherical body has none (refused).
    """
    moments = _moments(body)
    energy = require_positive(energy, "energy")
    theta = _angles(require_count(n, "n", 3))
    i1, i2, i3 = moments
    if i1 == i2 or i2 == i3:
        c = 2 if i1 == i2 else 0
        return _curve(moments, 2.0 * energy * (i2 - moments), c, 1, theta)[None]
    u1 = np.sqrt((i3 - i2) / (i1 * (i3 - i1)))
    u3 = np.sqrt((i2 - i1) / (i3 * (i3 - i1)))
    scale = np.sqrt(2.0 * energy)
    ellipse = np.stack([u1 * np.sin(theta), np.cos(theta) / np.sqrt(i2), u3 * np.sin(theta)], axis=-1) * scale
    mirrored = ellipse * [1.0, 1.0, -1.0]
    return np.stack([ellipse, mirrored])


def _plane_basis(normal: np.ndarray) -> np.ndarray:
    """Orthonormal in-plane axes (2, 3) for ``normal``: ``a``, the inertial axis least aligned with it
    made orthogonal to it, then ``normal × a``."""
    axis = np.eye(3)[np.argmin(np.abs(normal))]
    a = axis - (axis @ normal) * normal
    a /= np.linalg.norm(a)
    return np.stack([a, np.cross(normal, a)])


def herpolhode(trajectory: Trajectory) -> Herpolhode:
    """The herpolhode of a torque-free trajectory: the path of ``ω`` on the invariable plane (inertial axes).

    ``ω_I = R(q) ω_B`` (rad/s). Because ``ω·L = 2T``, ``ω_I`` stays on the plane
    ``ω_I · L̂_I = 2T/|L|`` (Poinsot). The plane's normal ``L̂_I`` and height
    ``2T/|L|`` are taken at the first sample; ``points`` are the components
    of ``ω_I`` along two orthonormal in-plane axes (:class:`Herpolhode`).
    One body; a trajectory with a torque is refused (its ``info["torque"]``
    must be ``"none"`` or absent).
    """
    if not isinstance(trajectory, Trajectory):
        raise ValidationError(f"trajectory: must be a Trajectory, got {type(trajectory).__name__}")
    if trajectory.batch_size is not None:
        raise ValidationError(
            f"trajectory: must hold a single body, got a batch of {trajectory.batch_size}; pass trajectory.member(i)"
        )
    torque = trajectory.info.get("torque", "none")
    if torque != "none":
        raise ValidationError(f"trajectory: the herpolhode needs torque-free motion, got torque {torque}")
    momentum = trajectory.momentum_inertial[0]
    norm = float(np.linalg.norm(momentum))
    if norm == 0.0:
        raise ValidationError("trajectory: a body at rest (|L| = 0) has no herpolhode")
    normal = momentum / norm
    basis = _plane_basis(normal)
    omega_inertial = rotate(cast(np.ndarray, trajectory.q), cast(np.ndarray, trajectory.omega))
    return Herpolhode(
        points=omega_inertial @ basis.T,
        omega_inertial=omega_inertial,
        normal=normal,
        height=2.0 * float(trajectory.energy[0]) / norm,
        basis=basis,
    )
