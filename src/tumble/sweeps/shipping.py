"""The client's compiled code, shipped to a sweep's Dask workers before the first chunk.

A worker without tumble's compiled code in its Numba cache (another machine,
another installation path, an empty ``NUMBA_CACHE_DIR``) would compile every
kernel a chunk runs, seconds to a minute each, before its first result. The
client has that code: :func:`compiled_for` runs the sweep's first chunk over
its first output interval here (loading the code from this machine's cache,
or compiling it once), and collects Numba's cache entries of every tumble
function this process then holds compiled code for. :class:`CompiledCode`, a
``distributed`` worker plugin, writes them into each worker's own cache
directory when the worker joins (or when the plugin is registered), so the
chunks load them instead of compiling.

**What a worker can use.** Numba keeps a function's compiled code in two
files, in the directory its locator picks for the source file (``NUMBA_CACHE_DIR``,
``__pycache__`` beside the source, or the user's cache directory, in that
order, as Numba does): an index ``NAME-LINE.pyXY.nbi``, which maps each key
``(signature, (target triple, CPU name, CPU features), bytecode digests)`` to
a data file ``NAME-LINE.pyXY.N.nbc``, and is stamped with the source's stamp
(for tumble, :func:`tumble._cache.content_key`: the digest of tumble's
compiled sources and of the versions of Numba, llvmlite and NumPy, not the
file's path or time). None of it names the installation's path. A worker
takes an entry when its tumble has the same content key, its Python the same
version tag (the files' names) and its CPU the same name and features (the
entry's key); for another CPU it takes nothing and compiles, as without the
plugin. The files are written atomically (a temporary file, then a rename),
data before index, and merged into an index already there, so workers that
share a cache directory, or a chunk loading while they are written, never
read a partial file.
"""

from __future__ import annotations

import dataclasses
import gc
import itertools
import os
import sys
from typing import TYPE_CHECKING

import numpy as np
from distributed.diagnostics.plugin import WorkerPlugin

from tumble._cache import PACKAGE, _writable, content_key

if TYPE_CHECKING:
    from tumble.sweeps.plan import Plan

__all__ = ["CompiledCode", "Entry", "compiled_for", "install", "target"]


@dataclasses.dataclass(frozen=True)
class Entry:
    """One compiled version of one function: where Numba keeps it (``source``, the function's file relative to
    the tumble package; ``name``, the index file's name without ``.nbi``), its index ``key`` and the bytes
    of its data file."""

    source: str
    name: str
    key: tuple
    data: bytes

    @property
    def cpu(self) -> tuple:
        """The code's target: (triple, CPU name, CPU features)."""
        return self.key[1]


def target() -> tuple:
    """This process's code target as Numba keys cache entries by it: (triple, CPU name, CPU features)."""
    from numba.core.registry import cpu_target

    return cpu_target.target_context.codegen().magic_tuple()


def _python_tag() -> str:
    """The Python version in Numba's cache file names (``py311``, with ABI flags)."""
    return f"py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}"


def _tumble_dispatchers() -> list[tuple[object, str]]:
    """Numba's dispatchers of the functions defined in tumble's package that hold compiled code in this
    process and cache it on disk, each with its source file relative to the package."""
    from numba.core.caching import Cache
    from numba.core.dispatcher import Dispatcher

    # type(), not isinstance(): an object the collector holds may be a proxy whose __class__ lookup raises
    held = [d for d in gc.get_objects() if issubclass(type(d), Dispatcher) and d.overloads
            and isinstance(getattr(d, "_cache", None), Cache)]
    return [(d, source) for d in held if (source := _relative_source(d.py_func.__code__.co_filename)) is not None]


def _relative_source(path: str) -> str | None:
    """``path`` relative to the tumble package (POSIX), or None for a file outside it."""
    real = os.path.realpath(path)
    return os.path.relpath(real, PACKAGE).replace(os.sep, "/") if real.startswith(str(PACKAGE) + os.sep) else None


def _entries(dispatcher, source: str) -> list[Entry]:
    """The cache entries of ``dispatcher`` (of the function defined in ``source``) for the signatures it holds
    compiled code for here."""
    from numba.core import sigutils

    cache_file = dispatcher._cache._cache_file
    held = set(dispatcher.overloads)
    found = []
    for key, data_name in cache_file._load_index().items():
        if tuple(sigutils.normalize_signature(key[0])[0]) not in held:
            continue
        try:
            with open(cache_file._data_path(data_name), "rb") as f:
                data = f.read()
        except OSError:  # removed since the index was written: the worker compiles this one
            continue
        found.append(Entry(source, cache_file._index_name.removesuffix(".nbi"), key, data))
    return found


