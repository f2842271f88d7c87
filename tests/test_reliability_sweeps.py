"""Reliability of sweeps (issue 34): no silent wrong result from a sweep.

Each test runs the real thing: sweeps in this process (``workers=0``) and on a
``dask scheduler`` with a ``dask worker`` process started here on 127.0.0.1,
stores on disk interrupted, damaged and resumed, processes killed with SIGKILL.
Every result is compared bit for bit with the same sweep run whole in this
process. docs/reliability.md lists the guarantee each test checks.
"""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import cloudpickle
import numpy as np
import pytest
from helpers import dask_processes, sigint_as_in_a_terminal, stop

import tumble
from tumble import _callback
from tumble.sweeps import Component, CrossingTime, Final, Normal, NutationAngle, StoreMismatchError
from tumble.sweeps.store import writing

distributed = pytest.importorskip("distributed")

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
T = np.linspace(0.0, 2.0, 11)
OUTCOMES = {"nutation": Final(NutationAngle([0.0, 0.0, 1.0])), "omega_z": Final(Component("omega", 2))}
RUN = dict(t=T, method="rk4", dt=0.01, outcomes=OUTCOMES, statistics={"omega_x": Component("omega", 0)})
DISPERSIONS = {"omega0": Normal([0.0, 0.0, 1.0], [0.05, 0.05, 0.1])}
N, CHUNK = 23, 5  # 5 chunks, the last one of 3 samples
SRC = str(Path(tumble.__file__).parents[1])
ENV = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", ""), "NUMBA_NUM_THREADS": "1"}
TIMEOUT = 60  # s: the longest a step of these tests may take before it is counted as hung


def tabulated(scale: float) -> tumble.torques.Tabulated:
    """A body-axes torque ramp (N·m) over the run; ``scale`` changes its values only, not its repr."""
    return tumble.torques.Tabulated([0.0, 2.0], scale * np.array([[0.0, 0.01, 0.1], [0.0, 0.03, 0.3]]))


def assert_same(ds, reference):
    assert ds.attrs["tumble_sweep_complete"]
    for name in reference.data_vars:
        np.testing.assert_array_equal(ds[name].values, reference[name].values, err_msg=name)


def stop_after(n):
    """A progress callback that interrupts the sweep (as Ctrl-C would) once ``n`` chunks are written."""

    def progress(done, total):
        if done >= n:
            raise KeyboardInterrupt

    return progress




@pytest.fixture(scope="module")
def scheduler_file(tmp_path_factory):
    """``dask scheduler`` and one ``dask worker`` process of 2 threads on 127.0.0.1, started and stopped here."""
    with dask_processes(tmp_path_factory.mktemp("dask") / "scheduler.json", [("w1", 2)], ENV, TIMEOUT) as path:
        yield path


# -- 1. two sweeps on one scheduler never share a task ------------------------------------

# 4 chunks of 8 bodies, each 40 000 rk4 steps (about 0.1 s a chunk): the two sweeps' chunks are in flight together
SLOW = dict(dispersions=DISPERSIONS, samples=32, seed=2, chunk=8, t=np.linspace(0.0, 10.0, 11), method="rk4",
            dt=2.5e-4, outcomes=OUTCOMES)


