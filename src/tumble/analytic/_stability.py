"""Stability of steady rotation about the principal axes: the intermediate-axis (tennis-racket) theorem.

A torque-free rigid body with principal moments ``I₁ < I₂ < I₃`` (kg·m²) can
spin steadily about each principal axis. Linearising Euler's equations
``I₁ω̇₁ = (I₂ − I₃) ω₂ω₃`` (and cyclic) about the spin ``ω = Ω eᵢ`` gives, for
the other two rates ``ωⱼ, ωₖ``,

    ω̈ⱼ = Ω² (Iᵢ − Iⱼ)(Iₖ − Iᵢ) / (Iⱼ Iₖ) · ωⱼ.

About the first and third axes the factor is negative: the perturbation
oscillates (stable). About the intermediate axis it is positive: the
perturbation grows like ``e^{σt}``,

    σ = Ω √((I₃ − I₂)(I₂ − I₁) / (I₁ I₃))

(Landau & Lifshitz, *Mechanics*, §37, problem 1; Ashbaugh, Chicone & Cushman,
J. Dyn. Diff. Eq. 3, 67 (1991)). The body then turns over, again and again:
the rate about the intermediate axis ``ω₂`` changes sign every half period of
the elliptic solution, ``2K(m)/λ``, and the polhode closes after ``4K(m)/λ``
(``λ`` and ``m = k²`` from :func:`tumble.analytic._free.free_parameters`).

Equal moments make the linearisation degenerate (a zero eigenvalue): about a
transverse axis of a symmetric top, or any axis of a sphere, the rotation is
*neutral* — every rotation in the plane of equal moments is steady, and a
perturbation carries the rate slowly from one of them to the next without
exponential growth. Moments equal within ``RigidBody.symmetry``'s relative
tolerance (1e-9 of ``I₃``) count as equal.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scipy.special import elliprf

from tumble._validate import ValidationError, as_array, require_positive
from tumble.analytic._free import free_parameters
from tumble.analytic._geometry import _amplitude, _circled, _omega_principal
from tumble.rigid_body import RigidBody

__all__ = [
    "StabilityReport",
    "stability",
    "classify_axes",
    "growth_rate",
    "flip_interval",
    "polhode_period",
    "flip_times",
]

STABLE, UNSTABLE, NEUTRAL = "stable", "unstable", "neutral"

_CLASSES = {
    "asymmetric": (STABLE, UNSTABLE, STABLE),
    "oblate": (NEUTRAL, NEUTRAL, STABLE),
    "prolate": (STABLE, NEUTRAL, NEUTRAL),
    "spherical": (NEUTRAL, NEUTRAL, NEUTRAL),
}
_ROLES = ("minor axis", "intermediate axis", "major axis")


@dataclass(frozen=True, eq=False)
class StabilityReport:
    """Stability of the principal axes of a body and the elliptic timing of one torque-free motion.

    Fields (SI; principal axes ordered by ascending moment):

    ``moments`` (3,) kg·m²; ``axes`` (3, 3) ``R_BP``, principal axes as
    columns in body axes; ``symmetry``: ``"asymmetric"``, ``"oblate"``,
    ``"prolate"`` or ``"spherical"``; ``axis_stability``: ``"stable"``,
    ``"unstable"`` or ``"neutral"`` for steady rotation about each principal
    axis; ``omega_principal`` (3,) the body rate in principal axes, rad/s;
    ``energy`` ``T`` (J); ``momentum`` ``|L|`` (N·m·s); ``regime`` of the
    motion (see :func:`~tumble.analytic._free.free_parameters`);
    ``growth_rate`` ``σ`` (1/s) of a perturbation of the spin ``|L|/I₂``
    about the intermediate axis (0 without an unstable axis; it equals ``λ``
    on the separatrix); ``flip_interval`` ``2K/λ`` and ``polhode_period``
    ``4K/λ`` (s), ``inf`` when the rate never returns (steady rotation of a
    sphere, the separatrix).
    """

    moments: np.ndarray
    axes: np.ndarray
    symmetry: str
    axis_stability: tuple[str, str, str]
    omega_principal: np.ndarray
    energy: float
    momentum: float
    regime: str
    growth_rate: float
    flip_interval: float
    polhode_period: float

    def __str__(self) -> str:
        lines = [f"principal axes ({self.symmetry} body, moments ascending):"]
        for i, (moment, kind) in enumerate(zip(self.moments, self.axis_stability)):
            role = f" ({_ROLES[i]})" if self.symmetry == "asymmetric" else ""
            lines.append(f"  axis {i + 1}: I = {moment:.6g} kg m^2, {kind}{role}")
        if self.growth_rate > 0.0:
            lines.append(f"  growth rate about axis 2 at spin |L|/I2 = {self.momentum / self.moments[1]:.6g} "
                         f"rad/s: sigma = {self.growth_rate:.6g} 1/s")
        w = ", ".join(f"{x:.6g}" for x in self.omega_principal)
        lines += [
            f"motion: omega = [{w}] rad/s (principal axes), T = {self.energy:.6g} J, "
            f"|L| = {self.momentum:.6g} N m s, regime {self.regime!r}",
            f"  time between flips 2K/lambda = {self.flip_interval:.6g} s, "
            f"polhode period 4K/lambda = {self.polhode_period:.6g} s",
        ]
        return "\n".join(lines)


def _body(body) -> RigidBody:
    if not isinstance(body, RigidBody):
        raise ValidationError(f"body: must be a RigidBody, got {type(body).__name__}")
    return body


def classify_axes(body: RigidBody) -> tuple[str, str, str]:
    """Stability of steady rotation about principal axes 1, 2, 3 (ascending moments).

    ``"stable"`` (largest and smallest of distinct moments), ``"unstable"``
    (intermediate) or ``"neutral"`` (an axis whose moment equals another's,
    within ``RigidBody.symmetry``'s tolerance): asymmetric body
    (stable, unstable, stable); oblate top ``I₁ = I₂ < I₃`` (neutral, neutral,
    stable); prolate top ``I₁ < I₂ = I₃`` (stable, neutral, neutral); sphere:
    all neutral.
    """
    return _CLASSES[_body(body).symmetry()]


def growth_rate(body: RigidBody, spin: float) -> float:
    """Exponential growth rate (1/s) of a small perturbation of a spin about the intermediate axis.

    ``σ = |Ω| √((I₃ − I₂)(I₂ − I₁) / (I₁ I₃))`` for the spin ``Ω = spin``
    (rad/s) about the intermediate principal axis: the perturbing rates grow
    like ``e^{σt}`` while they stay small. 0 for a symmetric body.
    """
    i1, i2, i3 = _body(body).moments
    rate = as_array(spin, "spin")
    if rate.ndim != 0:
        raise ValidationError(f"spin: must be a number (rad/s), got shape {rate.shape}")
    return abs(float(rate)) * float(np.sqrt(max((i3 - i2) * (i2 - i1), 0.0) / (i1 * i3)))


def flip_interval(body: RigidBody, omega) -> float:
    """Time (s) between successive sign changes of the intermediate-axis rate: ``2K(m)/λ``.

    ``omega`` is the body rate (rad/s, body axes) at any instant of the
    torque-free motion; ``m`` and ``λ`` from :func:`free_parameters`. The
    rate ``ω₂`` is ``∝ sn(λt)``-like in every regime, and ``sn`` changes sign
    every ``2K``. ``inf`` when the motion does not return (a steady rotation
    of a sphere; the separatrix, where the body turns over once). On a
    principal axis of a non-spherical body it is the limit for small
    perturbations.
    """
    return 2.0 * _quarter_period(_body(body), omega)


def polhode_period(body: RigidBody, omega) -> float:
    """Period (s) of the body rate along its polhode: ``4K(m)/λ`` (see :func:`flip_interval`)."""
    return 4.0 * _quarter_period(_body(body), omega)


def _quarter_period(body: RigidBody, omega) -> float:
    return float(free_parameters(body.moments, _omega_principal(body, omega)).quarter_period)


def stability(body: RigidBody, omega) -> StabilityReport:
    """Stability of the principal axes of ``body`` and the timing of the motion with body rate ``omega``.

    ``omega`` (3,) rad/s in body axes. See :class:`StabilityReport`; print it
    for a summary.
    """
    body = _body(body)
    omega_p = _omega_principal(body, omega)
    params = free_parameters(body.moments, omega_p)
    quarter = float(params.quarter_period)
    classes = classify_axes(body)
    return StabilityReport(
        moments=body.moments,
        axes=body.axes,
        symmetry=body.symmetry(),
        axis_stability=classes,
        omega_principal=omega_p,
        energy=float(params.energy),
        momentum=float(params.momentum),
        regime=str(params.regime),
        growth_rate=growth_rate(body, params.momentum / body.moments[1]) if classes[1] == UNSTABLE else 0.0,
        flip_interval=2.0 * quarter,
        polhode_period=4.0 * quarter,
    )


def flip_times(body: RigidBody, omega0, t_end: float) -> np.ndarray:
    """Times (s) in ``(0, t_end]`` at which the intermediate-axis rate ``ω₂`` changes sign, exactly.

    ``omega0`` (3,) is the body rate at ``t = 0`` (rad/s, body axes) of the
    torque-free motion. Along the polhode the Jacobi amplitude ``φ = am(u)``,
    ``u = λt + u₀``, advances as ``dφ/dt = λ √(1 − m sin²φ)``, and ``ω₂ ∝ sn u``
    vanishes at ``φ = jπ`` (``u = 2jK``). The initial phase is
    ``u₀ = F(φ₀|m)``, with ``φ₀`` from the rates at ``t = 0`` (the angle of
    :func:`tumble.analytic._geometry.polhode_through`, shifted by ``π/2`` in
    the minor regime) and the incomplete integral
    ``F(φ|m) = sin φ R_F(cos²φ, m1 + m cos²φ, 1)`` (DLMF 19.25.5, Carlson's
    ``R_F`` of :func:`scipy.special.elliprf`, free of cancellation as
    ``m1 → 0``). The flips are then ``t₁ + 2jK/λ``, ``j = 0, 1, …``;
    ``m``, ``m1``, ``λ`` and ``K/λ`` come from :func:`free_parameters`.
    Empty when ``ω₂`` never changes sign (a sphere, a steady rotation, the
    separatrix after its one flip). ``measure.flip_times`` measures the
    same events on a sampled trajectory.
    """
    body = _body(body)
    t_end = require_positive(t_end, "t_end")
    moments = body.moments
    omega_p = _omega_principal(body, omega0)
    params = free_parameters(moments, omega_p)
    c = _circled(params)
    j, k = (c + 1) % 3, (c + 2) % 3
    if params.regime in ("sphere", "rest") or (omega_p[j] == 0.0 and omega_p[k] == 0.0):
        return np.empty(0)  # ω constant, or a steady rotation about the circled axis: ω₂ ≡ 0
    sign = -1 if omega_p[c] < 0.0 else 1
    phi = _amplitude(moments, c, sign, omega_p) - (0.5 * np.pi if c == 0 else 0.0)
    phi -= np.pi * np.round(phi / np.pi)  # into [−π/2, π/2]: same ω₂ zeros, phase shifted by 2K
    cos = np.cos(phi)
    u0 = np.sin(phi) * elliprf(cos * cos, params.m1 + params.m * cos * cos, 1.0)
    half = 2.0 * params.quarter_period  # 2K/λ, s
    first = (-u0 / params.lam) if phi < 0.0 else half - u0 / params.lam
    if not np.isfinite(first) or first > t_end:
        return np.empty(0)
    count = 1 if not np.isfinite(half) else int(np.floor((t_end - first) / half)) + 1
    return first + half * np.arange(count)
