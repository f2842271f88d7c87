"""``tumble.sweep``: the function :func:`tumble.sweeps.sweep`; the sweeps package is :mod:`tumble.sweeps`.

``tumble.sweep`` was the package itself, made callable. The package's old
spellings keep working until tumble 0.5 with a :class:`DeprecationWarning`
that names the new one: ``tumble.sweep.NAME`` and ``from tumble.sweep import
NAME`` give ``tumble.sweeps.NAME``; ``import tumble.sweep.MODULE`` and ``from
tumble.sweep.MODULE import NAME`` give the module ``tumble.sweeps.MODULE``.

For that, importing this module puts in its place (``sys.modules``, and so the
attribute ``tumble.sweep`` that ``import tumble.sweep`` binds) one
:class:`_Sweep`: the function, which also answers for the package's names; the
package's modules are found under their old names by :func:`tumble._moved.moved_modules`. In 0.5 this
file goes and ``tumble.sweep`` is :func:`tumble.sweeps.sweep` itself.
"""

from __future__ import annotations

import functools
import pkgutil
import sys
from typing import Any

from tumble import sweeps
from tumble._moved import deprecated, moved_modules

_OLD, _NEW = "tumble.sweep", "tumble.sweeps"


class _Sweep:
    """:func:`tumble.sweeps.sweep`, which also answers for the names of the package that ``tumble.sweep`` was
    (deprecated: each gives the name of :mod:`tumble.sweeps`, with a warning)."""

    __path__: list[str] = []  # a package to the import system, so that its modules are looked for (_Modules)

    def __init__(self, spec) -> None:
        functools.update_wrapper(self, sweeps.sweep)
        self.__spec__ = spec  # this file's, which the import system reads from a package

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return sweeps.sweep(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):  # what tools ask of any object: none of the package's names
            raise AttributeError(name)
        value = getattr(sweeps, name)
        deprecated(f"{_OLD}.{name}", f"{_NEW}.{name}")
        return value


# the package's modules under their old names (not tumble.sweep itself, this file)
moved_modules({f"{_OLD}.{m.name}": f"{_NEW}.{m.name}" for m in pkgutil.iter_modules(sweeps.__path__)})
sys.modules[__name__] = _Sweep(__spec__)  # type: ignore[assignment]
