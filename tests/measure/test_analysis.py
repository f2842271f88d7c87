"""Flip detection: sign changes of the intermediate-axis rate, placed by linear interpolation."""

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.measure import flip_times, intermediate_rate

# Linear interpolation of a linear signal is exact up to rounding of times ~10 s.
ROUNDING = 1e-14  # s


def trajectory(t, rate_principal, body):
    """A trajectory whose body rate has principal-axis components ``rate_principal`` (n, 3)."""
    q = np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1))
    return tumble.Trajectory(t=t, q=q, omega=rate_principal @ body.axes.T, inertia=body.inertia)


@pytest.fixture
def tilted_body():
    """Moments (1, 2, 3) kg m² with principal axes rotated away from the body axes."""
    rotation = attitude.to_matrix(attitude.from_rotvec([0.3, -0.5, 0.7]))
    return tumble.RigidBody(rotation @ np.diag([1.0, 2.0, 3.0]) @ rotation.T)


def test_flips_of_a_piecewise_linear_rate_are_exact(tilted_body):
    t = np.linspace(0.0, 10.0, 101)
    triangle = 1.0 - np.abs((t % 4.0) - 2.0)  # zero at t = 1, 3, 5, 7, 9; linear between samples
    rates = np.stack([np.full_like(t, 0.2), triangle, np.full_like(t, -0.1)], axis=-1)
    traj = trajectory(t, rates, tilted_body)
    np.testing.assert_allclose(np.abs(intermediate_rate(traj, tilted_body)), np.abs(triangle), rtol=0, atol=ROUNDING)
    np.testing.assert_allclose(flip_times(traj, tilted_body), [1.0, 3.0, 5.0, 7.0, 9.0], rtol=0, atol=ROUNDING)


def test_crossing_between_samples_is_interpolated():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    t = np.array([0.0, 1.0, 2.0])
    rates = np.array([[0.0, 3.0, 0.0], [0.0, 1.0, 0.0], [0.0, -3.0, 0.0]])  # zero at t = 1 + 1/4
    assert flip_times(trajectory(t, rates, body), body).tolist() == [1.25]


@pytest.mark.parametrize(("rate", "expected"), [([1.0, 0.0, -1.0], [1.0]), ([1.0, 0.0, 1.0], [])])
def test_a_zero_sample_counts_as_positive(rate, expected):
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    t = np.array([0.0, 1.0, 2.0])
    rates = np.stack([np.zeros(3), rate, np.zeros(3)], axis=-1)
    assert flip_times(trajectory(t, rates, body), body).tolist() == expected


def test_a_batch_is_refused():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    t = np.linspace(0.0, 1.0, 3)
    rates = np.stack([np.zeros((3, 2)), np.tile([1.0, 2.0], (3, 1)), np.zeros((3, 2))], axis=-1)  # (n, 2 bodies, 3)
    batch = tumble.Trajectory(t=t, q=np.tile([1.0, 0.0, 0.0, 0.0], (3, 2, 1)), omega=rates, inertia=body.inertia)
    with pytest.raises(tumble.ValidationError, match="trajectory: must hold a single body"):
        flip_times(batch, body)
