"""RK4 on the GPU (tumble.integrate._cuda) against the CPU kernels, without a GPU.

Numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) runs the kernel as Python,
one thread per body. Numba reads that variable when it is imported, so the
simulated runs happen in a child process; the results come back in a .npz.
The kernel is also compiled for a real GPU (sm_90 PTX) where the CUDA
toolkit's NVVM is installed, which the simulator alone would not check.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba.core import config

from helpers import compile_ptx, nvvm_available

import tumble
from tumble import attitude, integrate, torques
from tumble.kernels import rigid as _rigid
from tumble._validate import ValidationError
from tumble.integrate import _cuda

# Simulated threads run the same float64 operations in the same order as the
# compiled CPU RK4 (IEEE arithmetic, no fused multiply-adds on either side):
# the results are compared bit for bit.
# On a real GPU, NVVM fuses a·b + c (one rounding instead of two): over the 22
# steps of these runs the states (of order 1) differ by rounding. Run on an
# H100 (docs/gpu.md) this test passed, and benchmarks/bench_gpu.py measured
# 5.0e-16 over 1e5 bodies and 1000 steps; 1e-12 is the bound promised there.
TOL_GPU = 1e-12

DT = 0.01
# Spans of 0.013, 0.037, 0.0001 and 0.1499 s: 2, 4, 1 and 15 steps of at most DT,
# landing on each output time.
T_OUT = np.array([0.0, 0.013, 0.05, 0.0501, 0.2])
STEPS = [2, 4, 1, 15]

# Every compiled torque model, with samples that the steps straddle.
PROGRAM = (
    torques.ConstantBody([0.1, 0.0, -0.2])
    + torques.ConstantInertial([0.0, 0.3, 0.1])
    + torques.Tabulated([0.0, 0.04, 0.1, 0.15], [[0, 0, 1], [1, 0, 0], [0, 1, 0], [0.5, 0.5, 0]], frame="inertial")
    + torques.Tabulated([0.02, 0.07], [[0.2, 0, 0], [0, -0.1, 0]], interpolation="previous")
    + torques.Gravity(2.0, [0.05, -0.02, 0.3])
)


def _bodies(n, seed):
    """n bodies with distinct moments and rotated principal axes (so the torque programs are rotated too)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        r = attitude.to_matrix(attitude.normalize(rng.standard_normal(4)))
        out.append(tumble.RigidBody(inertia=r @ np.diag(rng.uniform(1.0, 3.0, 3)) @ r.T))
    return out


def _states(n, seed):
    rng = np.random.default_rng(seed)
    return np.concatenate([attitude.normalize(rng.standard_normal((n, 4))), rng.uniform(-2, 2, (n, 3))], axis=1)


# name: (bodies: one shared or one per state, torque model, number of bodies)
CASES = {
    "free, shared body": (_bodies(1, 1), None, 3),
    "free, one body each": (_bodies(4, 2), None, 4),
    "torque, shared body": (_bodies(1, 3), PROGRAM, 3),
    "torque, one body each": (_bodies(4, 4), PROGRAM, 4),
}

# Run in the child process with the simulator on: solve_cuda for every case in the .npz.
_CHILD = """
import sys
import numpy as np
from tumble.integrate import _cuda
from tumble.kernels.rigid import RigidModel
assert _cuda.cuda_available()
cases = np.load(sys.argv[1])
out = {}
for i in range(int(cases["n"])):
    codes = cases[f"codes{i}"] if f"codes{i}" in cases else None
    model = RigidModel(cases[f"coefficients{i}"], cases[f"params{i}"], codes, np.ones((1, 3)))
    out[f"out{i}"], n_steps = _cuda.solve_cuda(model, cases[f"y0_{i}"], cases["t"], float(cases["dt"]))
    out[f"stats{i}"] = [n_steps, 0, 4 * n_steps]
np.savez(sys.argv[2], **out)
"""


