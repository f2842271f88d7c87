"""A sweep on the GPU (``tumble.sweep(..., device="cuda")``) and its reductions (tumble.sweeps.device), without a GPU.

Under Numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``, read when Numba is imported: in a child process) the
kernels run as Python, one thread each, with the CPU's rounding. The percentiles are compared with NumPy's bit
for bit: the device only sorts and gathers, the host interpolates with NumPy's arithmetic. The moments are sums
in another order than NumPy's pairwise ones (blocks of samples summed in order, merged by Chan et al.'s update),
so the mean and standard deviation agree to rounding: within 4 ε relative here (sums of 40 numbers of one
sign and magnitude; each order's error is at most (n − 1) ε of the sum and in practice a few ε); the minimum and
maximum are exact.
"""

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble.sweeps import (Component, CrossingTime, Final, Inertia, Max, Normal, NutationAngle, PointingError,
                           SettlingTime, sweep)

from helpers import compile_ptx, nvvm_available

EPS = np.finfo(np.float64).eps
P = (0.0, 1.0, 5.0, 33.3, 50.0, 95.0, 99.0, 100.0)
T = np.array([0.0, 0.02, 0.05])
DT = 0.01


def roll_rate_squared(traj):
    """A Python outcome (evaluated on the host, from the chunk's results copied back): ω_x² at the end, rad²/s²."""
    return traj.omega[-1, :, 0] ** 2


def _sweep_arguments():
    """A sweep of 5 rigid bodies with dispersed inertia and rates, two chunks, series and outcomes: built-ins
    (evaluated on the GPU) and a Python function (on the host)."""
    return dict(dispersions={"inertia": Inertia([1.0, 2.0, 2.4], [0.05, 0.05, 0.05], angle=0.3),
                             "omega0": Normal([0.2, 1.0, 0.0], 0.1)},
                samples=5, seed=11, chunk=3, t=T, method="rk4", dt=DT,
                statistics={"wy": Component("omega", 1), "nutation": NutationAngle([0.0, 1.0, 0.2])},
                outcomes={"pointing": Final(PointingError()), "peak": Max(Component("omega", 0)),
                          "roll": roll_rate_squared},
                percentiles=P, workers=0)


def spacecraft():
    """A spacecraft with four wheels in a pyramid and MRP feedback to a target attitude: the kind of the issue's
    sweep of 10⁶ spacecraft."""
    from tumble.spacecraft import MRPFeedback, Spacecraft, pyramid_wheels

    return Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02),
                      controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))


def spacecraft_sweeps():
    """name -> the arguments of a sweep of 4 spacecraft (dispersed rates and wheel speeds, two chunks): with the
    built-ins that read ``q`` and ``omega`` alone (evaluated on the GPU), and with one more that reads the
    system's energy (wheels included: made on the host, from the chunk's states copied back)."""
    on_the_gpu = dict(dispersions={"omega0": Normal([0.05, -0.02, 0.03], 0.02),
                                   "wheel_speeds0": Normal([10.0, -5.0, 3.0, 0.0], 5.0)},
                      samples=4, seed=3, chunk=2, t=T, method="rk4", dt=DT,
                      statistics={"qw": Component("q", 0), "pointing_error": PointingError(TARGET)},
                      outcomes={"pointing": Final(PointingError(TARGET)), "peak": Max(Component("omega", 2)),
                                "settled": SettlingTime(PointingError(TARGET), below=0.2)},
                      percentiles=P, workers=0)
    energy = {**on_the_gpu, "outcomes": {**on_the_gpu["outcomes"], "energy": Final(Component("energy"))}}
    return {"q and omega": on_the_gpu, "and the energy": energy}


# The built-ins evaluated on a chunk's results on the GPU (tumble.sweeps.device), by name.
TARGET = (np.cos(0.15), 0.0, np.sin(0.15), 0.0)
SERIES = {
    "pointing": PointingError(TARGET),
    "nutation": NutationAngle([0.2, 0.1, 1.0]),
    "wy": Component("omega", 1),
    "qz": Component("q", -1),
    "Lz": Component("momentum_body", 2),
    "energy": Component("energy"),
}
OUTCOMES = {
    "final pointing": Final(PointingError(TARGET)),
    "final energy": Final(Component("energy")),
    "peak nutation after 0.2 s": Max(NutationAngle([0.2, 0.1, 1.0]), after=0.2),
    "peak wx": Max(Component("omega", 0)),
    "settling of wz": SettlingTime(Component("omega", 2), below=0.3),
    "crossing of the pointing error": CrossingTime(PointingError(TARGET), above=0.4),
}
T_RUN = np.linspace(0.0, 0.5, 11)
OMEGA0 = np.array([[0.2, 1.0, 0.0], [0.01, 0.02, 0.0], [-0.5, 0.3, 0.8], [0.0, 0.0, 0.1], [1.5, -0.2, 0.4],
                   [0.3, 0.3, 0.3]])  # rad/s, body axes: some cross and settle, some never