@pytest.mark.slow
def test_two_sweeps_on_one_scheduler_at_once_each_keep_their_own_results(scheduler_file):
    # the two differ only in a tabulated torque's values, which their recorded settings do not show: their
    # tasks once had the same keys, and the second sweep's store silently held the first one's results
    torques = (tabulated(1.0), tabulated(2.0))
    alone = [tumble.sweep(BODY, torque=torque, workers=0, **SLOW) for torque in torques]
    assert alone[0].attrs["tumble_sweep"] == alone[1].attrs["tumble_sweep"]
    assert not np.array_equal(alone[0].omega_z.values, alone[1].omega_z.values)
    together = threading.Barrier(2, timeout=TIMEOUT)
    results: list = [None, None]

    def run(j):
        def submit_together(done, total):
            if done == 0:
                together.wait()  # both sweeps submit their chunks at the same time

        # not the default client: two of them in threads would leave the last one's Dask setting behind
        with distributed.Client(scheduler_file=str(scheduler_file), timeout=TIMEOUT, set_as_default=False) as client:
            results[j] = tumble.sweep(BODY, torque=torques[j], client=client, progress=submit_together, **SLOW)

    threads = [threading.Thread(target=run, args=(j,)) for j in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(4 * TIMEOUT)
    for ds, reference in zip(results, alone, strict=True):
        assert_same(ds, reference)


# -- 2. a store records the whole content of its sweep --------------------------------------


def test_a_sweep_resumed_after_its_torque_table_changed_is_refused_and_unchanged_equals_a_whole_run(tmp_path):
    store = tmp_path / "mc.zarr"
    args = dict(samples=N, seed=1, chunk=CHUNK, **RUN)
    whole = tumble.sweep(BODY, DISPERSIONS, torque=tabulated(1.0), workers=0, **args)
    with pytest.raises(KeyboardInterrupt):
        tumble.sweep(BODY, DISPERSIONS, torque=tabulated(1.0), workers=0, store=store, progress=stop_after(2), **args)
    done = tumble.sweeps.open_sweep(store).done.values.tolist()
    assert done == [True, True, False, False, False]
    with pytest.raises(StoreMismatchError, match=r"^store: .*mc\.zarr was written by another sweep: the settings "
                                                 r"agree but not the content .* delete the store"):
        tumble.sweep(BODY, DISPERSIONS, torque=tabulated(1.5), workers=0, store=store, **args)
    assert tumble.sweeps.open_sweep(store).done.values.tolist() == done  # left alone
    resumed = tumble.sweep(BODY, DISPERSIONS, torque=tabulated(1.0), workers=0, store=store, **args)
    assert resumed.attrs["chunks_computed"] == 3
    assert_same(resumed, whole)


def test_a_store_without_a_content_digest_is_refused_as_unverifiable(tmp_path):
    import zarr

    store = tmp_path / "mc.zarr"
    args = dict(samples=N, seed=1, chunk=CHUNK, store=store, workers=0, **RUN)
    tumble.sweep(BODY, DISPERSIONS, **args)
    del zarr.open_group(store, mode="r+").attrs["tumble_sweep_digest"]  # as an earlier tumble wrote it
    with pytest.raises(StoreMismatchError, match=r"^store: .*mc\.zarr was written by an earlier tumble, which did "
                                                 r"not record the sweep's content"):
        tumble.sweep(BODY, DISPERSIONS, **args)


EXPLORER = (tumble.examples.directory() / "spacecraft" / "explorer1.toml").read_text() + textwrap.dedent("""
    [sweep]
    samples = 4
    [sweep.dispersions]
    "damper.damping" = { uniform = { low = 1e-4, high = 3e-4 } }
    [sweep.outcomes]
    omega_z = { series = "component", name = "omega", index = 2, reduce = "final" }
""")


@pytest.mark.slow  # the plan compiles the spacecraft of the file (~80 CPU s on a cold cache)
def test_a_scenario_whose_undispersed_table_changed_has_another_digest(tmp_path):
    # a dispersed non-state key (the damper's damping) rebuilds the model per sample from the file: the
    # recorded settings name the file and the keys only, the digest holds every table of it (here the
    # damper's sphere inertia, which nothing else records)
    from tumble.scenario.sweep import sweep_arguments
    from tumble.sweeps.plan import make_plan

    path = tmp_path / "explorer1.toml"
    plans = []
    for text in (EXPLORER, EXPLORER.replace("inertia = 3e-4", "inertia = 4e-4")):
        path.write_text(text)
        a = sweep_arguments(tumble.scenario.load(path))
        plans.append(make_plan(a.pop("model"), a.pop("dispersions"), samples=a.pop("samples"), seed=a.pop("seed"),
                               chunk=a.pop("chunk"), t=a.pop("t"), method=a.pop("method"),
                               options={"rtol": 1e-12, "atol": 1e-12}, torque=a.pop("torque"),
                               outcomes=a.pop("outcomes"), series=a.pop("statistics"), fixed={"omega0": a["omega0"]}))
    assert plans[0].settings() == plans[1].settings()
    assert plans[0].digest() != plans[1].digest()


# -- 3. a Python function in a model runs on a Dask worker --------------------------------


def test_a_python_callback_pickled_to_another_process_registers_there_under_its_own_slot():
    torque = tabulated(1.0) + tumble.torques.PythonTorque(lambda t, q, omega: np.array([0.0, 0.0, 0.1 * t]))
    copy = pickle.loads(cloudpickle.dumps(torque))
    original, arrived = torque.terms()[1].callback, copy.terms()[1].callback
    assert arrived.slot != original.slot  # registered again, as a worker process would
    assert _callback._ENTRIES[arrived.slot].function is arrived.function
    # at 0.5 s: a quarter of the ramp from [0, 0.01, 0.1] to [0, 0.03, 0.3], and 0.05 N·m from the function
    np.testing.assert_allclose(copy(0.5, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), [0.0, 0.015, 0.2], rtol=1e-15)


@pytest.mark.slow  # compiles the spacecraft (~35 CPU s on a cold cache)
def test_a_spacecraft_pickled_after_compiling_its_python_law_compiles_it_again_with_its_own_slot():
    # the compiled programs (a cached property) held the client's slot number: they are left out of the pickle
    from tumble.spacecraft import Spacecraft, pyramid_wheels

    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02),
                       controller=lambda t, q, omega, wheel_speeds: -omega)
    compiled = craft._programs  # what a run in this process computes and caches
    copy = pickle.loads(cloudpickle.dumps(craft))
    law, arrived = craft.controller[0], copy.controller[0]
    assert "_programs" not in vars(copy) and arrived.callback.slot != law.callback.slot
    slots = [int(p.params[0]) for p in copy._programs if p.kind == "python_law"]
    assert slots == [arrived.callback.slot] and [p.kind for p in compiled] == [p.kind for p in copy._programs]


