"""Batches behind function pointers (:mod:`tumble._block`): one block driver per method for every kind that gives
its block functions, and each member of a batch equal to its lone run (whose path inlines the kind's kernel), bit
for bit.

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

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
OMEGA = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9], [0.1, 0.1, 0.7]])
T = np.linspace(0.0, 3.0, 7)


def flexible():
    return FlexibleBody(INERTIA, [Mode(3.0, 0.02, [0.3, 0.5, 0.2]), Mode(7.0, 0.01, [0.1, -0.4, 0.6])])


def kirchhoff():
    fluid = np.diag([5.0, 8.0, 9.0, 1.0, 2.0, 2.5])
    fluid[0, 4] = fluid[4, 0] = 0.3
    return KirchhoffBody(tumble.RigidBody(INERTIA, mass=20.0), fluid)


def assert_members_are_lone_runs(model, per_member, method, torque=None, shared=None, t=T, dt=0.05, states=None):
    """A batch of ``model`` runs through the pointers, and each of its members is its lone run bit for bit (a lone
    body's path inlines the kind's kernel, as the block did before the pointers; the drivers' arithmetic is the
    same on a state vector and on a lane). ``per_member``: initial states, one row per member; ``shared``: the
    initial states all members share; ``states``: compare only these arrays of the trajectories (``q`` and
    extras), the integrated state, where the host computes the other outputs with NumPy, whose sums over a batch
    and over one body may round differently (a KirchhoffBody's ω = W [K; P]: within 2.2e-16 of its largest value)."""
    shared = shared or {}
    with _callback.keep_alive():
        assert type(_block.block_model(model.compile(torque, 0.0))) is _block.BlockModel
    run = dict(t=t, method=method, dt=dt, torque=torque, **shared)
    batch = tumble.simulate(model, **per_member, **run)
    for i in range(len(next(iter(per_member.values())))):
        member, lone = batch.member(i), tumble.simulate(model, **{k: v[i] for k, v in per_member.items()}, **run)
        if states is None:
            assert_same_run(member, lone)
        for name in states or ():
            a, b = (member.q, lone.q) if name == "q" else (member.extras[name].data, lone.extras[name].data)
            np.testing.assert_array_equal(a, b, err_msg=name)


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
@pytest.mark.parametrize("method", ["rk4", "cf4"])
@pytest.mark.parametrize("model, torque", [
    (flexible(), torques.ConstantBody([0.05, -0.02, 0.1])),
    # a Python torque function: called from the kind's function through tumble._callback (reference counts kept)
    (flexible(), lambda t, q, omega: np.array([0.01 * np.sin(t), 0.0, -0.02])),
    (kirchhoff(), None),  # its own body rate (W [K; P]) under cf4
], ids=["flexible", "flexible-python-torque", "kirchhoff"])
def test_a_batch_through_the_pointers_is_each_members_lone_run(model, torque, method):
    states = ("q", "angular_impulse", "linear_impulse", "position") if isinstance(model, KirchhoffBody) else None
    assert_members_are_lone_runs(model, {"omega0": OMEGA}, method, torque, states=states)


# Within the deformable bodies' splines (0 to 1 s); three members, their rates scaled by 1, 1.01, 1.02.
SCALES = np.array([[1.0], [1.01], [1.02]])
SPLINES = {"t": np.linspace(0.0, 0.5, 5), "dt": 0.01}


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
@pytest.mark.parametrize("method", ["rk4", "cf4"])
@pytest.mark.parametrize("example, torque", [
    ("variable", None),  # the torque-free variant (codes None)
    ("variable", torques.ConstantBody([0.05, -0.02, 0.1])),
    ("human", None),
], ids=["variable", "variable-torque", "human"])
def test_a_batch_of_deformable_bodies_through_the_pointers_is_each_members_lone_run(example, torque, method):
    from tumble import _warmup

    model, state = getattr(_warmup, example)()
    assert_members_are_lone_runs(model, {"omega0": np.asarray(state["omega0"]) * SCALES}, method, torque, **SPLINES)


@pytest.mark.slow  # compiles kinds other than the rigid body's (the fast lane's rule: docs/architecture.md)
def test_a_batch_of_gimbaled_gyros_through_the_pointers_is_each_members_lone_run():
    from tumble import _warmup

    gyro, state = _warmup.gimbaled_gyro()  # a kind without body rates (no cf4)
    assert_members_are_lone_runs(gyro, {"spin": state["spin"] * SCALES}, "rk4", shared={"theta0": state["theta0"]},
                                 **SPLINES)


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