Q0 = np.array([[1.0, 0.0, 0.0, 0.0]] * 3 + [[np.cos(0.5), np.sin(0.5), 0.0, 0.0]] + [[1.0, 0.0, 0.0, 0.0]] * 2)
TENSORS = np.array([[[1.0, 0.1, -0.05], [0.1, 2.0, 0.02], [-0.05, 0.02, 2.4]], np.diag([1.0, 2.0, 2.5]),
                    [[1.5, -0.2, 0.1], [-0.2, 1.2, 0.0], [0.1, 0.0, 2.0]], np.diag([2.0, 2.0, 1.0]),
                    [[1.1, 0.0, 0.3], [0.0, 1.9, 0.0], [0.3, 0.0, 2.2]], np.diag([3.0, 2.0, 1.5])])  # kg·m²


def evaluated_on_the_device():
    """name -> (device value, host value) of every built-in series and outcome of two runs left on the GPU (one
    inertia per sample, and one body for all), each also evaluated on the host from the results copied back."""
    from tumble.sweeps import device

    out = {}
    for bodies, model in (("each", TENSORS), ("shared", tumble.RigidBody(TENSORS[0]))):
        traj = tumble.simulate(model, OMEGA0, q0=Q0, t=T_RUN, method="rk4", dt=DT, device="cuda", output="device")
        assert traj.on_device
        host = traj.to_host()
        for name, f in SERIES.items():
            out[f"{bodies}: {name}"] = (device.series(f, traj).copy_to_host(), f(host))
        for name, f in OUTCOMES.items():
            out[f"{bodies}: {name}"] = (device.outcome(f, traj), f(host))
    return out


_CHILD = """
import os
import sys
import numpy as np
import runpy
from tumble.sweeps import device, sweep
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[1]))))  # tests/: its helpers
module = runpy.run_path(sys.argv[1])
tables = np.load(sys.argv[2])
device.BLOCK = 16  # several blocks of samples, merged
out = {}
for name in ("table", "with_nan"):
    values = tables[name]
    out[name + "/percentiles"] = device.percentiles(values, module["P"])
    out[name + "/nanpercentiles"] = device.percentiles(values, module["P"], ignore_nan=True)
    out[name + "/moments"] = np.array(device.moments(values))
from tumble.trajectory import Trajectory
to_host = Trajectory.to_host
copies = []  # the chunks' results copied to the host: counted, then copied as ever
Trajectory.to_host = lambda traj: (copies.append(traj.on_device), to_host(traj))[1]
ds = sweep(module["tumble"].RigidBody(np.diag([1.0, 2.0, 2.5])), device="cuda", **module["_sweep_arguments"]())
Trajectory.to_host = to_host
out["sweep host copies"] = np.array(copies)
for case, arguments in module["spacecraft_sweeps"]().items():
    craft_copies = []
    Trajectory.to_host = lambda traj: (craft_copies.append(traj.on_device), to_host(traj))[1]
    crafts = sweep(module["spacecraft"](), device="cuda", **arguments)
    Trajectory.to_host = to_host
    out[f"{case} host copies"] = np.array(craft_copies, dtype=bool)
    for variable in crafts.data_vars:
        out[f"{case}/{variable}"] = crafts[variable].values
for name in ds.data_vars:
    out["sweep/" + name] = ds[name].values
for name, (on_gpu, on_host) in module["evaluated_on_the_device"]().items():
    out["evaluated/" + name] = np.stack([on_gpu, on_host])
np.savez(sys.argv[3], **out)
"""


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sweep_device")
    rng = np.random.default_rng(5)
    table = rng.uniform(1.0, 2.0, (40, 3))
    table[7, 0] = table[3, 0]  # a tie
    with_nan = table.copy()
    with_nan[[2, 9, 30], 1] = np.nan
    with_nan[:, 2] = np.nan
    tables = {"table": table, "with_nan": with_nan}
    np.savez(tmp / "tables.npz", **tables)
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(tumble.__file__).parents[1]), env.get("PYTHONPATH", "")])
    subprocess.run([sys.executable, "-c", _CHILD, __file__, str(tmp / "tables.npz"), str(tmp / "out.npz")], env=env,
                   check=True, timeout=900)
    with np.load(tmp / "out.npz") as out:
        return tables, {key: out[key] for key in out.files}