@pytest.mark.slow  # a sweep on a Dask worker process, compiling on a cold cache (~6 CPU s)
def test_a_summed_torque_with_a_python_function_sweeps_on_a_worker_process_as_in_this_one(scheduler_file):
    # the function's slot was a number of the client's registry: the worker raised KeyError, or called another
    # function registered there under the same number
    def spin_up(t, q, omega):
        return np.array([0.0, 0.0, 0.05 * t])

    def decoys():  # in the worker: its first callback slots taken by other functions (1 N·m about x)
        import tumble._callback as registry

        for _ in range(64):  # owned by the registry's module: they live as long as the worker
            registry.register(registry, lambda t, q, omega: [1.0, 0.0, 0.0], field="torque",
                              signature="(t, q, omega)", returns="3 numbers")
        return len(registry._ENTRIES)

    torque = tabulated(1.0) + spin_up
    args = dict(dispersions=DISPERSIONS, samples=8, seed=4, chunk=2, torque=torque, **RUN)
    reference = tumble.sweep(BODY, workers=0, **args)
    with distributed.Client(scheduler_file=str(scheduler_file), timeout=TIMEOUT) as client:
        assert all(n >= 64 for n in client.run(decoys).values())
        ds = tumble.sweep(BODY, client=client, **args)
    assert_same(ds, reference)


# -- 4. a lost chunk file is computed again ---------------------------------------------


