"""Public names and modules that moved keep working from their old place for one release, with a warning.

A module whose names moved sets ``__getattr__ = moved(__name__, {"name": "new.module", ...})`` (PEP 562): reading
``old.name`` warns (:class:`DeprecationWarning` naming the new place) and returns ``new.module.name``. The new
module is imported by name when the old name is read, so the old module, often a layer below the new one (a model
below its figures in :mod:`tumble.viz`), does not import it.

A module that moved as a whole is named in :func:`moved_modules`: importing it by its old name (or a module under
it, ``old.MODULE``) warns (:func:`deprecated`) and gives the module of the new name itself, so that its classes,
functions and state are the same objects under both names (``tumble.frames.AxisymmetricBody is
tumble.axisymmetric.AxisymmetricBody``) and an object pickled under the old module path loads.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["deprecated", "moved", "moved_modules"]

#: The release in which the deprecated spellings go.
REMOVED_IN = "tumble 0.5"


def moved(module: str, names: Mapping[str, str]) -> Callable[[str], Any]:
    """The ``__getattr__`` of ``module`` for its ``names`` that moved, each to the module it names."""

    def __getattr__(name: str) -> Any:
        if name not in names:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        warnings.warn(f"{module}.{name} moved to {names[name]}.{name}; the old name is removed in the next release",
                      DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(names[name]), name)

    return __getattr__


def deprecated(old: str, new: str) -> None:
    """Warn that the spelling ``old`` is deprecated for ``new``, pointing at the caller's caller (the user's line;
    the import system's own frames are skipped by :func:`warnings.warn`)."""
    warnings.warn(f"{old} is deprecated and will be removed in {REMOVED_IN}: use {new}", DeprecationWarning,
                  stacklevel=3)


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds a module under an old name (``old`` or ``old.MODULE``) as the module of its new name itself."""

    def __init__(self, names: Mapping[str, str]) -> None:
        self.names = dict(names)  # old module name -> new module name

    def _new_name(self, fullname: str) -> str | None:
        for old, new in self.names.items():
            if fullname == old or fullname.startswith(old + "."):
                return new + fullname[len(old):]
        return None

    def find_spec(self, fullname, path, target=None):
        new = self._new_name(fullname)
        if new is None or importlib.util.find_spec(new) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec) -> None:
        return None  # the default module, replaced in sys.modules by exec_module

    def exec_module(self, module) -> None:
        new = self._new_name(module.__name__)
        assert new is not None  # find_spec gave this module's spec
        deprecated(module.__name__, new)
        sys.modules[module.__name__] = importlib.import_module(new)  # the import system returns this one


def moved_modules(names: Mapping[str, str]) -> None:
    """Import each old module name of ``names`` (and every module under it) as its new name, with a
    :class:`DeprecationWarning` naming the new one (:func:`deprecated`).

    The finder goes first on :data:`sys.meta_path`: the old name of a package that moved (``tumble.viewer``) is
    bound to the new package, whose ``__path__`` would otherwise let the path finder load its modules a second
    time under the old name (``tumble.viewer.scenes``). It answers only for the old names, which no file has."""
    sys.meta_path.insert(0, _MovedModules(names))
