"""Where a demo writes: an existing directory, and its figures as PNG files written atomically."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from tumble._files import write_atomic
from tumble._validate import ValidationError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["out_directory", "save_png"]


def out_directory(out_dir: str | os.PathLike[str]) -> str:
    """``out_dir`` as a string, refused (:class:`ValidationError` naming ``out_dir``) unless an existing directory."""
    if not os.path.isdir(out_dir):
        raise ValidationError(f"out_dir: {os.fspath(out_dir)!r} is not an existing directory")
    return os.fspath(out_dir)


def save_png(figure: Figure, path: str | os.PathLike[str]) -> str | os.PathLike[str]:
    """Write ``figure`` to ``path`` as a 120 dpi PNG, atomically (:func:`tumble._files.write_atomic`); returns ``path``."""
    write_atomic(path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))
    return path
