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
