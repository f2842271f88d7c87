"""Monte-Carlo: an Explorer-1-like minor-axis spinner with a dispersed nutation damper → time to flat spin.

A prolate hub (moments 1, 1, 0.4 kg m²; spin axis z the minor axis) spins at
2 rad/s with a spherical viscous damper tuned for that spin (the scaled
Explorer 1 of tests/spacecraft/test_spacecraft_passive_damper.py: sphere J = 0.02 kg m²,
c = J Ω I_s / I_t, energy-sink time constant 87 s). Energy dissipation at
fixed angular momentum drives the spin into a flat spin about a transverse
(major) axis. Each sample disperses

* the sphere's inertia J: N(0.02, (10 %)²) kg m², truncated at 3σ;
* the damping c: N(c₀, (30 %)²) N m s, truncated at 3σ;
* the initial body rate: N((0, 0, 2), (0.004, 0.004, 0.02)²) rad/s (nutation
  angles of about 0.5°);

and keeps the time to flat spin: the first time the nutation angle (between
the body z axis and the angular momentum) reaches 80°. Each sample's energy-
sink estimate τ ln(θ_f/θ₀) is kept beside it for comparison.

Run:  python src/tumble/examples/sweep/explorer1_damper.py [SAMPLES] [figure.png]
"""

from __future__ import annotations

import math
import os
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

import tumble
from tumble.spacecraft import Spacecraft, SphericalDamper
from tumble.spacecraft.damper import energy_sink_time_constant
from tumble.sweeps import CrossingTime, Normal, NutationAngle, TruncatedNormal, sweep

if TYPE_CHECKING:
    import xarray
    from numpy.typing import ArrayLike

HUB = tumble.RigidBody(np.diag([1.0, 1.0, 0.4]))  # kg m², without the sphere
J, SPIN = 0.02, 2.0  # kg m², rad/s
NOMINAL = SphericalDamper.tuned(J, 0.4 + J, 1.0 + J, SPIN)
FLAT = math.radians(80.0)  # rad: the nutation angle counted as a flat spin
T = np.arange(0.0, 1500.0 + 0.5, 1.0)  # s


def spacecraft(damper_inertia: float, damping: float) -> Spacecraft:
    """The hub with a sphere of inertia ``damper_inertia`` (kg m²) in a viscous film ``damping`` (N m s)."""
    return Spacecraft(hub=HUB, damper=SphericalDamper(float(damper_inertia), float(damping)))


def estimate(damper_inertia: float, damping: float, omega0: np.ndarray) -> float:
    """Energy-sink estimate of the time (s) from the initial nutation angle to FLAT: τ ln(θ_f / θ₀)."""
    i_s, i_t = 0.4 + damper_inertia, 1.0 + damper_inertia
    tau = energy_sink_time_constant(i_s, i_t, SphericalDamper(damper_inertia, damping), omega0[2])
    theta0 = math.atan2(i_t * math.hypot(omega0[0], omega0[1]), i_s * omega0[2])
    return tau * math.log(FLAT / theta0)


def run(samples: int = 500, t: ArrayLike = T, seed: int = 1958, **dask: Any) -> xarray.Dataset:
    c = NOMINAL.damping
    return sweep(
        spacecraft,
        {"damper_inertia": TruncatedNormal(np.array(J), np.array(0.1 * J)),
         "damping": TruncatedNormal(np.array(c), np.array(0.3 * c)),
         "omega0": Normal(np.array([0.0, 0.0, SPIN]), np.array([0.004, 0.004, 0.02]))},
        samples=samples, seed=seed, t=t, rtol=1e-10, atol=1e-12,
        outcomes={"time_to_flat_spin": CrossingTime(NutationAngle((0.0, 0.0, 1.0)), above=FLAT)},
        statistics={"nutation_angle": NutationAngle((0.0, 0.0, 1.0))}, **dask)


def main(samples: int = 500, figure: str | os.PathLike[str] | None = None) -> xarray.Dataset:
    ds = run(samples)
    measured = ds.time_to_flat_spin.values
    expected = np.array([estimate(j, c, w) for j, c, w in
                         zip(ds.damper_inertia.values, ds.damping.values, ds.omega0.values, strict=True)])
    p = dict(zip(ds.percentile.values, ds.time_to_flat_spin_percentiles.values, strict=True))
    ratio = measured / expected
    print(f"{samples} samples, time to flat spin (nutation >= 80 deg), s: 1st percentile {p[1.0]:.1f}, "
          f"median {p[50.0]:.1f}, 99th percentile {p[99.0]:.1f}; never reached: {int(np.isnan(measured).sum())}")
    print(f"measured / energy-sink estimate tau ln(theta_f/theta_0), over the samples that reached it: median "
          f"{np.nanmedian(ratio):.3f}, range {np.nanmin(ratio):.3f} to {np.nanmax(ratio):.3f}")
    if figure:
        from tumble.viz.sweep import sweep_figure

        fig = sweep_figure(ds, title="Explorer-1-like spinner, dispersed damper: time to flat spin",
                           units={"time_to_flat_spin": "s", "nutation_angle": "rad"})
        tumble.trajectory.write_atomic(figure, lambda path: fig.savefig(path, format="png", dpi=110))
    return ds


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 500, sys.argv[2] if len(sys.argv) > 2 else None)
