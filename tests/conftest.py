"""Shared fixtures of the dynamics, torque and simulation tests."""

import numpy as np
import pytest


@pytest.fixture
def random_rotation():
    """``random_rotation(seed)``: a proper rotation matrix drawn from the QR of a Gaussian matrix."""

    def make(seed):
        q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
        q = q * np.sign(np.diag(r))
        return q if np.linalg.det(q) > 0.0 else -q

    return make