@pytest.mark.slow  # a sweep on Dask worker processes, each compiling on a cold cache (~8 CPU s)
def test_a_complete_store_that_lost_a_chunk_file_computes_that_chunk_again(tmp_path):
    store = tmp_path / "mc.zarr"
    outcomes = {**OUTCOMES, "never": CrossingTime(Component("omega", 2), above=100.0)}  # NaN in every sample
    args = dict(samples=N, seed=1, chunk=CHUNK, **{**RUN, "outcomes": outcomes}, workers=0)
    whole = tumble.sweep(BODY, DISPERSIONS, store=store, **args)
    assert np.isnan(whole.never.values).all()
    again = tumble.sweep(BODY, DISPERSIONS, store=store, **args)
    assert again.attrs["chunks_computed"] == 0  # chunks of NaN (the fill value) are files too
    os.remove(store / "omega_z" / "c" / "3")  # chunk 3 of an outcome, samples 15 to 19
    damaged = tumble.sweeps.open_sweep(store)
    assert np.isnan(damaged.omega_z.values[15:20]).all() and damaged.done.values.all()  # what resuming once read
    resumed = tumble.sweep(BODY, DISPERSIONS, store=store, **args)
    assert resumed.attrs["chunks_computed"] == 1
    assert_same(resumed, whole.load())


# -- 5. percentiles changed on a complete store ---------------------------------------------


def test_other_percentiles_on_a_complete_store_replace_its_statistics(tmp_path):
    store = tmp_path / "mc.zarr"
    args = dict(samples=N, seed=1, chunk=CHUNK, **RUN, workers=0)
    first = tumble.sweep(BODY, DISPERSIONS, store=store, **args)
    again = tumble.sweep(BODY, DISPERSIONS, store=store, percentiles=[10, 90], **args)
    assert again.attrs["chunks_computed"] == 0 and again.percentile.values.tolist() == [10.0, 90.0]
    np.testing.assert_array_equal(again.omega_z_percentiles.values,
                                  np.percentile(first.omega_z.values, [10, 90]))
    np.testing.assert_array_equal(again.omega_x_percentiles.values,
                                  np.percentile(first.omega_x.values, [10, 90], axis=0))


# -- 7. temporaries of killed runs ------------------------------------------------------------

KILLED = textwrap.dedent("""
    import numpy as np, tumble
    # 2000 bodies x 4001 output times: chunks of 131 bodies, one written at a time
    tumble.sweeps.simulate_to_store(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), np.tile([0.1, 0.0, 1.0], (2000, 1)),
                                    store={store!r}, t=np.linspace(0.0, 40.0, 4001), method="rk4", dt=0.01)
""")


@pytest.mark.slow
def test_a_store_killed_mid_run_leaves_a_temporary_that_the_next_run_removes(tmp_path):
    store = tmp_path / "run.zarr"
    process = subprocess.Popen([sys.executable, "-c", KILLED.format(store=str(store))], env=ENV,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + TIMEOUT
        while not list(tmp_path.glob(".run.zarr.*.tmp/q/c/0/1/0")):  # a chunk after the first written
            assert process.poll() is None, process.stderr.read().decode()
            assert time.monotonic() < deadline, "the run wrote no chunk"
            time.sleep(0.02)
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=TIMEOUT)
    finally:
        stop(process)
        process.stderr.close()
    assert not store.exists() and len(list(tmp_path.glob(".run.zarr.*.tmp"))) == 1
    tumble.sweeps.simulate_to_store(BODY, np.tile([0.1, 0.0, 1.0], (3, 1)), store=store, t=T, method="rk4", dt=0.01)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.zarr"]


def test_a_live_writers_temporary_is_left_alone_and_a_second_writer_refused(tmp_path):
    store = tmp_path / "mc.zarr"
    with writing(store):  # a live writer: holds the lock, its temporary in use
        live = tmp_path / ".mc.zarr.0123abcd.tmp"  # of the pattern of a stale one: the lock is what keeps it
        live.mkdir()
        with pytest.raises(FileExistsError, match=r"mc\.zarr: another process is writing it now"):
            tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=CHUNK, store=store, **RUN, workers=0)
        assert live.is_dir() and not store.exists()


