"""A first run, measured: ``import tumble``, the first ``tumble demo racket``, the first one-body ``simulate``
of each method, each in a new Python process with an empty Numba cache (cold) and with the cache that run
left (warm).

    python benchmarks/bench_startup.py [--repeats 5] [--src DIR] [--methods rk4 dop853 ...]

``--src`` measures another checkout's ``src`` (e.g. an older commit in a git worktree, for a before/after
table); the default is the tumble this script imports. Every row is min / median over ``--repeats`` (at
least 5) new processes, in wall time and in CPU time of the process (user + system, from
``getrusage(RUSAGE_CHILDREN)``), each cold row with a new empty ``NUMBA_CACHE_DIR``. Goals (issue 16, on an
idle 2-core machine with an empty cache): first ``tumble demo racket`` ≤ 3 s wall, first one-body
``simulate`` of each method ≤ 2 s, ``import tumble`` ≤ 0.3 s. On a shared machine read the CPU column.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _timing import REPEATS, machine

METHODS = ("dop853", "rk4", "cf4", "splitting2", "splitting4", "exact_split2", "exact_split4", "exact")

IMPORT = "import tumble"
SIMULATE = """
import numpy as np, tumble
method = {method!r}
options = {{"rtol": 1e-10, "atol": 1e-12}} if method == "dop853" else {{}} if method == "exact" else {{"dt": 0.01}}
tumble.simulate(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), [0.1, 1.0, 0.1], t=[0.0, 0.5, 1.0], method=method,
                **options)
"""
RACKET = "import sys; from tumble.cli import app; sys.argv = ['tumble', 'demo', 'racket', '-q', '-o', {out!r}, " \
         "'--plot', {png!r}]; app()"


def run(code: str, env: dict) -> tuple[float, float]:
    """Wall and CPU seconds of ``python -c code`` in a new process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], env=env, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def row(name: str, code: str, env: dict, repeats: int, goal: str) -> None:
    """Print min / median of the cold runs (a new cache each) and of the warm ones (the cache left behind)."""
    cold, warm = [], []
    for _ in range(repeats):
        cache = tempfile.mkdtemp(prefix="tumble-bench-cache-")
        try:
            cold.append(run(code, {**env, "NUMBA_CACHE_DIR": cache}))
            warm.append(run(code, {**env, "NUMBA_CACHE_DIR": cache}))
        finally:
            shutil.rmtree(cache, ignore_errors=True)
    cells = []
    for runs in (cold, warm):
        for k in (0, 1):
            values = [r[k] for r in runs]
            cells.append(f"{min(values):7.2f} / {statistics.median(values):7.2f}")
    print(f"{name:<24} {cells[0]}  {cells[1]}   {cells[2]}  {cells[3]}   {goal}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=REPEATS)
    parser.add_argument("--src", type=Path, default=None, help="a checkout's src directory to measure")
    parser.add_argument("--methods", nargs="*", default=list(METHODS))
    args = parser.parse_args()
    repeats = max(args.repeats, REPEATS)
    src = (args.src or Path(__file__).resolve().parents[1] / "src").resolve()
    env = {**os.environ, "PYTHONPATH": str(src)}
    print(machine())
    print(f"tumble from {src}; {repeats} new processes per row, min / median, s")
    print(f"{'':<24} {'cold wall':^17}  {'cold CPU':^17}   {'warm wall':^17}  {'warm CPU':^17}   goal (cold wall)")
    row("import tumble", IMPORT, env, repeats, "<= 0.3 s")
    with tempfile.TemporaryDirectory() as out:
        row("tumble demo racket", RACKET.format(out=f"{out}/racket.nc", png=f"{out}/racket.png"), env, repeats,
            "<= 3 s")
    for method in args.methods:
        row(f"simulate, {method}", SIMULATE.format(method=method), env, repeats, "<= 2 s")


if __name__ == "__main__":
    main()
