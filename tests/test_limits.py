"""Guard rails of the rigid model (tumble.limits): warnings at the edges of its domain."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tumble
from tumble import limits
from tumble.limits import RigidityWarning

# A uniform sphere, m = 2 kg, radius 0.1 m: I = 2/5 m r² = 0.008 kg·m². Spinning
# at ω its RMS particle speed is √(ω·Iω/m) = √(2/5) r ω = 0.0632 ω (m/s).
SPHERE = tumble.RigidBody.sphere(mass=2.0, radius=0.1)
RMS_PER_RATE = np.sqrt(0.4) * 0.1  # m/s per rad/s, exact
T = np.linspace(0.0, 1e-9, 3)  # a few nanoseconds: the motion is not the point here
# (the default method, dop853, whose compiled code the other tests share: no extra compile)


def _spin(rate):
    return tumble.simulate(SPHERE, [0.0, 0.0, rate], t=T)


def test_rms_speed_is_the_energy_speed_of_a_sphere():
    # the threshold speed: just below and just above 2 km/s (factor 1 ± 1e-6)
    rate = limits.BURST_SPEED / RMS_PER_RATE
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _spin(rate * (1.0 - 1e-6))
    with pytest.warns(RigidityWarning, match=r"2e\+03 m/s or more .*burst"):
        _spin(rate * (1.0 + 1e-6))


def test_relativistic_speed_names_the_fraction_of_c_and_what_is_ignored():
    rate = 2.0 * limits.RELATIVISTIC_SPEED / RMS_PER_RATE  # v_rms = 2e-3 c exactly (to rounding)
    with pytest.warns(RigidityWarning, match=r"0\.002 c.*relativistic corrections") as record:
        _spin(rate)
    assert len(record) == 1  # one warning, not one per check or per sample
    assert record[0].filename == __file__  # points at the caller's line


def test_batch_warning_counts_the_members():
    rates = np.zeros((5, 3))
    rates[[1, 3], 2] = 1e5 / RMS_PER_RATE  # 100 km/s: above the burst speed, below 1e-3 c
    with pytest.warns(RigidityWarning, match=r"2 of 5 members, first 1"):
        tumble.simulate([SPHERE] * 5, rates, t=T)


def test_torque_that_spins_the_body_up_is_caught_at_the_end():
    # ω̇ = τ/I = 1e5 rad/s² for 1 s about z: final v_rms = 0.0632 × 1e5 m/s = 6.3 km/s, initial 0
    torque = tumble.torques.ConstantBody([0.0, 0.0, 1e5 * 0.008])
    with pytest.warns(RigidityWarning, match="burst"):
        tumble.simulate(SPHERE, [0.0, 0.0, 0.0], t=[0.0, 1.0], torque=torque)


def test_without_mass_the_speed_checks_are_skipped():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tumble.simulate(tumble.RigidBody(SPHERE.inertia), [0.0, 0.0, 1e12], t=T)


def test_a_practically_linear_body_is_flagged():
    rod = tumble.RigidBody(np.diag([1e-12, 1.0, 1.0]))
    with pytest.warns(RigidityWarning, match=r"1e-12 times the largest .*practically a line"):
        tumble.simulate(rod, [0.0, 1.0, 0.0], t=T)


def test_zero_and_negative_moments_are_refused_not_warned():
    for moments in ([0.0, 1.0, 1.0], [-1.0, 2.0, 2.0]):
        with pytest.raises(tumble.ValidationError, match="positive definite"):
            tumble.RigidBody(np.diag(moments))
