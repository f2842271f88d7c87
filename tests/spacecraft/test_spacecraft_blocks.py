"""A batch of spacecraft runs its blocks through function pointers (``tumble._block``), and each member is its
lone run, bit for bit.

The spacecraft registers two sets of block functions, as its kernel type has two variants (``python_calls``): one
compiled without reference counts, and one with them, for a Python control law or torque function (called from
the kind's function through ``tumble._callback``). Each compiles the spacecraft's assembled right-hand side and
discrete updates on a block once for every method (~45 CPU s cold): slow. The reference is each member's lone run,
whose path inlines the spacecraft's kernel (a lone body never runs through the pointers), as the inlined block
did before the pointers: equal to it bit for bit.
"""

import numpy as np
import pytest
from helpers import assert_same_run

import tumble
from tumble import _block, _callback, torques
from tumble.spacecraft import MRPFeedback, QuaternionPD, Spacecraft, pyramid_wheels

pytestmark = pytest.mark.slow

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
TARGET = [np.cos(0.2), 0.0, np.sin(0.2), 0.0]
OMEGA = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9], [0.1, 0.1, 0.7]])
WHEELS = [10.0, -5.0, 3.0, 0.0]  # rad/s
T = np.linspace(0.0, 3.0, 7)


@pytest.mark.parametrize("method", ["rk4", "cf4"])
@pytest.mark.parametrize("spacecraft, torque", [
    (Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02, max_torque=0.1),
                controller=QuaternionPD(0.2, 0.8, target=TARGET), control_period=0.05),
     torques.ConstantBody([0.05, -0.02, 0.1])),
    (Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=MRPFeedback(K=1.0, P=5.0, target=TARGET)),
     lambda t, q, omega: np.array([0.01 * np.sin(t), 0.0, -0.02])),
], ids=["held-pd-torque-program", "mrp-python-torque"])
def test_a_batch_of_spacecraft_through_the_pointers_is_each_members_lone_run(spacecraft, torque, method):
    with _callback.keep_alive():
        kernel = spacecraft.compile(torque, 0.0)
        assert type(_block.block_model(kernel)) is _block.BlockModel  # the batch runs through the pointers
        assert bool(kernel.python_calls) == (not isinstance(torque, torques.TorqueModel))  # the variant tested
    run = dict(t=T, method=method, dt=0.05, torque=torque, wheel_speeds0=WHEELS)
    batch = tumble.simulate(spacecraft, OMEGA, **run)
    for i in range(OMEGA.shape[0]):
        assert_same_run(batch.member(i), tumble.simulate(spacecraft, OMEGA[i], **run))