def _run_simulated(models, y0s, tmp):
    """solve_cuda of each (RigidModel, y0) under Numba's CUDA simulator, in a fresh Python."""
    arrays = {"n": len(models), "t": T_OUT, "dt": DT}
    for i, (m, y0) in enumerate(zip(models, y0s)):
        arrays.update({f"coefficients{i}": m.coefficients, f"params{i}": m.params, f"y0_{i}": y0})
        if m.codes is not None:
            arrays[f"codes{i}"] = m.codes
    np.savez(tmp / "in.npz", **arrays)
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(tumble.__file__).parents[1]), env.get("PYTHONPATH", "")])
    subprocess.run([sys.executable, "-c", _CHILD, str(tmp / "in.npz"), str(tmp / "out.npz")],
                   env=env, check=True, timeout=300)
    with np.load(tmp / "out.npz") as out:
        return [(out[f"out{i}"], dict(zip(("n_steps", "n_rejected", "n_rhs"), out[f"stats{i}"].tolist())))
                for i in range(len(models))]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """name -> (y0, CPU states and statistics, simulated GPU states and statistics), for every case."""
    models, y0s = [], []
    for seed, (bodies, torque, n) in enumerate(CASES.values()):
        models.append(_rigid.build(bodies, torque))
        y0s.append(_states(n, seed))
    simulated = _run_simulated(models, y0s, tmp_path_factory.mktemp("cuda"))
    out = {}
    for name, m, y0, gpu in zip(CASES, models, y0s, simulated):
        cpu = integrate.solve(m, y0, T_OUT, method="rk4", dt=DT)
        out[name] = (y0, (cpu.states, cpu.statistics()), gpu)
    return out


@pytest.mark.parametrize("name", CASES)
def test_simulated_gpu_equals_cpu(runs, name):
    y0, (cpu, _), (gpu, _) = runs[name]
    assert gpu.shape == (T_OUT.size, y0.shape[0], 7)
    np.testing.assert_array_equal(gpu[0], y0)
    np.testing.assert_array_equal(gpu, cpu)


def test_bodies_differ(runs):
    # guards the comparison above: the bodies, torques and states of a case give distinct paths
    free = runs["free, one body each"][1][0]
    torqued = runs["torque, one body each"][1][0]
    assert np.all(np.abs(np.diff(free[-1], axis=0)).max(axis=1) > 1e-2)
    assert np.abs(torqued[-1] - free[-1]).max() > 1e-3


@pytest.mark.parametrize("name", CASES)
def test_step_counts(runs, name):
    # hand-counted steps per body; the CPU reports the same statistics
    y0, (_, cpu), (_, gpu) = runs[name]
    n_steps = y0.shape[0] * sum(STEPS)
    assert gpu == {"n_steps": n_steps, "n_rejected": 0, "n_rhs": 4 * n_steps}
    assert gpu == cpu


def test_python_torque_refused():
    model = _rigid.build(_bodies(1, 0), torques.ConstantBody([0, 0, 1]) + torques.PythonTorque(lambda t, q, w: w))
    with pytest.raises(ValidationError, match="torque: a Python function cannot run on the GPU"):
        _cuda.solve_cuda(model, _states(2, 0), T_OUT, DT)


@pytest.mark.skipif(_cuda.cuda_available(), reason="a GPU (or the simulator) is present")
def test_no_gpu_is_a_clear_error():
    model = _rigid.build(_bodies(1, 0), None)
    with pytest.raises(ValidationError, match="device: 'cuda' needs an NVIDIA GPU"):
        _cuda.solve_cuda(model, _states(2, 0), T_OUT, DT)


@pytest.mark.skipif(not nvvm_available(), reason="no NVVM (CUDA toolkit) to compile with")
@pytest.mark.parametrize("torque", [False, True])
def test_compiles_for_a_gpu(monkeypatch, torque):
    """The kernel types and compiles for sm_90, keeping each body's state in registers (no local memory)."""
    from numba import float64, int64, types

    codes = int64[::1] if torque else types.Tuple(())
    signature = (float64[:, ::1], float64[:, ::1], codes, float64[:, ::1], float64[::1], int64[::1], float64[::1],
                 float64[:, :, ::1])
    ptx = compile_ptx(monkeypatch, _cuda._rk4_kernel, signature)
    assert ptx.count(".entry") == 1
    # The kernel keeps every state in registers. The one local array allowed is
    # libdevice's Payne–Hanek argument reduction for sin/cos of huge angles
    # (the gravity-gradient torque's orbit), a 40-byte scratch of that function.
    functions = re.split(r"\n(?=\.(?:visible \.)?(?:entry|func))", ptx)
    with_local = [re.search(r"([\w$]+)\($", f.splitlines()[0].rstrip()).group(1) for f in functions if ".local" in f]
    assert set(with_local) <= {"__internal_trig_reduction_slowpathd"}, with_local
    assert "fma.rn.f64" in ptx  # NVVM's default contraction, as docs/gpu.md says


