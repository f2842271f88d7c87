"""Energy dissipation on board: a rigid hub with a spherical viscous nutation damper.

The damper is a rigid sphere of moment of inertia ``J`` (about any diameter)
in a concentric spherical cavity at the hub's centre of mass, coupled to the
hub by a viscous fluid film: the torque on the sphere is ``−c (ω_d − ω)``
(``c`` N·m·s) and the hub gets the opposite (the spherical or "Kane"
damper; Hughes, *Spacecraft Attitude Dynamics*, ch. 5; derivations in
``docs/passive_stability.md``). ``ω`` is the hub rate and ``ω_d`` the sphere's,
both relative to inertial space, in hub (body) axes. Euler's equations of
the two bodies, written in body axes (the sphere's inertia is isotropic, so
its inertial derivative seen from the rotating hub adds ``ω × J ω_d``)::

    I ω̇ + ω × (I ω)        = τ_ext + c (ω_d − ω)       (hub)
    J (ω̇_d + ω × ω_d)      = −c (ω_d − ω)               (sphere)
    q̇ = ½ q ⊗ [0, ω]

``I`` is the hub's inertia about the common centre of mass, without the
sphere. Without external torque the total angular momentum
``L = I ω + J ω_d`` is constant in inertial axes, and the kinetic energy
``T = ½ ω·Iω + ½ J |ω_d|²`` falls at the rate ``Ṫ = −c |ω_d − ω|² ≤ 0``:
the body ends in the state of least energy for its ``|L|``, a spin about the
axis of largest moment (the major-axis rule; :mod:`tumble.spacecraft.passive`).

The damper is a part of :class:`tumble.spacecraft.Spacecraft`
(``Spacecraft(hub=body, damper=SphericalDamper(J, c))``, or the total inertia
with the sphere counted as locked to the hub, ``inertia = I + J E``), integrated
by :func:`tumble.simulate` with the initial sphere rate ``damper_omega0``
(default: ``omega0``, the sphere turning with the hub); the compiled part is
:mod:`tumble.kernels.spacecraft.damper`. The trajectory carries the sphere's
rate in ``extras["damper_omega"]`` and the totals of hub and sphere (plus any
wheels) in ``traj.energy``, ``traj.momentum_body`` and ``traj.momentum_inertial``.

The nutation time constant of a nearly axisymmetric spinner (spin ``Ω``
about the symmetry axis, moments ``I_s`` axial and ``I_t`` transverse) by
the energy-sink method (:func:`energy_sink_time_constant`)::

    1/τ = c J² Ω² (I_t − I_s) I_s / (I_t (c² I_t² + J² Ω² I_s²))

``τ > 0``: the nutation angle grows like ``e^{t/τ}`` (spin about the minor
axis, ``I_s < I_t``, the Explorer 1 case); ``τ < 0``: it decays (major axis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError, as_array, require_positive
from tumble.kernels.spacecraft import damper as _kernel
from tumble.kernels.spacecraft._base import Program
from tumble.trajectory import Trajectory

__all__ = [
    "SphericalDamper",
    "energy_sink_time_constant",
    "measured_time_constant",
    "nutation_angle",
]


@dataclass(frozen=True)
class SphericalDamper:
    """A spherical viscous nutation damper: sphere inertia ``inertia`` (J, kg·m²), damping ``damping``
    (c, N·m·s)."""

    inertia: float
    damping: float

    def __post_init__(self):
        object.__setattr__(self, "inertia", require_positive(self.inertia, "damper.inertia"))
        object.__setattr__(self, "damping", require_positive(self.damping, "damper.damping"))

    @classmethod
    def tuned(cls, inertia: float, axial: float, transverse: float, spin: float) -> SphericalDamper:
        """The damper of sphere inertia ``inertia`` whose ``c`` maximises the energy-sink rate ``1/|τ|``.

        ``c = J |Ω| I_s / I_t``: the damper's time constant ``J/c`` is then the
        inverse of the nutation rate seen in inertial space, ``Ω I_s/I_t``, and
        ``1/|τ| = J |Ω| |I_t − I_s| / (2 I_t²)``. ``axial``, ``transverse``:
        ``I_s``, ``I_t`` with the sphere locked (kg·m²); ``spin``: ``Ω`` (rad/s).
        """
        inertia = require_positive(inertia, "inertia")
        return cls(inertia, inertia * abs(float(spin)) * require_positive(axial, "axial")
                   / require_positive(transverse, "transverse"))

    def _program(self) -> Program:
        return _kernel.program(self.inertia, self.damping)


def nutation_angle(traj: Trajectory, axis: ArrayLike) -> np.ndarray:
    """Angle (rad) between the body axis ``axis`` (body axes) and the total angular momentum of the
    trajectory's system (``traj.momentum_body``: hub, sphere, wheels), (n, [N])."""
    a = as_array(axis, "axis", tail=(3,))
    if a.shape != (3,) or not np.linalg.norm(a) > 0.0:
        raise ValidationError(f"axis: must be a non-zero vector of shape (3,), got {a.tolist()}")
    a = a / np.linalg.norm(a)
    L = traj.momentum_body
    x, y, z = L[..., 0], L[..., 1], L[..., 2]
    along = x * a[0] + y * a[1] + z * a[2]  # L·a
    across = np.sqrt((y * a[2] - z * a[1]) ** 2 + (z * a[0] - x * a[2]) ** 2 + (x * a[1] - y * a[0]) ** 2)  # |L × a|
    return np.arctan2(across, along)  # atan2 of the two (|L| cancels): accurate at 0 and π/2 alike


