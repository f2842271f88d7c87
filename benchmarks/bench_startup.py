"""A first run, measured: ``import tumble``, the first ``tumble demo racket``, and the first ``simulate`` of
every built-in model kind under every method it provides (the paths of ``tumble warmup``,
``tumble._warmup``), each in a new Python process with an empty Numba cache (cold: a fresh install) and with
the cache that run left (warm).

    python benchmarks/bench_startup.py [--repeats 5 | --quick] [--src DIR] [--kinds RigidBody ...]
                                       [--methods rk4 dop853 ...]

``--src`` measures another checkout's ``src`` (e.g. an older commit in a git worktree, for a before/after
table); the default is the tumble this script imports. Every row is min / median over ``--repeats`` (at
least 5) new processes, or one with ``--quick``, in wall time and in CPU time of the process (user + system,
from ``getrusage(RUSAGE_CHILDREN)``), each cold row with a new empty ``NUMBA_CACHE_DIR``; a warm row
includes ``import tumble``. Goals (issues 16 and 29, on an idle 2-core machine): ``import tumble`` ≤ 0.3 s,
first ``tumble demo racket`` ≤ 3 s, first call of a model kind's default method ≤ 2 s, a cached call ≤ 0.5 s
including the import. On a shared machine read the CPU columns.
"""

from __future__ import annotations

import argparse
import ast
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

IMPORT = "import tumble"
DEFAULT_METHOD = "dop853"  # simulate's
SIMULATE = "from tumble._warmup import kind_path; kind_path({kind!r}, {method!r})()"
# the kinds and the methods each provides, as tumble warmup finds them (in the tumble measured)
KINDS = "from tumble._kinds import MODEL_KINDS; from tumble._warmup import methods; print(repr({kind: methods(kind) for kind in MODEL_KINDS}))"
RACKET = "import sys; from tumble.cli import app; sys.argv = ['tumble', 'demo', 'racket', '-q', '-o', {out!r}]; app()"


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
    print(f"{name:<28} {cells[0]}  {cells[1]}   {cells[2]}  {cells[3]}   {goal}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=REPEATS)
    parser.add_argument("--quick", action="store_true", help="one new process per row instead of --repeats")
    parser.add_argument("--src", type=Path, default=None, help="a checkout's src directory to measure")
    parser.add_argument("--kinds", nargs="*", default=None, help="model kinds to measure (default: all)")
    parser.add_argument("--methods", nargs="*", default=None, help="methods to measure (default: all)")
    args = parser.parse_args()
    repeats = 1 if args.quick else max(args.repeats, REPEATS)
    src = (args.src or Path(__file__).resolve().parents[1] / "src").resolve()
    env = {**os.environ, "PYTHONPATH": str(src), "TUMBLE_QUIET": "1"}
    kinds = ast.literal_eval(subprocess.run([sys.executable, "-c", KINDS], env=env, check=True, capture_output=True,
                                            text=True).stdout)
    print(machine())
    print(f"tumble from {src}; {repeats} new process{'es' if repeats > 1 else ''} per row, min / median, s")
    print(f"{'':<28} {'cold wall':^17}  {'cold CPU':^17}   {'warm wall':^17}  {'warm CPU':^17}   goal (cold wall)")
    row("import tumble", IMPORT, env, repeats, "<= 0.3 s")
    with tempfile.TemporaryDirectory() as out:
        row("tumble demo racket", RACKET.format(out=out), env, repeats,
            "<= 3 s")
    for kind, provided in kinds.items():
        if args.kinds is not None and kind not in args.kinds:
            continue
        for method in provided:
            if args.methods is None or method in args.methods:
                row(f"{kind}, {method}", SIMULATE.format(kind=kind, method=method), env, repeats,
                    "<= 2 s (the default method)" if method == DEFAULT_METHOD else "")


if __name__ == "__main__":
    main()