def test_cleaning_a_store_leaves_the_temporaries_of_a_store_whose_name_begins_with_its_name(tmp_path):
    other = tmp_path / ".mc.zarr.x.0123abcd.tmp"  # store "mc.zarr.x", being written by another run
    stale = tmp_path / ".mc.zarr.89abcdef.tmp"  # store "mc.zarr", left by a killed run
    other.mkdir(), stale.mkdir()
    with writing(tmp_path / "mc.zarr"):
        pass
    assert other.is_dir() and not stale.exists()


# -- 5. a [sweep] table the sweep would fail on is refused before any chunk runs ------------------

TABLE = textwrap.dedent("""
    [body]
    inertia = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.5]]
    [initial]
    omega = [0.0, 0.0, 1.0]
    [time]
    stop = 1.0
    step = 0.5
    [solver]
    method = "rk4"
    dt = 0.01
    [sweep]
    samples = 4
    chunk = 2
    [sweep.dispersions]
    "initial.omega" = { normal = { mean = [0.0, 0.0, 1.0], std = [0.02, 0.02, 0.01] } }
""")


@pytest.mark.parametrize("table, message", [
    ('[sweep.outcomes]\ndone = { series = "nutation_angle", reduce = "max" }',
     "sweep.outcomes.done: 'done' is a variable of the store itself"),
    ('[sweep.outcomes]\nsample = { series = "nutation_angle", reduce = "max" }',
     "sweep.outcomes.sample: 'sample' is a variable of the store itself"),
    ('[sweep.outcomes]\na = { series = "nutation_angle", reduce = "max" }\n'
     'a_percentiles = { series = "nutation_angle", reduce = "final" }',
     "sweep.outcomes.a_percentiles: names ending in _percentiles, _count, _mean, _std, _min, _max or _dimN are "
     "the store's statistics"),
    ('[sweep.statistics]\nx_mean = { series = "nutation_angle" }', "sweep.statistics.x_mean: names ending in"),
    ('[sweep.outcomes]\na = { series = "component", name = "wheel_speed", reduce = "max" }',
     "sweep.outcomes.a: component: name: the trajectory has no sampled field 'wheel_speed' (it has energy, "
     "momentum_body, momentum_inertial, omega, q)"),
    ('[sweep.outcomes]\na = { series = "component", name = "omega", index = 3, reduce = "final" }',
     "sweep.outcomes.a: component: index: omega has components of shape (3,): give one index per axis, each in "
     "range, got [3]"),
    ('[sweep.statistics]\na = { series = "component", name = "omega" }',
     "sweep.statistics.a: component: index: omega has components of shape (3,)"),
    ('[sweep.dispersions."body.inertia[0]"]\ngrid = [1.0, 1.1]',
     "sweep.dispersions.body.inertia[0]: a dispersion replaces a whole value, named by its dotted key"),
])
def test_a_sweep_table_that_would_fail_after_its_chunks_is_refused_naming_the_key(tmp_path, table, message):
    from typer.testing import CliRunner

    from tumble.cli import app

    scenario = tmp_path / "bad.toml"
    scenario.write_text(TABLE + table + "\n")
    result = CliRunner().invoke(app, ["sweep", str(scenario), "-o", str(tmp_path / "out.zarr"), "--workers", "0"])
    assert result.exit_code == 2, result.output
    assert f"error: {scenario}: {message}" in result.output.replace("\n", " ")
    assert sorted(os.listdir(tmp_path)) == ["bad.toml"]


def test_outcome_names_of_the_stores_own_variables_are_refused_by_the_function_too():
    for name in ("done", "time", "nutation_count", "w_dim0"):
        with pytest.raises(tumble.ValidationError, match=rf"^outcomes\['{name}'\]: .*; give another name$"):
            tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, t=T, method="rk4", dt=0.01, workers=0,
                         outcomes={name: Final(NutationAngle())})


# -- 6. Ctrl-C during tumble sweep ----------------------------------------------------------------

