"""The momentum-budget demo: an Earth-pointing LEO smallsat's disturbance torques, wheel momentum and eclipses.

:func:`demo_budget` runs :class:`tumble.spacecraft.budget.SmallSat` on the dawn-dusk orbit and draws its
budget (``tumble demo budget``, ``docs/spacecraft_environment.md``).
"""

from __future__ import annotations

import os
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from tumble.spacecraft.budget import (DEMO_EPOCH, SOURCES, Budget, SmallSat, demo_orbit, eclipse_fraction,
                                      momentum_budget, smad_estimates)
from tumble.spacecraft.environment_table import Environment, SpaceWeather
from tumble.viz._output import out_directory, save_png

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["demo_budget"]

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
    out_directory(out_dir)
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
    save_png(_figure(budget, summary, days, fraction, peaks, orbit.period), path)
    return {**summary, "png": path}


def _figure(budget: Budget, summary: dict, days, fraction, peaks, period) -> Figure:
    """(a) the disturbance torques by source, (b) the momentum the wheels store, (c) the eclipse seasons, (d) the
    Monte-Carlo peaks of ``|h|``; matplotlib's object-oriented API, nothing shown."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 8), layout="constrained")
    ax = fig.subplots(2, 2)
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

