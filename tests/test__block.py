"""Batches behind function pointers (:mod:`tumble._block`): one block driver per method for every kind that gives
its block functions, and the results of the inlined path, bit for bit.

The first test also checks the Numba internals the module relies on (``_get_jit_address``,
``_get_wrapper_address``, the fields of a first-class function): it runs kinds through the drivers.
"""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from helpers import assert_same_run

import tumble
from tumble import _block, _callback, torques
from tumble.flexible import FlexibleBody, Mode
from tumble.fluid import KirchhoffBody
from tumble.integrate import _fixed

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
OMEGA = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9], [0.1, 0.1, 0.7]])
T = np.linspace(0.0, 3.0, 7)


def flexible():
    return FlexibleBody(INERTIA, [Mode(3.0, 0.02, [0.3, 0.5, 0.2]), Mode(7.0, 0.01, [0.1, -0.4, 0.6])])


def kirchhoff():
    fluid = np.diag([5.0, 8.0, 9.0, 1.0, 2.0, 2.5])
    fluid[0, 4] = fluid[4, 0] = 0.3
    return KirchhoffBody(tumble.RigidBody(INERTIA, mass=20.0), fluid)


def block_path(kernel, method, y0, t=T, dt=0.05):
    """The path (outputs × bodies × state) of one block of ``y0`` (bodies × state) through ``_fixed.run_block``
    of ``method`` with ``kernel`` as it is given (a kind's own kernel: its overloads inlined into the driver)."""
    from tumble.integrate import METHODS

    driver = METHODS[method].driver
    y = np.array(y0)
    out = np.empty((t.shape[0], *y.shape))
    m, h = driver.plan(t, {"dt": dt, "max_steps": 10**6})
    _fixed.run_block(driver.scheme, kernel, 0, y, t, m, h, out, np.zeros((y.shape[0], 5)))
    return out


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
@pytest.mark.parametrize("method", ["rk4", "cf4"])
@pytest.mark.parametrize("model, torque", [
    (flexible(), torques.ConstantBody([0.05, -0.02, 0.1])),
    # a Python torque function: called from the kind's function through tumble._callback (reference counts kept)
    (flexible(), lambda t, q, omega: np.array([0.01 * np.sin(t), 0.0, -0.02])),
    (kirchhoff(), None),  # its own body rate (W [K; P]) under cf4
], ids=["flexible", "flexible-python-torque", "kirchhoff"])
def test_a_block_through_the_pointers_is_the_inlined_block_bit_for_bit(model, torque, method):
    from tumble.simulate import _initial_values

    with _callback.keep_alive():
        kernel = model.compile(torque, 0.0)
        values, _ = _initial_values(model, {"omega0": OMEGA})
        y0 = model.initial_states(kernel, values, 0.0)
        pointers = _block.block_model(kernel)
        assert type(pointers) is _block.BlockModel
        np.testing.assert_array_equal(block_path(pointers, method, y0), block_path(kernel, method, y0))


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
@pytest.mark.parametrize("method", ["rk4", "cf4"])
@pytest.mark.parametrize("example, torque", [
    ("variable", None),  # the torque-free variant (codes None)
    ("variable", torques.ConstantBody([0.05, -0.02, 0.1])),
    ("human", None),
], ids=["variable", "variable-torque", "human"])
def test_a_block_of_deformable_bodies_through_the_pointers_is_the_inlined_block(example, torque, method):
    assert_warmup_example_block(example, torque, method)


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
def test_a_block_of_gimbaled_gyros_through_the_pointers_is_the_inlined_block():
    assert_warmup_example_block("gimbaled_gyro", None, "rk4")  # a kind without body rates (no cf4)


