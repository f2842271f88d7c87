"""tumble.sweep on real Dask components: a LocalCluster of 2 worker processes, and a ``dask scheduler`` with two
``dask worker`` processes started here on 127.0.0.1; a worker killed mid-sweep, a client killed and resumed;
workers importing tumble from another path, each with an empty cache, given the client's compiled code.

Every result is compared bit for bit with the same sweep run in this process
(``workers=0``), which is computed first: it compiles the kernel (a batch of
rigid bodies under rk4, as elsewhere in the suite) into Numba's on-disk cache,
from which the worker processes load it instead of compiling again.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import compiled, dask_processes, numba_cache_files, record_compiles, stop

import tumble
from tumble.sweeps import Final, Max, Normal, NutationAngle, PointingError, UniformAttitude

# Every test here starts a Dask scheduler and worker processes, each importing tumble (seconds of CPU each).
pytestmark = pytest.mark.slow

distributed = pytest.importorskip("distributed")

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
# 8 chunks of 24 bodies, each 80 000 rk4 steps: about 0.3 s a chunk on one core, long enough for a worker
# or the client to be killed while chunks are in flight
SWEEP = dict(dispersions={"omega0": Normal([0.0, 0.0, 1.0], 0.05), "q0": UniformAttitude()}, samples=192, seed=5,
             chunk=24, t=np.linspace(0.0, 20.0, 21), method="rk4", dt=2.5e-4,
             outcomes={"nutation": Final(NutationAngle([0.0, 0.0, 1.0])), "pointing": Max(PointingError())},
             statistics={"omega_z": tumble.sweeps.Component("omega", 2)})
CHUNKS = 8
SRC = str(Path(tumble.__file__).parents[1])
ENV = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", ""), "NUMBA_NUM_THREADS": "1"}
TESTS = [str(Path(__file__).parent), str(Path(__file__).parents[1])]  # this module's folder; helpers.py's
TIMEOUT = 60  # s: the longest a step of these tests may take before it is counted as hung


@pytest.fixture(scope="module")
def reference():
    """The sweep in this process, without Dask (and the compiled kernel in the on-disk cache)."""
    return tumble.sweep(BODY, workers=0, **SWEEP)


def assert_same(ds, reference):
    assert ds.attrs["tumble_sweep_complete"]
    for name in reference.data_vars:
        np.testing.assert_array_equal(ds[name].values, reference[name].values, err_msg=name)


@pytest.fixture(scope="module")
def local_client(reference):
    # as an earlier Dask cluster leaves this process (its Nanny sets Dask's malloc setting here before spawning)
    saved = os.environ.get("MALLOC_TRIM_THRESHOLD_")
    os.environ["MALLOC_TRIM_THRESHOLD_"] = "65536"
    try:
        cluster = tumble.sweeps.local_cluster(2)
        assert os.environ["MALLOC_TRIM_THRESHOLD_"] == "65536"  # given back
    finally:
        if saved is None:
            del os.environ["MALLOC_TRIM_THRESHOLD_"]
        else:
            os.environ["MALLOC_TRIM_THRESHOLD_"] = saved
    client = distributed.Client(cluster)
    yield client
    client.close(timeout=TIMEOUT)
    cluster.close(timeout=TIMEOUT)




@pytest.fixture(scope="module")
def scheduler_file(reference, tmp_path_factory):
    """``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1, started and stopped here."""
    with dask_processes(tmp_path_factory.mktemp("dask") / "scheduler.json", [("w1", 1), ("w2", 1)], ENV,
                        TIMEOUT) as path:
        yield path


def test_local_cluster_of_two_processes_equals_the_run_in_this_process(local_client, reference):
    assert len(local_client.scheduler_info()["workers"]) == 2
    pids = set(local_client.run(os.getpid).values())
    assert len(pids) == 2 and os.getpid() not in pids
    # glibc's own malloc thresholds: Dask's MALLOC_TRIM_THRESHOLD_=65536 is not set in tumble's workers
    trim = local_client.run(lambda: __import__("os").environ.get("MALLOC_TRIM_THRESHOLD_"))
    assert list(trim.values()) == [None, None]
    done = []
    ds = tumble.sweep(BODY, client=local_client, progress=lambda k, n: done.append((k, n)), **SWEEP)
    assert_same(ds, reference)
    assert ds.attrs["chunks_computed"] == CHUNKS and done == [(k, CHUNKS) for k in range(CHUNKS + 1)]


def test_a_worker_killed_mid_sweep_has_its_chunk_recomputed(local_client, reference, tmp_path):
    pids = list(local_client.run(os.getpid).values())
    killed = []

    def kill_one(done, total):
        if done == 1 and not killed:  # the other worker is running a chunk now
            os.kill(pids[0], signal.SIGKILL)
            killed.append(pids[0])

    ds = tumble.sweep(BODY, client=local_client, progress=kill_one, store=tmp_path / "mc.zarr", **SWEEP)
    assert killed and not _alive(killed[0])
    assert_same(ds, reference)
    local_client.wait_for_workers(2, timeout=TIMEOUT)  # the nanny restarted it: the cluster is whole again


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def test_scheduler_and_worker_processes_equal_the_run_in_this_process(scheduler_file, reference):
    with distributed.Client(scheduler_file=str(scheduler_file), timeout=TIMEOUT) as client:
        assert sorted(w["name"] for w in client.scheduler_info()["workers"].values()) == ["w1", "w2"]
        ds = tumble.sweep(BODY, client=client, **SWEEP)
    assert_same(ds, reference)


@pytest.fixture(scope="module")
def elsewhere(reference, tmp_path_factory):
    """``dask scheduler`` and two ``dask worker`` processes importing tumble from a copy of its sources at
    another path (without their caches), each worker with its own empty ``NUMBA_CACHE_DIR``; yields the
    scheduler's file and the copy's root."""
    root = tmp_path_factory.mktemp("elsewhere")
    shutil.copytree(Path(tumble.__file__).parent, root / "src" / "tumble", ignore=shutil.ignore_patterns("__pycache__"))
    env = {**ENV, "PYTHONPATH": os.pathsep.join([str(root / "src"), *TESTS])}
    workers = [(name, 1, {"NUMBA_CACHE_DIR": str(root / f"cache-{name}")}) for name in ("w1", "w2")]
    with dask_processes(root / "scheduler.json", workers, env, TIMEOUT) as path:
        yield path, root


def test_workers_elsewhere_with_empty_caches_load_the_clients_compiled_code(elsewhere, reference):
    path, root = elsewhere
    with distributed.Client(scheduler_file=str(path), timeout=TIMEOUT) as client:
        assert client.run(numba_cache_files) == {address: [] for address in client.scheduler_info()["workers"]}
        client.run(record_compiles)
        ds = tumble.sweep(BODY, client=client, **SWEEP)
        files = client.run(numba_cache_files)
        compiles = client.run(compiled)
        sources = client.run(lambda: __import__("tumble").__file__)
    assert_same(ds, reference)
    assert all(Path(source).is_relative_to(root) for source in sources.values())
    assert all(any(name.endswith(".nbi") for name in names) for names in files.values()), files
    assert compiles == {address: [] for address in files}  # every kernel of the sweep loaded, none compiled


CLIENT = textwrap.dedent("""
    import sys
    import distributed, numpy as np, tumble
    sys.path[:0] = {tests!r}
    from test_sweep_dask import BODY, SWEEP
    if __name__ == "__main__":
        with distributed.Client(scheduler_file={scheduler!r}) as client:
            tumble.sweep(BODY, client=client, store={store!r}, **SWEEP)
