"""Rigid bodies set up on the GPU and their results kept there (tumble._rigid_cuda), without a GPU.

The set-up's per-body functions are plain Python until compiled (``register_jitable``), so the first tests run
them here against the CPU's set-up (LAPACK's ``eigh``, :func:`tumble._inertia.principal_axes`). The front door
(``simulate(..., device="cuda", output=...)``) runs under Numba's CUDA simulator in a child process
(``NUMBA_ENABLE_CUDASIM=1`` is read when Numba is imported), one thread per body, and is compared with the CPU.

Tolerances: eigenvectors are defined up to sign and, for equal moments, up to a rotation in their plane, and
Jacobi's rounding is not LAPACK's. So the set-up is compared through what does not depend on that choice: the
tensor rebuilt from the moments and axes, ``R diag(I) Rᵀ``, within 8 ε of the largest entry (each of the two
decompositions is backward stable to a few ε), the moments within 8 ε of the largest, and the axes themselves
(canonical signs) within 1e-14 where the moments are apart. The motion in body axes does not depend on the
principal axes chosen: over the few RK4 steps of these runs the states of order 1 agree within 1e-14.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from helpers import compile_ptx, nvvm_available

import tumble
from tumble import attitude
from tumble._inertia import principal_axes

pytest.importorskip("numba.cuda")
from tumble._rigid_cuda import BROKEN, THIN, principal_axes_of_one  # noqa: E402

EPS = np.finfo(np.float64).eps
T = np.array([0.0, 0.03, 0.05])  # 3 and 2 steps of DT
DT = 0.01


def _rotated(moments, seed):
    """Tensors R diag(moments) Rᵀ (N, 3, 3) in random body axes."""
    rng = np.random.default_rng(seed)
    r = attitude.to_matrix(attitude.normalize(rng.standard_normal((len(moments), 4))))
    return r @ (np.asarray(moments)[..., None] * np.eye(3)) @ np.swapaxes(r, 1, 2)


def _device_set_up(tensor):
    """``principal_axes_of_one`` run as plain Python: (status, moments, axes)."""
    moments, axes = np.empty(3), np.empty((3, 3))
    status = principal_axes_of_one(np.asarray(tensor, dtype=np.float64), np.empty((3, 3)), moments, axes)
    return status, moments, axes


SEPARATE = _rotated(np.random.default_rng(7).uniform(1.0, 3.0, (20, 3)), 1)
DEGENERATE = _rotated([[1.0, 2.0, 2.0], [2.0, 2.0, 3.0], [1.5, 1.5, 1.5], [1e-3, 1.0, 1.0]], 2)


@pytest.mark.parametrize("tensor", list(SEPARATE) + list(DEGENERATE))
def test_principal_axes_rebuild_the_cpu_tensor(tensor):
    status, moments, axes = _device_set_up(tensor)
    symmetric, cpu_moments, _ = principal_axes(tensor)
    assert status == 0
    scale = np.abs(symmetric).max()
    np.testing.assert_allclose(axes @ np.diag(moments) @ axes.T, symmetric, rtol=0, atol=8 * EPS * scale)
    np.testing.assert_allclose(moments, cpu_moments, rtol=0, atol=8 * EPS * cpu_moments[2])
    np.testing.assert_allclose(axes.T @ axes, np.eye(3), rtol=0, atol=8 * EPS)
    assert np.linalg.det(axes) > 0


@pytest.mark.parametrize("tensor", list(SEPARATE))
def test_principal_axes_equal_the_cpus_where_the_moments_are_apart(tensor):
    _, _, axes = _device_set_up(tensor)
    np.testing.assert_allclose(axes, principal_axes(tensor)[2], rtol=0, atol=1e-14)


def test_equal_moments_are_merged_as_on_the_cpu():
    for tensor in DEGENERATE:
        _, moments, _ = _device_set_up(tensor)
        cpu = principal_axes(tensor)[1]
        assert np.array_equal(moments[1:] == moments[:-1], cpu[1:] == cpu[:-1])  # the same groups merged


@pytest.mark.parametrize(("tensor", "status"), [
    (np.diag([1.0, 2.0, 3.0]), 0),
    (np.array([[1.0, 1e-9, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]), BROKEN),  # not symmetric
    (np.diag([1.0, 2.0, 4.0]), BROKEN),                                        # triangle inequality
    (np.diag([0.0, 2.0, 2.0]), BROKEN),                                        # not positive definite
    (np.diag([np.nan, 2.0, 2.0]), BROKEN),                                     # not finite
    (np.diag([1e151, 2e151, 2e151]), BROKEN),                                  # entries too large
    (np.diag([1e-10, 1.0, 1.0]), THIN),                                        # a line: warned, run
])
def test_the_cpus_rules_are_checked(tensor, status):
    assert _device_set_up(tensor)[0] == status
    if status == BROKEN:
        with pytest.raises(tumble.ValidationError, match="^inertia: "):
            principal_axes(tensor)  # the CPU agrees: on the GPU's path it raises this message


def test_output_device_is_refused_where_it_cannot_be():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    with pytest.raises(tumble.ValidationError, match=r"^output: must be 'host', or 'device' with device='cuda'; "
                                                     r"got output='device' with device='cpu'$"):
        tumble.simulate(body, [0.1, 1.0, 0.1], t=T, method="rk4", dt=DT, output="device")
    with pytest.raises(tumble.ValidationError, match=r"^output: must be 'host', or 'device'"):
        tumble.simulate(body, [0.1, 1.0, 0.1], t=T, method="rk4", dt=DT, device="cuda", output="gpu")
    # a model whose attitude is not its state's: tests/integrate/test_cuda_models.py


# The simulated runs, in a child process: name -> arrays into one .npz.
_CHILD = """
import sys
import numpy as np
import tumble
from tumble import torques
cases = np.load(sys.argv[1])
inertia, omega0, q0, t, dt = (cases[k] for k in ("inertia", "omega0", "q0", "t", "dt"))
THIN = np.stack([np.diag([1e-10, 1.0, 1.0])] * 2)
out = {}
run = tumble.simulate(inertia, omega0, q0=q0, t=t, method="rk4", dt=float(dt), device="cuda", output="device")
out["on_device"] = run.on_device and hasattr(run.q, "copy_to_host") and not isinstance(run.q, np.ndarray)
host = run.to_host()
out["q"], out["omega"], out["inertia"] = host.q, host.omega, host.inertia
out["asarray_q"] = np.asarray(run.q)
out["n_steps"] = run.info["n_steps"]
copied = tumble.simulate(inertia, omega0, q0=q0, t=t, method="rk4", dt=float(dt), device="cuda")
out["copied_q"], out["copied_omega"] = copied.q, copied.omega
torque = torques.ConstantBody([0.1, -0.2, 0.05])
pushed = tumble.simulate(inertia, omega0, t=t, method="cf4", dt=float(dt), torque=torque, device="cuda")
out["torque_q"], out["torque_omega"] = pushed.q, pushed.omega
body = tumble.RigidBody(inertia[0])
one = tumble.simulate(body, omega0[0], t=t, method="cf4", dt=float(dt), device="cuda", output="device").to_host()
out["body_q"], out["body_omega"] = one.q, one.omega
import warnings
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    tumble.simulate(THIN, omega0[:2], t=t, method="rk4", dt=float(dt), device="cuda")
out["thin_warning"] = [str(w.message) for w in caught if type(w.message).__name__ == "RigidityWarning"]
bad = inertia.copy()
bad[1, 0, 1] += 1e-6
try:
    tumble.simulate(bad, omega0, t=t, method="rk4", dt=float(dt), device="cuda")
