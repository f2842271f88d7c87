"""Keplerian orbits and the local-vertical local-horizontal (LVLH) frame.

The orbit is a fixed Kepler ellipse about a point mass, propagated in closed
form alongside the attitude (no orbital perturbations): position ``r`` and
velocity ``v`` in inertial (ECI) axes, m and m/s.

The LVLH frame (Hughes, *Spacecraft Attitude Dynamics*, ch. 8; Wie, *Space
Vehicle Dynamics and Control*, ch. 6) has the axes, in inertial
components::

    o₃ = −r/|r|              nadir (yaw axis)
    o₂ = −h/|h|, h = r × v   minus the orbit normal (pitch axis)
    o₁ = o₂ × o₃             along-track for a circular orbit (roll axis)

``q_I_LVLH`` (scalar first) maps LVLH components to inertial ones, like a
body attitude: the rotation matrix ``R(q_I_LVLH)`` has columns ``o₁, o₂, o₃``.
On a circular orbit the frame turns at the orbit rate ``n`` about ``h``, so
its angular velocity in its own axes is ``(0, −n, 0)``.

    >>> orbit = Orbit.circular(700e3, inclination=np.radians(98.0))
    >>> r, v = orbit.state([0.0, 60.0])          # (2, 3) each, ECI
    >>> q_i_lvlh = lvlh_quaternion(r, v)        # (2, 4)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple, cast

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from tumble import _quat, attitude
from tumble._gravity import eccentric_anomaly, kepler_state, orbit_state
from tumble._validate import ValidationError, as_array, require_finite, require_positive

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory

__all__ = [
    "EARTH_J2",
    "EARTH_MU",
    "EARTH_RADIUS",
    "LvlhAttitude",
    "Orbit",
    "attitude_in_lvlh",
    "eccentric_anomaly",
    "lvlh_matrix",
    "lvlh_quat",
    "lvlh_quaternion",
    "orbit_state",
]

#: Earth's gravitational parameter GM, m³/s² (WGS 84, NIMA TR8350.2, 3rd ed., Table 3.1).
EARTH_MU = 3.986004418e14
#: Earth's equatorial radius, m (WGS 84 semi-major axis).
EARTH_RADIUS = 6378137.0
#: Earth's J₂ = −√5 C̄₂,₀ with C̄₂,₀ = −4.84166774985e-4 (WGS 84, NIMA TR8350.2, 3rd ed., Table 5.1).
EARTH_J2 = 1.0826298213133048e-3


@dataclass(frozen=True)
class Orbit:
    """A Kepler orbit: classical elements at ``t = 0``.

    semi_major_axis : a, m (> 0)
    eccentricity    : e, 0 ≤ e < 1 (circular and elliptic orbits)
    inclination     : i, rad, in [0, π]
    raan            : right ascension of the ascending node Ω, rad
    arg_periapsis   : argument of periapsis ω, rad
    mean_anomaly    : mean anomaly at t = 0, M₀, rad
    mu              : gravitational parameter of the central body, m³/s² (default: Earth's)
    """

    semi_major_axis: float
    eccentricity: float = 0.0
    inclination: float = 0.0
    raan: float = 0.0
    arg_periapsis: float = 0.0
    mean_anomaly: float = 0.0
    mu: float = EARTH_MU

    def __post_init__(self):
        object.__setattr__(self, "semi_major_axis", require_positive(self.semi_major_axis, "semi_major_axis"))
        object.__setattr__(self, "mu", require_positive(self.mu, "mu"))
        for name in ("eccentricity", "inclination", "raan", "arg_periapsis", "mean_anomaly"):
            value = float(getattr(self, name))
            require_finite(np.asarray(value), name)
            object.__setattr__(self, name, value)
        if not 0.0 <= self.eccentricity < 1.0:
            raise ValidationError(f"eccentricity: must be in [0, 1) (closed orbits), got {self.eccentricity}")
        if not 0.0 <= self.inclination <= math.pi:
            raise ValidationError(f"inclination: must be in [0, π] rad, got {self.inclination}")

    @classmethod
    def circular(cls, altitude: float, inclination: float = 0.0, *, raan: float = 0.0,
                 arg_latitude: float = 0.0, mu: float = EARTH_MU, radius: float = EARTH_RADIUS) -> Orbit:
        """A circular orbit at ``altitude`` (m) above a sphere of ``radius`` (default Earth's, 6378137 m).

        ``arg_latitude`` (rad) is the angle from the ascending node at ``t = 0``.
        """
        altitude = float(altitude)
        require_finite(np.asarray(altitude), "altitude")
        if radius + altitude <= 0.0:
            raise ValidationError(f"altitude: must be > -radius = {-radius} m, got {altitude}")
        return cls(semi_major_axis=radius + altitude, inclination=inclination, raan=raan,
                   mean_anomaly=arg_latitude, mu=mu)

    def elements(self) -> np.ndarray:
        """``[a, e, i, Ω, ω, M₀, μ]`` as float64, the argument of :func:`orbit_state`."""
        return np.array([self.semi_major_axis, self.eccentricity, self.inclination, self.raan,
                         self.arg_periapsis, self.mean_anomaly, self.mu])

    @property
    def mean_motion(self) -> float:
        """n = √(μ/a³), rad/s."""
        return math.sqrt(self.mu / self.semi_major_axis**3)

    @property
    def period(self) -> float:
        """Orbital period 2π/n, s."""
        return 2.0 * math.pi / self.mean_motion

    def j2_rates(self, j2: float = EARTH_J2, radius: float = EARTH_RADIUS) -> tuple[float, float, float]:
        """``(Ω̇, ω̇, Ṁ)``, rad/s: the secular drift of the node, the periapsis and the mean anomaly under the
        Earth's oblateness, to first order in J₂ (Vallado, 4th ed., §9.6, eqs. 9-41; the elements taken as
        mean elements)::

            p = a (1 − e²),   k = (3/2) n J₂ (R/p)²
            Ω̇ = −k cos i,   ω̇ = (k/2)(5 cos² i − 1),   Ṁ = n + (k/2) √(1 − e²) (3 cos² i − 1)
        """
        n, e, ci = self.mean_motion, self.eccentricity, math.cos(self.inclination)
        k = 1.5 * n * j2 * (radius / (self.semi_major_axis * (1.0 - e * e))) ** 2
        return -k * ci, 0.5 * k * (5.0 * ci * ci - 1.0), n + 0.5 * k * math.sqrt(1.0 - e * e) * (3.0 * ci * ci - 1.0)

    def state(self, t: ArrayLike, *, j2: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Position (m) and velocity (m/s) in inertial axes at the times ``t`` (s, any shape): two (…, 3) arrays.

        With ``j2=True`` the node, the periapsis and the mean anomaly drift at :meth:`j2_rates` (the Earth's
        J₂ and equatorial radius) and the velocity is the time derivative of that position::

            v = (Ṁ/n) v_Kepler + Ω̇ ẑ × r + ω̇ ĥ × r        (ĥ: the unit orbit normal)
        """
        t = as_array(t, "t")
        out = np.empty((t.size, 6))
        if j2:
            _drifting_states(self.elements(), np.array(self.j2_rates()), t.ravel(), out)
        else:
            _states(self.elements(), t.ravel(), out)
        out = out.reshape((*t.shape, 6))
        return out[..., :3], out[..., 3:]


@njit(cache=True)
def _states(el, t, out):
    for k in range(t.shape[0]):
        out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4], out[k, 5] = orbit_state(el, t[k])


