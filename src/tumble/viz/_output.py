"""Where a demo writes: an existing directory, its figures as PNG files and its pages as text, written atomically."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from tumble._files import write_atomic
from tumble._validate import ValidationError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["out_directory", "png_writer", "save_png", "text_writer"]


def out_directory(out_dir: str | os.PathLike[str]) -> str:
    """``out_dir`` as a string, refused (:class:`ValidationError` naming ``out_dir``) unless an existing directory."""
    if not os.path.isdir(out_dir):
        raise ValidationError(f"out_dir: {os.fspath(out_dir)!r} is not an existing directory")
    return os.fspath(out_dir)


def png_writer(figure: Figure) -> Callable[[str], None]:
    """The write of ``figure`` as a 120 dpi PNG for :func:`tumble._files.write_atomic_all`."""
    def write(tmp_path: str) -> None:
        figure.savefig(tmp_path, format="png", dpi=120)

    return write


def text_writer(text: str) -> Callable[[str], None]:
    """The write of ``text`` (UTF-8) for :func:`tumble._files.write_atomic_all`."""
    def write(tmp_path: str) -> None:
        Path(tmp_path).write_text(text, encoding="utf-8")

    return write


def save_png(figure: Figure, path: str | os.PathLike[str]) -> str | os.PathLike[str]:
    """Write ``figure`` to ``path`` as a 120 dpi PNG, atomically (:func:`tumble._files.write_atomic`); returns ``path``."""
    write_atomic(path, png_writer(figure))
    return path
