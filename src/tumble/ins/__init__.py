"""Gyroscopes and strapdown inertial navigation.

================================  ==============================================================
``Gyroscope``                     a spinning rotor on a pivot (a model of ``tumble.simulate``): precession
                                  ``τ/(I_s ω_s)``, nutation ``I_s ω_s/I_t``, imbalance and friction drift
``GimbaledGyro``                  a rotor in a two-axis gimbal with gimbal inertia (Lagrange's
                                  equations; a model of ``tumble.simulate``)
``Increments``                    angle (and velocity) increments over uniform sample intervals;
``from_trajectory``               exact increments of a true motion; ``read_csv`` / ``write_csv``
``SensorErrors``, ``Imu``         bias, ARW N, bias instability B, RRW K, scale factor,
                                  misalignment, quantization (IEEE Std 952-1997), seeded
``allan_deviation``               overlapping Allan deviation, N / B / K fits
``strapdown``                     rotation-vector attitude integration with none / one- / two- /
                                  three-sample coning compensation, velocity with sculling
``Coning``, ``drift_law``,        the classic coning motion (closed form) and the coning drift
``measure_drift``                 of each algorithm, predicted and measured
================================  ==============================================================

Conventions as everywhere in tumble: SI units, attitude ``q`` scalar-first
body → inertial, rates and increments in body axes. See ``docs/ins.md``; the figures and
demos are :mod:`tumble.viz.ins`.
"""

from tumble._moved import moved
from tumble.ins.allan import FLICKER_FACTOR, AllanDeviation, allan_deviation, gauss_markov_adev
from tumble.ins.coning import Coning, drift_law, measure_drift
from tumble.ins.gimbal import GimbaledGyro
from tumble.ins.gyroscope import Gyroscope
from tumble.ins.increments import Increments, from_trajectory, read_csv, write_csv
from tumble.ins.sensors import Imu, SensorErrors
from tumble.ins.strapdown import ALGORITHMS, Navigation, strapdown

__all__ = [
    "ALGORITHMS",
    "FLICKER_FACTOR",
    "AllanDeviation",
    "Coning",
    "GimbaledGyro",
    "Gyroscope",
    "Imu",
    "Increments",
    "Navigation",
    "SensorErrors",
    "allan_deviation",
    "drift_law",
    "from_trajectory",
    "gauss_markov_adev",
    "measure_drift",
    "read_csv",
    "strapdown",
    "write_csv",
]

# The figure and the demos moved to tumble.viz.ins: the old names warn and work for one release.
__getattr__ = moved(__name__, dict.fromkeys(("allan_figure", "demo_coning", "demo_gyroscope", "demo_ins"), "tumble.viz.ins"))
