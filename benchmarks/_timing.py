"""Timing helper shared by the benchmark scripts (run them as ``python benchmarks/<name>.py``)."""

import time

import numpy as np


def best_of(repeats, fn):
    """Smallest wall time of ``repeats`` calls of ``fn`` (s) and its last result."""
    best, result = np.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def cpu_times(repeats, fn):
    """CPU time of ``repeats`` calls of ``fn`` (s, all threads of the process): ``(min, median, last result)``.

    CPU time, not wall time, so that other work on a shared machine does not
    count; for a threaded call it is the sum over the threads.
    """
    times, result = [], None
    for _ in range(repeats):
        start = time.process_time()
        result = fn()
        times.append(time.process_time() - start)
    return min(times), float(np.median(times)), result


def machine():
    """One line: CPU model, logical CPUs and the load average (1, 5, 15 min) of this machine."""
    import os
    import platform

    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as info:
            model = next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"{model}; {os.cpu_count()} logical CPUs; load average {load}"
