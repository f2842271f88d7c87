"""Helpers shared by the tests."""

import contextlib
import signal
import subprocess
import sys
import time

import numpy as np

from tumble.integrate import METHODS


def read_by(method: str, **options) -> dict:
    """The solver ``options`` that ``method`` reads, with ``method`` itself (``simulate`` refuses the others)."""
    return {"method": method, **{k: v for k, v in options.items() if k in METHODS[method].options}}


def assert_same_run(traj, reference):
    """Every sampled array of the two trajectories is the same, bit for bit."""
    np.testing.assert_array_equal(traj.t, reference.t)
    for name in ("q", "omega", "inertia"):
        a, b = getattr(traj, name), getattr(reference, name)
        assert (a is None) == (b is None), name
        if a is not None:
            np.testing.assert_array_equal(a, b, err_msg=name)
    assert traj.extras.keys() == reference.extras.keys() and traj.totals.keys() == reference.totals.keys()
    for name in traj.extras:
        np.testing.assert_array_equal(traj.extras[name].data, reference.extras[name].data, err_msg=name)
    for name in traj.totals:
        np.testing.assert_array_equal(traj.totals[name], reference.totals[name], err_msg=name)
    assert traj.method == reference.method and traj.model == reference.model


@contextlib.contextmanager
def sigint_as_in_a_terminal():
    """Processes started inside take Ctrl-C as a terminal's foreground command does (Python's KeyboardInterrupt),
    even where this process was started with SIGINT ignored (a shell's ``&`` without job control, ``nohup``): an
    ignored signal stays ignored across ``exec`` and Python then leaves it so, while a handled one is reset to
    the default. This process's handler comes back after."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def stop(*processes):
    """End processes a test module started: SIGTERM to all, then SIGKILL to any not exited within 5 s."""
    for process in processes:
        if process.poll() is None:
            process.terminate()
    for process in processes:
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=20)


def assert_one_line_error(result, message, code=2):
    """A CLI result (typer's ``CliRunner``): exit ``code`` (2: bad input), nothing on stdout, one ``error:`` line
    holding ``message``, no traceback."""
    assert result.exit_code == code, (result.exit_code, result.stderr, result.exception)
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], result.stderr
    assert "Traceback" not in result.stderr


@contextlib.contextmanager
def dask_processes(path, workers, env, timeout):
    """A ``dask scheduler`` process writing its address to ``path`` and one ``dask worker`` process per entry
    ``(name, threads)`` or ``(name, threads, environment)`` of ``workers`` (``env`` updated with the worker's own
    ``environment``), every server on 127.0.0.1; yields ``path`` once every worker has joined, and stops them
    all after (the workers first: a worker whose scheduler is gone retries it before it exits)."""
    import distributed

    cli = [sys.executable, "-m"]
    commands = [["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                 "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(path)]]
    commands += [["distributed.cli.dask_worker", "--scheduler-file", str(path), "--host", "127.0.0.1", "--nthreads",
                  str(worker[1]), "--nworkers", "1", "--name", worker[0], "--dashboard-address", "127.0.0.1:0"]
                 for worker in workers]  # a worker waits for the scheduler's file
    environments = [env] + [{**env, **(worker[2] if len(worker) > 2 else {})} for worker in workers]
    processes = []
    try:
        for command, environment in zip(commands, environments):
            processes.append(subprocess.Popen(cli + command, env=environment, stdout=subprocess.DEVNULL,
                                              stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + timeout
        while not path.exists():
            assert time.monotonic() < deadline, "the scheduler did not start"
            time.sleep(0.1)
        with distributed.Client(scheduler_file=str(path), timeout=timeout) as client:
            client.wait_for_workers(len(workers), timeout=timeout)
        yield path
    finally:
        stop(*processes[1:])
        stop(*processes[:1])


_RECORDERS: list = []  # the compile recorder of this process, once record_compiles has run


def record_compiles() -> None:
    """From now on, record Numba's compiles in this process (a Dask worker's, through ``client.run``)."""
    from numba.core import event

    if not _RECORDERS:
        _RECORDERS.append(event.RecordingListener())
        event.register("numba:compile", _RECORDERS[0])


def compiled() -> list[str]:
    """The functions Numba compiled in this process since :func:`record_compiles` (``module.qualname``)."""
    function = lambda ev: ev.data["dispatcher"].py_func  # noqa: E731
    return [f"{function(ev).__module__}.{function(ev).__qualname__}" for _, ev in _RECORDERS[0].buffer
            if ev.is_start]


def numba_cache_files() -> list[str]:
    """The names of Numba's cache files (index, data) under this process's ``NUMBA_CACHE_DIR``."""
    from pathlib import Path

    from numba.core import config

    return sorted(path.name for path in Path(config.CACHE_DIR).rglob("*.nb[ic]"))


def nvvm_available():
    """Whether NVIDIA's NVVM (a CUDA toolkit) is here to compile kernels to PTX (never under the simulator)."""
    from numba.core import config

    if config.ENABLE_CUDASIM:
        return False
    from numba.cuda.cudadrv import nvvm

    return nvvm.is_available()


def compile_ptx(monkeypatch, function, signature):
    """``function`` (a kernel or its Python function) compiled to PTX for sm_90: numba.cuda
    compiles the @njit callees for the current device, so without one its compute capability is named."""
    from types import SimpleNamespace

    import pytest
    from numba import cuda
    from numba.cuda import dispatcher

    if not hasattr(dispatcher, "get_current_device"):
        pytest.skip("this numba.cuda does not look up the device where these tests expect")
    monkeypatch.setattr(dispatcher, "get_current_device", lambda: SimpleNamespace(compute_capability=(9, 0)))
    ptx, _ = cuda.compile_ptx(getattr(function, "py_func", function), signature, cc=(9, 0))
    return ptx
