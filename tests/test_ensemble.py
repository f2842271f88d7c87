"""Streamed batch statistics (tumble.ensemble) against the statistics of the whole batch in memory."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble.ensemble import ensemble_statistics

# The chunked statistics merge partial means and sums of squares (Chan et al.):
# the same numbers as NumPy on the whole batch up to the rounding of the merge,
# measured ≤ 3e-16 relative to the spread; bound 1e-12 relative to the largest
# value of each statistic.
TOL = 1e-12

RNG = np.random.default_rng(7)
N = 23  # a prime: chunks of 5 leave a remainder
INERTIA = np.diag([1.0, 2.0, 3.0]) + np.einsum("n,ij->nij", RNG.uniform(0.0, 0.2, N), np.eye(3))
OMEGA0 = RNG.normal(size=(N, 3))
Q0 = tumble.attitude.normalize(RNG.normal(size=(N, 4)))
T = np.linspace(0.0, 2.0, 5)
OPTIONS = dict(method="rk4", dt=0.05)


def _whole():
    return tumble.simulate(INERTIA, OMEGA0, q0=Q0, t=T, **OPTIONS)


def _check(ds, name, values):
    expected = np.stack([values.mean(axis=1), values.std(axis=1), values.min(axis=1), values.max(axis=1)], axis=1)
    got = ds[name].values
    scale = np.abs(expected).max(axis=(0, 1) if expected.ndim == 3 else 0, keepdims=True) + 1e-300
    assert got.shape == expected.shape
    assert (np.abs(got - expected) / scale).max() <= TOL, name


@pytest.mark.parametrize("chunk", [5, N, 1000])
def test_streamed_statistics_equal_the_whole_batch(chunk):
    whole = _whole()
    ds = ensemble_statistics(INERTIA, OMEGA0, q0=Q0, t=T, chunk=chunk, **OPTIONS)
    assert list(ds["statistic"].values) == ["mean", "std", "min", "max"] and ds.attrs["bodies"] == N
    _check(ds, "omega", whole.omega)
    _check(ds, "energy_drift", whole.energy_drift)
    _check(ds, "momentum_inertial_drift", whole.momentum_inertial_drift)


def test_custom_quantity_and_progress_over_chunks():
    done = []
    ds = ensemble_statistics(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), OMEGA0, t=T, chunk=10,
                             quantities={"wz": lambda traj: traj.omega[..., 2]},
                             progress=lambda k, n: done.append((k, n)), **OPTIONS)
    assert done == [(10, N), (20, N), (23, N)]
    whole = tumble.simulate(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), OMEGA0, t=T, **OPTIONS)
    _check(ds, "wz", whole.omega[..., 2])


@pytest.mark.parametrize("kwargs, message", [
    (dict(omega0=[1.0, 2.0, 3.0]), r"omega0: must have shape \(N, 3\)"),
    (dict(chunk=0), "chunk: must be >= 1"),
    (dict(q0=np.ones((4, 4))), r"^q0: a batch of 4 does not match the 23 of omega0"),
    (dict(quantities={"bad": lambda traj: traj.t}), r"quantities\['bad'\]: must return an array"),
    (dict(quantities={}), "quantities: give at least one"),
])
def test_bad_arguments_name_the_field(kwargs, message):
    args = dict(omega0=OMEGA0, t=T, chunk=50) | kwargs
    with pytest.raises(tumble.ValidationError, match=message):
        ensemble_statistics(INERTIA, **args, **OPTIONS)
