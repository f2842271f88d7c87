"""Attitude estimation: determination from vector observations, Kalman and complementary filters.

=============================  ==================================================================
``triad``, ``davenport``,      attitude from vector observations (Wahba's problem); QUEST also
``quest``                      gives the attitude-error covariance
``mekf``                       multiplicative extended Kalman filter: attitude error + gyro bias,
                               star tracker quaternions and vector observations, batched over runs
``madgwick``, ``mahony``,      AHRS filters for gyro + accelerometer + magnetometer, batched
``ahrs_ekf``
``sensors``                    measurement models: star tracker, coarse and fine Sun sensors,
                               magnetometer, each read from a true motion with its own seed
=============================  ==================================================================

The estimators are compiled functions on arrays, free of any model: they
take measurements (from :mod:`tumble.estimation.sensors`, from
:mod:`tumble.ins`, or from a file) and return estimates. Conventions as
everywhere in tumble: SI units, ``q`` scalar-first body → inertial, rates in
body axes; attitude errors are rotation vectors ``δθ`` in body axes with
``q_true = q̂ ⊗ exp(δθ/2)``. See ``docs/estimation.md``.
"""

from tumble.estimation import sensors
from tumble.estimation._ahrs import ahrs_ekf, madgwick, mahony
from tumble.estimation._determination import AttitudeEstimate, davenport, quest, triad
from tumble.estimation._mekf import FilterResult, covariance_matrix, mekf

__all__ = [
    "AttitudeEstimate",
    "FilterResult",
    "ahrs_ekf",
    "covariance_matrix",
    "davenport",
    "madgwick",
    "mahony",
    "mekf",
    "sensors",
    "quest",
    "triad",
]
