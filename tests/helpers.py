"""Helpers shared by the tests."""

import numpy as np

from tumble.integrate import METHODS


def read_by(method: str, **options) -> dict:
    """The solver ``options`` that ``method`` reads, with ``method`` itself (``simulate`` refuses the others)."""
    return {"method": method, **{k: v for k, v in options.items() if k in METHODS[method].options}}


def assert_same_run(traj, reference):
    """Every sampled array of the two trajectories is the same, bit for bit."""
    np.testing.assert_array_equal(traj.t, reference.t)
    for name in ("q", "omega", "inertia"):
        a, b = getattr(traj, name), getattr(reference, name)
        assert (a is None) == (b is None), name
        if a is not None:
            np.testing.assert_array_equal(a, b, err_msg=name)
    assert traj.extras.keys() == reference.extras.keys() and traj.totals.keys() == reference.totals.keys()
    for name in traj.extras:
        np.testing.assert_array_equal(traj.extras[name].data, reference.extras[name].data, err_msg=name)
    for name in traj.totals:
        np.testing.assert_array_equal(traj.totals[name], reference.totals[name], err_msg=name)
    assert traj.method == reference.method and traj.model == reference.model
