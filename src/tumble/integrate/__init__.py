"""Integrators: one engine for every model, compiled, batched over bodies.

================  =====  =======================================================
method            order  notes
================  =====  =======================================================
``rk4``           4      fixed step ``dt``; any torque
``dop853``        8      adaptive (``rtol``, ``atol``), Dormand–Prince 8(5,3); any torque
``cf4``           4      fixed step; commutator-free Lie-group method: ``|q| = 1``
                         without projection; any torque
``splitting2``    2      fixed step; Lie–Poisson splitting into exact rotations
                         (Strang): ``|L|``, ``L_N`` and ``|q|`` kept to rounding,
                         energy error bounded; torque-free bodies only
``splitting4``    4      the same, composed to order 4 (Blanes–Moan S₆)
``exact_split2``  2      fixed step; exact free flow composed with torque kicks
                         (Strang): symplectic for potential torques (heavy top)
``exact_split4``  4      the same, composed to order 4 (Blanes–Moan S₆)
``exact``         —      the closed-form free motion (Jacobi elliptic functions),
                         no steps: exact to rounding at any time; torque-free only
================  =====  =======================================================

``rk4`` and ``dop853`` normalise the attitude quaternion after every step
(projection onto ``|q| = 1``); the geometric methods move it by exact
rotations only. Every method returns states exactly at the requested output
times (the fixed-step ones land on them, see :mod:`._fixed`), and runs a
batch of bodies in parallel over the cores (``numba.prange``) unless the
model calls back into Python.

Each method declares what it needs from the compiled model (``Method.needs``,
capability names of :data:`tumble._protocol.CAPABILITIES`), as diffrax solvers
declare the terms they accept; each compiled model says what it provides
(its ``provides`` property). :func:`check_method` is the one check, with one
message naming the method, what it misses and the methods that would work.
The engine imports no particular model.

:func:`solve` is the one entry point used by :func:`tumble.simulate`, which
runs every model.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from tumble._protocol import CAPABILITIES
from tumble._validate import ValidationError, readonly, require_memory, require_positive
from tumble.integrate import _dop853, _exact, _exactsplit, _fixed, _liegroup, _rk4, _splitting

__all__ = ["MAX_STEPS", "METHODS", "Diverged", "Method", "Solution", "SolverError", "check_method", "check_options",
           "solve"]

#: Default ``max_steps``: the most steps per body of one run, for every method (about 10 s of ``rk4`` on a
#: torque-free rigid body; a run past it is refused, before it starts for the fixed-step methods).
MAX_STEPS = 10**8

#: The largest ``max_steps`` accepted: step counts stay exact whole float64 numbers and fit an int64.
MAX_STEPS_LIMIT = 2**53


class SolverError(RuntimeError):
    """The integrator could not reach the requested times (the message says what to change)."""


class Diverged(SolverError):
    """The state stopped being finite: ``index`` is the first output sample that is not, ``member`` the batch
    member, ``states`` the output samples, ``method`` the method's name (:func:`tumble.simulate` turns it into
    a message naming the time and the body rate)."""

    def __init__(self, message: str, index: int, member: int, states: np.ndarray, method: str) -> None:
        super().__init__(message)
        self.index, self.member, self.states, self.method = index, member, states, method


@dataclass(frozen=True)
class Method:
    """An integration method: its name, order, step policy, what it keeps and what it needs.

    conserves : what the method keeps exactly, up to rounding (in words)
    needs     : the capabilities it needs from the compiled model (:data:`tumble._protocol.CAPABILITIES`)
    stepper   : False for a closed form that needs no step (``"exact"``)
    """

    name: str
    order: int
    adaptive: bool
    description: str
    conserves: str = "|q| = 1 by projection"
    needs: frozenset = frozenset({"rhs"})
    stepper: bool = True

    @property
    def options(self) -> tuple[str, ...]:
        """The solver options this method reads (the others are refused by :func:`tumble.simulate`)."""
        if self.adaptive:
            return ("rtol", "atol", "max_steps")
        return ("dt", "max_steps") if self.stepper else ()


_FREE_INVARIANTS = "|L|, L_N and |q| = 1 (exact rotations; energy error bounded, symplectic)"

_SPLIT_INVARIANTS = ("symplectic for a torque from a potential (heavy top): energy error bounded, the momentum "
                     "about g kept to rounding; torque-free: the exact motion")

METHODS = {
    "rk4": Method("rk4", _rk4.ORDER, False, "classical Runge–Kutta, fixed step dt"),
    "dop853": Method("dop853", _dop853.ORDER, True, "Dormand–Prince 8(5,3), adaptive rtol/atol"),
    "cf4": Method("cf4", _liegroup.ORDER, False,
                  "commutator-free Lie-group method CF4 (Celledoni–Marthinsen–Owren 2003), fixed step dt",
                  conserves="|q| = 1 without projection (exact rotations)", needs=frozenset({"rhs", "body_rate"})),
    "splitting2": Method("splitting2", _splitting.ORDERS["splitting2"], False,
                         "Lie–Poisson splitting of the free body into exact rotations, Strang, fixed step dt",
                         conserves=_FREE_INVARIANTS, needs=frozenset({"torque_free"})),
    "splitting4": Method("splitting4", _splitting.ORDERS["splitting4"], False,
                         "Lie–Poisson splitting of the free body into exact rotations, Blanes–Moan S6, "
                         "fixed step dt", conserves=_FREE_INVARIANTS, needs=frozenset({"torque_free"})),
    "exact_split2": Method("exact_split2", _exactsplit.ORDERS["exact_split2"], False,
                           "exact free flow composed with torque kicks, Strang, fixed step dt",
                           conserves=_SPLIT_INVARIANTS, needs=frozenset({"free_flow"})),
    "exact_split4": Method("exact_split4", _exactsplit.ORDERS["exact_split4"], False,
                           "exact free flow composed with torque kicks, Blanes–Moan S6, fixed step dt",
                           conserves=_SPLIT_INVARIANTS, needs=frozenset({"free_flow"})),
    "exact": Method("exact", 0, False, "closed-form torque-free motion (tumble.analytic.torque_free), no steps",
                    conserves="T, |L|, L_N and |q| = 1 to rounding (the exact flow)",
                    needs=frozenset({"free_flow", "torque_free"}), stepper=False),
}

# Fixed-step methods: (compiled scheme, right-hand-side evaluations per step).
_SCHEMES = {
    "rk4": (_rk4.SCHEME, 4),
    "cf4": (_liegroup.SCHEME, 4),
    "splitting2": (_splitting.STRANG, 0),
    "splitting4": (_splitting.BLANES_MOAN, 0),
    "exact_split2": (_exactsplit.STRANG, 4),       # torque evaluations: one RK4 kick per step
    "exact_split4": (_exactsplit.BLANES_MOAN, 24),  # six
}

# Output samples per chunk when progress is reported.
_CHUNKS = 100


def check_options(method: str, *, dt: Any, rtol: Any, atol: Any, max_steps: Any) -> Method:
    """Validate the options that ``method`` reads; returns the :class:`Method`.

    Options the method does not read are not looked at here (:func:`tumble.simulate`
    refuses them when they are given). The options are taken as given (``Any``): this is where a value that
    is not a positive number, or a ``max_steps`` that is not a whole number, is refused.
    """
    if method not in METHODS:
        raise ValidationError(f"method: must be one of {sorted(METHODS)}, got {method!r}")
    m = METHODS[method]
    if m.stepper:
        _check_max_steps(max_steps)
    if m.adaptive:
        require_positive(rtol, "rtol")
        require_positive(atol, "atol")
        if rtol < 1e-15:
            raise ValidationError(f"rtol: must be >= 1e-15 (float64 cannot do better), got {rtol}")
    elif m.stepper:
        if dt is None:
            raise ValidationError(f"dt: method {method!r} has a fixed step: give dt > 0 (s)")
        require_positive(dt, "dt")
    return m


def _check_max_steps(max_steps) -> None:
    """Refuse a ``max_steps`` that is not a whole number from 1 to :data:`MAX_STEPS_LIMIT`."""
    whole = (isinstance(max_steps, (int, float, np.integer, np.floating)) and not isinstance(max_steps, bool)
             and float(max_steps).is_integer())
    if whole and max_steps < 1:
        raise ValidationError(f"max_steps: must be >= 1, got {max_steps!r}")
    if not whole or max_steps > MAX_STEPS_LIMIT:
        raise ValidationError(f"max_steps: must be a whole number from 1 to 2**53 = {MAX_STEPS_LIMIT}, "
                              f"got {max_steps!r}")


def check_method(method: str, provides: Collection[str], who: str) -> Method:
    """Refuse ``method`` unless the model provides every capability it needs; returns the :class:`Method`.

    ``provides`` is the set of capabilities of the compiled model and ``who``
    names the model in the message (e.g. ``"a SloshBody"``), which lists what
    the method misses and the methods that would work.
    """
    if method not in METHODS:
        raise ValidationError(f"method: must be one of {sorted(METHODS)}, got {method!r}")
    m = METHODS[method]
    missing = m.needs - set(provides)
    if missing:
        needs = " and ".join(CAPABILITIES[c] for c in sorted(missing))
        working = ", ".join(repr(name) for name, other in METHODS.items() if other.needs <= set(provides))
        raise ValidationError(f"method: {method!r} needs {needs}, which {who} is not; "
                              f"methods for it: {working}")
    return m


@dataclass(frozen=True)
class Solution:
    """The result of :func:`solve`.

    states     : (len(t), N, n) the states at the output times
    n_steps    : steps taken, summed over the batch (0 for ``"exact"``)
    n_rejected : adaptive steps rejected, summed over the batch
    n_rhs      : right-hand-side (or torque) evaluations, summed over the batch
    """

    states: np.ndarray
    n_steps: int
    n_rejected: int
    n_rhs: int

    def statistics(self) -> dict[str, int]:
        """``n_steps``, ``n_rejected`` and ``n_rhs`` as a dict (for ``Trajectory.info``)."""
        return {"n_steps": self.n_steps, "n_rejected": self.n_rejected, "n_rhs": self.n_rhs}


def solve(model: Any, y0: np.ndarray, t: np.ndarray, *, method: str, dt: float | None = None, rtol: float | None = None,
          atol: float | None = None, max_steps: int = MAX_STEPS, progress: Callable[[int, int], None] | None = None,
          device: str = "cpu", overwrite_y0: bool = False) -> Solution:
    """Integrate the compiled ``model`` (:mod:`tumble._protocol`) for a batch of states ``y0`` (N, n) through ``t``.

    ``t`` (s) must be strictly increasing (:func:`tumble._validate.output_times`).
    A model whose ``calls_python`` is true runs body after body on one core.
    ``progress(done, total)`` is called after each chunk of output samples.
    ``device="cuda"`` runs ``rk4`` on an NVIDIA GPU (models that provide ``"cuda"``).

    Bounded before anything runs: a fixed-step run needing more than ``max_steps`` steps per body is
    refused (:func:`._fixed.landing_steps`), and so are states that would not fit in memory
    (:func:`tumble._validate.require_memory`). A state that stops being finite stops the run at the
    end of the chunk of output samples it is in, with :class:`Diverged`.

    With ``overwrite_y0``, a C-ordered float64 ``y0`` is integrated in place (it ends as the final states)
    instead of copied, as ``scipy.linalg``'s ``overwrite_a``: a caller that made ``y0`` for the run saves
    a copy (:func:`tumble.simulate`; 56 bytes per rigid body).
    """
    m = check_method(method, model.provides, f"a {type(model).__name__}")
    check_options(method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps)
    y = (np.asarray if overwrite_y0 else np.array)(y0, dtype=np.float64, order="C")
    t = readonly(t)  # the form simulate's output times come in: the drivers compile once
    n_out = t.shape[0]
    require_memory(n_out * y.shape[0] * y.shape[1] * 8, "t", f"the states at {n_out} output times × {y.shape[0]} "
                   f"member(s) × {y.shape[1]} values")
    if device == "cuda":
        from tumble.integrate import _cuda  # imports numba.cuda: only when asked for

        states, n_steps = _cuda.solve_cuda(model, y, t, dt, max_steps)
        _raise_on_divergence(states, method)
        return Solution(states, n_steps, 0, 4 * n_steps)
    steps = _fixed.landing_steps(t, cast(float, dt), max_steps) if method in _SCHEMES else None  # dt checked
    out = np.empty((n_out, y.shape[0], y.shape[1]))
    stats = np.zeros((y.shape[0], 5))
    bounds = [0, n_out - 1]
    if progress is not None and n_out > 2 and m.stepper:
        bounds = np.unique(np.linspace(0, n_out - 1, min(_CHUNKS, n_out - 1) + 1).astype(int)).tolist()
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        chunk = None if steps is None else (steps[0][lo:hi], steps[1][lo:hi])
        _run_chunk(method, model, y, t[lo:hi + 1], out[lo:hi + 1], stats,
                   steps=chunk, rtol=rtol, atol=atol, max_steps=max_steps, serial=model.calls_python)
        _raise_on_failure(stats, t, max_steps)  # first: a body that gave up left its later rows unwritten
        _raise_on_divergence(out, method, lo, hi)
        if progress is not None:
            progress(hi + 1, n_out)
    if n_out == 1:
        out[0] = y
    def total(k):  # statistic k summed over the members (a lone body's own: no reduction to set up)
        return int(stats[0, k] if stats.shape[0] == 1 else stats[:, k].sum())

    n_steps = total(0)
    # a fixed-step method: a set number of evaluations per step (counted here, not per body)
    n_rhs = _SCHEMES[method][1] * n_steps if method in _SCHEMES else total(2)
    return Solution(out, n_steps, total(1), n_rhs)


def _run_chunk(method, model, y, t, out, stats, *, steps, rtol, atol, max_steps, serial):
    # One body, or a model that calls back into Python: no parallel region
    # (its start-up costs more than a short run, and callbacks need the GIL).
    # Nor for a fixed-step batch of one block (at most LANES bodies): its one task runs on one core anyway,
    # and the parallel driver is not compiled for it.
    serial = serial or y.shape[0] == 1
    if method == "exact":
        _exact.run(model, y, t, out)
    elif method in _SCHEMES:
        scheme, _ = _SCHEMES[method]
        m, h = steps
        if y.shape[0] == 1:
            _fixed.run_one(scheme, model, y, t, m, h, out, stats)
        elif serial or y.shape[0] <= _fixed.LANES:
            for k in range(-(-y.shape[0] // _fixed.LANES)):
                _fixed.run_block(scheme, model, k, y, t, m, h, out, stats)
        else:
            _fixed.run_batch(scheme, model, y, t, m, h, out, stats)
    elif serial:
        for b in range(y.shape[0]):
            _dop853.dop853_path(model, b, y[b], t, rtol, atol, max_steps, _dop853.tableau(), out[:, b], stats[b])
    else:
        _dop853.dop853_batch(model, y, t, rtol, atol, max_steps, _dop853.tableau(), out, stats)


def _raise_on_divergence(states, method, lo=0, hi=None):
    """Raise :class:`Diverged` at the first output sample of ``states[lo:hi + 1]`` that is not finite."""
    rows = states[lo:None if hi is None else hi + 1]
    if np.isfinite(rows).all():  # the usual case in one pass: 3.6 ms for 10 000 members x 101 x 7, 17.6 ms below
        return
    finite = np.isfinite(rows).reshape(rows.shape[0], rows.shape[1], -1).all(axis=2)
    k, member = (int(i) for i in np.argwhere(~finite)[0])
    raise Diverged(f"simulation diverged at output sample {lo + k} (body {member})", lo + k, member, states, method)


def _raise_on_failure(stats, t, max_steps):
    failed = stats[:, 3] != _dop853.OK
    if not failed.any():
        return
    bad = np.flatnonzero(failed)
    b = int(bad[0])
    who = f"body {b}: " if stats.shape[0] > 1 else ""
    if stats[b, 3] == _dop853.STEP_TOO_SMALL:
        raise SolverError(f"{who}the step size fell below the float64 resolution of t; the motion may be "
                          "singular there, or loosen rtol/atol (or, for times far from 0, shift them nearer to it)")
    if stats[b, 3] == _dop853.TOO_MANY_PROJECTED:
        need = f"{stats[b, 4]:.2g}" if stats[b, 4] < np.inf else "more than 1e308"
        raise SolverError(f"{who}max_steps: the run would need {need} steps or more to t={t[-1]:g} "
                          f"(projected from its first {int(stats[b, 0])} at their mean step size), more than "
                          f"max_steps = {max_steps:g}; shorten the run or loosen rtol/atol")
    raise SolverError(f"{who}max_steps={int(stats[b, 0])} reached before t={t[-1]}; raise max_steps "
                      "or loosen rtol/atol")
