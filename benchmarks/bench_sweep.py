"""Sweep throughput on Dask against the plain in-process batch, the Dask overhead per chunk, and the peak memory
of a big ``tumble.sweeps.simulate_to_store`` run.

    python benchmarks/bench_sweep.py [--samples 40000] [--chunk 10000] [--big 100000] [--repeats 5] [--dt 0.01]

Workload: rigid bodies I = diag(1, 2, 3) kg m², rk4 at dt = 0.01 s (``--dt``) for 10 s
(1000 steps), 101 output times, initial rates N((0, 0, 1), 0.05²) and uniform
attitudes; the sweep keeps one outcome (the final nutation angle) and one
series (ω_z, with its per-time statistics and percentiles). Figures:

* plain batch: ``tumble.simulate`` of all the samples in this process (Numba
  threads on every core), the inputs drawn beforehand;
* the plain batch followed by the sweep's reductions, then also by its per-time
  statistics and percentiles (the sweep's work in one process, without chunks,
  store or Dask; the percentiles on one thread per core, as the sweep's), and the drawing of the inputs alone (one vectorised Philox
  draw per chunk);
* the sweep in this process (``workers=0``: draws, chunks, reductions, store in memory);
* the sweep on a LocalCluster of 1 and of 2 single-threaded worker processes
  (started and warmed up before the timing), and on 2 with the outcomes only
  (no per-time series, whose exact percentiles need every sample at the end);
* the overhead per chunk: a sweep of ``--tiny`` one-sample chunks of one step
  on 2 workers, minus the same sweep in this process, per chunk;
* the peak RSS of ``tumble.sweeps.simulate_to_store`` of ``--big`` bodies × 1000 output
  times in a child process (its ``VmHWM``: a child's ``ru_maxrss`` starts from
  its parent's peak at the fork, here that of the sweeps above), and its wall time.

Samples/s are given from the wall time and from the CPU time (user + system,
of this process and of the workers), min and median over ``--repeats`` runs.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import psutil

import tumble
from tumble.sweeps import PERCENTILES, Component, Final, Normal, NutationAngle, UniformAttitude
from tumble.sweeps.moments import moments
from tumble.sweeps.plan import make_plan

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
T = np.linspace(0.0, 10.0, 101)
OPTIONS = dict(method="rk4", dt=0.01)
DISPERSIONS = {"omega0": Normal([0.0, 0.0, 1.0], 0.05), "q0": UniformAttitude()}
REDUCE = dict(outcomes={"nutation": Final(NutationAngle([0.0, 0.0, 1.0]))},
              statistics={"omega_z": Component("omega", 2)})

BIG = """
import numpy as np, sys, time, tumble
n, path, inertia = int(sys.argv[1]), sys.argv[2], [float(x) for x in sys.argv[3:6]]
omega0 = np.random.default_rng(0).normal([0.0, 0.0, 1.0], 0.05, size=(n, 3))
start = time.perf_counter()
ds = tumble.sweeps.simulate_to_store(tumble.RigidBody(np.diag(inertia)), omega0, store=path,
                                     t=np.linspace(0.0, 10.0, 1000), method="rk4", dt=0.01)
# this process's own peak (VmHWM, KiB); ru_maxrss would be at least the parent's at the fork that started it
peak = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmHWM:"))
print(time.perf_counter() - start, peak, dict(ds.sizes))
"""


def machine() -> str:
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")),
               platform.processor()) if os.path.exists("/proc/cpuinfo") else platform.processor()
    return (f"{platform.platform()}, Python {platform.python_version()}, {cpu}, {os.cpu_count()} cores, "
            f"{psutil.virtual_memory().total / 2**30:.1f} GiB; tumble {tumble.__version__}, "
            f"numba threads {__import__('numba').get_num_threads()}")


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def cpu_seconds(client=None) -> float:
    """User + system CPU time of this process, plus that of the client's workers (``time.process_time``:
    nanosecond resolution, where psutil's clock ticks of 10 ms read 0 s for the 11 ms draw of the inputs)."""
    total = time.process_time()
    if client is not None:
        total += sum(client.run(time.process_time).values())
    return total


