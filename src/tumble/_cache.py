"""Where Numba caches tumble's compiled code, and when that code is stale.

**Where.** Numba's ``cache=True`` looks for a writable directory when a
function is decorated, i.e. when a compiled module is imported: ``NUMBA_CACHE_DIR``
if set, else ``__pycache__`` beside the source, else the user's cache
directory (``~/.cache/numba``); with none of them it raises
``RuntimeError: cannot cache function ...: no locator available`` and the
import fails. That happens to a non-root user of a read-only site-packages
whose ``HOME`` is unset or unwritable (a container, a service account).
:func:`ensure_writable_cache` runs before any compiled module is decorated
(:func:`prepare_when_numba_loads`: as soon as Numba itself is imported, which
``import tumble`` does not do): when
neither the package directory nor the user's cache directory can be written
(the same test as Numba's, creating a temporary file there) and
``NUMBA_CACHE_DIR`` is not set, it points Numba at a fresh temporary
directory, for this process and its children, and says so in one warning.
The compiled code is then cached for this process only (the next process
compiles again).

**When stale.** Numba stamps each cached function with a hash of its own
source file only, but a compiled function contains the code of every
function it calls or inlines from other files (``_quat``, the protocol
overloads of every kernel, the schemes of ``integrate/``), and the values of
the globals it reads. :func:`use_content_key` makes the stamp of every
function defined in tumble the digest of all of tumble's sources that can be
compiled into one (:func:`content_key`), with the versions of Numba's
compiler stack and NumPy: editing any of them makes every cached tumble
function stale, and its next use compiles and replaces it (Numba rewrites a
function's index in place when its stamp changes, so old generations do not
pile up). The key is coarse: an edit of one kernel recompiles all of tumble
on next use, which is correct whatever calls what. It leaves out the layers
above the compiled code (:data:`UNCOMPILED`: the CLI, scenario files, sweeps,
figures, the viewer, the examples), so editing those recompiles nothing;
``tests/test_cache.py`` checks that none of them compiles code and that no
other module imports them at module level, i.e. that no compiled function
can read them. The CPU (name and features) is part of Numba's own key of each
entry; Python's version is in the index file's name. An index written by
another version of tumble that names a class this one lacks is stale too
(:func:`tolerate_stale_indexes`), not an error.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.abc
import importlib.util
import os
import sys
import tempfile
import warnings
from pathlib import Path

__all__ = ["PACKAGE", "UNCOMPILED", "cache_directories", "cached_files", "content_key", "ensure_writable_cache",
           "prepare", "prepare_when_numba_loads", "sources", "use_content_key"]

#: The directory of the tumble package.
PACKAGE = Path(__file__).resolve().parent

#: What the content key leaves out, relative to :data:`PACKAGE`: modules and sub-packages above the compiled
#: layers (docs/architecture.md), which define no compiled code and which no compiled module imports.
UNCOMPILED = ("__main__.py", "cli", "_warmup.py", "ensemble.py", "examples", "scenario", "sweep.py", "sweeps", "viz")


def _writable(directory: str) -> bool:
    """True when a file can be created in ``directory`` (made if missing), as Numba's locators test it."""
    try:
        os.makedirs(directory, exist_ok=True)
        tempfile.TemporaryFile(dir=directory).close()
    except OSError:
        return False
    return True


def ensure_writable_cache() -> str | None:
    """Give Numba a writable cache directory when it would find none; returns the directory chosen, or None
    when Numba's own choice works (or ``NUMBA_CACHE_DIR`` was set by the user)."""
    from numba.core import config
    from numba.misc.appdirs import AppDirs

    if config.CACHE_DIR:
        return None
    if _writable(str(PACKAGE / "__pycache__")) or _writable(AppDirs(appname="numba", appauthor=False).user_cache_dir):
        return None
    directory = tempfile.mkdtemp(prefix="tumble-numba-cache-")
    config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"] = directory
    warnings.warn(f"tumble: neither the package directory nor the user's cache directory is writable (HOME unset or "
                  f"read-only?): compiled code is cached in {directory} for this process only; set NUMBA_CACHE_DIR "
                  "to a writable directory to keep it", RuntimeWarning, stacklevel=3)
    return directory


def sources(package: Path = PACKAGE) -> list[Path]:
    """The Python sources of ``package`` that can be compiled into a function: all but :data:`UNCOMPILED`,
    sorted by their path relative to ``package``."""
    found = []
    for directory, subdirectories, files in os.walk(package):
        here = Path(directory)
        subdirectories[:] = [name for name in subdirectories if name != "__pycache__"
                             and (here != package or name not in UNCOMPILED)]
        found += [here / name for name in files if name.endswith(".py") and (here != package or name not in UNCOMPILED)]
    return sorted(found, key=lambda path: path.relative_to(package).as_posix())


@functools.cache
def content_key(package: Path = PACKAGE) -> str:
    """BLAKE2b digest (hex, 128 bits) of the compiler stack's versions (Numba, llvmlite, NumPy) and of each of
    :func:`sources` (its path relative to ``package`` and its bytes); computed once per process."""
    import llvmlite
    import numba
    import numpy

    digest = hashlib.blake2b(digest_size=16)
    digest.update(f"numba {numba.__version__} llvmlite {llvmlite.__version__} numpy {numpy.__version__}".encode())
    for path in sources(package):
        digest.update(b"\0" + path.relative_to(package).as_posix().encode() + b"\0")
        digest.update(path.read_bytes())
    return digest.hexdigest()