def compiled_for(plan: Plan) -> CompiledCode:
    """The plugin carrying the cache entries of the tumble functions that ``plan``'s chunks run, compiled for
    this process's CPU: the first chunk's samples are simulated here over the first output interval (at most
    one step of a fixed-step method), which loads or compiles them, then the entries of every tumble function
    compiled in this process are taken (in a process that ran other models before, theirs too)."""
    lo, hi = plan.chunks.bounds(0)
    t = np.array(plan.t[:2], dtype=np.float64)
    if len(t) == 2 and "dt" in plan.options:
        t[1] = min(t[1], t[0] + float(plan.options["dt"]))
    dataclasses.replace(plan, t=t).simulate(plan.inputs(lo, hi))
    cpu = target()
    entries: dict[tuple, Entry] = {}  # one of each: a module imported again (a reload) leaves a second dispatcher of its functions
    for dispatcher, source in _tumble_dispatchers():
        for entry in _entries(dispatcher, source):
            if entry.cpu == cpu:
                entries.setdefault((entry.source, entry.name, entry.key), entry)
    return CompiledCode(content_key(), _python_tag(), tuple(entries.values()))


def _cache_directory(source: str) -> str | None:
    """The directory where Numba's locators put the compiled code of tumble's ``source`` (relative to the
    package) in this process, or None when none is writable: ``NUMBA_CACHE_DIR``'s directory for the source's
    directory, else ``__pycache__`` beside the source, else the user's cache directory's."""
    import tumble
    from numba.core import caching, config
    from numba.misc.appdirs import AppDirs

    path = os.path.join(os.path.dirname(tumble.__file__), *source.split("/"))  # as Numba sees the module's file
    subpath = caching._CacheLocator.get_suitable_cache_subpath(path)
    candidates = [os.path.join(config.CACHE_DIR, subpath)] if config.CACHE_DIR else []
    candidates += [os.path.join(os.path.dirname(path), "__pycache__"),
                   os.path.join(AppDirs(appname="numba", appauthor=False).user_cache_dir, subpath)]
    return next((directory for directory in candidates if _writable(directory)), None)


def install(code: CompiledCode, cpu: tuple | None = None) -> int:
    """Write the entries of ``code`` compiled for ``cpu`` (default: this process's :func:`target`) into this
    process's cache directories, merged into the indexes found there; return how many were written. Nothing
    is written where this tumble's content key or Python's version tag differs from the client's (the entries
    would not be read); an entry whose key an index has already is kept as it is."""
    from numba.core.caching import IndexDataCacheFile

    if (code.stamp, code.python) != (content_key(), _python_tag()):
        return 0
    cpu = target() if cpu is None else cpu
    by_index: dict[tuple[str, str], list[Entry]] = {}
    for entry in code.entries:
        if entry.cpu == cpu:
            by_index.setdefault((entry.source, entry.name), []).append(entry)
    written = 0
    for (source, name), group in by_index.items():
        directory = _cache_directory(source)
        if directory is None:
            continue
        try:
            written += _merge(IndexDataCacheFile(directory, name, code.stamp), group)
        except OSError:  # a full disk, say: these functions compile on first use, as without the plugin
            continue
    return written


def _merge(cache_file, entries: list[Entry]) -> int:
    """Add the ``entries`` whose keys it lacks to ``cache_file`` (Numba's ``IndexDataCacheFile``): each data
    file under the first free number, then the index (each written to a temporary file, then renamed: the
    index never names a file not yet complete); return how many were added."""
    overloads = cache_file._load_index()
    numbers = (n for n in itertools.count(1) if cache_file._data_name(n) not in set(overloads.values()))
    new = [entry for entry in entries if entry.key not in overloads]
    for entry in new:
        overloads[entry.key] = cache_file._data_name(next(numbers))
        with cache_file._open_for_write(cache_file._data_path(overloads[entry.key])) as f:
            f.write(entry.data)
    if new:
        cache_file._save_index(overloads)
    return len(new)


class CompiledCode(WorkerPlugin):
    """A worker plugin carrying compiled code (:class:`Entry`) of a client whose tumble has the content key
    ``stamp`` under Python ``python`` (``py311``); :meth:`setup` installs it on each worker as it joins."""

    def __init__(self, stamp: str, python: str, entries: tuple[Entry, ...]) -> None:
        self.stamp, self.python, self.entries = stamp, python, entries

    def setup(self, worker: object = None) -> None:
        install(self)
