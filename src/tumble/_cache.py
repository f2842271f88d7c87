"""Where Numba caches tumble's compiled code, with a fallback for read-only installs.

Numba's ``cache=True`` looks for a writable directory when a function is
decorated, i.e. when ``import tumble`` runs: ``NUMBA_CACHE_DIR`` if set, else
``__pycache__`` beside the source, else the user's cache directory
(``~/.cache/numba``); with none of them it raises
``RuntimeError: cannot cache function ...: no locator available`` and the
import fails. That happens to a non-root user of a read-only site-packages
whose ``HOME`` is unset or unwritable (a container, a service account).

:func:`ensure_writable_cache` runs before any compiled module is imported: when
neither the package directory nor the user's cache directory can be written
(the same test as Numba's, creating a temporary file there) and
``NUMBA_CACHE_DIR`` is not set, it points Numba at a fresh temporary
directory, for this process and its children, and says so in one warning.
The compiled code is then cached for this process only (the next process
compiles again).
"""

from __future__ import annotations

import os
import tempfile
import warnings

__all__ = ["ensure_writable_cache"]


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
    package = os.path.join(os.path.dirname(os.path.abspath(__file__)), "__pycache__")
    if _writable(package) or _writable(AppDirs(appname="numba", appauthor=False).user_cache_dir):
        return None
    directory = tempfile.mkdtemp(prefix="tumble-numba-cache-")
    config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"] = directory
    warnings.warn(f"tumble: neither the package directory nor the user's cache directory is writable (HOME unset or "
                  f"read-only?): compiled code is cached in {directory} for this process only; set NUMBA_CACHE_DIR "
                  "to a writable directory to keep it", RuntimeWarning, stacklevel=3)
    return directory
