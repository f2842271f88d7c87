"""Never a silent wait: one line when compiling holds a call up for more than a second.

A model kind's first run under a method, or a user's own compiled torque or
control law, makes Numba compile for seconds to a minute (the compiled code
is then cached on disk, docs/architecture.md). :func:`notice` watches Numba's
``"numba:compile"`` events (:mod:`numba.core.event`) during a call; when a
compile has been under way for :data:`DELAY` seconds it says, once, what is
compiled and why::

    tumble: compiling the rk4 path of RigidBody (tumble.attitude._from_matrix_loop: first use of this model
    kind and method here; cached for later runs)...

Where the line goes: nowhere with the environment variable ``TUMBLE_QUIET=1``;
as an INFO record of the ``"tumble"`` logger where logging is configured to
pass it (``logging.basicConfig(level=logging.INFO)``, say); else, while the
``"tumble"`` logger has no level of its own, to stderr. So
``logging.getLogger("tumble").setLevel(logging.WARNING)`` silences it too.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import threading
from collections.abc import Iterator

from numba.core import event

__all__ = ["DELAY", "notice"]

#: Seconds of compiling before the line is written.
DELAY = 1.0

logger = logging.getLogger("tumble")


def _say(line: str) -> None:
    """Write ``line`` as :mod:`tumble._compiling` says: a log record, stderr, or nothing."""
    if os.environ.get("TUMBLE_QUIET", "") not in ("", "0"):
        return
    if logger.isEnabledFor(logging.INFO):
        logger.info(line)
    elif logger.level == logging.NOTSET:
        print(f"tumble: {line}", file=sys.stderr, flush=True)


def _what(dispatcher, purpose: str) -> str:
    """The line for a compile of ``dispatcher`` (a Numba dispatcher) made for ``purpose``."""
    function = dispatcher.py_func
    name = f"{function.__module__}.{function.__qualname__}"
    if function.__module__.partition(".")[0] == "tumble":
        return f"compiling {purpose} ({name}: first use of this model kind and method here; cached for later runs)..."
    return f"compiling {name} for {purpose} (a compiled function of yours, first called in this process)..."


class _Watch(event.Listener):
    """A ``numba:compile`` listener: the dispatchers being compiled, outermost first, and a timer started by
    the first compile; the line is said when the timer fires during a compile, or at the next compile after."""

    def __init__(self, purpose: str, delay: float):
        self._purpose, self._delay = purpose, delay
        self._compiling: list = []
        self._lock = threading.Lock()
        self._timer: threading.Timer | None = None
        self._due = self._said = False

    def on_start(self, event) -> None:
        dispatcher = event.data["dispatcher"]
        with self._lock:
            self._compiling.append(dispatcher)
            if self._timer is None:
                self._timer = threading.Timer(self._delay, self._fire)
                self._timer.daemon = True
                self._timer.start()
            say = self._due and not self._said
            self._said |= say
        if say:
            _say(_what(dispatcher, self._purpose))

    def on_end(self, event) -> None:
        with self._lock:
            if self._compiling:  # a compile of another thread may have started before the watch
                self._compiling.pop()

    def _fire(self) -> None:
        with self._lock:
            self._due = True
            outermost = self._compiling[0] if self._compiling and not self._said else None
            self._said |= outermost is not None
        if outermost is not None:
            _say(_what(outermost, self._purpose))

    def stop(self) -> None:
        if self._timer is not None:
            self._timer.cancel()


@contextlib.contextmanager
def notice(purpose: str, *, delay: float = DELAY) -> Iterator[None]:
    """Within the block, say once what is compiled for ``purpose`` (e.g. ``"the rk4 path of RigidBody"``)
    when compiling has taken ``delay`` seconds (module docstring)."""
    watch = _Watch(purpose, delay)
    try:
        with event.install_listener("numba:compile", watch):
            yield
    finally:
        watch.stop()
