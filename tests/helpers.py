"""Helpers shared by the tests."""

import contextlib
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
    ``(name, threads)`` of ``workers``, every server on 127.0.0.1; yields ``path`` once every worker has joined,
    and stops them all after (the workers first: a worker whose scheduler is gone retries it before it exits)."""
    import distributed

    cli = [sys.executable, "-m"]
    commands = [["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                 "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(path)]]
    commands += [["distributed.cli.dask_worker", "--scheduler-file", str(path), "--host", "127.0.0.1", "--nthreads",
                  str(threads), "--nworkers", "1", "--name", name, "--dashboard-address", "127.0.0.1:0"]
                 for name, threads in workers]  # a worker waits for the scheduler's file
    processes = []
    try:
        for command in commands:
            processes.append(subprocess.Popen(cli + command, env=env, stdout=subprocess.DEVNULL,
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
