"""A pointing and momentum budget: the disturbance torques on an Earth-pointing spacecraft along its orbit, the
angular momentum its wheels must store, eclipse seasons, and a Monte-Carlo sweep (``tumble demo budget``).

The momentum budget is the textbook one (Larson & Wertz, *Space Mission
Analysis and Design*, 3rd ed., 1999, §11.1; Wertz, *Spacecraft Attitude
Determination and Control*, 1978, ch. 17): the attitude is held exactly on
the local-vertical local-horizontal frame (body axes = LVLH axes: x along
track, z nadir), so the body turns at ``ω = (0, −|r × v|/|r|², 0)`` and
the wheels' momentum ``h`` (body axes) must absorb what the disturbances
leave::

    dh/dt = τ_d(t) − ω × (J ω + h)

The disturbance torques ``τ_d`` are the spacecraft's own compiled parts
(gravity gradient, solar radiation pressure and drag on facets, residual
dipole in IGRF-14) evaluated along that attitude in an :class:`Environment`;
the four pyramid wheels share ``h`` by the minimum-norm split
``h_w = (Aᵀ)⁺ h``. Closed-form estimates to set against it (SMAD Table 11-9
and §11.1)::

    gravity gradient, product of inertia J_xz:  τ_y = 3 n² J_xz   (exact here: h_y = 3 n² J_xz t, secular)
    solar pressure:  T = Φ/c A (1 + q) L      cyclic: h = T (P/4)(0.707)
    drag:            T = ½ ρ C_D A v² L        secular: h = T t
    magnetic:        T = D 2M/R³               cyclic: h = T (P/4)(0.707)

with ``A`` the largest face, ``q`` its reflectance, ``L`` the centre-of-mass
offset, ``M = 7.96e15 T·m³`` the Earth's dipole strength, ``P`` the orbit
period and 0.707 the RMS of a sinusoid.

Eclipse seasons (Wertz, §3.3): with ``β`` the angle of the Sun out of the
orbit plane, a circular orbit of altitude ``H`` spends the fraction
``f = (1/π) arccos(√(H² + 2RH) / ((R + H) cos β))`` of each orbit in the
cylindrical shadow while ``|β| < arcsin(R/(R+H))``, none otherwise; ``β``
follows the Sun (DE421) and the node drifting at the J₂ rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any, NamedTuple, cast

import numpy as np

from tumble._moved import moved
from tumble.kernels import spacecraft as _kernel
from tumble.kernels.spacecraft import environment_table as _table
from tumble.spacecraft import _ephemeris
from tumble.spacecraft.actuators import pyramid_wheels
from tumble.spacecraft.environment import ResidualDipole
from tumble.spacecraft.environment_table import Environment
from tumble.spacecraft.model import Spacecraft
from tumble.spacecraft.orbit import EARTH_RADIUS, Orbit, lvlh_quaternion
from tumble.spacecraft.surfaces import SOLAR_IRRADIANCE, Drag, SolarPressure, box_facets

__all__ = ["Budget", "SmallSat", "eclipse_fraction", "momentum_budget", "smad_estimates"]

__getattr__ = moved(__name__, {"demo_budget": "tumble.viz.budget"})

#: The Earth's dipole strength M (T·m³) of SMAD's magnetic-torque estimate, B = 2M/R³ at the magnetic pole.
EARTH_DIPOLE = 7.96e15
#: The torque sources, in the order of :attr:`Budget.torques`.
SOURCES = ("gravity_gradient", "solar_pressure", "drag", "residual_dipole")
_LIGHT_SPEED = 299792458.0


@dataclass(frozen=True)
class SmallSat:
    """The demo's spacecraft: a box (m) with moments and a product of inertia J_xz (kg m²), its centre of mass
    off the box's centre (m), facet coefficients, and a residual dipole (A m²); body z nadir, x along track."""

    size: tuple[float, float, float] = (0.2, 0.1, 0.34)
    moments: tuple[float, float, float] = (0.20, 0.22, 0.08)
    product_xz: float = 0.003
    centre_of_mass: tuple[float, float, float] = (0.0, 0.005, 0.02)
    absorbed: float = 0.6
    specular: float = 0.3
    diffuse: float = 0.1
    drag_coefficient: float = 2.2
    dipole: tuple[float, float, float] = (0.0, 0.0, 0.05)

    @property
    def inertia(self) -> np.ndarray:
        J = np.diag(self.moments)
        J[0, 2] = J[2, 0] = self.product_xz
        return J

    def spacecraft(self, env: Environment) -> Spacecraft:
        """The disturbances as a :class:`Spacecraft` in ``env`` (no actuators: the budget's wheels are ``h``)."""
        faces = box_facets(self.size, centre_of_mass=self.centre_of_mass, absorbed=self.absorbed,
                           specular=self.specular, diffuse=self.diffuse, drag_coefficient=self.drag_coefficient)
        return Spacecraft(inertia=self.inertia, environment=env, gravity_gradient=True,
                          solar_pressure=SolarPressure(faces), drag=Drag(faces),
                          residual_dipole=ResidualDipole(np.array(self.dipole)))