def energy_sink_time_constant(axial: float, transverse: float, damper: SphericalDamper, spin: float) -> float:
    """Nutation time constant ``τ`` (s) of an axisymmetric spinner with a spherical damper, energy-sink estimate.

    ``axial``, ``transverse``: ``I_s``, ``I_t`` of the whole body with the
    sphere locked (hub + ``J``), kg·m²; ``spin``: ``Ω`` (rad/s). For small
    nutation angle ``θ``, ``θ ∝ e^{t/τ}`` with (derivation in
    ``docs/passive_stability.md``)::

        1/τ = c J² Ω² (I_t − I_s) I_s / (I_t (c² I_t² + J² Ω² I_s²))

    Valid for ``J ≪ I_s, I_t`` (the damper does not change the nutation
    frequency) and a quasi-steady damper (``J/c`` short against ``|τ|``).
    Positive for a minor-axis spin (nutation grows), negative for a
    major-axis spin (it decays), infinite for ``I_s = I_t``.
    """
    i_s, i_t = require_positive(axial, "axial"), require_positive(transverse, "transverse")
    spin = float(spin)
    j, c = damper.inertia, damper.damping
    rate = c * j * j * spin * spin * (i_t - i_s) * i_s / (i_t * (c * c * i_t * i_t + j * j * spin * spin * i_s * i_s))
    return math.inf if rate == 0.0 else 1.0 / rate


def measured_time_constant(t: ArrayLike, angle: ArrayLike, *, window: tuple[float, float]) -> float:
    """Time constant ``τ`` (s) of an exponential ``angle ∝ e^{t/τ}``, fitted to the samples in ``window``.

    Least-squares line through ``ln angle`` against ``t`` over the samples
    with ``low ≤ angle ≤ high`` (``window = (low, high)``, rad): the
    small-angle phase where the energy-sink estimate applies. ``τ < 0`` for a
    decaying angle. Needs at least 3 such samples.
    """
    t = as_array(t, "t")
    angle = as_array(angle, "angle")
    low, high = (float(w) for w in window)
    if not 0.0 < low < high:
        raise ValidationError(f"window: must be (low, high) with 0 < low < high, got {window}")
    inside = (angle >= low) & (angle <= high)
    if np.count_nonzero(inside) < 3:
        raise ValidationError(f"angle: fewer than 3 samples between {low} and {high} rad to fit")
    return float(1.0 / np.polyfit(t[inside], np.log(angle[inside]), 1)[0])
