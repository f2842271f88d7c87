"""The example files installed with the package: scenarios, robot descriptions and INS data.

Every scenario, robot (DH tables, the Panda's URDF) and data file the
documentation uses ships inside the package, so the docs run from any
directory once ``tumble`` is installed::

    >>> import tumble
    >>> arm = tumble.robot.load(tumble.examples.path("puma560.toml"))

A file is named by its path under this directory (``"robots/puma560.toml"``)
or, where that is unique, by its bare file name (``"puma560.toml"``).
:func:`names` lists them; :func:`copy` copies them all into a directory to
edit (``tumble examples list``, ``tumble examples copy DIR``). Scenario files
name their robot files by relative paths (``../robots/panda.urdf``), which
hold both here and in a copy.
"""

from __future__ import annotations

import shutil
from importlib import resources
from pathlib import Path

from tumble._validate import ValidationError

__all__ = ["copy", "directory", "names", "path"]

# What is an example file: data, scenarios and scripts, not this module or Python's caches.
_SUFFIXES = frozenset({".toml", ".urdf", ".csv", ".md", ".py"})


def directory() -> Path:
    """The directory the example files are installed in (ordinary files: a wheel or an editable install)."""
    return Path(str(resources.files(__name__)))


def names() -> list[str]:
    """Every example file as a path relative to the examples directory (``"robots/puma560.toml"``), sorted."""
    root = directory()
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*")
                  if p.is_file() and p.suffix in _SUFFIXES and p != root / "__init__.py"
                  and "__pycache__" not in p.parts)


def path(name: str) -> Path:
    """The installed path of the example file ``name``.

    ``name`` is a path under the examples directory (``"robots/puma560.toml"``) or the bare name of a
    file that occurs once (``"puma560.toml"``). Raises :class:`tumble.ValidationError` ``name: ...`` for
    an unknown or ambiguous name; the message lists the files.
    """
    if not isinstance(name, str) or not name:
        raise ValidationError(f"name: must be the name of an example file, got {name!r}")
    known = names()
    if name in known:
        return directory() / name
    matches = [n for n in known if n.rsplit("/", 1)[-1] == name]
    if len(matches) == 1:
        return directory() / matches[0]
    if matches:
        raise ValidationError(f"name: {name!r} is ambiguous: give one of {', '.join(matches)}")
    raise ValidationError(f"name: no example file {name!r}; the files are: {', '.join(known)}")


def copy(destination: str | Path) -> list[Path]:
    """Copy every example file into the directory ``destination`` (created if missing), keeping the
    sub-directories.

    Refuses (``destination: ...``) to overwrite a file that exists there; returns the paths written.
    """
    target = Path(destination)
    if target.exists() and not target.is_dir():
        raise ValidationError(f"destination: {str(target)!r} exists and is not a directory")
    files = names()
    clashes = [n for n in files if (target / n).exists()]
    if clashes:
        raise ValidationError(f"destination: {str(target)!r} already has {len(clashes)} of the files "
                              f"({', '.join(clashes[:3])}{', ...' if len(clashes) > 3 else ''}); "
                              "copy into a new or empty directory")
    written = []
    for name in files:
        destination = target / name
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(directory() / name, destination)
        written.append(destination)
    return written
