"""Input checks shared by every public entry point.

Each check raises :class:`tumble.ValidationError` (a ``ValueError``) with a
message that names the field and the rule it breaks, e.g.
``"omega0: must be finite (found nan at index 1)"``.
"""

from __future__ import annotations

import numpy as np


class ValidationError(ValueError):
    """Invalid input: the message names the field and the rule it breaks."""


def as_array(value, name: str, *, tail: tuple[int, ...] = (), finite: bool = True) -> np.ndarray:
    """Return ``value`` as a float64 array whose trailing axes are ``tail``.

    Raises :class:`ValidationError` naming ``name`` when the value is not
    numeric, has the wrong trailing shape, or (with ``finite``) holds NaN/inf.
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValidationError(f"{name}: must be an array of numbers ({exc})") from None
    if tail and (arr.ndim < len(tail) or arr.shape[arr.ndim - len(tail):] != tail):
        want = "(…, " + ", ".join(map(str, tail)) + ")"
        raise ValidationError(f"{name}: must have shape {want}, got {arr.shape}")
    if finite:
        require_finite(arr, name)
    return arr


def require_finite(arr: np.ndarray, name: str) -> None:
    """Raise :class:`ValidationError` if ``arr`` holds NaN or ±inf."""
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f" at index {idx[0] if len(idx) == 1 else idx}" if arr.ndim else ""
        raise ValidationError(f"{name}: must be finite (found {arr[bad].flat[0]}{where})")


def require_positive(x: float, name: str) -> float:
    """Return ``float(x)`` if it is finite and > 0, else raise naming ``name``."""
    x = float(x)
    if not np.isfinite(x) or x <= 0.0:
        raise ValidationError(f"{name}: must be a finite number > 0, got {x}")
    return x


def require_non_negative(x: float, name: str) -> float:
    """Return ``float(x)`` if it is finite and >= 0, else raise naming ``name``."""
    x = float(x)
    if not np.isfinite(x) or x < 0.0:
        raise ValidationError(f"{name}: must be a finite number >= 0, got {x}")
    return x