@pytest.mark.slow
@pytest.mark.parametrize("name", ["table", "with_nan"])
def test_percentiles_on_the_device_equal_numpys_bit_for_bit(simulated, name):
    tables, gpu = simulated
    with warnings.catch_warnings():  # a column of NaN only: NumPy warns, and gives NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        nan_percentiles = np.nanpercentile(tables[name], P, axis=0)
    np.testing.assert_array_equal(gpu[f"{name}/percentiles"], np.percentile(tables[name], P, axis=0))
    np.testing.assert_array_equal(gpu[f"{name}/nanpercentiles"], nan_percentiles)
    if name == "with_nan":  # a NaN makes the column's percentiles NaN; ignored, the others' are numbers
        assert np.isnan(gpu[f"{name}/percentiles"][:, 1:]).all()
        assert np.isfinite(gpu[f"{name}/nanpercentiles"][:, :2]).all()


@pytest.mark.slow
def test_moments_on_the_device_equal_numpys_to_rounding(simulated):
    tables, gpu = simulated
    values = tables["table"]
    count, mean, m2, low, high = gpu["table/moments"]
    np.testing.assert_array_equal(count, [40.0] * 3)
    np.testing.assert_allclose(mean, values.mean(axis=0), rtol=4 * EPS, atol=0)
    np.testing.assert_allclose(np.sqrt(m2 / count), values.std(axis=0), rtol=4 * EPS, atol=0)
    np.testing.assert_array_equal(low, values.min(axis=0))
    np.testing.assert_array_equal(high, values.max(axis=0))
    _, mean, _, low, high = gpu["with_nan/moments"]  # NaN propagates, as NumPy's min and max say
    assert np.isnan(mean[1:]).all() and np.isnan(low[1:]).all() and np.isnan(high[1:]).all()
    assert np.isfinite([mean[0], low[0], high[0]]).all()


@pytest.mark.slow
def test_the_sweep_on_the_device_writes_the_cpus_store(simulated):
    _, gpu = simulated
    cpu = sweep(tumble.RigidBody(np.diag([1.0, 2.0, 2.5])), **_sweep_arguments())
    assert {key.removeprefix("sweep/") for key in gpu if key.startswith("sweep/")} == set(cpu.data_vars)
    for name in ("inertia", "omega0", "done"):  # the inputs: the same draws
        np.testing.assert_array_equal(gpu[f"sweep/{name}"], cpu[name].values)
    # the outcomes: each sample's run, its principal axes found by Jacobi on the device (tests/integrate/test_cuda_rigid.py)
    for name in ("wy", "nutation", "pointing", "peak", "roll", "wy_mean", "wy_min", "wy_max"):
        np.testing.assert_allclose(gpu[f"sweep/{name}"], cpu[name].values, rtol=0, atol=1e-14)
    np.testing.assert_allclose(gpu["sweep/wy_std"], cpu["wy_std"].values, rtol=0, atol=1e-14)
    assert np.ptp(cpu["wy"].values[:, -1]) > 1e-3  # the samples differ
    # the chunks' results stayed on the GPU, but for one copy per chunk (of 3 and 2 samples) for the Python outcome
    assert gpu["sweep host copies"].tolist() == [True, True]
    # the percentiles are those of the stored values, bit for bit
    np.testing.assert_array_equal(gpu["sweep/wy_percentiles"], np.percentile(gpu["sweep/wy"], P, axis=0))
    np.testing.assert_array_equal(gpu["sweep/pointing_percentiles"], np.nanpercentile(gpu["sweep/pointing"], P))
    np.testing.assert_array_equal(gpu["sweep/pointing_count"], cpu["pointing_count"].values)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(spacecraft_sweeps()))
def test_a_spacecraft_sweep_on_the_device_writes_the_cpus_store(simulated, name):
    # q and ω stay on the GPU (the kernel's body rate: a slice of the state); the outcomes that read them are
    # evaluated there, bit for bit the host's; what reads the system's energy copies the chunk back, once
    _, gpu = simulated
    cpu = sweep(spacecraft(), **spacecraft_sweeps()[name])
    assert {key.removeprefix(f"{name}/") for key in gpu if key.startswith(f"{name}/")} == set(cpu.data_vars)
    for variable in cpu.data_vars:
        if variable.endswith(("_mean", "_std")):  # summed on the device in another order (the moments' test):
            scale = np.abs(cpu[variable.rsplit("_", 1)[0]].values).max()  # to rounding of the values summed
            np.testing.assert_allclose(gpu[f"{name}/{variable}"], cpu[variable].values, rtol=0, atol=4 * EPS * scale)
        else:
            np.testing.assert_array_equal(gpu[f"{name}/{variable}"], cpu[variable].values, err_msg=variable)
    assert np.ptp(cpu["pointing"].values) > 1e-4 and np.ptp(cpu["peak"].values) > 1e-4  # the samples differ
    # the chunks (of 2 samples) are copied to the host only for the energy, a total made there
    assert gpu[f"{name} host copies"].tolist() == ([] if name == "q and omega" else [True, True])