@pytest.mark.skipif(config.ENABLE_CUDASIM or not _cuda.cuda_available(), reason="no GPU")
def test_gpu_equals_cpu():
    model = _rigid.build(_bodies(4, 4), PROGRAM)
    y0 = _states(4, 0)
    cpu = integrate.solve(model, y0, T_OUT, method="rk4", dt=DT).states
    gpu, _ = _cuda.solve_cuda(model, y0, T_OUT, DT)
    np.testing.assert_allclose(gpu, cpu, rtol=0, atol=TOL_GPU)


@pytest.mark.skipif(config.ENABLE_CUDASIM or not _cuda.cuda_available(), reason="no GPU")
def test_simulate_device_cuda_equals_cpu_on_a_gpu():
    # The front door on a real GPU: rotated bodies, one each, body axes in and out, every compiled torque.
    bodies, y0 = _bodies(4, 5), _states(4, 1)
    run = {device: tumble.simulate(bodies, y0[:, 4:], q0=y0[:, :4], t=T_OUT, method="rk4", dt=DT, torque=PROGRAM,
                                   device=device) for device in ("cpu", "cuda")}
    np.testing.assert_allclose(run["cuda"].q, run["cpu"].q, rtol=0, atol=TOL_GPU)
    np.testing.assert_allclose(run["cuda"].omega, run["cpu"].omega, rtol=0, atol=TOL_GPU)
    assert np.abs(run["cpu"].omega[-1] - y0[:, 4:]).max() > 1e-2   # the bodies moved


def test_simulate_refuses_bad_device_settings():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    with pytest.raises(tumble.ValidationError, match="device"):
        tumble.simulate(body, [0.1, 1.0, 0.1], t=[0.0, 1.0], method="rk4", dt=0.1, device="tpu")
    with pytest.raises(tumble.ValidationError, match="device: 'cuda' runs the methods 'rk4', 'cf4'; got "
                                                     "method='dop853'"):
        tumble.simulate(body, [0.1, 1.0, 0.1], t=[0.0, 1.0], device="cuda")


def test_simulate_device_cuda_equals_cpu_under_the_simulator(tmp_path):
    # End to end through simulate(): body axes in and out, a torque, a batch of 3.
    script = (
        "import numpy as np, tumble\n"
        "body = tumble.RigidBody(np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]]))\n"
        "w = np.array([[0.3, 1.0, -0.2], [1.0, 0.1, 0.5], [0.0, 0.2, 2.0]])\n"
        "tr = tumble.simulate(body, w, t=[0.0, 0.05, 0.12], method='rk4', dt=0.02, device='cuda',\n"
        "                     torque=tumble.torques.ConstantInertial([0.0, 0.1, 0.0]))\n"
        f"np.savez({str(tmp_path / 'gpu.npz')!r}, q=tr.q, omega=tr.omega)\n"
    )
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1"}
    subprocess.run([sys.executable, "-c", script], check=True, env=env, timeout=600)
    gpu = np.load(tmp_path / "gpu.npz")
    body = tumble.RigidBody(np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]]))
    w = np.array([[0.3, 1.0, -0.2], [1.0, 0.1, 0.5], [0.0, 0.2, 2.0]])
    cpu = tumble.simulate(body, w, t=[0.0, 0.05, 0.12], method="rk4", dt=0.02,
                          torque=tumble.torques.ConstantInertial([0.0, 0.1, 0.0]))
    assert np.array_equal(gpu["q"], cpu.q) and np.array_equal(gpu["omega"], cpu.omega)  # bitwise (simulator)