#: 64 chunks of about 0.1 CPU s each: the client's first write of the store (importing xarray, dask.array and
#: zarr, creating the arrays: 1-3 s) lets the workers finish a few of them, so Ctrl-C after the first written
#: chunk finds most of the sweep still to do (16 chunks of 0.02 s were all done by then)
SLOW_SPINNER = TABLE.replace("stop = 1.0", "stop = 800.0").replace("dt = 0.01", "dt = 0.0005").replace(
    "samples = 4\nchunk = 2", "samples = 128\nchunk = 2") + ('[sweep.outcomes]\n'
                                                         'nutation = { series = "nutation_angle", reduce = "max" }\n')


@pytest.mark.slow  # two sweeps of a 2-worker local cluster, about 7 CPU s of chunks in all
def test_ctrl_c_during_tumble_sweep_is_one_line_and_exit_130_and_the_same_command_resumes(tmp_path):
    # a terminal's Ctrl-C reaches the whole process group: the command and its local cluster's workers
    import zarr  # noqa: F401 - imported before the sweep starts, so that polling the store is quick

    scenario, store = tmp_path / "spinner.toml", tmp_path / "out.zarr"
    scenario.write_text(SLOW_SPINNER)
    command = [sys.executable, "-m", "tumble", "sweep", str(scenario), "-o", str(store), "-q", "--workers", "2"]
    with sigint_as_in_a_terminal():
        process = subprocess.Popen(command, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                   start_new_session=True)
    try:
        deadline = time.monotonic() + 4 * TIMEOUT
        while _done(store) < 1:
            assert process.poll() is None, process.stderr.read()
            assert time.monotonic() < deadline, "the sweep wrote no chunk"
            time.sleep(0.02)
        os.killpg(process.pid, signal.SIGINT)
        _, stderr = process.communicate(timeout=TIMEOUT)
    finally:
        stop(process)
    assert process.returncode == 130
    assert stderr.splitlines() == [f"error: interrupted; the chunks written are kept in {store}: the same command "
                                   "resumes the sweep"]
    written = _done(store)
    assert 1 <= written < 64
    resumed = subprocess.run(command, env=ENV, capture_output=True, text=True, timeout=4 * TIMEOUT)
    assert resumed.returncode == 0, resumed.stderr
    assert f"computed  {64 - written} chunks in this run" in resumed.stdout
    assert _done(store) == 64


def _done(store):
    """Chunks marked done in the store (0 while it does not exist)."""
    if not store.exists():
        return 0
    import zarr

    return int(np.sum(zarr.open_group(store, mode="r")["done"][:]))


# -- 9. the default chunk shares a small sweep between the workers ---------------------------------


@pytest.mark.slow  # a sweep on a Dask worker process, compiling rk4's batch on a cold cache (~12 CPU s there)
def test_a_small_sweeps_default_chunk_gives_every_worker_a_chunk_and_a_resume_keeps_it(scheduler_file, tmp_path):
    store = tmp_path / "mc.zarr"
    args = dict(dispersions=DISPERSIONS, samples=N, seed=1, **RUN)
    whole = tumble.sweep(BODY, workers=0, **args)
    assert whole.attrs["tumble_sweep"]["chunk"] == N  # one worker: one chunk
    with distributed.Client(scheduler_file=str(scheduler_file), timeout=TIMEOUT) as client:
        assert sum(client.nthreads().values()) == 2
        ds = tumble.sweep(BODY, client=client, store=store, **args)
    assert ds.attrs["tumble_sweep"]["chunk"] == 12 and ds.done.size == 2  # ceil(23 / 2): a chunk per thread
    per_sample = [name for name, v in whole.data_vars.items() if v.dims[:1] == ("sample",)]
    assert_same(ds, whole[per_sample])  # the same samples, whatever the chunks (their moments merge otherwise)
    resumed = tumble.sweep(BODY, workers=0, store=store, **args)  # the store's chunk, not one of 23 samples
    assert resumed.attrs["chunks_computed"] == 0 and resumed.attrs["tumble_sweep"]["chunk"] == 12


# -- 8. a sweep too big for this process is refused before it holds anything --------------------------


