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

Each method file declares its methods (:class:`Method`: name, order, options
with their defaults and rules, evaluations per step, driver, and what it needs
from the compiled model, capability names of
:data:`tumble._protocol.CAPABILITIES`, as diffrax solvers declare the terms
they accept); :data:`METHODS` is built from those declarations and
:func:`method` is the one place a name is checked. Each compiled model says
what it provides (its ``provides`` property); :func:`check_method` is the one
check, with one message naming the method, what it misses and the methods that
would work. The engine imports no particular model.

:func:`solve` is the one entry point used by :func:`tumble.simulate`, which
runs every model; :class:`Run` is the same run advanced chunk by chunk of
output times, for an analysis that acts on the states between them
(:func:`tumble.measure.lyapunov_exponents`).
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any

import numpy as np

from tumble._protocol import CAPABILITIES
from tumble._validate import ValidationError, readonly, require_memory
from tumble.integrate import _dop853, _exact, _exactsplit, _liegroup, _rk4, _splitting
from tumble.integrate._method import MAX_STEPS, MAX_STEPS_LIMIT, Driver, Method, Option

__all__ = ["MAX_STEPS", "MAX_STEPS_LIMIT", "METHODS", "Diverged", "Driver", "Method", "Option", "Run", "Solution",
           "SolverError", "check_method", "method", "solve"]

#: Every method by name, as the method files declare them (their ``METHODS``), in the order of the table above.
#: Adding a method is its file and its entry here (and its row in the order test, tests/integrate/test_methods.py).
METHODS: dict[str, Method] = {m.name: m for module in (_rk4, _dop853, _liegroup, _splitting, _exactsplit, _exact)
                              for m in module.METHODS}


class SolverError(RuntimeError):
    """The integrator could not reach the requested times (the message says what to change)."""


class Diverged(SolverError):
    """The state stopped being finite: ``index`` is the first output sample that is not, ``member`` the batch
    member, ``states`` the output samples, ``method`` the method's name (:func:`tumble.simulate` turns it into
    a message naming the time and the body rate)."""

    def __init__(self, message: str, index: int, member: int, states: np.ndarray, method: str) -> None:
        super().__init__(message)
        self.index, self.member, self.states, self.method = index, member, states, method


# Output samples per chunk when progress is reported.
_CHUNKS = 100


def method(name: Any) -> Method:
    """The :class:`Method` called ``name``: the one check of a method's name (a
    :class:`~tumble.ValidationError` naming ``method`` lists the valid names)."""
    if not isinstance(name, str) or name not in METHODS:
        raise ValidationError(f"method: must be one of {sorted(METHODS)}, got {name!r}")
    return METHODS[name]


def check_method(name: str, provides: Collection[str], who: str) -> Method:
    """Refuse the method ``name`` unless the model provides every capability it needs; returns the
    :class:`Method`.

    ``provides`` is the set of capabilities of the compiled model and ``who``
    names the model in the message (e.g. ``"a SloshBody"``), which lists what
    the method misses and the methods that would work.
    """
    m = method(name)
    missing = m.needs - set(provides)
    if missing:
        needs = " and ".join(CAPABILITIES[c] for c in sorted(missing))
        working = ", ".join(repr(other.name) for other in METHODS.values() if other.needs <= set(provides))
        raise ValidationError(f"method: {name!r} needs {needs}, which {who} is not; methods for it: {working}")
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


class Run:
    """A run of the method ``method`` on the compiled ``model`` (:mod:`tumble._protocol`) from the states
    ``y0`` (N, n) at ``t[0]`` through the output times ``t`` (s, strictly increasing), advanced chunk by
    chunk of output times, as scipy's ``OdeSolver.step``.

    ``y`` (N, n) holds the states at ``t[reached]``; between chunks a caller may change them in place (an
    analysis that re-orthonormalises tangent vectors). The method's driver carries its step size and step
    count from one chunk to the next, so a run advanced in chunks takes the steps of the run made at once
    (DOP853 evaluates its first stage again at each chunk: the states agree to rounding).

    ``options`` are the solver options (``dt``, ``rtol``, ``atol``, ``max_steps``): those the method reads,
    checked against its rules, defaults filled in (:meth:`Method.resolve`); with ``overwrite_y0``, a
    C-ordered float64 ``y0`` is integrated in place instead of copied (as ``scipy.linalg``'s ``overwrite_a``).
    ``parallel=False`` runs the batch on one core: for a caller that advances many short chunks, where
    starting a parallel region for each would cost more than it saves.
    """

    def __init__(self, model: Any, y0: np.ndarray, t: np.ndarray, *, method: str, overwrite_y0: bool = False,
                 parallel: bool = True, **options: Any) -> None:
        self.method = check_method(method, model.provides, f"a {type(model).__name__}")
        self.options = self.method.resolve(options)
        self.model = model
        self.t = readonly(t)  # the form simulate's output times come in: the drivers compile once
        self.y = (np.asarray if overwrite_y0 else np.array)(y0, dtype=np.float64, order="C")
        # before anything runs: a fixed-step run needing more than max_steps is refused (_fixed.landing_steps)
        self.plan = self.method.driver.plan(self.t, self.options)
        self.stats = np.zeros((self.y.shape[0], 5))
        self.reached = 0
        # one body, or a model that calls back into Python: no parallel region (its start-up costs more than
        # a short run, and callbacks need the GIL)
        self.serial = not parallel or bool(model.calls_python) or self.y.shape[0] == 1

    def advance(self, hi: int, out: np.ndarray) -> None:
        """Advance the states to ``t[hi]``; ``out`` (hi − reached + 1, N, n) receives them at ``t[reached]``
        … ``t[hi]``. A member that cannot go on (step too small, ``max_steps``) raises :class:`SolverError`."""
        self.method.driver.advance(self.model, self.y, self.t, self.reached, hi, out, self.stats, self.plan,
                                   self.serial)
        _raise_on_failure(self.stats, self.t, self.options.get("max_steps"))
        self.reached = hi

    def total(self, k: int) -> int:
        """Statistic ``k`` (0 steps, 1 rejected steps, 2 evaluations) summed over the members (a lone body's
        own: no reduction to set up)."""
        return int(self.stats[0, k] if self.stats.shape[0] == 1 else self.stats[:, k].sum())

    def solution(self, states: np.ndarray) -> Solution:
        """The :class:`Solution` of the run, with its sampled ``states``: a fixed-step method makes its
        declared evaluations per step (counted here, not per body); an adaptive one counts its own."""
        n_steps = self.total(0)
        n_rhs = self.total(2) if self.method.adaptive else self.method.evaluations * n_steps
        return Solution(states, n_steps, self.total(1), n_rhs)


