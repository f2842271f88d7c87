"""Never a silent wait (tumble/_compiling.py): a compile that holds a call up past the delay is announced in
one line, on stderr or as a log record of the "tumble" logger, and can be silenced; a cached run says
nothing."""

import logging
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from numba import njit
from numba.extending import intrinsic

import tumble
from tumble import _compiling

SRC = str(Path(tumble.__file__).resolve().parents[1])


def _slow_to_type():
    """A new intrinsic ``x -> x`` whose typing takes 0.3 s: a compile that outlasts the tests' 0.05 s delay
    whatever the load (a new one each time: Numba keeps an intrinsic's typing once done)."""

    @intrinsic
    def slow(typingctx, x):
        time.sleep(0.3)

        def codegen(context, builder, signature, args):
            return args[0]

        return x(x), codegen

    return slow


def _compile_two_laws() -> None:
    """Compile two new functions of the test module, each slower than the delay."""
    first, second = _slow_to_type(), _slow_to_type()
    njit(lambda x: first(x) + 1.0)(1.0)
    njit(lambda x: second(x) * 2.0)(1.0)


def test_a_long_compile_is_announced_once_on_stderr_naming_the_function_and_the_purpose(capsys, monkeypatch):
    monkeypatch.delenv("TUMBLE_QUIET", raising=False)
    with _compiling.notice("the rk4 path of RigidBody", delay=0.05):
        _compile_two_laws()
    lines = capsys.readouterr().err.splitlines()
    assert lines == ["tumble: compiling test_compiling._compile_two_laws.<locals>.<lambda> for the rk4 path of "
                     "RigidBody (a compiled function of yours, first called in this process)..."]


def test_a_compile_shorter_than_the_delay_says_nothing(capsys, monkeypatch):
    monkeypatch.delenv("TUMBLE_QUIET", raising=False)
    with _compiling.notice("the rk4 path of RigidBody", delay=60.0):
        njit(lambda x: x + 1.0)(1.0)
    assert capsys.readouterr().err == ""


def test_the_notice_is_silenced_by_tumble_quiet_or_the_loggers_level(capsys, caplog, monkeypatch):
    monkeypatch.setenv("TUMBLE_QUIET", "1")
    caplog.set_level(logging.INFO, logger="tumble")  # quiet even where logging would pass the record
    with _compiling.notice("a run", delay=0.05):
        _compile_two_laws()
    monkeypatch.delenv("TUMBLE_QUIET")
    caplog.set_level(logging.WARNING, logger="tumble")
    with _compiling.notice("a run", delay=0.05):
        _compile_two_laws()
    assert capsys.readouterr().err == "" and not caplog.records


def test_the_notice_is_a_log_record_where_logging_enables_it(capsys, caplog, monkeypatch):
    monkeypatch.delenv("TUMBLE_QUIET", raising=False)
    caplog.set_level(logging.INFO, logger="tumble")
    with _compiling.notice("a run", delay=0.05):
        _compile_two_laws()
    assert [(r.name, r.levelno) for r in caplog.records] == [("tumble", logging.INFO)]
    assert caplog.records[0].getMessage().startswith(
        "compiling test_compiling._compile_two_laws.<locals>.<lambda> for a run (")
    assert capsys.readouterr().err == ""


RUN = """
import numpy as np, tumble
tumble.simulate(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), [0.1, 1.0, 0.1], t=[0.0, 0.5], method="rk4", dt=0.01)
"""


@pytest.mark.slow
def test_simulate_announces_a_first_compile_and_a_cached_run_is_silent(tmp_path):
    env = {**os.environ, "PYTHONPATH": SRC, "NUMBA_CACHE_DIR": str(tmp_path)}
    env.pop("TUMBLE_QUIET", None)
    first, cached = (subprocess.run([sys.executable, "-c", RUN], env=env, capture_output=True, text=True,
                                    timeout=600, check=True) for _ in range(2))
    assert re.fullmatch(r"tumble: compiling the rk4 path of RigidBody \(tumble\.[\w.]+: first use of this model "
                        r"kind and method here; cached for later runs\)\.\.\.\n", first.stderr), first.stderr
    assert cached.stderr == ""


# -- import tumble stays light -------------------------------------------------------------------------------

# what `import tumble` must not load: the writers, the figures, the viewer's bundle, the sweeps' scheduler, the
# scenario files' validation, the CLI, the file lock (each loaded by the feature that uses it)
HEAVY = ("dask", "distributed", "matplotlib", "plotly", "xarray", "zarr", "h5netcdf", "h5py", "pandas", "pydantic",
         "typer", "rich", "psutil", "filelock", "defusedxml")


def test_import_tumble_imports_nothing_heavy_and_compiles_nothing(tmp_path):
    probe = ("import sys, numba.core.event as event\n"
             "class Count(event.Listener):\n"
             "    compiles = 0\n"
             "    def on_start(self, e): Count.compiles += 1\n"
             "    def on_end(self, e): pass\n"
             "event.register('numba:compile', Count())\n"
             "import tumble\n"
             f"print(sorted({{m.partition('.')[0] for m in sys.modules}} & set({HEAVY!r})), Count.compiles)\n")
    env = {**os.environ, "PYTHONPATH": SRC, "NUMBA_CACHE_DIR": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=120,
                          check=True)
    assert done.stdout == "[] 0\n"


# the modules `import tumble` must not load: Numba (and its compiler llvmlite) load with the first compiled module
COMPILER = ("numba", "llvmlite", "scipy")


def test_import_tumble_loads_no_compiler_and_every_public_name_resolves():
    probe = ("import sys, tumble\n"
             f"print(sorted({{m.partition('.')[0] for m in sys.modules}} & set({COMPILER!r})))\n"
             "import tumble.simulate\n"  # the import system sets tumble.simulate to the module: it stays the function
             "from tumble import simulate, RigidBody, Trajectory, attitude, SolverError\n"
             "print(type(tumble.simulate).__name__, simulate is tumble.simulate, RigidBody.__module__,\n"
             "      Trajectory.__module__, attitude.__name__, issubclass(SolverError, Exception))\n"
             "print(sorted(set(tumble.__all__) - set(dir(tumble))), [n for n in tumble.__all__ if not hasattr(tumble, n)])\n"
             # Numba, first loaded by tumble.simulate, was prepared on its import: tumble's locators come first
             "print(type(attitude.qmul._cache._impl.locator).__name__.startswith('TumbleContentKeyed'))\n")
    env = {**os.environ, "PYTHONPATH": SRC}
    done = subprocess.run([sys.executable, "-W", "ignore::DeprecationWarning", "-c", probe], env=env,
                          capture_output=True, text=True, timeout=120, check=True)
    assert done.stdout.splitlines() == [
        "[]",
        "function True tumble.rigid_body tumble.trajectory tumble.attitude True",
        "[] []",
        "True"]
