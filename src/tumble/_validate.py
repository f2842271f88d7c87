"""Input checks shared by every public entry point.

Each check raises :class:`tumble.ValidationError` (a ``ValueError``) with a
message that names the field and the rule it breaks, e.g.
``"omega0: must be finite (found nan at index 1)"``.
"""

from __future__ import annotations

import functools
import math
import os

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


# Its public name: tracebacks, reprs and pickles say tumble.ValidationError, not this private module.
ValidationError.__module__ = "tumble"


def as_array(value, name: str, *, tail: tuple[int, ...] = (), finite: bool = True) -> np.ndarray:
    """Return ``value`` as a float64 array whose trailing axes are ``tail``.

    Raises :class:`ValidationError` naming ``name`` when the value is not
    real numbers (text such as ``["0", "1", "0"]`` and complex numbers
    included, which NumPy would convert), has the wrong trailing shape, or
    (with ``finite``) holds NaN/inf.
    """
    try:
        arr = value if isinstance(value, np.ndarray) else np.asarray(value)
        kind = "text" if arr.dtype.kind in "USO" and _holds_text(arr) else "complex" if arr.dtype.kind == "c" else ""
        if not kind:
            arr = arr.astype(np.float64, copy=False)
    except (TypeError, ValueError) as exc:
        raise ValidationError(f"{name}: must be an array of numbers ({exc})") from None
    if kind:
        raise ValidationError(f"{name}: must be an array of real numbers, not {kind}, got {value!r}")
    if tail and (arr.ndim < len(tail) or arr.shape[arr.ndim - len(tail):] != tail):
        want = "(…, " + ", ".join(map(str, tail)) + ")"
        raise ValidationError(f"{name}: must have shape {want}, got {arr.shape}")
    if finite:
        require_finite(arr, name)
    return arr


def _holds_text(arr: np.ndarray) -> bool:
    """Whether an array of strings, bytes or objects holds text (a ``str`` or ``bytes`` element)."""
    return arr.dtype.kind in "US" or any(isinstance(x, (str, bytes)) for x in arr.flat)


def readonly(arr: np.ndarray) -> np.ndarray:
    """``arr`` C-contiguous and read-only (a view when it is already contiguous), the one form in which the
    compiled loops that only read an array take it.

    Numba compiles a function once per combination of its arrays' layout and writeability, so handing every
    input over in one form compiles one copy, whether it came from a user or from a Trajectory (whose
    arrays are read-only).
    """
    arr = np.ascontiguousarray(arr)
    if arr.flags.writeable:
        arr = arr.view()
        arr.flags.writeable = False
    return arr


def require_finite(arr: np.ndarray, name: str) -> None:
    """Raise :class:`ValidationError` if ``arr`` holds NaN or ±inf."""
    finite = np.isfinite(arr)
    if finite.all():
        return
    bad = ~finite
    idx = tuple(int(i) for i in np.argwhere(bad)[0])
    where = f" at index {idx[0] if len(idx) == 1 else idx}" if arr.ndim else ""
    raise ValidationError(f"{name}: must be finite (found {arr[bad].flat[0]}{where})")


def _scalar(x, name: str, rule: str) -> float:
    """``float(x)`` for a single number; anything else (a list, a string) is refused naming ``name``."""
    if type(x) is float:
        return x
    try:
        if np.ndim(x) != 0:
            raise TypeError
        return float(x)
    except (TypeError, ValueError):
        raise ValidationError(f"{name}: must be {rule}, got {x!r}") from None


def require_positive(x: float, name: str) -> float:
    """Return ``float(x)`` if it is finite and > 0, else raise naming ``name``."""
    x = _scalar(x, name, "a finite number > 0")
    if not math.isfinite(x) or x <= 0.0:
        raise ValidationError(f"{name}: must be a finite number > 0, got {x}")
    return x


def require_count(n, name: str, minimum: int = 1) -> int:
    """Return ``int(n)`` if ``n`` is an integer (not a bool) >= ``minimum``, else raise naming ``name``."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < minimum:
        raise ValidationError(f"{name}: must be an integer >= {minimum}, got {n!r}")
    return int(n)


def require_non_negative(x: float, name: str) -> float:
    """Return ``float(x)`` if it is finite and >= 0, else raise naming ``name``."""
    x = _scalar(x, name, "a finite number >= 0")
    if not math.isfinite(x) or x < 0.0:
        raise ValidationError(f"{name}: must be a finite number >= 0, got {x}")
    return x


def increasing_times(t, name: str = "t", *, what: str = "output times", at_least: int = 1) -> np.ndarray:
    """``t`` (s) as a 1-D float64 array of at least ``at_least`` strictly increasing times, else a
    :class:`ValidationError` naming ``name``, ``what`` the times are and the first step that does not increase.

    The one check of times, used for the output times of every model (:func:`output_times`) and the sample
    times of tabulated inputs (torques, motor torques, variable inertia)."""
    times = as_array(t, name)
    if times.ndim != 1 or times.size < at_least:
        count = "one" if at_least == 1 else f"at least {at_least}"
        raise ValidationError(f"{name}: must be a 1-D array of {count} {what}, got shape {times.shape}")
    stalled = times[1:] <= times[:-1]  # compared, not subtracted: t = [-1e308, 1e308] is increasing
    if stalled.any():
        k = int(np.flatnonzero(stalled)[0])
        raise ValidationError(f"{name}: {what} must be strictly increasing ({name}[{k + 1}] = {times[k + 1]} "
                              f"<= {name}[{k}] = {times[k]})")
    return times


def output_times(t) -> np.ndarray:
    """The output times ``t`` (s) as a 1-D float64 array of at least one strictly increasing time, C-contiguous
    and read-only (:func:`readonly`: one compiled copy of each driver, whatever array the times came in).

    The one check of output times, used by every model through :func:`tumble.simulate`.
    """
    return readonly(increasing_times(t))



@functools.cache
def memory_bytes() -> int:
    """The machine's physical memory (bytes), or 2⁶³ − 1 where the system does not say."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return 2**63 - 1


def require_memory(nbytes: float, name: str, what: str) -> None:
    """Refuse (naming ``name``) an allocation of ``nbytes`` sized from input — ``what`` says what it holds —
    when it is more than half the machine's physical memory: checked before allocating, so that a hostile
    size is a one-line error, not an hour of swapping or a process killed for memory."""
    limit = memory_bytes() // 2
    if not nbytes <= limit:
        exact = f"{float(nbytes):.2g} bytes" if np.isfinite(nbytes) else "more than 1.8e308 bytes"
        raise ValidationError(f"{name}: {what} need {_binary(nbytes)} ({exact}), more than half this machine's "
                              f"memory ({_binary(2 * limit)}); ask for less")


def _binary(n: float) -> str:
    """``n`` bytes in binary units, e.g. ``"7.3 TiB"``."""
    units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB", "ZiB", "YiB"]
    k, value = 0, float(n)
    while value >= 1024.0 and k < len(units) - 1:
        value /= 1024.0
        k += 1
    return f"{value:.1f} {units[k]}" if np.isfinite(value) else "an unbounded amount"