@pytest.mark.parametrize("store", [None, "mc.zarr"])
def test_a_sweep_whose_index_and_outcomes_outgrow_memory_is_refused_at_once(tmp_path, store):
    # 1e13 samples: the sample index alone is 80 TB
    with pytest.raises(tumble.ValidationError, match=r"^samples: 10000000000000 samples \(the store's sample "
                                                     r"index and the outcomes' percentiles.*\) need \d+\.\d [TP]iB "
                                                     r".*more than half this machine's memory"):
        tumble.sweep(BODY, DISPERSIONS, samples=10**13, seed=1, store=None if store is None else tmp_path / store,
                     **RUN, workers=0)
    assert os.listdir(tmp_path) == []


@pytest.mark.slow  # a sweep on a Dask worker process, which loads or compiles rk4's batch (~4 CPU s there, cold)
def test_a_sweep_of_more_chunks_than_its_window_holds_a_window_of_tasks_at_a_time(scheduler_file):
    # 40 chunks of one sample, a window of 32 (tumble.sweeps.runner.IN_FLIGHT): each completed chunk submits one
    args = dict(dispersions=DISPERSIONS, samples=40, seed=1, chunk=1, **RUN)
    reference = tumble.sweep(BODY, workers=0, **args)
    held = []
    with distributed.Client(scheduler_file=str(scheduler_file), timeout=TIMEOUT) as client:
        def count(done, total):
            held.append(client.run_on_scheduler(lambda dask_scheduler: sum(
                key.startswith("tumble-sweep-") for key in map(str, dask_scheduler.tasks))))

        ds = tumble.sweep(BODY, client=client, progress=count, **args)
    assert_same(ds, reference)
    assert max(held) <= 32 and held[0] == 0 and len(held) == 41



# the plans of three sweeps: a rigid body, a spacecraft rebuilt per sample from its file, a robot arm
DIGESTS = textwrap.dedent("""
    import sys, warnings
    warnings.simplefilter("ignore")
    import tumble
    from tumble.scenario.sweep import sweep_arguments
    from tumble.sweeps.plan import make_plan

    for path in sys.argv[1:]:
        a = sweep_arguments(tumble.scenario.load(path))
        options = {k: a.pop(k) for k in ("dt", "rtol", "atol", "max_steps") if k in a}
        a.pop("percentiles", None)
        plan = make_plan(a.pop("model"), a.pop("dispersions"), samples=a.pop("samples"), seed=a.pop("seed"),
                         chunk=a.pop("chunk"), t=a.pop("t"), method=a.pop("method"), options=options,
                         torque=a.pop("torque"), outcomes=a.pop("outcomes"), series=a.pop("statistics"), fixed=a)
        print(plan.digest())
""")

@pytest.mark.slow
@pytest.mark.parametrize("name, dispersion", [
    ("sweep/spinner.toml", None),
    ("spacecraft/explorer1.toml", '"damper.damping" = { uniform = { low = 1e-4, high = 3e-4 } }'),
    ("robot/planar_2link_torque.toml", '"initial.qd" = { normal = { mean = [0.0, 0.0], std = 0.1 } }'),
])
def test_a_plans_digest_is_the_same_in_another_process(tmp_path, name, dispersion):
    # what a store records must be found again by the process that resumes it (another hash seed, other
    # callback slots): a rigid body, a spacecraft rebuilt per sample from its file, a robot arm
    tumble.examples.copy(tmp_path)
    path = tmp_path / name
    if dispersion is not None:
        path.write_text(path.read_text() + f"\n[sweep]\nsamples = 4\n[sweep.dispersions]\n{dispersion}\n")
    run = [sys.executable, "-c", DIGESTS, str(path)]
    here = subprocess.run(run, env=ENV, capture_output=True, text=True, timeout=4 * TIMEOUT, check=True).stdout
    there = subprocess.run(run, env={**ENV, "PYTHONHASHSEED": "12345"}, capture_output=True, text=True,
                           timeout=4 * TIMEOUT, check=True).stdout
    assert len(here.split()) == 1 and here == there