except tumble.ValidationError as error:
    out["refusal"] = str(error)
np.savez(sys.argv[2], **out)
"""


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("cuda_rigid")
    rng = np.random.default_rng(3)
    cases = {"inertia": _rotated(rng.uniform(1.0, 3.0, (3, 3)), 4), "omega0": rng.uniform(-2.0, 2.0, (3, 3)),
             "q0": attitude.normalize(rng.standard_normal((3, 4))), "t": T, "dt": DT}
    np.savez(tmp / "in.npz", **cases)
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(tumble.__file__).parents[1]), env.get("PYTHONPATH", "")])
    subprocess.run([sys.executable, "-c", _CHILD, str(tmp / "in.npz"), str(tmp / "out.npz")], env=env, check=True,
                   timeout=900)
    with np.load(tmp / "out.npz") as out:
        return cases, {key: out[key] for key in out.files}


@pytest.mark.slow
def test_results_stay_on_the_device_and_equal_the_cpus(simulated):
    cases, gpu = simulated
    cpu = tumble.simulate(cases["inertia"], cases["omega0"], q0=cases["q0"], t=T, method="rk4", dt=DT)
    assert gpu["on_device"]
    np.testing.assert_array_equal(gpu["inertia"], cpu.inertia)  # symmetrised by the same arithmetic
    np.testing.assert_allclose(gpu["q"], cpu.q, rtol=0, atol=1e-14)  # principal axes by Jacobi, not LAPACK
    np.testing.assert_allclose(gpu["omega"], cpu.omega, rtol=0, atol=1e-14)
    assert np.abs(cpu.omega[-1] - cpu.omega[0]).max() > 1e-2  # the bodies turned: the comparison sees it
    assert int(gpu["n_steps"]) == cpu.info["n_steps"] == 3 * 5
    np.testing.assert_array_equal(gpu["asarray_q"], gpu["q"])  # np.asarray copies back the same numbers
    np.testing.assert_array_equal(gpu["copied_q"], gpu["q"])  # output="host": the same run, copied back
    np.testing.assert_array_equal(gpu["copied_omega"], gpu["omega"])


@pytest.mark.slow
def test_a_torque_program_on_bodies_set_up_on_the_device(simulated):
    cases, gpu = simulated
    from tumble import torques

    cpu = tumble.simulate(cases["inertia"], cases["omega0"], t=T, method="cf4", dt=DT,
                          torque=torques.ConstantBody([0.1, -0.2, 0.05]))
    np.testing.assert_allclose(gpu["torque_q"], cpu.q, rtol=0, atol=1e-14)
    np.testing.assert_allclose(gpu["torque_omega"], cpu.omega, rtol=0, atol=1e-14)


@pytest.mark.slow
def test_a_body_set_up_on_the_host_converts_on_the_device_bit_for_bit(simulated):
    cases, gpu = simulated
    cpu = tumble.simulate(tumble.RigidBody(cases["inertia"][0]), cases["omega0"][0], t=T, method="cf4", dt=DT)
    np.testing.assert_array_equal(gpu["body_q"], cpu.q)  # the CPU's set-up, the conversions' own arithmetic
    np.testing.assert_array_equal(gpu["body_omega"], cpu.omega)


@pytest.mark.slow
def test_a_thin_body_set_up_on_the_device_is_warned_as_on_the_cpu(simulated):
    cases, gpu = simulated
    with pytest.warns(tumble.limits.RigidityWarning) as cpu:
        tumble.simulate(np.stack([np.diag([1e-10, 1.0, 1.0])] * 2), cases["omega0"][:2], t=T, method="rk4", dt=DT)
    assert list(gpu["thin_warning"]) == [str(w.message) for w in cpu]
    assert "practically a line" in gpu["thin_warning"][0]


@pytest.mark.slow
def test_a_broken_tensor_is_refused_with_the_cpus_message(simulated):
    cases, gpu = simulated
    bad = cases["inertia"].copy()
    bad[1, 0, 1] += 1e-6
    with pytest.raises(tumble.ValidationError) as cpu:
        tumble.simulate(bad, cases["omega0"], t=T, method="rk4", dt=DT)
    assert str(gpu["refusal"]) == str(cpu.value)
    assert str(cpu.value).startswith("inertia[1]: must be symmetric")


@pytest.mark.skipif(not nvvm_available(), reason="no NVVM (CUDA toolkit) to compile with")
@pytest.mark.parametrize("name", ["_principal_axes_kernel", "_coefficients_kernel", "_to_principal_kernel",
                                  "_to_body_kernel"])
def test_set_up_kernels_compile_for_a_gpu(monkeypatch, name):
    """What the simulator cannot see: each kernel types and compiles for sm_90, calling no Python and
    allocating nothing (no ``malloc``: its 3×3 scratch is per-thread local memory)."""
    from numba import float64, int8

    from tumble import _rigid_cuda

    a2, a3 = float64[:, ::1], float64[:, :, ::1]
    signatures = {"_principal_axes_kernel": (a3, a3, a2, a3, a2, a2, int8[::1]), "_coefficients_kernel": (a2, a2),
                  "_to_principal_kernel": (a2, a2, a2, a3, a2), "_to_body_kernel": (a3, a2, a3, a3, a3)}
    ptx = compile_ptx(monkeypatch, getattr(_rigid_cuda, name), signatures[name])
    assert ptx.count(".entry") == 1
    assert "malloc" not in ptx