@njit(cache=True)
def _drifting_states(el, rates, t, out):
    """Kepler states with Ω, ω and M drifting at ``rates = (Ω̇, ω̇, Ṁ)``; see :meth:`Orbit.state`."""
    a, e, inc, raan, argp, m0, mu = el[0], el[1], el[2], el[3], el[4], el[5], el[6]
    n = math.sqrt(mu / a**3)
    for k in range(t.shape[0]):
        node = raan + rates[0] * t[k]
        rx, ry, rz, vx, vy, vz = kepler_state(a, e, inc, node, argp + rates[1] * t[k], m0 + (rates[2] - n) * t[k],
                                              mu, t[k])
        hx, hy, hz = math.sin(inc) * math.sin(node), -math.sin(inc) * math.cos(node), math.cos(inc)
        scale = rates[2] / n
        out[k, 0], out[k, 1], out[k, 2] = rx, ry, rz
        out[k, 3] = scale * vx - rates[0] * ry + rates[1] * (hy * rz - hz * ry)
        out[k, 4] = scale * vy + rates[0] * rx + rates[1] * (hz * rx - hx * rz)
        out[k, 5] = scale * vz + rates[1] * (hx * ry - hy * rx)


@njit(cache=True)
def _lvlh_axes(rx, ry, rz, vx, vy, vz, m):
    """Write the columns o₁, o₂, o₃ of the LVLH frame (inertial components) into the 3×3 ``m``."""
    r = math.sqrt(rx * rx + ry * ry + rz * rz)
    hx, hy, hz = ry * vz - rz * vy, rz * vx - rx * vz, rx * vy - ry * vx
    h = math.sqrt(hx * hx + hy * hy + hz * hz)
    o3x, o3y, o3z = -rx / r, -ry / r, -rz / r
    o2x, o2y, o2z = -hx / h, -hy / h, -hz / h
    m[0, 2], m[1, 2], m[2, 2] = o3x, o3y, o3z
    m[0, 1], m[1, 1], m[2, 1] = o2x, o2y, o2z
    m[0, 0], m[1, 0], m[2, 0] = o2y * o3z - o2z * o3y, o2z * o3x - o2x * o3z, o2x * o3y - o2y * o3x