""")


def test_a_client_killed_mid_sweep_resumes_computing_only_the_missing_chunks(scheduler_file, reference, tmp_path):
    store = tmp_path / "mc.zarr"
    script = CLIENT.format(tests=TESTS, scheduler=str(scheduler_file), store=str(store))
    client_process = subprocess.Popen([sys.executable, "-c", script], env=ENV, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + TIMEOUT
        while _done(store) < 2:  # some chunks written, the others still to come
            assert client_process.poll() is None, client_process.stderr.read().decode()
            assert time.monotonic() < deadline, "the client wrote no chunk"
            time.sleep(0.02)
        client_process.send_signal(signal.SIGKILL)
        client_process.wait(timeout=TIMEOUT)
    finally:
        stop(client_process)
        client_process.stderr.close()
    written = _done(store)
    assert 2 <= written < CHUNKS
    with distributed.Client(scheduler_file=str(scheduler_file), timeout=TIMEOUT) as client:
        ds = tumble.sweep(BODY, client=client, store=store, **SWEEP)
    assert ds.attrs["chunks_computed"] == CHUNKS - written
    assert_same(ds, reference)


THREADS = textwrap.dedent("""
    import numba, numpy as np, tumble  # imported by the spawned workers too, before their environment is set

    @numba.njit
    def _full(m, value):
        return np.full(m, value)

    def threads(traj):  # compiled in the worker, after the chunk's run started Numba's threads
        return _full(traj.q.shape[1], numba.get_num_threads())

    if __name__ == "__main__":
        body, dispersions = tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), {"omega0": tumble.sweeps.Normal([0, 0, 1.0], 0.1)}
        with tumble.sweeps.local_cluster(1) as cluster, cluster.get_client() as client:
            ds = tumble.sweep(body, dispersions, samples=4, chunk=2, t=[0.0, 0.01], method="rk4", dt=0.01,
                              client=client, outcomes={"threads": threads})
        print(numba.config.NUMBA_NUM_THREADS, ds.threads.values.tolist())
""")


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="Numba's pool has one thread on one core whatever the setting")
def test_a_local_clusters_tasks_run_numba_on_one_thread_and_compile(reference, tmp_path):
    # a script that imports tumble at the top, as most do: a spawned worker process re-imports it, and with
    # it Numba, before the Nanny sets NUMBA_NUM_THREADS=1; the tasks still run on one thread, and a function
    # compiled in a task after Numba's threads started does not fail on the changed setting
    script = tmp_path / "threads.py"
    script.write_text(THREADS)
    env = {name: value for name, value in ENV.items() if name != "NUMBA_NUM_THREADS"}
    out = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, timeout=4 * TIMEOUT,
                         check=True).stdout.split(maxsplit=1)
    assert int(out[0]) > 1 and out[1].strip() == "[1, 1, 1, 1]"  # a pool of threads; the tasks on one


def _done(store):
    """Chunks marked done in the store (0 while it does not exist)."""
    if not store.exists():
        return 0
    import zarr

    return int(np.sum(zarr.open_group(store, mode="r")["done"][:]))
