"""A sweep on every GPU of the machine (``tumble.sweep(..., device="cuda")``): one Dask worker per GPU.

Which GPUs a sweep's workers get is checked for any machine by giving the
count CUDA would see (:func:`tumble.sweeps.runner.visible_gpus`'s ``count``).
The cluster itself runs under Numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``,
read when Numba is imported: in a child process, whose Dask workers inherit
it), which shows one GPU: a real ``LocalCluster`` on 127.0.0.1, its worker
given ``CUDA_VISIBLE_DEVICES``, and a sweep on a cluster of one worker per GPU
against the same sweep in the process, bit for bit (the simulator rounds as
the CPU does, and sample ``i``'s results depend on ``(seed, i)`` alone).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble.sweeps import Component, Final, Max, Normal, NutationAngle, UniformAttitude
from tumble.sweeps.runner import gpu_workers, visible_gpus

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 2.5]))
T = np.array([0.0, 0.02, 0.05])
DT = 0.01


def sweep_arguments():
    """A sweep of 4 rigid bodies with dispersed rates and attitudes, two chunks, a series and outcomes."""
    return dict(dispersions={"omega0": Normal([0.2, 1.0, 0.0], 0.1), "q0": UniformAttitude()}, samples=4, seed=3,
                chunk=2, t=T, method="rk4", dt=DT, statistics={"wy": Component("omega", 1)},
                outcomes={"nutation": Final(NutationAngle([0.0, 1.0, 0.0])), "peak": Max(Component("omega", 0))},
                percentiles=(5.0, 50.0, 95.0))


@pytest.mark.parametrize(("listed", "count", "ids"), [
    (None, 0, []),
    (None, 2, ["0", "1"]),
    ("0,1", 2, ["0", "1"]),
    ("3, 1", 2, ["3", "1"]),  # CUDA's order, not sorted: the process's device 0 is GPU 3
    ("GPU-5b1c6f3e-0d2a-4c1e-9b7f-1a2b3c4d5e6f,2", 2, ["GPU-5b1c6f3e-0d2a-4c1e-9b7f-1a2b3c4d5e6f", "2"]),
    ("2,7", 1, ["2"]),  # CUDA stops at the first entry that names no GPU: 7 here
    ("", 0, []),
])
def test_visible_gpus_are_named_as_cuda_visible_devices_names_them(listed, count, ids):
    environ = {} if listed is None else {"CUDA_VISIBLE_DEVICES": listed}
    assert visible_gpus(environ, count) == ids


def test_a_sweep_takes_one_worker_per_gpu_where_there_are_several():
    assert gpu_workers(None, ["0", "1"]) == ["0", "1"]
    assert gpu_workers(None, ["3"]) == []  # one GPU: in this process
    assert gpu_workers(None, []) == []
    assert gpu_workers(0, ["0", "1"]) == []
    assert gpu_workers(1, ["2", "5"]) == ["2"]
    assert gpu_workers(2, ["2", "5"]) == ["2", "5"]
    with pytest.raises(tumble.ValidationError, match=r"^workers: device='cuda' runs one worker per GPU, and "
                                                     r"numba.cuda finds 2 GPUs here; got workers=3$"):
        gpu_workers(3, ["0", "1"])
    with pytest.raises(tumble.ValidationError, match=r"^workers: device='cuda' runs one worker per GPU, and "
                                                     r"numba.cuda finds 1 GPU here; got workers=2$"):
        gpu_workers(2, ["0"])


def test_a_device_sweep_refuses_more_workers_than_gpus():
    found = len(visible_gpus())  # this machine's GPUs, none without one
    with pytest.raises(tumble.ValidationError, match=rf"^workers: device='cuda' runs one worker per GPU, and "
                                                     rf"numba.cuda finds {found} GPUs? here; "
                                                     rf"got workers={found + 1}$"):
        tumble.sweep(BODY, device="cuda", workers=found + 1, **sweep_arguments())


_CHILD = """
import json
import os
import runpy
import sys

import numpy as np
from distributed import Client

from tumble import ValidationError
from tumble.sweeps import local_cluster, sweep
from tumble.sweeps.runner import visible_gpus

module = runpy.run_path(sys.argv[1])
found = {"unset": visible_gpus(), "listed": visible_gpus({"CUDA_VISIBLE_DEVICES": "3,1"})}
try:
    sweep(module["BODY"], device="cuda", workers=2, **module["sweep_arguments"]())
except ValidationError as error:
    found["refusal"] = str(error)
with local_cluster(gpus=["3", "1"]) as cluster, Client(cluster) as client:
    seen = client.run(lambda dask_worker: [dask_worker.name, os.environ["CUDA_VISIBLE_DEVICES"]])
    found["environments"] = dict(sorted(seen.values()))
here = sweep(module["BODY"], device="cuda", workers=0, **module["sweep_arguments"]())
cluster = sweep(module["BODY"], device="cuda", workers=1, **module["sweep_arguments"]())
found["computed"] = [here.attrs["chunks_computed"], cluster.attrs["chunks_computed"]]
np.savez(sys.argv[2], **{"here/" + k: here[k].values for k in here.data_vars},
         **{"cluster/" + k: cluster[k].values for k in cluster.data_vars})
print(json.dumps(found))
"""


@pytest.mark.slow
def test_a_sweep_on_a_cluster_of_one_worker_per_gpu_equals_the_run_in_this_process(tmp_path):
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    env.pop("CUDA_VISIBLE_DEVICES", None)
    env["PYTHONPATH"] = os.pathsep.join([str(Path(tumble.__file__).parents[1]), env.get("PYTHONPATH", "")])
    run = subprocess.run([sys.executable, "-c", _CHILD, __file__, str(tmp_path / "out.npz")], env=env,
                         check=True, timeout=600, capture_output=True, text=True)
    found = json.loads(run.stdout.splitlines()[-1])
    assert found["unset"] == ["0"]  # the simulator's one GPU
    assert found["listed"] == ["3"]
    assert found["refusal"] == ("workers: device='cuda' runs one worker per GPU, and numba.cuda finds 1 GPU here; "
                                "got workers=2")
    assert found["environments"] == {"cuda-1": "1", "cuda-3": "3"}  # each worker sees its own GPU alone
    assert found["computed"] == [2, 2]
    with np.load(tmp_path / "out.npz") as out:
        names = {key.split("/", 1)[1] for key in out.files}
        assert {"omega0", "q0", "wy", "wy_percentiles", "nutation", "peak_percentiles"} <= names
        assert np.ptp(out["here/wy"][:, -1]) > 1e-3  # the samples differ
        for name in names:
            np.testing.assert_array_equal(out[f"cluster/{name}"], out[f"here/{name}"], err_msg=name)
