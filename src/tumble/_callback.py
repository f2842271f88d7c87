"""Python functions called back from compiled code: the one registry for every model.

A model that accepts a Python function (an external torque ``f(t, q, omega)``,
a spacecraft control law, a robot's joint-torque law) registers it here and
gets a *slot*, an integer it stores among its compiled parameters. Compiled
code calls :func:`invoke` in object mode with that slot; the call costs a few
microseconds, and a batch that makes such calls runs on one core (the kernel's
``calls_python``).

A registration lasts as long as its *owner*, the object that registered the
function (a :class:`Callback`, held by a :class:`tumble.torques.PythonTorque`,
a control law, ...): the entry goes when the owner is garbage-collected. An
owner made while a model compiles (a plain function wrapped as a torque model)
lives as long as the run, which holds it through :func:`keep_alive`.

Slots are numbers local to a process. A model sent to another process (a
sweep's chunk on a Dask worker) carries its functions as :class:`Callback`
values, which pickle as the function alone and register it again where they
are unpickled, under that process's own slot: a slot number never travels.
"""

from __future__ import annotations

import inspect
import itertools
import weakref
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from tumble._validate import ValidationError

__all__ = ["Callback", "invoke", "keep_alive", "register"]


class _Entry(NamedTuple):
    function: Callable
    field: str       # the argument the function was given as, for the message
    signature: str   # its arguments, e.g. "(t, q, omega)"
    returns: str     # what it must return, e.g. "3 finite numbers (body torque, N·m)"


_ENTRIES: dict[int, _Entry] = {}
_SLOTS = itertools.count()
_KEPT: list[list] = []  # the owners registered inside each open keep_alive() scope


class keep_alive:  # noqa: N801 - used as a function: ``with keep_alive():``
    """Hold every owner registered inside the ``with`` block until it ends (a run: compile, then integrate).

    A class rather than a ``contextlib.contextmanager`` generator: entered on every ``simulate`` call, it
    costs a tenth as much."""

    __slots__ = ()

    def __enter__(self) -> None:
        _KEPT.append([])

    def __exit__(self, *exc) -> None:
        _KEPT.pop()


def register(owner, function: Callable, *, field: str, signature: str, returns: str) -> int:
    """Register ``function`` for as long as ``owner`` lives; returns its slot.

    ``field``, ``signature`` and ``returns`` word the error raised when the
    function returns something other than what its caller needs.
    """
    if not callable(function):
        raise ValidationError(f"{field}: must be a callable f{signature}, got {function!r}")
    _require_arity(function, field, signature)
    slot = next(_SLOTS)
    _ENTRIES[slot] = _Entry(function, field, signature, returns)
    weakref.finalize(owner, _ENTRIES.pop, slot, None)
    if _KEPT:
        _KEPT[-1].append(owner)
    return slot


def _require_arity(function: Callable, field: str, signature: str) -> None:
    """Refuse a function that cannot be called with the arguments of ``signature`` (e.g. ``"(t, q, omega)"``,
    passed by position), naming ``field`` and the function's own signature; a callable whose signature Python
    cannot read (some built-ins) is taken as it is."""
    names = [name.strip() for name in signature.strip("()").split(",")]
    try:
        own = inspect.signature(function)
    except (TypeError, ValueError):
        return
    try:
        own.bind(*names)
    except TypeError:
        name = getattr(function, "__name__", type(function).__name__)
        raise ValidationError(f"{field}: the function {name}{own} must take the {len(names)} arguments "
                              f"{signature}") from None


def invoke(slot: int, t: float, args: tuple, out: np.ndarray) -> None:
    """``out[:] = f(t, *args)`` for the function in ``slot`` (each argument passed as a fresh copy).

    Raises :class:`~tumble.ValidationError` naming the function when its
    result does not have the shape of ``out`` or is not finite.
    """
    entry = _ENTRIES[int(slot)]
    result = entry.function(float(t), *(np.array(a) for a in args))
    try:
        value = None if result is None else np.asarray(result, dtype=np.float64)  # asarray(None) would be nan
    except (TypeError, ValueError):
        value = None  # not numbers at all (a string, a ragged list): said as returned, below
    if value is None or value.shape != out.shape or not np.all(np.isfinite(value)):
        name = getattr(entry.function, "__name__", repr(entry.function))
        raise ValidationError(f"{entry.field}: the function {name}{entry.signature} must return {entry.returns}; "
                              f"at t={t} it returned {result!r}")
    out[:] = value


class Callback:
    """A Python function registered for compiled code: ``slot`` is its slot in this process's registry, for as
    long as this object lives.

    Pickled (a model sent to a Dask worker), it carries the function and the wording of its errors, not the
    slot; unpickled, it registers the function in the receiving process and takes the slot given there."""

    __slots__ = ("function", "field", "signature", "returns", "slot", "__weakref__")

    def __init__(self, function: Callable, *, field: str, signature: str, returns: str) -> None:
        self.function, self.field, self.signature, self.returns = function, field, signature, returns
        self.slot = register(self, function, field=field, signature=signature, returns=returns)

    def __reduce__(self):
        return _registered, (self.function, self.field, self.signature, self.returns)

    def __repr__(self):
        return f"Callback({getattr(self.function, '__name__', self.function)!r}, field={self.field!r})"


def _registered(function: Callable, field: str, signature: str, returns: str) -> Callback:
    """A :class:`Callback` unpickled: the function registered in this process."""
    return Callback(function, field=field, signature=signature, returns=returns)