@njit(cache=True)
def lvlh_quat(rx: float, ry: float, rz: float, vx: float, vy: float, vz: float) -> tuple[float, float, float, float]:
    """``q_I_LVLH`` (LVLH → inertial, scalar first) of the position ``r`` and velocity ``v`` (inertial axes).

    Axes as in the module docstring; undefined for ``r = 0`` or ``r ∥ v``.
    Returns ``(qw, qx, qy, qz)`` with ``qw ≥ 0``.
    """
    m = np.empty((3, 3))
    _lvlh_axes(rx, ry, rz, vx, vy, vz, m)
    return _quat.qfrom_matrix(m)


@njit(cache=True)
def _lvlh_matrices(r, v, out):
    for k in range(r.shape[0]):
        _lvlh_axes(r[k, 0], r[k, 1], r[k, 2], v[k, 0], v[k, 1], v[k, 2], out[k])


def _checked_rv(r: ArrayLike, v: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    r = as_array(r, "r", tail=(3,))
    v = as_array(v, "v", tail=(3,))
    r, v = np.broadcast_arrays(r, v)
    h = np.linalg.norm(np.cross(r, v), axis=-1)
    if np.any(h == 0.0):
        raise ValidationError("r, v: the LVLH frame needs r ≠ 0 and v not parallel to r (|r × v| = 0 here)")
    return r, v


def lvlh_matrix(r: ArrayLike, v: ArrayLike) -> np.ndarray:
    """``R_I_LVLH`` (…, 3, 3): columns o₁, o₂, o₃ of the LVLH frame in inertial axes, from ``r``, ``v`` (…, 3)
    in inertial axes."""
    r, v = _checked_rv(r, v)
    batch = r.shape[:-1]
    out = np.empty((math.prod(batch), 3, 3))
    _lvlh_matrices(np.ascontiguousarray(r.reshape(-1, 3)), np.ascontiguousarray(v.reshape(-1, 3)), out)
    return out.reshape((*batch, 3, 3))


def lvlh_quaternion(r: ArrayLike, v: ArrayLike) -> np.ndarray:
    """``q_I_LVLH`` (…, 4), LVLH → inertial, scalar first, from ``r``, ``v`` (…, 3) in inertial axes."""
    return attitude.from_matrix(lvlh_matrix(r, v))


class LvlhAttitude(NamedTuple):
    """Attitude of the body relative to the LVLH frame, sampled along a trajectory.

    q     : (n, [N,] 4) ``q_LVLH_B`` (body → LVLH, scalar first)
    roll  : (n, [N]) rotation about o₁ (rad)
    pitch : (n, [N]) rotation about o₂ (rad)
    yaw   : (n, [N]) rotation about o₃ (rad)

    The angles are the 3-2-1 sequence ``q_LVLH_B = q₃(yaw) ⊗ q₂(pitch) ⊗ q₁(roll)``
    (intrinsic "ZYX"), the usual choice for an Earth-pointing spacecraft
    (Wie, ch. 6): for small angles they are the rotations about the roll,
    pitch and yaw axes.
    """

    q: np.ndarray
    roll: np.ndarray
    pitch: np.ndarray
    yaw: np.ndarray


def attitude_in_lvlh(traj: Trajectory, orbit: Orbit) -> LvlhAttitude:
    """The body attitude of ``traj`` (a :class:`tumble.Trajectory`) relative to the LVLH frame of ``orbit``.

    ``q_LVLH_B = q_I_LVLH* ⊗ q_I_B`` at each output time, with the orbit's
    ``t = 0`` at the trajectory's ``t = 0``.
    """
    r, v = orbit.state(traj.t)
    q_i_lvlh = lvlh_quaternion(r, v)
    q_i_b = cast(np.ndarray, traj.q)
    if q_i_b.ndim == 3:
        q_i_lvlh = q_i_lvlh[:, None, :]
    q = attitude.multiply(attitude.conjugate(q_i_lvlh), q_i_b)
    yaw, pitch, roll = np.moveaxis(attitude.to_euler(q, "ZYX"), -1, 0)
    return LvlhAttitude(q=q, roll=roll, pitch=pitch, yaw=yaw)
