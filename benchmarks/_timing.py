"""Timing helpers shared by the benchmark scripts (run them as ``python benchmarks/<name>.py``).

Every figure is taken over at least 5 repeats and reported as min and median, in wall time and in
CPU time of this process (all its threads): on a machine shared with other work the wall time of a
threaded run says little, while ``work / CPU seconds × cores`` is the rate the cores would give
if they were this run's alone (it assumes perfect scaling, so it is an upper bound for threads).
"""

from __future__ import annotations

import os
import platform
import time
from dataclasses import dataclass

import numpy as np

REPEATS = 5


def machine() -> str:
    """One line: CPU model, cores available to this process, load average (1, 5, 15 min), Python, NumPy, Numba."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            model = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    import numba

    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"{model}; {len(os.sched_getaffinity(0))} cores; load average {load}; Python {platform.python_version()}, "
            f"NumPy {np.__version__}, Numba {numba.__version__}")


@dataclass
class Timing:
    """Wall and CPU seconds (of this process, all threads) of each repeat, and the last result."""

    wall: np.ndarray
    cpu: np.ndarray
    result: object

    def seconds(self) -> tuple[float, float]:
        """Wall time, s: (min, median)."""
        return float(self.wall.min()), float(np.median(self.wall))

    def rates(self, work: float, cores: int | None = None) -> dict[str, tuple[float, float]]:
        """``work`` per second, (best, median): from wall time, and from CPU time × ``cores`` (the rate
        the cores would give if they were this run's alone; omit ``cores`` for a one-core run)."""
        cores = cores or 1
        return {"wall": (work / self.wall.min(), work / np.median(self.wall)),
                "cpu": (cores * work / self.cpu.min(), cores * work / np.median(self.cpu))}


def measure(fn, repeats: int = REPEATS) -> Timing:
    """Call ``fn`` ``repeats`` times (at least 5), timing each call in wall and process CPU time."""
    wall, cpu, result = [], [], None
    for _ in range(max(repeats, REPEATS)):
        w, c = time.perf_counter(), time.process_time()
        result = fn()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - w)
    return Timing(np.array(wall), np.array(cpu), result)


def best_of(repeats, fn):
    """Smallest wall time of ``max(repeats, 5)`` calls of ``fn`` (s) and its last result."""
    t = measure(fn, repeats)
    return t.seconds()[0], t.result


def fmt(pair, unit="") -> str:
    """``min / median`` of a pair, 3 significant digits."""
    return f"{pair[0]:.3g} / {pair[1]:.3g}{unit}"


def cpu_times(repeats, fn):
    """CPU time of ``max(repeats, 5)`` calls of ``fn`` (s, all threads of the process): ``(min, median, last
    result)`` — CPU time, not wall time, so that other work on a shared machine does not count."""
    t = measure(fn, repeats)
    return float(t.cpu.min()), float(np.median(t.cpu)), t.result
