"""Input checks shared by every public entry point.

Each check raises :class:`tumble.ValidationError` (a ``ValueError``) with a
message that names the field and the rule it breaks, e.g.
``"omega0: must be finite (found nan at index 1)"``.
"""

from __future__ import annotations

import numpy as np


class ValidationError(ValueError):
    """Invalid input: the message is ``"FIELD: RULE"``, naming the field and the rule it breaks.

    ``field`` and ``rule`` give the two parts (``field`` is ``""`` for a
    message that names no field), so that callers such as the scenario files
    can map the field to their own keys without reading the text.
    """

    @property
    def field(self) -> str:
        """The field the message names (an argument, a key path such as ``inertia[1]``), or ``""``."""
        head, sep, _ = str(self).partition(": ")
        return head if sep and " " not in head else ""

    @property
    def rule(self) -> str:
        """The rule that was broken: the message after ``"FIELD: "``."""
        text = str(self)
        return text[len(self.field) + 2:] if self.field else text


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


def output_times(t) -> np.ndarray:
    """The output times ``t`` (s) as a 1-D float64 array of at least one strictly increasing time.

    The one check of output times, used by every model through :func:`tumble.simulate`.
    """
    times = as_array(t, "t")
    if times.ndim != 1 or times.size < 1:
        raise ValidationError(f"t: must be a 1-D array of output times, got shape {times.shape}")
    steps = np.diff(times)
    if np.any(steps <= 0.0):
        k = int(np.flatnonzero(steps <= 0.0)[0])
        raise ValidationError(
            f"t: output times must be strictly increasing (t[{k + 1}] = {times[k + 1]} <= t[{k}] = {times[k]})"
        )
    return times

