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
import os
from dataclasses import dataclass, replace
from datetime import datetime, timezone
from typing import Any, NamedTuple, cast

import numpy as np

from tumble.kernels import spacecraft as _kernel
from tumble.kernels.spacecraft import environment_table as _table
from tumble.spacecraft import _ephemeris
from tumble.spacecraft.actuators import pyramid_wheels
from tumble.spacecraft.environment import ResidualDipole
from tumble.spacecraft.environment_table import Environment, SpaceWeather
from tumble.spacecraft.model import Spacecraft
from tumble.spacecraft.orbit import EARTH_RADIUS, Orbit, lvlh_quaternion
from tumble.spacecraft.surfaces import SOLAR_IRRADIANCE, Drag, SolarPressure, box_facets

__all__ = ["Budget", "SmallSat", "demo_budget", "eclipse_fraction", "momentum_budget", "smad_estimates"]

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


def _monte_carlo(sat: SmallSat, env: Environment, samples: int, seed: int) -> np.ndarray:
    """Peak |h| (N m s) over ``env`` of ``samples`` satellites with the facet coefficients and the centre of
    mass drawn: specular U[0, 0.5], diffuse U[0, 0.3] (absorbed the rest), each offset component U[−2, 2] cm."""
    rng = np.random.default_rng(seed)
    peaks = np.empty(samples)
    for k in range(samples):
        specular, diffuse = rng.uniform(0.0, 0.5), rng.uniform(0.0, 0.3)
        drawn = replace(sat, specular=specular, diffuse=diffuse, absorbed=1.0 - specular - diffuse,
                        centre_of_mass=tuple(rng.uniform(-0.02, 0.02, 3)))
        peaks[k] = np.linalg.norm(momentum_budget(drawn, env).total, axis=1).max()
    return peaks


def demo_budget(out_dir: str | os.PathLike[str], *, hours: float = 24.0, samples: int = 32,
                seed: int = 2026) -> dict:
    """The budget of :class:`SmallSat` on the dawn-dusk orbit over ``hours`` from :data:`DEMO_EPOCH`, eclipse
    seasons over a year, and ``samples`` Monte-Carlo draws over one orbit. Writes ``budget.png`` in
    ``out_dir`` (atomically) and returns the numbers."""
    from tumble.spacecraft.passive import _check_dir, _save_png

    _check_dir(out_dir)
    sat, orbit = SmallSat(), demo_orbit()
    env = Environment.sample(orbit, DEMO_EPOCH, duration=hours * 3600.0, step=10.0,
                             space_weather=SpaceWeather(150.0, 150.0, 15.0), j2=True)
    budget = momentum_budget(sat, env)
    estimates = smad_estimates(sat, orbit, float(np.mean(env.density)))
    one_orbit = Environment.sample(orbit, DEMO_EPOCH, duration=orbit.period, step=10.0, j2=True)
    peaks = _monte_carlo(sat, one_orbit, samples, seed)
    days = np.arange(0.0, 366.0)
    beta, fraction = eclipse_fraction(orbit, DEMO_EPOCH, days)
    duration = float(budget.t[-1])
    summary = {
        "hours": duration / 3600.0,
        "peak_torque": {s: float(np.linalg.norm(budget.torques[:, i], axis=1).max()) for i, s in enumerate(SOURCES)},
        "peak_momentum": {s: float(np.linalg.norm(budget.momentum[:, i], axis=1).max())
                          for i, s in enumerate(SOURCES)},
        "estimate_momentum": {s: e.get("momentum_per_orbit", e.get("momentum_per_s", 0.0) * duration)
                              for s, e in estimates.items()},
        "estimate_torque": {s: e["torque"] for s, e in estimates.items()},
        "peak_total_momentum": float(np.linalg.norm(budget.total, axis=1).max()),
        "peak_wheel_momentum": float(np.abs(budget.wheels).max()),
        "monte_carlo_median": float(np.median(peaks)),
        "monte_carlo_p95": float(np.quantile(peaks, 0.95)),
        "monte_carlo_samples": samples,
        "eclipse_days": int((fraction > 0.0).sum()),
        "eclipse_max_fraction": float(fraction.max()),
        "beta_range_deg": (float(np.degrees(beta.min())), float(np.degrees(beta.max()))),
    }
    path = os.path.join(out_dir, "budget.png")
    _save_png(_figure(budget, summary, days, fraction, peaks, orbit.period), path)
    return {**summary, "png": path}


def _figure(budget: Budget, summary: dict, days, fraction, peaks, period):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 2, figsize=(12, 8), constrained_layout=True)
    hours = budget.t / 3600.0
    for i, source in enumerate(SOURCES):
        ax[0, 0].semilogy(hours, np.linalg.norm(budget.torques[:, i], axis=1) + 1e-16, lw=0.8,
                          label=source.replace("_", " "))
        ax[0, 1].plot(hours, np.linalg.norm(budget.momentum[:, i], axis=1), lw=0.8,
                      label=f"{source.replace('_', ' ')} (SMAD {summary['estimate_momentum'][source]:.2g})")
    ax[0, 0].set(xlabel="time (h)", ylabel="|torque| (N m)", title="Disturbance torques, Earth pointing")
    ax[0, 1].plot(hours, np.linalg.norm(budget.total, axis=1), "k", lw=1.2, label="all")
    ax[0, 1].set(xlabel="time (h)", ylabel="|h| (N m s)", title="Momentum the wheels store")
    ax[1, 0].plot(days, fraction, "k")
    ax[1, 0].set(xlabel="days from the epoch", ylabel="fraction of the orbit in shadow",
                 title="Eclipse seasons (cylindrical shadow, J2 node drift)")
    ax[1, 1].hist(peaks, bins=max(5, len(peaks) // 4), color="0.6")
    ax[1, 1].set(xlabel="peak |h| over one orbit (N m s)", ylabel="samples",
                 title=f"Monte Carlo: facet coefficients and centre of mass ({len(peaks)} draws)")
    for a in (ax[0, 0], ax[0, 1]):
        a.legend(fontsize=8)
        a.grid(alpha=0.3)
    fig.suptitle(f"Momentum budget, 500 km dawn-dusk orbit ({period / 60:.1f} min)")
    return fig
