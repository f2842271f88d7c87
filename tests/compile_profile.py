"""Where the suite's CPU goes: a pytest plugin that logs, per test, its CPU time and each Numba compilation.

Enabled by ``TUMBLE_COMPILE_PROFILE=DIR`` (``tests/conftest.py`` registers it): each pytest process (the
controller and every xdist worker) appends JSON lines to ``DIR/<pid>.jsonl``, one per test::

    {"test": nodeid, "outcome": "passed" | "failed" | "skipped", "cpu": s, "children": s,
     "compiles": [[function, signature, inclusive s, self s, depth], ...]}

``cpu`` is the process's CPU time (user + system, all threads) from the start of the test's setup to the
end of its teardown; ``children`` that of the subprocesses it started and waited for (the CLI's, Dask's). A compilation is what Numba's ``numba:compile`` event brackets: a signature that the
disk cache did not answer. Compilations nest (a kernel compiles the dispatchers it calls); *inclusive* counts
the callees, *self* does not, so the self times of a test add up to its compile time. Compilations in
subprocesses are not seen (only their CPU time, in ``children``). ``benchmarks/compile_report.py`` sums the logs.
"""

from __future__ import annotations

import json
import os
import resource
import time
from pathlib import Path

import pytest
from numba.core import event


def _children_cpu() -> float:
    """User + system CPU seconds of the subprocesses this process has waited for."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


class CompileClock(event.Listener):
    """Collects ``[function, signature, inclusive, self, depth]`` for every compilation, CPU seconds."""

    def __init__(self) -> None:
        self.open: list[list[float]] = []   # [start, callees' inclusive time] of each compilation in progress
        self.done: list[list] = []

    def on_start(self, ev: event.Event) -> None:
        self.open.append([time.process_time(), 0.0])

    def on_end(self, ev: event.Event) -> None:
        start, callees = self.open.pop()
        inclusive = time.process_time() - start
        if self.open:
            self.open[-1][1] += inclusive
        function = ev.data["dispatcher"].py_func
        self.done.append([f"{function.__module__}.{function.__qualname__}", str(ev.data["args"]), inclusive,
                          inclusive - callees, len(self.open)])


class CompileProfile:
    """The plugin: one :class:`CompileClock` listening for the whole session, read out after each test."""

    def __init__(self, directory: str) -> None:
        self.log = Path(directory) / f"{os.getpid()}.jsonl"
        self.log.parent.mkdir(parents=True, exist_ok=True)
        self.clock = CompileClock()
        self.outcome = "passed"
        event.register("numba:compile", self.clock)

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        if report.outcome != "passed" and self.outcome != "failed":
            self.outcome = report.outcome

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item: pytest.Item, nextitem: pytest.Item | None):
        start, children = time.process_time(), _children_cpu()
        yield
        record = {"test": item.nodeid, "outcome": self.outcome, "cpu": time.process_time() - start,
                  "children": _children_cpu() - children, "compiles": self.clock.done}
        self.clock.done, self.outcome = [], "passed"
        with self.log.open("a") as log:
            log.write(json.dumps(record) + "\n")
