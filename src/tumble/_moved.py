"""Public names that moved to another module keep working from their old place for one release, with a warning.

A module whose names moved sets ``__getattr__ = moved(__name__, {"name": "new.module", ...})`` (PEP 562): reading
``old.name`` warns (:class:`DeprecationWarning` naming the new place) and returns ``new.module.name``. The new
module is imported by name when the old name is read, so the old module, often a layer below the new one (a model
below its figures in :mod:`tumble.viz`), does not import it.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["moved"]


def moved(module: str, names: Mapping[str, str]) -> Callable[[str], Any]:
    """The ``__getattr__`` of ``module`` for its ``names`` that moved, each to the module it names."""

    def __getattr__(name: str) -> Any:
        if name not in names:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        warnings.warn(f"{module}.{name} moved to {names[name]}.{name}; the old name is removed in the next release",
                      DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(names[name]), name)

    return __getattr__
