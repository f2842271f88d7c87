"""A block of spacecraft through function pointers (``tumble._block``) is the inlined block, bit for bit.

The spacecraft registers two sets of block functions, as its kernel type has two variants (``python_calls``): one
compiled without reference counts, and one with them, for a Python control law or torque function (called from
the kind's function through ``tumble._callback``). Each compiles the spacecraft's assembled right-hand side and
discrete updates on a block once for every method (~45 CPU s cold), and the reference here, the kernel inlined
into ``run_block``, compiles them again: slow.
"""

import numpy as np
import pytest

from tumble import _block, _callback, torques
from tumble.integrate import METHODS, _fixed
from tumble.simulate import _initial_values
from tumble.spacecraft import MRPFeedback, QuaternionPD, Spacecraft, pyramid_wheels

pytestmark = pytest.mark.slow

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
TARGET = [np.cos(0.2), 0.0, np.sin(0.2), 0.0]
OMEGA = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9], [0.1, 0.1, 0.7]])
T = np.linspace(0.0, 3.0, 7)


def block_path(kernel, method, y0):
    """The path (outputs × bodies × state) of the block ``y0`` through ``run_block`` of ``method`` with
    ``kernel`` as given (the spacecraft's own kernel, inlined, or its BlockModel)."""
    driver = METHODS[method].driver
    y = np.array(y0)
    out = np.empty((T.shape[0], *y.shape))
    m, h = driver.plan(T, {"dt": 0.05, "max_steps": 10**6})
    _fixed.run_block(driver.scheme, kernel, 0, y, T, m, h, out, np.zeros((y.shape[0], 5)))
    return out


@pytest.mark.parametrize("spacecraft, torque", [
    (Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02, max_torque=0.1),
                controller=QuaternionPD(0.2, 0.8, target=TARGET), control_period=0.05),
     torques.ConstantBody([0.05, -0.02, 0.1])),
    (Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=MRPFeedback(K=1.0, P=5.0, target=TARGET)),
     lambda t, q, omega: np.array([0.01 * np.sin(t), 0.0, -0.02])),
], ids=["held-pd-torque-program", "mrp-python-torque"])
def test_a_block_of_spacecraft_through_the_pointers_is_the_inlined_block(spacecraft, torque):
    with _callback.keep_alive():
        kernel = spacecraft.compile(torque, 0.0)
        values, _ = _initial_values(spacecraft, {"omega0": OMEGA, "wheel_speeds0": [10.0, -5.0, 3.0, 0.0]})
        y0 = spacecraft.initial_states(kernel, values, 0.0)
        pointers = _block.block_model(kernel)
        assert type(pointers) is _block.BlockModel
        assert bool(kernel.python_calls) == (not isinstance(torque, torques.TorqueModel))  # the variant tested
        np.testing.assert_array_equal(block_path(pointers, "rk4", y0), block_path(kernel, "rk4", y0))