def solve(model: Any, y0: np.ndarray, t: np.ndarray, *, method: str, progress: Callable[[int, int], None] | None = None,
          device: str = "cpu", overwrite_y0: bool = False, **options: Any) -> Solution:
    """Integrate the compiled ``model`` (:mod:`tumble._protocol`) for a batch of states ``y0`` (N, n) through ``t``.

    ``t`` (s) must be strictly increasing (:func:`tumble._validate.output_times`); ``options`` are the
    solver options the method reads (:class:`Run`).
    A model whose ``calls_python`` is true runs body after body on one core.
    ``progress(done, total)`` is called after each chunk of output samples.
    ``device="cuda"`` runs ``rk4`` or ``cf4`` on an NVIDIA GPU (models that provide ``"cuda"``); ``y0`` may
    be a device array there, and the states are then left on the device.

    Bounded before anything runs: a fixed-step run needing more than ``max_steps`` steps per body is
    refused (:func:`._fixed.landing_steps`), and so are states that would not fit in memory
    (:func:`tumble._validate.require_memory`). A state that stops being finite stops the run at the
    end of the chunk of output samples it is in, with :class:`Diverged`.

    With ``overwrite_y0``, a C-ordered float64 ``y0`` is integrated in place (it ends as the final states)
    instead of copied, as ``scipy.linalg``'s ``overwrite_a``: a caller that made ``y0`` for the run saves
    a copy (:func:`tumble.simulate`; 56 bytes per rigid body).
    """
    if device == "cuda":
        from tumble.integrate import _cuda  # imports numba.cuda: only when asked for

        return _solve_on_gpu(_cuda, model, y0, t, method, options)
    run = Run(model, y0, t, method=method, overwrite_y0=overwrite_y0, **options)
    y, n_out = run.y, run.t.shape[0]
    require_memory(n_out * y.shape[0] * y.shape[1] * 8, "t", f"the states at {n_out} output times × {y.shape[0]} "
                   f"member(s) × {y.shape[1]} values")
    out = np.empty((n_out, y.shape[0], y.shape[1]))
    bounds = [0, n_out - 1]
    if progress is not None and n_out > 2 and run.method.stepper:
        bounds = np.unique(np.linspace(0, n_out - 1, min(_CHUNKS, n_out - 1) + 1).astype(int)).tolist()
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        run.advance(hi, out[lo:hi + 1])
        _raise_on_divergence(out, method, lo, hi)
        if progress is not None:
            progress(hi + 1, n_out)
    if n_out == 1:
        out[0] = y
    return run.solution(out)


def _solve_on_gpu(gpu, model: Any, y0, t: np.ndarray, method: str, options: dict) -> Solution:
    """:func:`solve` on the GPU (``gpu``: :mod:`tumble.integrate._cuda`, imported by the caller): the states
    left on the device when ``y0`` is there, copied back otherwise. A state that stops being finite raises
    :class:`Diverged` as on the CPU (found on the device; the states copied back for its message)."""
    m = check_method(method, model.provides, f"a {type(model).__name__}")
    options = m.resolve(options)
    host = not gpu.is_on_device(y0)
    if host:
        require_memory(8 * len(t) * y0.shape[0] * y0.shape[1], "t", f"the states at {len(t)} output times × "
                       f"{y0.shape[0]} member(s) × {y0.shape[1]} values")
    states: Any
    states, n_steps = gpu.solve_cuda(model, y0, t, options["dt"], options["max_steps"], method=m.name, keep=True)
    if not gpu.all_finite(states):
        _raise_on_divergence(states.copy_to_host(), method)
    return Solution(states.copy_to_host() if host else states, n_steps, 0, m.evaluations * n_steps)


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