@functools.cache
def _in_package(py_file: str) -> bool:
    """True when ``py_file`` is a file of tumble's package, installed as a directory (not in a zip)."""
    return PACKAGE.is_dir() and os.path.realpath(py_file).startswith(str(PACKAGE) + os.sep)


def _keyed_by_content(locator: type) -> type:
    """A subclass of one of Numba's file-backed cache locators that stamps the functions defined in tumble's
    package with :func:`content_key`, where ``locator`` puts them; other functions it leaves to the next
    locator."""

    class ContentKeyed(locator):
        @classmethod
        def from_function(cls, py_func, py_file):
            return super().from_function(py_func, py_file) if _in_package(py_file) else None

        def get_source_stamp(self):
            return content_key()

    ContentKeyed.__name__ = ContentKeyed.__qualname__ = f"TumbleContentKeyed{locator.__name__.lstrip('_')}"
    return ContentKeyed


def use_content_key() -> None:
    """Put content-keyed copies (:func:`_keyed_by_content`) of Numba's file-backed locators (``NUMBA_CACHE_DIR``,
    ``__pycache__`` beside the source, the user's cache directory) first in Numba's list, in Numba's order;
    called once, before any compiled module is imported. A list given in ``NUMBA_CACHE_LOCATOR_CLASSES``
    replaces Numba's and is left as the user set it."""
    from numba.core import caching

    implementation = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # Numba >= 0.68 / older
    locators = implementation._locator_classes
    if any(locator.__name__.startswith("TumbleContentKeyed") for locator in locators):
        return
    backed = [locator for locator in locators if issubclass(locator, caching._SourceFileBackedLocatorMixin)
              and "Zip" not in locator.__name__]
    locators[:0] = [_keyed_by_content(locator) for locator in backed]


def tolerate_stale_indexes() -> None:
    """Make a cache index that names a class no longer there stale, not an error.

    An index written by another version of tumble (a git branch, an upgrade or a downgrade: the cache files
    outlive the sources they were compiled from) may name, in the signatures it lists, a compiled model's
    class that this version does not have. Numba unpickles an index before it compares its stamp, so the
    missing module or class raised ``ModuleNotFoundError`` (or ``AttributeError``) at every call of the
    function. Such an index now reads as empty: the function compiles, and saving it rewrites the index.
    Called once, before any compiled module is imported."""
    from numba.core import caching

    load_index = caching.IndexDataCacheFile._load_index
    if getattr(load_index, "tolerates_stale", False):
        return

    def _load_index(self):
        try:
            return load_index(self)
        except (ImportError, AttributeError):
            return {}

    _load_index.tolerates_stale = True  # type: ignore[attr-defined]
    caching.IndexDataCacheFile._load_index = _load_index


def prepare() -> None:
    """What Numba needs before it decorates any of tumble's functions: a writable cache
    (:func:`ensure_writable_cache`), the content key (:func:`use_content_key`) and indexes of other versions
    read as stale (:func:`tolerate_stale_indexes`)."""
    ensure_writable_cache()
    use_content_key()
    tolerate_stale_indexes()


class _AfterNumbaLoads(importlib.abc.MetaPathFinder):
    """Finds ``numba`` for the import system (through the finders after it) and has its loader run
    :func:`prepare` right after Numba's package has executed, before any module can decorate with it; then
    leaves ``sys.meta_path``."""

    def find_spec(self, fullname, path, target=None):
        if fullname != "numba":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is not None and spec.loader is not None:
            spec.loader.exec_module = functools.partial(_execute_then_prepare, spec.loader.exec_module)
        return spec


def _execute_then_prepare(execute, module) -> None:
    execute(module)
    prepare()


def prepare_when_numba_loads() -> None:
    """Run :func:`prepare` now when Numba is already imported, else as soon as something imports it: so that
    ``import tumble`` does not import Numba (0.25 CPU s), yet every compiled module finds Numba prepared."""
    if "numba" in sys.modules:
        prepare()
    elif not any(isinstance(finder, _AfterNumbaLoads) for finder in sys.meta_path):
        sys.meta_path.insert(0, _AfterNumbaLoads())


def cache_directories(package: Path = PACKAGE) -> list[Path]:
    """The existing directories where Numba keeps compiled code of ``package``'s functions, named as Numba names
    them: for each source directory, its directory under ``NUMBA_CACHE_DIR`` when that is set, else its
    ``__pycache__`` and (Numba's fallback when that is not writable) its directory under the user's cache
    directory."""
    from numba.core import caching, config
    from numba.misc.appdirs import AppDirs

    found = []
    for directory in sorted({path.parent for path in package.rglob("*.py") if "__pycache__" not in path.parts}):
        subpath = caching._CacheLocator.get_suitable_cache_subpath(str(directory / "__init__.py"))
        user_wide = Path(AppDirs(appname="numba", appauthor=False).user_cache_dir) / subpath
        candidates = [Path(config.CACHE_DIR) / subpath] if config.CACHE_DIR else [directory / "__pycache__", user_wide]
        found += [candidate for candidate in candidates if candidate.is_dir()]
    return found


def cached_files(package: Path = PACKAGE) -> list[Path]:
    """Numba's index (``.nbi``) and data (``.nbc``) files of ``package``'s compiled functions."""
    return [path for directory in cache_directories(package) for pattern in ("*.nbi", "*.nbc")
            for path in sorted(directory.glob(pattern))]
