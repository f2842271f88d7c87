"""tumble.sweeps.shipping: the compiled code a sweep's client gives its Dask workers, and what a worker takes.

The workers' side on real ``dask worker`` processes (another installation
path, empty caches, nothing compiled) is in tests/sweeps/test_sweep_dask.py; here the
plugin's entries are installed in this process into an empty
``NUMBA_CACHE_DIR``.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest
from numba.core import config
from numba.core.caching import IndexDataCacheFile

import tumble
from tumble._cache import content_key
from tumble.sweeps import Normal
from tumble.sweeps.plan import make_plan

pytest.importorskip("distributed")

from tumble.sweeps.shipping import CompiledCode, compiled_for, install, target  # noqa: E402  (needs distributed)


@pytest.fixture(scope="module")
def code() -> CompiledCode:
    """The plugin of a sweep of 16 rigid bodies under rk4 (one chunk)."""
    plan = make_plan(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), {"omega0": Normal([0.0, 0.0, 1.0], 0.05)},
                     samples=16, seed=1, chunk=16, t=np.linspace(0.0, 1.0, 3), method="rk4", options={"dt": 0.01},
                     torque=None, outcomes={}, series={}, fixed={})
    return compiled_for(plan)


@pytest.fixture
def empty_cache(tmp_path, monkeypatch) -> Path:
    """This process's ``NUMBA_CACHE_DIR`` set to an empty directory for the test."""
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    return tmp_path


def test_the_client_ships_its_entries_for_its_own_cpu_under_its_content_key(code):
    assert code.stamp == content_key() and code.entries
    assert {entry.cpu for entry in code.entries} == {target()}
    assert all(not entry.source.startswith(("/", "..")) and entry.source.endswith(".py") for entry in code.entries)
    assert len({(entry.source, entry.name, entry.key) for entry in code.entries}) == len(code.entries)


def test_a_worker_writes_the_entries_into_its_cache_where_numba_reads_them(code, empty_cache):
    assert install(code) == len(code.entries)
    for entry in code.entries:
        directory = next(empty_cache.glob(f"*/{entry.name}.nbi")).parent
        cache_file = IndexDataCacheFile(str(directory), entry.name, content_key())
        data_name = cache_file._load_index()[entry.key]
        assert (directory / data_name).read_bytes() == entry.data
        pickle.loads(entry.data)  # Numba's reduced compile result, as it loads it
    assert not list(empty_cache.rglob("*.tmp.*"))  # every temporary renamed into place
    assert install(code) == 0  # the keys are there: nothing written again


def test_a_worker_of_another_cpu_or_another_tumble_takes_nothing(code, empty_cache):
    triple, _, _ = target()
    assert install(code, cpu=(triple, "haswell", "+avx,+avx2,+fma,-avx512f")) == 0
    assert install(CompiledCode("0" * 32, code.python, code.entries)) == 0
    assert install(CompiledCode(code.stamp, "py27", code.entries)) == 0
    assert not list(empty_cache.rglob("*.nb[ic]"))
