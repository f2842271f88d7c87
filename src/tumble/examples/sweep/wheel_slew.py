"""Monte-Carlo: a 60° reaction-wheel slew with dispersed inertia, wheel misalignment and initial rates.

The spacecraft of examples/spacecraft/slew_wheels.toml (total inertia about
10, 12, 8 kg m², four wheels in a pyramid, quaternion PD law with a 0.02
rad/s slew-rate limit, controller sampled at 2 Hz) slews 60° about z. Each
sample disperses

* the inertia: principal moments N(m, (2 %)²) truncated at 3σ, principal axes
  turned by a small rotation of 1° per axis (:class:`tumble.sweeps.Inertia`);
* each wheel's spin axis: tilted by a Rayleigh angle of scale 0.5°
  (:class:`tumble.sweeps.Misalignment`); the spacecraft model allocates the
  command with the wheels' actual axes (it has no separate estimate of them),
  so the misalignment acts through the wheels' momentum directions;
* the initial body rate: N(0, (1 mrad/s)²) per axis;

and keeps the pointing error (the rotation angle from the target attitude)
at the end of the slew, t = 150 s, with its percentiles, and the pointing
error over time (percentile bands).

Run:  python src/tumble/examples/sweep/wheel_slew.py [SAMPLES] [figure.png]
"""

from __future__ import annotations

import math
import os
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

import tumble
from tumble.spacecraft import QuaternionPD, ReactionWheel, Spacecraft
from tumble.spacecraft.actuators import pyramid_wheels
from tumble.sweeps import Final, Inertia, Misalignment, Normal, PointingError, sweep

if TYPE_CHECKING:
    import xarray
    from numpy.typing import ArrayLike

    from tumble.sweeps import Dispersion

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])  # kg m², total, body axes
NOMINAL = pyramid_wheels(0.02, max_torque=0.05, max_speed=600.0, viscous=1e-5)
TARGET = tumble.attitude.from_euler("ZYX", [60.0, 0.0, 0.0], degrees=True)  # body → inertial
LAW = QuaternionPD(natural_frequency=0.15, damping_ratio=0.9, max_rate=0.02, target=TARGET)
T = np.arange(0.0, 150.0 + 0.25, 0.5)  # s


def spacecraft(inertia: np.ndarray, wheel_axes: np.ndarray) -> Spacecraft:
    """The spacecraft of one sample: its inertia (kg m², body axes) and the spin axes of its wheels."""
    wheels = [ReactionWheel(axis=a, inertia=w.inertia, max_torque=w.max_torque, max_speed=w.max_speed,
                            viscous=w.viscous) for a, w in zip(wheel_axes, NOMINAL, strict=True)]
    return Spacecraft(inertia=inertia, wheels=wheels, controller=LAW, control_period=0.5)


def dispersions() -> dict[str, Dispersion]:
    moments, axes = np.linalg.eigh(INERTIA)
    axes[:, 2] *= np.sign(np.linalg.det(axes))  # a proper rotation
    return {
        "inertia": Inertia(moments, 0.02 * moments, angle=math.radians(1.0), axes=axes),
        "wheel_axes": Misalignment(np.array([w.axis for w in NOMINAL]), math.radians(0.5)),
        "omega0": Normal(np.zeros(3), np.array(1e-3)),
    }


def run(samples: int = 1000, t: ArrayLike = T, seed: int = 13, **dask: Any) -> xarray.Dataset:
    """The sweep: pointing error at the end (rad) and over time."""
    return sweep(spacecraft, dispersions(), samples=samples, seed=seed, t=t, method="rk4", dt=0.05,
                 outcomes={"final_pointing_error": Final(PointingError(tuple(TARGET)))},
                 statistics={"pointing_error": PointingError(tuple(TARGET))}, **dask)


def main(samples: int = 1000, figure: str | os.PathLike[str] | None = None) -> xarray.Dataset:
    ds = run(samples)
    error = ds.final_pointing_error.values
    p = dict(zip(ds.percentile.values, ds.final_pointing_error_percentiles.values, strict=True))
    print(f"{samples} samples, pointing error at t = {T[-1]:g} s (deg): median {math.degrees(p[50.0]):.4g}, "
          f"95th percentile {math.degrees(p[95.0]):.4g}, 99th percentile {math.degrees(p[99.0]):.4g}, "
          f"max {math.degrees(error.max()):.4g}")
    if figure:
        from tumble.viz.sweep import sweep_figure

        fig = sweep_figure(ds, title="60° slew, 4 wheels: dispersed inertia, wheel axes, initial rates",
                           units={"final_pointing_error": "rad", "pointing_error": "rad"})
        fig.axes[1].set_yscale("log")
        tumble.trajectory.write_atomic(figure, lambda path: fig.savefig(path, format="png", dpi=110))
    return ds


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1000, sys.argv[2] if len(sys.argv) > 2 else None)