# What reads the angular momentum L = I ω sums its three terms in another order than NumPy's einsum, which the host
# uses (tumble.dynamics.angular_momentum): a few units in the last place of L, and as many of ε in the nutation angle.
SUMS_OF_I_OMEGA = {"nutation", "Lz", "peak nutation after 0.2 s"}


@pytest.mark.slow
@pytest.mark.parametrize("bodies", ["each", "shared"])
@pytest.mark.parametrize("name", [*SERIES, *OUTCOMES])
def test_built_in_outcomes_on_the_device_equal_the_hosts(simulated, bodies, name):
    # the same arithmetic on the chunk's device arrays as on the host's copy: under the simulator, which rounds
    # as the CPU does, the same bits, but for the order of the sums of I ω (a GPU fuses multiply-adds: docs/gpu.md)
    _, gpu = simulated
    on_gpu, on_host = gpu[f"evaluated/{bodies}: {name}"]
    assert on_gpu.shape[-1] == len(OMEGA0)
    if name in SUMS_OF_I_OMEGA:
        np.testing.assert_allclose(on_gpu, on_host, rtol=0, atol=4 * EPS * np.abs(on_host).max())
    else:
        np.testing.assert_array_equal(on_gpu, on_host)


@pytest.mark.slow
def test_the_outcomes_on_the_device_see_each_case(simulated):
    # the runs reach each branch of the reductions: samples that cross at once, later and never, that settle at
    # once, later and never; a maximum after 0.2 s below the whole run's
    _, gpu = simulated
    crossing, settling = (np.concatenate([gpu[f"evaluated/{bodies}: {name}"][0] for bodies in ("each", "shared")])
                          for name in ("crossing of the pointing error", "settling of wz"))
    for times in (crossing, settling):
        assert np.isnan(times).any() and (times == 0.0).any() and ((times > 0.0) & (times <= T_RUN[-1])).any()
    nutation = gpu["evaluated/each: nutation"][0]
    assert (gpu["evaluated/each: peak nutation after 0.2 s"][0] < nutation.max(axis=0)).any()


def test_a_device_sweep_refuses_what_it_cannot_run():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 2.5]))
    arguments = dict(dispersions={"omega0": Normal([0.2, 1.0, 0.0], 0.1)}, samples=2, t=T)
    with pytest.raises(tumble.ValidationError, match=r"^device: 'cuda' runs the methods 'rk4', 'cf4'; "
                                                     r"got method='dop853'$"):
        sweep(body, device="cuda", **arguments)
    with pytest.raises(tumble.ValidationError, match=r"^device: must be 'cpu' or 'cuda', got 'tpu'$"):
        sweep(body, device="tpu", method="rk4", dt=DT, **arguments)



@pytest.mark.skipif(not nvvm_available(), reason="no NVVM (CUDA toolkit) to compile with")
@pytest.mark.parametrize("name", ["block_moments_kernel", "bitonic_kernel", "count_kernel", "gather_kernel",
                                  "pointing_kernel", "nutation_kernel", "momentum_kernel", "energy_kernel",
                                  "component_kernel", "max_kernel", "settling_kernel", "crossing_kernel"])
def test_reduction_kernels_compile_for_a_gpu(monkeypatch, name):
    """What the simulator cannot see: each reduction kernel types and compiles for sm_90, allocating nothing."""
    from numba import float64, int64

    from tumble.integrate import _cuda_reductions as device

    a1, a2, a3 = float64[::1], float64[:, ::1], float64[:, :, ::1]
    signatures = {"block_moments_kernel": (a2, int64, a3), "bitonic_kernel": (a2, int64, int64),
                  "count_kernel": (a2, int64[::1]),
                  "gather_kernel": (a2, int64[:, ::1], int64[:, ::1], a3),
                  "pointing_kernel": (a3, float64, float64, float64, float64, a2),
                  "nutation_kernel": (a3, a3, float64, float64, float64, a2), "momentum_kernel": (a3, a3, int64, a2),
                  "energy_kernel": (a3, a3, a2), "component_kernel": (a3, int64, a2), "max_kernel": (a2, int64, a1),
                  "settling_kernel": (a2, a1, float64, a1), "crossing_kernel": (a2, a1, float64, a1)}
    ptx = compile_ptx(monkeypatch, getattr(device, name), signatures[name])
    assert ptx.count(".entry") == 1
    assert "malloc" not in ptx
