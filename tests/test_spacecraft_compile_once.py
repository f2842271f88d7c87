"""The spacecraft is compiled once: a new composition of parts, torque terms and control law is data.

``SpacecraftModel`` has one Numba type for every spacecraft (each part's field an int64, −1 when absent; the
torque program always arrays), so a spacecraft of other parts runs the integrators compiled for the first one.
Counted two ways: Numba's ``numba:compile`` events (fired by every compilation that the disk cache does not
answer) and the signatures of the compiled diagnostics (one per model type, cache hits included).
"""

import numba
import numpy as np
from numba.core import event

import tumble
from tumble import torques
from tumble.kernels import spacecraft as kernel
from tumble.spacecraft import (CMGCluster, MRPFeedback, QuaternionPD, ResidualDipole, Spacecraft,
                               pyramid_wheels)

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
T = np.linspace(0.0, 2.0, 3)
TARGET = [np.cos(0.2), 0.0, np.sin(0.2), 0.0]


def wheels_and_mrp():
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                      controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))


def wheels_cmgs_pd_dipole():
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02, max_torque=0.1), cmgs=CMGCluster.pyramid(1.0),
                      magnetic_field=[2e-5, -1e-5, 3e-5], residual_dipole=ResidualDipole([0.5, 0.0, -0.2]),
                      controller=QuaternionPD(0.2, 0.8, target=TARGET))


def test_every_composition_has_one_numba_type():
    first = wheels_and_mrp().compile(None, 0.0)
    second = wheels_cmgs_pd_dipole().compile(torques.ConstantBody([1e-3, 0.0, -2e-3]), 0.0)
    assert numba.typeof(first) == numba.typeof(second)


def test_a_new_composition_compiles_nothing():
    tumble.simulate(wheels_and_mrp(), [0.01, -0.02, 0.03], t=T, method="rk4", dt=0.1)
    signatures = len(kernel.evaluate.signatures)
    with event.install_recorder("numba:compile") as compiles:
        traj = tumble.simulate(wheels_cmgs_pd_dipole(), [0.01, -0.02, 0.03], t=T, method="rk4", dt=0.1,
                               torque=torques.ConstantBody([1e-3, 0.0, -2e-3]))
    assert [e.data["dispatcher"].py_func.__qualname__ for e in compiles.buffer if e.is_start] == []
    assert len(kernel.evaluate.signatures) == signatures
    np.testing.assert_array_equal(traj.external_torque[-1], [1e-3, 0.0, -2e-3])  # the new parts ran
    assert np.abs(traj.residual_dipole_torque).max() > 0.0