class Budget(NamedTuple):
    """The momentum budget along an Earth-pointing attitude (see the module docstring).

    t        : (n,) s from the environment's epoch
    torques  : (n, 4, 3) N m, body axes, by source (:data:`SOURCES`)
    momentum : (n, 4, 3) N m s, body axes: the momentum each source alone leaves in the wheels
    total    : (n, 3) N m s, body axes: all sources together
    wheels   : (n, 4) N m s: the four pyramid wheels' share of ``total`` (minimum norm)
    """

    t: np.ndarray
    torques: np.ndarray
    momentum: np.ndarray
    total: np.ndarray
    wheels: np.ndarray


def _earth_pointing(env: Environment, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``q_I_B`` (n, 4) with body = LVLH and the body rate ``ω`` (n, 3) of that attitude, rad/s."""
    rows = env.at(t)
    r, v = rows[:, _table.POSITION:_table.POSITION + 3], rows[:, _table.VELOCITY:_table.VELOCITY + 3]
    rate = np.linalg.norm(np.cross(r, v), axis=1) / np.einsum("ki,ki->k", r, r)
    return lvlh_quaternion(r, v), np.stack([np.zeros_like(rate), -rate, np.zeros_like(rate)], axis=1)


def disturbance_torques(craft: Spacecraft, t: np.ndarray, q: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The torques (n, 4, 3) of :data:`SOURCES` (N m, body axes) on ``craft`` at the attitudes ``q`` and rates
    ``omega``, from its compiled diagnostics."""
    model: Any = craft.compile(None, 0.0)
    y = np.zeros((len(t), model.size))
    y[:, :4], y[:, 4:7] = q, omega
    aux = np.empty((len(t), model.aux_size))
    _kernel.evaluate(model, np.ascontiguousarray(t), y, aux)
    starts = [_kernel.AUX_GRAVITY] + [cast(_kernel.Slices, _kernel.slices(model, kind)).a for kind in SOURCES[1:]]
    return np.stack([aux[:, a:a + 3] for a in starts], axis=1)


def _integrate(t, torque, omega, inertia):
    """``h`` (n, 3) from ``dh/dt = τ − ω × (J ω + h)``, h(0) = 0: RK4 on the grid, τ and ω linear between
    samples (the grid's step is the table's, where τ varies by parts in 1e3)."""
    h = np.zeros((len(t), 3))

    def rate(k, s, x):
        tau = (1.0 - s) * torque[k] + s * torque[k + 1]
        w = (1.0 - s) * omega[k] + s * omega[k + 1]
        return tau - np.cross(w, inertia @ w + x)

    for k in range(len(t) - 1):
        dt = t[k + 1] - t[k]
        k1 = rate(k, 0.0, h[k])
        k2 = rate(k, 0.5, h[k] + 0.5 * dt * k1)
        k3 = rate(k, 0.5, h[k] + 0.5 * dt * k2)
        k4 = rate(k, 1.0, h[k] + dt * k3)
        h[k + 1] = h[k] + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return h


def momentum_budget(sat: SmallSat, env: Environment, t: np.ndarray | None = None) -> Budget:
    """The :class:`Budget` of ``sat`` held on LVLH in ``env`` at the times ``t`` (default the table's)."""
    t = env.t if t is None else np.asarray(t, dtype=float)
    q, omega = _earth_pointing(env, t)
    torques = disturbance_torques(sat.spacecraft(env), t, q, omega)
    J = sat.inertia
    zero = np.zeros((len(t), 3))
    momentum = np.stack([_integrate(t, torques[:, i], omega, J) - _integrate(t, zero, omega, J)
                         for i in range(len(SOURCES))], axis=1)
    total = _integrate(t, torques.sum(axis=1), omega, J)
    axes = np.array([w.axis for w in pyramid_wheels(1.0)])
    return Budget(t=t, torques=torques, momentum=momentum, total=total, wheels=total @ np.linalg.pinv(axes.T).T)


def smad_estimates(sat: SmallSat, orbit: Orbit, density: float) -> dict[str, dict[str, float]]:
    """SMAD's closed-form torque (N m) and momentum (N m s per orbit, cyclic, or per second, secular) of each
    source for ``sat`` on the circular ``orbit``, at the air ``density`` (kg/m³); see the module docstring."""
    n, r = orbit.mean_motion, orbit.semi_major_axis
    period = 2.0 * math.pi / n
    faces = np.array([sat.size[1] * sat.size[2], sat.size[0] * sat.size[2], sat.size[0] * sat.size[1]])
    offset = float(np.linalg.norm(sat.centre_of_mass))
    ram = faces[0]                                        # the face across the flow (x along track)
    solar = SOLAR_IRRADIANCE / _LIGHT_SPEED * faces.max() * (1.0 + sat.specular + sat.diffuse) * offset
    drag = 0.5 * density * sat.drag_coefficient * ram * (n * r) ** 2 * offset
    magnetic = float(np.linalg.norm(sat.dipole)) * 2.0 * EARTH_DIPOLE / r**3
    gravity = 3.0 * n * n * abs(sat.product_xz)
    cyclic = period / 4.0 * 0.707
    return {"gravity_gradient": {"torque": gravity, "momentum_per_s": gravity},
            "solar_pressure": {"torque": solar, "momentum_per_orbit": solar * cyclic},
            "drag": {"torque": drag, "momentum_per_s": drag},
            "residual_dipole": {"torque": magnetic, "momentum_per_orbit": magnetic * cyclic}}


def eclipse_fraction(orbit: Orbit, epoch: datetime, days: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(β, f)``: the Sun's angle out of the orbit plane (rad) and the fraction of the orbit in the
    cylindrical shadow at ``epoch + days``, the node drifting at the J₂ rate (module docstring)."""
    seconds = np.asarray(days, dtype=float) * _ephemeris.DAY
    time = _ephemeris.times(epoch, seconds)
    _, planets = _ephemeris.loaded()
    sun = planets["earth"].at(time).observe(planets["sun"]).position.m.T
    node = orbit.raan + orbit.j2_rates()[0] * seconds
    i = orbit.inclination
    normal = np.stack([np.sin(i) * np.sin(node), -np.sin(i) * np.cos(node), np.full_like(node, np.cos(i))], axis=1)
    beta = np.arcsin(np.einsum("ki,ki->k", normal, sun) / np.linalg.norm(sun, axis=1))
    height = orbit.semi_major_axis - EARTH_RADIUS
    ratio = math.sqrt(height**2 + 2.0 * EARTH_RADIUS * height) / (orbit.semi_major_axis * np.cos(beta))
    return beta, np.where(ratio < 1.0, np.arccos(np.minimum(ratio, 1.0)) / math.pi, 0.0)


#: The demo's orbit: 500 km, sun-synchronous (97.4°), node at 6 h local time at the epoch (dawn-dusk).
DEMO_EPOCH = datetime(2026, 3, 20, 12, 0, tzinfo=timezone.utc)


def demo_orbit() -> Orbit:
    """The demo's dawn-dusk sun-synchronous orbit: the node 90° east of the Sun's right ascension at the
    epoch (the March equinox: the Sun near RA 0)."""
    return Orbit.circular(500e3, math.radians(97.4), raan=math.radians(90.0))


