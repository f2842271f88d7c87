"""Passive attitude stability: the major-axis rule for spinners and the gravity-gradient stability regions.

**Major-axis rule.** A rigid body spins steadily about any principal axis;
the spin is (Lyapunov) stable about the axes of largest and smallest moment
and unstable about the intermediate one (:mod:`tumble.analytic`). With
internal energy dissipation (flexible parts, fuel, a nutation damper) the
body loses kinetic energy ``T = L²/(2 I_spin)`` at fixed ``|L|``, so it drifts
towards the state of least energy for its momentum: a spin about the axis of
*largest* moment. Only a major-axis spin is stable (Hughes, *Spacecraft
Attitude Dynamics*, ch. 5; Wie, *Space Vehicle Dynamics and Control*,
ch. 6; Explorer 1, 1958, is the classic failure: see
:mod:`tumble.spacecraft.damper`).

**Gravity gradient.** A body on a circular orbit (rate ``n``) with principal
axes 1 (roll, along-track), 2 (pitch, minus the orbit normal) and 3 (yaw,
nadir) held on the LVLH axes is in equilibrium. With the inertia ratios
(Hughes, ch. 9; Wie, ch. 6)::

    k_R = (I₂ − I₃)/I₁        k_Y = (I₂ − I₁)/I₃

the linearised motion is a pitch oscillation ``θ̈ + 3n² (I₁ − I₃)/I₂ θ = 0``
and a coupled roll/yaw pair with characteristic equation::

    s⁴ + (1 + 3k_R + k_R k_Y) n² s² + 4 k_R k_Y n⁴ = 0

It is stable (all roots imaginary) where

    pitch:     k_R > k_Y                       (I₁ > I₃)
    roll/yaw:  k_R k_Y > 0  and  1 + 3k_R + k_R k_Y > 4 √(k_R k_Y)

The part of the stable set with ``k_R, k_Y > 0`` (``I₂ > I₁ > I₃``: the
largest moment about the orbit normal, the smallest about the vertical) is
the *Lagrange region*, stable even with energy dissipation (the equilibrium is
a minimum of the Hamiltonian). The part with ``k_R, k_Y < 0`` is the
*DeBra–Delp region* (DeBra & Delp, J. Astronaut. Sci. 8, 1961): gyroscopic
stability only, lost to dissipation.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._moved import moved
from tumble._validate import ValidationError, as_array
from tumble.analytic import classify_axes
from tumble.rigid_body import RigidBody
from tumble.simulate import simulate
from tumble.spacecraft import damper as _damper
from tumble.spacecraft.model import Spacecraft
from tumble.spacecraft.orbit import Orbit, lvlh_quaternion
from tumble.torques import GravityGradient
from tumble.trajectory import Trajectory

__all__ = [
    "EXPLORER1",
    "Explorer1",
    "GravityGradientStability",
    "SpinStability",
    "gravity_gradient_libration",
    "gravity_gradient_stability",
    "roll_yaw_conditions",
    "spin_stability",
]

__getattr__ = moved(__name__, dict.fromkeys(
    ("demo_explorer1", "demo_gravity_gradient", "explorer1_figure", "gravity_gradient_stability_figure"),
    "tumble.viz.passive"))

# An axis is principal when |I â − (â·Iâ) â| <= _PRINCIPAL_RTOL · max moment,
# and its moment counts as the largest when within _PRINCIPAL_RTOL of it
# (RigidBody.symmetry's tolerance for equal moments).
_PRINCIPAL_RTOL = 1e-9
LAGRANGE, DEBRA_DELP, UNSTABLE = "Lagrange", "DeBra-Delp", "unstable"


class SpinStability(NamedTuple):
    """Stability of a steady spin about a principal axis.

    moment           : moment of inertia about the spin axis, kg·m²
    role             : ``"major"``, ``"intermediate"`` or ``"minor"`` (``"major"`` when
                       the moment equals the largest, ``"minor"`` when it equals the
                       smallest and not the largest)
    rigid            : ``"stable"``, ``"unstable"`` or ``"neutral"``, the rigid body
                       (:func:`tumble.analytic.classify_axes`)
    with_dissipation : True only for a major-axis spin (the major-axis rule)
    """

    moment: float
    role: str
    rigid: str
    with_dissipation: bool


def _as_body(body) -> RigidBody:
    if isinstance(body, RigidBody):
        return body
    return RigidBody(as_array(body, "body", tail=(3, 3)), check_triangle=False)


def spin_stability(body: RigidBody | ArrayLike, axis: ArrayLike) -> SpinStability:
    """Is a spin about ``axis`` (body axes, any length) stable, as a rigid body and with energy dissipation?

    ``body``: a :class:`~tumble.RigidBody` or a (3, 3) inertia tensor (kg·m²,
    body axes). The axis must be a principal axis (a spin about any other axis
    is not steady): ValidationError otherwise.
    """
    body = _as_body(body)
    a = as_array(axis, "axis", tail=(3,))
    if a.ndim != 1 or not np.linalg.norm(a) > 0.0:
        raise ValidationError(f"axis: must be a non-zero vector of shape (3,), got {a.tolist()}")
    a = a / np.linalg.norm(a)
    ia = body.inertia @ a
    moment = float(a @ ia)
    largest = float(body.moments[-1])
    if np.linalg.norm(ia - moment * a) > _PRINCIPAL_RTOL * largest:
        raise ValidationError(f"axis: must be a principal axis of the body (I a is not parallel to a for "
                              f"a = {a.tolist()}); a spin about another axis is not steady")
    k = int(np.argmin(np.abs(body.moments - moment)))
    if largest - moment <= _PRINCIPAL_RTOL * largest:
        role = "major"
    elif moment - body.moments[0] <= _PRINCIPAL_RTOL * largest:
        role = "minor"
    else:
        role = "intermediate"
    return SpinStability(moment=moment, role=role, rigid=classify_axes(body)[k], with_dissipation=role == "major")


class GravityGradientStability(NamedTuple):
    """Linear stability of the LVLH-held attitude of a body on a circular orbit.

    k_roll, k_yaw          : k_R = (I₂ − I₃)/I₁, k_Y = (I₂ − I₁)/I₃
    pitch_stable           : k_R > k_Y (I₁ > I₃)
    roll_yaw_stable        : k_R k_Y > 0 and 1 + 3k_R + k_R k_Y > 4 √(k_R k_Y)
    stable                 : both
    region                 : ``"Lagrange"`` (stable, k_R, k_Y > 0), ``"DeBra-Delp"``
                             (stable, k_R, k_Y < 0) or ``"unstable"``
    pitch_frequency        : ω_p/n = √(3 (I₁ − I₃)/I₂), nan when pitch is unstable
    roll_yaw_frequencies   : (2,) ω/n of the roll/yaw modes, descending, nan when unstable
    """

    k_roll: float
    k_yaw: float
    pitch_stable: bool
    roll_yaw_stable: bool
    stable: bool
    region: str
    pitch_frequency: float
    roll_yaw_frequencies: np.ndarray


def roll_yaw_conditions(kr: np.ndarray | np.floating, ky: np.ndarray | np.floating) -> tuple[Any, Any, Any]:
    """The roll/yaw stability conditions on (arrays of) (k_R, k_Y): (b, c, stable) of s⁴ + b s² + c, of their shape."""
    b = 1.0 + 3.0 * kr + kr * ky
    c = 4.0 * kr * ky
    with np.errstate(invalid="ignore"):
        stable = (c > 0.0) & (b > np.sqrt(np.maximum(c, 0.0)) * 2.0)  # b > 2√c = 4√(k_R k_Y)
    return b, c, stable


def _moments(inertia) -> np.ndarray:
    if isinstance(inertia, RigidBody):
        inertia = inertia.inertia
    i = as_array(inertia, "inertia")
    if i.shape == (3,):
        i = np.diag(i)
    if i.shape != (3, 3):
        raise ValidationError(f"inertia: must be the moments (3,) or a diagonal tensor (3, 3), got shape {i.shape}")
    off = np.abs(i - np.diag(np.diag(i))).max()
    if off > _PRINCIPAL_RTOL * np.abs(i).max():
        raise ValidationError("inertia: the body axes must be principal axes (roll, pitch, yaw) for the "
                              f"LVLH attitude to be an equilibrium; largest off-diagonal term {off:.3g} kg m^2")
    m = np.diag(i).copy()
    if not np.all(m > 0.0):
        raise ValidationError(f"inertia: moments must be > 0, got {m.tolist()}")
    return m


def gravity_gradient_stability(inertia: RigidBody | ArrayLike) -> GravityGradientStability:
    """Classify the gravity-gradient stability of a body held on the LVLH axes of a circular orbit.

    ``inertia``: the moments ``(I₁, I₂, I₃)`` about roll (along-track), pitch
    (minus the orbit normal) and yaw (nadir), kg·m², as a (3,) array, a diagonal (3, 3)
    tensor or a :class:`~tumble.RigidBody` whose body axes are those.
    Frequencies in units of the orbit rate ``n`` (module docstring).
    """
    i1, i2, i3 = _moments(inertia)
    kr, ky = (i2 - i3) / i1, (i2 - i1) / i3
    pitch = bool(kr > ky)
    b, c, roll_yaw = roll_yaw_conditions(np.float64(kr), np.float64(ky))
    roll_yaw = bool(roll_yaw)
    if pitch and roll_yaw:
        region = LAGRANGE if kr > 0.0 else DEBRA_DELP
    else:
        region = UNSTABLE
    pitch_frequency = math.sqrt(3.0 * (i1 - i3) / i2) if pitch else math.nan
    if roll_yaw:
        root = math.sqrt(b * b - 4.0 * c)
        freqs = np.sqrt([(b + root) / 2.0, (b - root) / 2.0])
    else:
        freqs = np.full(2, np.nan)
    return GravityGradientStability(k_roll=float(kr), k_yaw=float(ky), pitch_stable=pitch,
                                    roll_yaw_stable=roll_yaw, stable=pitch and roll_yaw, region=region,
                                    pitch_frequency=pitch_frequency, roll_yaw_frequencies=freqs)


# --- a gravity-gradient-stabilised satellite ----------------------------------------------------------

#: Moments (roll, pitch, yaw), kg·m², of a small satellite with a nadir boom (k_R = 0.958, k_Y = 0.5: Lagrange).
GG_SATELLITE = (120.0, 125.0, 10.0)
#: Its orbit: circular, 700 km, sun-synchronous inclination.
GG_ORBIT = Orbit.circular(700e3, inclination=math.radians(98.19))


def gravity_gradient_libration(moments: ArrayLike, orbit: Orbit, angles: ArrayLike, *, orbits: float = 10.0,
                               samples_per_orbit: int = 200) -> Trajectory:
    """Simulate a body released at roll/pitch/yaw ``angles`` (rad) from the LVLH attitude, at rest in LVLH.

    ``moments``: (roll, pitch, yaw) principal moments, kg·m² (body axes =
    principal axes); gravity-gradient torque of ``orbit``; ``dop853`` at
    rtol 1e-11. The body rate at release is the LVLH frame's, ``(0, −n, 0)``
    in LVLH axes. Read the angles back with
    :func:`tumble.spacecraft.orbit.attitude_in_lvlh`.
    """
    roll, pitch, yaw = as_array(angles, "angles", tail=(3,))
    q_lvlh_b = attitude.from_euler("ZYX", [yaw, pitch, roll])
    omega0 = attitude.rotate_inverse(q_lvlh_b, [0.0, -orbit.mean_motion, 0.0])
    q0 = attitude.multiply(lvlh_quaternion(*orbit.state(0.0)), q_lvlh_b)
    inertia = np.diag(_moments(moments))
    t = np.linspace(0.0, orbits * orbit.period, int(math.ceil(orbits * samples_per_orbit)) + 1)
    return simulate(inertia, omega0, q0=q0, t=t, rtol=1e-11, atol=1e-14, torque=GravityGradient(orbit, inertia))


# --- Explorer 1 ------------------------------------------------------------------------------------------


class Explorer1(NamedTuple):
    """An Explorer-1-like spinner: a uniform cylinder spinning about its long (minor) axis z, with a damper.

    Explorer 1 (launched 31 January 1958): 13.97 kg, 2.03 m long, 0.152 m in
    diameter, spun at about 750 rpm about its long axis (NASA/JPL mission
    facts). Its energy sink was four flexible whip antennas; here it is a
    spherical damper (:mod:`tumble.spacecraft.damper`) sized so that the
    flat spin comes within the first orbit (114.8 min), as observed.
    """

    mass: float = 13.97
    length: float = 2.03
    radius: float = 0.0762
    spin: float = 750.0 * 2.0 * math.pi / 60.0
    nutation0: float = math.radians(0.5)
    damper_inertia: float = 3e-4
    duration: float = 6900.0

    def hub(self) -> RigidBody:
        """The cylinder (without the damper sphere), long axis z."""
        return RigidBody.cylinder(mass=self.mass, radius=self.radius, length=self.length, axis="z")

    def locked_moments(self) -> tuple[float, float]:
        """``(I_s, I_t)``: axial and transverse moments with the damper sphere locked to the hub, kg·m²."""
        hub = self.hub()
        return hub.inertia[2, 2] + self.damper_inertia, hub.inertia[0, 0] + self.damper_inertia

    def damper(self) -> _damper.SphericalDamper:
        """The damper tuned for the initial spin (:meth:`SphericalDamper.tuned`)."""
        return _damper.SphericalDamper.tuned(self.damper_inertia, *self.locked_moments(), self.spin)

    def spacecraft(self) -> Spacecraft:
        """The hub with its damper, a model of :func:`tumble.simulate`."""
        return Spacecraft(hub=self.hub(), damper=self.damper())

    def omega0(self) -> np.ndarray:
        """Body rate (rad/s) with spin ``spin`` and nutation angle ``nutation0`` between L and the z axis."""
        i_s, i_t = self.locked_moments()
        return np.array([i_s * self.spin * math.tan(self.nutation0) / i_t, 0.0, self.spin])


#: The demo's Explorer 1.
EXPLORER1 = Explorer1()