def assert_warmup_example_block(example, torque, method):
    """A block of three of ``tumble warmup``'s example of a kind (its states 4…6 scaled by 1, 1.01, 1.02)
    through the pointers and inlined: equal bit for bit over 0.5 s (within the deformable bodies' splines)."""
    from tumble import _warmup
    from tumble.simulate import _initial_values

    model, state = getattr(_warmup, example)()
    kernel = model.compile(torque, 0.0)
    values, _ = _initial_values(model, state)
    y0 = np.tile(model.initial_states(kernel, values, 0.0)[0], (3, 1))
    y0[:, 4:7] *= np.array([[1.0], [1.01], [1.02]])
    pointers = _block.block_model(kernel)
    assert type(pointers) is _block.BlockModel
    t = np.linspace(0.0, 0.5, 5)
    np.testing.assert_array_equal(block_path(pointers, method, y0, t, 0.01), block_path(kernel, method, y0, t, 0.01))


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
def test_a_batch_of_two_blocks_runs_the_parallel_driver_through_the_pointers():
    # 65 bodies: two blocks, run_batch (prange over the blocks); a FlexibleBody's block rounds as its lone body
    model = flexible()
    omega = np.array([0.3, 1.0, -0.4]) * (1.0 + 0.01 * np.arange(65))[:, None]
    batch = tumble.simulate(model, omega, t=T, method="rk4", dt=0.05)
    for i in (0, 63, 64):
        assert_same_run(batch.member(i), tumble.simulate(model, omega[i], t=T, method="rk4", dt=0.05))


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
def test_pack_and_unpack_give_the_kernel_back():
    from tumble.kernels import flexible as kernels

    kernel = flexible().compile(torques.ConstantBody([0.05, -0.02, 0.1]), 0.0)
    again = kernels.unpack(*kernels.pack(kernel))
    for name, value in kernel._asdict().items():
        np.testing.assert_array_equal(getattr(again, name), value, err_msg=name)
        assert getattr(again, name).shape == value.shape, name


def test_a_kind_without_block_functions_keeps_its_own_kernel():
    # the fused rigid-body kernels stay specialised
    kernel = tumble.as_model(tumble.RigidBody(INERTIA)).compile(None, 0.0)
    assert _block.block_model(kernel) is kernel


# In a new process, so that every dispatcher starts without signatures (a signature loaded from the disk cache is
# counted as one compiled: either way the process holds code for that type).
COUNT = textwrap.dedent("""
    import json
    import numpy as np
    import tumble
    from tumble import _block
    from tumble.integrate import _fixed
    from tumble.flexible import FlexibleBody, Mode
    from tumble.fluid import KirchhoffBody
    from tumble.slosh import Pendulum, SloshBody

    I = np.diag([10.0, 12.0, 8.0])
    OMEGA = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9], [0.1, 0.1, 0.7]])
    kinds = {
        "flexible": (FlexibleBody(I, [Mode(3.0, 0.02, [0.3, 0.5, 0.2])]), {}),
        "slosh": (SloshBody(tumble.RigidBody(I, mass=10.0), Pendulum(mass=2.0, length=0.5, hinge=[0.3, -0.2, 0.4])),
                  {"direction0": np.tile([0.0, 0.0, -1.0], (3, 1))}),
        "kirchhoff": (KirchhoffBody(tumble.RigidBody(I, mass=20.0), np.diag([5.0, 8.0, 9.0, 1.0, 2.0, 2.5])), {}),
    }
    counts = []
    for method, kind in [("rk4", "flexible"), ("rk4", "slosh"), ("rk4", "kirchhoff"), ("cf4", "flexible"),
                         ("cf4", "slosh")]:
        model, state = kinds[kind]
        tumble.simulate(model, OMEGA, t=[0.0, 0.1], method=method, dt=0.05, **state)
        counts.append({"drivers": len(_fixed.run_block.signatures),
                       "functions": {f.py_func.__qualname__ if f.py_func.__module__ == "tumble._block"
                                     else f.py_func.__module__ + "." + f.py_func.__qualname__: len(f.signatures)
                                     for f in _block._COMPILED.values()}})
    print(json.dumps(counts))
""")


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
def test_a_second_kind_compiles_its_functions_and_no_driver_and_a_second_method_no_function():
    done = subprocess.run([sys.executable, "-c", COUNT], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    counts = json.loads(done.stdout.strip().splitlines()[-1])
    # rk4: one block driver for the three kinds; cf4: one more, for the two kinds
    assert [c["drivers"] for c in counts] == [1, 1, 1, 2, 2]
    # each kind compiled its own functions, once, with its first batch; cf4 compiled none of them again
    assert counts[0]["functions"] == {"tumble.kernels.flexible.block_rhs": 1, "quaternion_project": 1,
                                      "rate_at_4": 1}
    assert counts[1]["functions"] == {**counts[0]["functions"], "tumble.kernels.slosh.block_rhs": 1,
                                      "tumble.kernels.slosh.block_project": 1}
    assert counts[2]["functions"] == {**counts[1]["functions"], "tumble.kernels.fluid.block_rhs": 1,
                                      "tumble.kernels.fluid.block_body_rate": 1}
    assert counts[4]["functions"] == counts[3]["functions"] == counts[2]["functions"]