def timed(repeats, fn, client=None):
    """Wall and CPU seconds of each of ``repeats`` calls of ``fn``."""
    walls, cpus = [], []
    for _ in range(repeats):
        c0, w0 = cpu_seconds(client), time.perf_counter()
        fn()
        walls.append(time.perf_counter() - w0)
        cpus.append(cpu_seconds(client) - c0)
    return walls, cpus


def row(label, samples, walls, cpus):
    w_min, w_med = min(walls), statistics.median(walls)
    c_min, c_med = min(cpus), statistics.median(cpus)
    print(f"  {label:<34} {samples / w_min:>10,.0f} {samples / w_med:>10,.0f}   {samples / c_min:>10,.0f} "
          f"{samples / c_med:>10,.0f}   {w_min:7.3f} {w_med:7.3f}")
    return samples / w_min


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=40_000)
    parser.add_argument("--chunk", type=int, default=10_000)
    parser.add_argument("--tiny", type=int, default=200, help="one-sample chunks for the overhead per chunk")
    parser.add_argument("--big", type=int, default=100_000, help="bodies of the simulate_to_store run (0: skip it)")
    parser.add_argument("--big-inertia", type=float, nargs=3, default=[1.0, 2.0, 3.0], metavar="I",
                        help="principal moments of the stored run's body, kg m2 (1 1 2, a symmetric top: ω_z and "
                        "the z momentum stay constant and compress, 60 GiB on disk at 1e6 bodies against 77 GiB)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--dt", type=float, default=0.01, help="rk4 step, s (0.001: 10 000 steps a sample, an "
                        "integration ten times as costly for the same outputs and statistics)")
    parser.add_argument("--warm-only", action="store_true", help="compile the paths into the cache and exit (the "
                        "script runs itself so first: every figure is then of code loaded from the cache, as "
                        "every later process runs it)")
    args = parser.parse_args()
    from distributed import Client

    if not args.warm_only:
        subprocess.run([sys.executable, __file__, "--warm-only", "--dt", str(args.dt)], check=True)
        print(machine())
        print(load(), "(before)")
    s, chunk, repeats = args.samples, args.chunk, args.repeats
    OPTIONS["dt"] = args.dt
    steps = round(T[-1] / args.dt)
    sweep = dict(dispersions=DISPERSIONS, samples=s, seed=1, chunk=chunk, t=T, **OPTIONS, **REDUCE)
    inputs = tumble.sweep(BODY, **{**sweep, "samples": 8, "chunk": 8}, workers=0)  # compile, or load from the cache
    if args.warm_only:
        tumble.simulate(BODY, inputs.omega0.values, q0=inputs.q0.values, t=T, **OPTIONS)
        return
    inputs = tumble.sweep(BODY, **sweep, workers=0)
    omega0, q0 = inputs.omega0.values, inputs.q0.values
    print(f"\nsamples/s: {s} samples of {steps} rk4 steps, 101 outputs, chunks of {chunk}; {repeats} repeats")
    print(f"  {'':<34} {'wall min':>10} {'wall med':>10}   {'CPU min':>10} {'CPU med':>10}   {'s min':>7} "
          f"{'s med':>7}")
    plain = row(f"plain batch, {os.cpu_count()} threads", s,
                *timed(repeats, lambda: tumble.simulate(BODY, omega0, q0=q0, t=T, **OPTIONS)))

    def reduced():
        traj = tumble.simulate(BODY, omega0, q0=q0, t=T, **OPTIONS)
        return [f(traj) for f in (*REDUCE["outcomes"].values(), *REDUCE["statistics"].values())]

    row("plain batch + the same reductions", s, *timed(repeats, reduced))

    def summarised():  # the sweep's work in one process, without chunks, store or Dask
        outcome, series = reduced()  # (samples,) and (time, samples)
        moments(series)  # per-time count, mean, M2, min, max
        # the per-time percentiles with the times shared between one thread per core, as the sweep takes them
        with ThreadPoolExecutor(os.cpu_count()) as pool:
            bands = list(pool.map(lambda rows: np.percentile(series[rows], PERCENTILES, axis=1),
                                  np.array_split(np.arange(series.shape[0]), os.cpu_count() or 1)))
        return np.concatenate(bands, axis=1), np.nanpercentile(outcome, PERCENTILES, axis=0)

    full = row("  + per-time statistics, percentiles", s, *timed(repeats, summarised))
    row("drawing the inputs only", s, *timed(repeats, lambda: make_plan(
        BODY, DISPERSIONS, samples=s, seed=1, chunk=chunk, t=T, method="rk4", options={"dt": 0.01}, torque=None,
        outcomes={}, series={}, fixed={}).inputs(0, s)))
    row("sweep in this process (workers=0)", s, *timed(repeats, lambda: tumble.sweep(BODY, **sweep, workers=0)))
    rates = {}
    for n in (1, 2):
        start = time.perf_counter()
        cluster = tumble.sweeps.local_cluster(n)
        client = Client(cluster)
        started = time.perf_counter() - start
        tumble.sweep(BODY, **{**sweep, "samples": 2 * n, "chunk": 1}, client=client)  # workers load the kernel
        rates[n] = row(f"sweep on {n} local worker{'s' if n > 1 else ''}", s,
                       *timed(repeats, lambda client=client: tumble.sweep(BODY, **sweep, client=client), client))
        if n == 2:
            lean = {**sweep, "statistics": None}  # no per-time series: the outcomes and their percentiles only
            rates["lean"] = row("  the same, outcomes only", s, *timed(
                repeats, lambda client=client: tumble.sweep(BODY, **lean, client=client), client))
            tiny = dict(dispersions=DISPERSIONS, samples=args.tiny, seed=1, chunk=1, t=[0.0, 0.01], **OPTIONS)
            local, _ = timed(repeats, lambda: tumble.sweep(BODY, **tiny, workers=0))
            dask, _ = timed(repeats, lambda client=client: tumble.sweep(BODY, **tiny, client=client))
        client.close()
        cluster.close()
        print(f"    (cluster of {n} started in {started:.2f} s, not counted)")
    print(f"\n2 workers / plain batch on {os.cpu_count()} threads: {rates[2] / plain:.3f} (wall, best runs); "
          f"2 workers / the same work in one process: {rates[2] / full:.3f}; 2 workers / 1 worker: "
          f"{rates[2] / rates[1]:.2f}; 2 workers with the outcomes only / plain batch: {rates['lean'] / plain:.3f}")
    per_chunk = [(d - l) / args.tiny for d, l in zip(sorted(dask), sorted(local), strict=True)]
    print(f"Dask overhead per chunk ({args.tiny} one-sample chunks on 2 workers, minus the same in this process): "
          f"min {min(per_chunk) * 1e3:.2f} ms, median {statistics.median(per_chunk) * 1e3:.2f} ms "
          f"(whole sweep min {min(dask):.2f} s vs {min(local):.2f} s in this process)")
    if args.big:
        directory = tempfile.mkdtemp(prefix="bench_sweep_", dir=os.environ.get("TMPDIR"))
        try:
            out = subprocess.run([sys.executable, "-c", BIG, str(args.big), os.path.join(directory, "big.zarr"),
                                  *map(str, args.big_inertia)],
                                 capture_output=True, text=True, check=True).stdout.split(maxsplit=2)
            size = sum(os.path.getsize(os.path.join(r, f)) for r, _, fs in os.walk(directory) for f in fs)
        finally:
            shutil.rmtree(directory, ignore_errors=True)
        wall, rss_kib, sizes = float(out[0]), int(out[1]), out[2].strip()
        print(f"\nsimulate_to_store of {args.big} bodies x 1000 output times (rk4, 1000 steps, I = "
              f"diag({', '.join(f'{x:g}' for x in args.big_inertia)})): {wall:.1f} s, "
              f"peak RSS {rss_kib / 2**20:.2f} GiB, store {size / 2**30:.2f} GiB on disk, sizes {sizes}")
        print(f"  (in memory the same run would need at least "
              f"{8 * 1000 * args.big * (7 + 11) / 2**30:.1f} GiB of states and outputs)")
    print(load(), "(after)")


if __name__ == "__main__":
    main()
