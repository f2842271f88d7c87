"""The front door: ``simulate(model, ...)`` runs every model, and :class:`Model` is what a model implements.

One function integrates every model of the package: a rigid body (or a batch
of them), a hub with flexible appendages, a sloshing hub, a body whose inertia
changes, a spacecraft with actuators and controllers, a robot arm, a
gyroscope. Everything common to them is written here once, as
``scipy.integrate``'s ``check_arguments`` is: the output times, the solver
options (refused when the method does not read them), the initial state by
name (unknown names refused, quaternions checked and normalised, batches
broadcast), which method applies to which model (:func:`tumble.integrate.check_method`),
progress reporting, the device, and the one result type :class:`~tumble.Trajectory`.

A model is an immutable, validated description (MuJoCo's ``MjModel``,
Pinocchio's ``Model``) that implements :class:`Model` once:

* :meth:`Model.state_fields`: the named parts of its initial state (the
  keywords of :func:`simulate`, e.g. ``omega0``, ``q0``, ``wheel_speeds0``);
* :meth:`Model.compile`: its compiled kernel (:mod:`tumble.kernels`) under a
  torque, which says which methods it provides for (``provides``);
* :meth:`Model.initial_states`: the state vectors from the named values;
* :meth:`Model.outputs`: the :class:`~tumble.Trajectory` fields from the
  integrated states (attitude, body rate, named extras, the system's totals);
* :meth:`Model.invariants`: what its exact motion keeps constant on a run.

Sweeps, the viewer, scenario files and the command line work on any model
through this interface.
"""

from __future__ import annotations

import abc
import difflib
import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple, TypedDict, overload

import numpy as np
from numpy.typing import ArrayLike

from tumble import _callback, _compiling, attitude, integrate
from tumble._validate import ValidationError, as_array, output_times, require_finite
from tumble._vec import norm
from tumble.trajectory import Extra, Trajectory

if TYPE_CHECKING:
    import xarray

    from tumble.body import RigidBody
    from tumble.torques import TorqueLike

__all__ = ["Model", "Outputs", "StateField", "as_model", "simulate"]

#: The largest |component| of an initial state (quaternions aside: normalised): its square stays finite in float64.
_LARGEST_STATE = 1e150

#: An initial quaternion whose length is within this of 1 is normalised silently (a unit quaternion typed to 7
#: digits, or rounded by a computation); one further off is normalised with a NonUnitQuaternionWarning.
UNIT_Q0_TOL = 1e-6

#: Solver options when not given (those the method reads).
DEFAULTS = {"rtol": 1e-10, "atol": 1e-12, "max_steps": integrate.MAX_STEPS}


class SolverOptions(TypedDict, total=False):
    """The solver options of :func:`simulate` as keyword arguments (``**options``): those the method reads.

    dt : fixed step, s; rtol, atol : tolerances of an adaptive method; max_steps : steps per body
    """

    dt: float
    rtol: float
    atol: float
    max_steps: int


@dataclass(frozen=True)
class StateField:
    """One named part of a model's initial state: a keyword of :func:`simulate`.

    name        : the keyword, e.g. ``"omega0"``
    size        : number of components; a value has shape (size,) or (N, size) (a batch);
                  a field of size 1 also takes a plain number
    description : what it is, with units and frame (used in messages and the docs)
    default     : array_like, a function of the values of the fields before it
                  (``dict`` name → (N, size) array) returning one, or None for a required field;
                  an array_like is checked (and a quaternion normalised) here, once
    quaternion  : a unit quaternion ``[w, x, y, z]``: refused when zero, normalised here
    """

    name: str
    size: int
    description: str
    default: Any = None
    quaternion: bool = False

    def __post_init__(self) -> None:
        if self.default is not None and not callable(self.default):
            default = np.array(_checked_value(self, self.default))  # its own copy, shared by every run: read-only
            default.setflags(write=False)
            object.__setattr__(self, "default", default)


class Outputs(NamedTuple):
    """What a model makes of its integrated states (see :meth:`Model.outputs`); every sampled array has
    the leading axes (time, member) of the states, which :func:`simulate` removes for a single run.

    q, omega : (n, N, 4), (n, N, 3) attitude (body → inertial) and body rate (rad/s, body axes), or None
    inertia  : (3, 3) or (N, 3, 3), kg·m², body axes, or None
    extras   : name → :class:`~tumble.trajectory.Extra` with data (n, N, ...)
    totals   : ``"energy"`` (n, N) J and ``"momentum_body"`` (n, N, 3) N·m·s of the whole system
    info     : model entries for ``Trajectory.info``
    """

    q: np.ndarray | None
    omega: np.ndarray | None
    inertia: np.ndarray | None
    extras: dict
    totals: dict
    info: dict


class Model(abc.ABC):
    """The interface every model implements once (see the module docstring).

    Class attribute ``torque``: what the ``torque=`` argument of :func:`simulate`
    means for this model (in words, with units and frame), or ``None`` when the
    model takes none.
    """

    __slots__ = ()

    torque: str | None = "external torque on the body, body axes (N·m): a tumble.torques model or f(t, q, omega)"

    @property
    def batch_size(self) -> int | None:
        """Members of a batch carried by the model itself (one inertia per body), or None."""
        return None

    @abc.abstractmethod
    def state_fields(self) -> tuple[StateField, ...]:
        """The named parts of the initial state, in the order their defaults may depend on."""

    @abc.abstractmethod
    def compile(self, torque: Any, t0: float) -> Any:
        """The compiled kernel (a NamedTuple of :mod:`tumble.kernels`) under ``torque`` (None: none), clock at ``t0`` (s).

        The kernel's ``provides`` says which methods apply; its ``calls_python``
        whether the run must stay on one core.
        """

    @abc.abstractmethod
    def initial_states(self, kernel: Any, values: dict[str, np.ndarray], t0: float) -> np.ndarray:
        """The state vectors (N, n) from the validated initial values (name → (N, size)): a new array, which
        the run integrates in place."""

    @abc.abstractmethod
    def outputs(self, kernel: Any, t: np.ndarray, states: np.ndarray) -> Outputs:
        """The trajectory's fields from the states (len(t), N, n) at the output times ``t`` (s)."""

    def check_run(self, method: integrate.Method, t: np.ndarray, dt: float | None) -> None:  # noqa: B027
        """Refuse a run this model cannot make (e.g. output times outside its data); nothing by default."""

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """What the exact motion keeps constant on the run ``traj`` (name → samples (n, [N,] ...)).

        By default: the total energy and the inertial angular momentum of the
        system when the run had no torque. Models with internal work or
        dissipation say what remains.
        """
        if traj.info.get("torque") != "none":
            return {}
        return {"energy": traj.energy, "momentum_inertial": traj.momentum_inertial}


def as_model(model: Model | RigidBody | Sequence[RigidBody] | ArrayLike) -> Model:
    """``model`` itself when it is a :class:`Model`; a rigid body, a sequence of them or an inertia array
    (3, 3) or (N, 3, 3) (kg·m², body axes) as the rigid-body model."""
    if isinstance(model, Model):
        return model
    from tumble.rigid import RigidBodies  # the rigid model builds on this module

    return RigidBodies.of(model)


@overload
def simulate(
    model: Model | RigidBody | Sequence[RigidBody] | ArrayLike,
    omega0: ArrayLike | None = None,
    *,
    t: ArrayLike,
    method: str = "dop853",
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    torque: TorqueLike | ArrayLike = None,
    progress: Callable[[int, int], None] | None = None,
    device: str = "cpu",
    store: None = None,
    **initial_state: ArrayLike | None,
) -> Trajectory: ...


@overload
def simulate(
    model: Model | RigidBody | Sequence[RigidBody] | ArrayLike,
    omega0: ArrayLike | None = None,
    *,
    t: ArrayLike,
    method: str = "dop853",
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    torque: TorqueLike | ArrayLike = None,
    progress: Callable[[int, int], None] | None = None,
    device: str = "cpu",
    store: str | os.PathLike[str],
    **initial_state: ArrayLike | None,
) -> xarray.Dataset: ...


def simulate(
    model: Model | RigidBody | Sequence[RigidBody] | ArrayLike,
    omega0: ArrayLike | None = None,
    *,
    t: ArrayLike,
    method: str = "dop853",
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    torque: TorqueLike | ArrayLike = None,
    progress: Callable[[int, int], None] | None = None,
    device: str = "cpu",
    store: str | os.PathLike[str] | None = None,
    **initial_state: ArrayLike | None,
) -> Trajectory | xarray.Dataset:
    """Integrate any model through the output times ``t``: the one front door.

    For a rigid body it solves Euler's equations ``I ω̇ + ω × (I ω) = τ``
    (body axes) with the attitude kinematics ``q̇ = ½ q ⊗ [0, ω]``; every
    other model adds its own states (see its class).

    Parameters
    ----------
    model : Model, RigidBody, a sequence of RigidBody, or an inertia array (3, 3) or (N, 3, 3)
        What to simulate (kg·m², body axes for an inertia array).
    omega0 : (3,) or (N, 3) array_like, optional
        Initial body rate, rad/s, body axes (the models with an attitude): the
        same as ``omega0=...``.
    t : (n,) array_like
        Output times, s, strictly increasing; ``t[0]`` is the start.
    method : str, one of ``tumble.integrate.METHODS``
        ``"dop853"`` (default): adaptive 8th-order Dormand–Prince (``rtol``,
        default 1e-10; ``atol``, default 1e-12); ``"rk4"``, ``"cf4"`` (Lie group),
        ``"splitting2"``/``"splitting4"`` (Lie–Poisson, torque-free rigid bodies),
        ``"exact_split2"``/``"exact_split4"`` (exact free flow + torque kicks):
        fixed step ``dt`` (s); ``"exact"``: the closed-form torque-free motion.
        Every stepping method takes ``max_steps`` per body (default
        ``tumble.integrate.MAX_STEPS`` = 1e8): a fixed-step run that needs more
        is refused before it starts, an adaptive one stops there. A method the model does not provide for
        is refused, naming those that work; so is an option the method does not
        read. See ``docs/integrators.md``.
    torque
        What ``model.torque`` says: for the bodies and spacecraft an external
        torque in body axes (N·m), a :mod:`tumble.torques` model or a Python
        callable ``f(t, q, omega)`` (at Python speed, on one core); for a robot
        the joint torques.
    progress : callable ``progress(done, total)``, optional
        Called as output samples are completed (the CLI draws a progress bar).
    device : {"cpu", "cuda"}
        ``"cuda"``: ``method="rk4"`` or ``"cf4"`` on an NVIDIA GPU, one thread
        per batch member, for every model whose compiled functions run there
        (compiled torques and laws; ``docs/gpu.md``).
    store : path of a Zarr store (a directory that does not exist), optional
        Run the batch in chunks of members, each written to the store as it
        completes, and return the run as a lazily opened ``xarray.Dataset``
        (:mod:`tumble.sweep.stream`): memory bounded by a chunk, not by the
        batch. Without it, a run whose states and outputs cannot fit in the
        memory available is refused before they are allocated, with the bytes
        it needs.
    **initial_state
        The model's initial state by name (:meth:`Model.state_fields`), e.g.
        ``q0`` (unit quaternion ``[w, x, y, z]``, body → inertial, default
        identity), ``wheel_speeds0``, ``eta0``; a leading axis of length N runs
        N initial states at once, in parallel over the cores.

    Returns
    -------
    Trajectory
        ``t`` (n,), ``q`` (n, [N,] 4), ``omega`` (n, [N,] 3), the model's named
        extras, the energy and angular momentum of the whole system, and
        ``info`` (method, options, statistics).
    """
    model = as_model(model)
    times = output_times(t)
    if omega0 is not None:
        initial_state["omega0"] = omega0
    if store is not None:  # streamed in chunks by the layer above, each chunk through this function
        from tumble.sweep.stream import simulate_to_store

        return simulate_to_store(model, store, t=times, initial_state=initial_state, progress=progress,
                                 options=dict(method=method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps,
                                              torque=torque, device=device))
    m, options = _solver_options(model, method, dict(dt=dt, rtol=rtol, atol=atol, max_steps=max_steps))
    if device not in ("cpu", "cuda"):
        raise ValidationError(f"device: must be 'cpu' or 'cuda', got {device!r}")
    if torque is not None and model.torque is None:
        raise ValidationError(f"torque: a {type(model).__name__} takes no torque argument")
    values, n = _initial_values(model, initial_state)
    model.check_run(m, times, options.get("dt"))
    # Python functions wrapped while compiling live through the run, outputs included (a model may
    # evaluate its torque law at the samples)
    with _callback.keep_alive(), _compiling.notice(f"the {m.name} path of {type(model).__name__}"):
        kernel = model.compile(torque, float(times[0]))
        who = f"a {type(model).__name__}" + (f" under torque={torque!r}" if torque is not None else "")
        integrate.check_method(m.name, kernel.provides, who)
        if device == "cuda":
            from tumble.integrate import _cuda  # imports numba.cuda: only when asked for

            _cuda.check(kernel, m.name, who)
            if progress is not None:
                raise ValidationError("progress: device='cuda' reports no progress; got a progress callback")
        y0 = model.initial_states(kernel, values, float(times[0]))
        _check_memory(times.size, y0)
        try:
            solution = integrate.solve(kernel, y0, times, method=m.name, progress=progress, device=device,
                                       overwrite_y0=True, **options)
        except integrate.Diverged as diverged:
            raise _divergence(model, kernel, times, diverged) from None
        out = model.outputs(kernel, times, solution.states)
    info = {**out.info, "torque": _describe(torque), **solution.statistics(), **options}
    info.pop("max_steps", None)
    return _trajectory(model, m.name, times, out, info, single=n is None)


def _divergence(model: Model, kernel, t: np.ndarray, diverged: integrate.Diverged) -> integrate.SolverError:
    """The message of a run whose state stopped being finite: the output time where it is first seen, and
    the body rate at the output time before (the last finite state), from the model's own outputs."""
    k, b = diverged.index, diverged.member
    who = f"body {b}: " if diverged.states.shape[1] > 1 else ""
    rate = ""
    try:
        with np.errstate(all="ignore"):
            omega = model.outputs(kernel, t[k - 1:k], diverged.states[k - 1:k]).omega if k > 0 else None
    except ValueError:  # a model may refuse states near overflow: the time alone is said
        omega = None
    if omega is not None:
        rate = f" (|ω| = {np.linalg.norm(omega[0, b]):.3g} rad/s at t = {t[k - 1]:g} s, the last finite state)"
    m = integrate.METHODS[diverged.method]
    change = ("tighten rtol/atol or check the torque" if m.adaptive else "reduce dt or check the torque" if m.stepper
              else "check the initial state and the model")  # "exact": no step, no torque
    return integrate.SolverError(f"{who}simulation diverged at t = {t[k]:g} s{rate}: {change}")


#: Output words per member and time beyond the states: q (4), omega (3), energy (1), momentum (3).
_OUTPUT_WORDS = 11


#: Runs that need less memory (bytes) are not checked: asking the system (``psutil``, 30-50 µs) would cost more
#: than a small run, and a process with less than this left could not run anything.
_UNCHECKED_BYTES = 2**24


def _check_memory(n_times: int, y0: np.ndarray) -> None:
    """Refuse a run whose sampled states and outputs (float64, ``n_times × members × (state + 11)`` words)
    exceed the memory available now, before they are allocated: the error says how many bytes and
    suggests ``store=``. Runs under :data:`_UNCHECKED_BYTES` are not checked."""
    members, size = y0.shape
    need = 8 * n_times * members * (size + _OUTPUT_WORDS)
    if need < _UNCHECKED_BYTES:
        return
    import psutil

    available = psutil.virtual_memory().available
    if need > available:
        raise ValidationError(f"store: {members} members x {n_times} output times need at least {need:,} bytes "
                              f"({need / 2**30:.1f} GiB) of memory, more than the {available:,} available; pass "
                              "store='run.zarr' to stream the run to a Zarr store in chunks")


def _describe(torque) -> str:
    """``Trajectory.info["torque"]``: "none", a torque model's repr, or the name of a Python function."""
    if torque is None:
        return "none"
    if callable(torque) and hasattr(torque, "__name__"):
        return f"Python function {torque.__name__}"
    return repr(torque)


def _solver_options(model: Model | None, method, given: dict) -> tuple[integrate.Method, dict]:
    """The :class:`~tumble.integrate.Method` and the options it reads (defaults filled in); an option given
    that the method does not read is refused."""
    method = str(method)
    if method not in integrate.METHODS:
        raise ValidationError(f"method: must be one of {sorted(integrate.METHODS)}, got {method!r}")
    m = integrate.METHODS[method]
    for name, value in given.items():
        if value is not None and name not in m.options:
            reads = f"it reads {', '.join(m.options)}" if m.options else "it has no options"
            raise ValidationError(f"{name}: method {method!r} does not use {name} ({reads})")
    options = {name: DEFAULTS[name] if given[name] is None and name in DEFAULTS else given[name]
               for name in m.options}
    integrate.check_options(method, dt=options.get("dt"), rtol=options.get("rtol"), atol=options.get("atol"),
                            max_steps=options.get("max_steps"))
    return m, {name: (int(v) if name == "max_steps" else float(v)) for name, v in options.items()}


def _initial_values(model: Model, given: Mapping) -> tuple[dict[str, np.ndarray], int | None]:
    """Validate the initial state by name: each value (size,) or (N, size), one N for all (and the model's
    own batch); returns the values broadcast to (N, size) and N (None for a single run)."""
    fields = model.state_fields()
    names = [f.name for f in fields]
    for name in given:
        if name not in names:
            close = difflib.get_close_matches(name, names, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ValidationError(f"{name}: a {type(model).__name__} has no initial state {name!r}{hint}; it takes "
                                  + ", ".join(f"{f.name} ({f.description})" for f in fields))
    arrays: dict[str, np.ndarray] = {}
    sizes: dict[str, int] = {}
    for f in fields:
        value = given.get(f.name)
        if value is not None:
            arr = _checked_value(f, value)
            if arr.ndim == 2:
                sizes[f.name] = arr.shape[0]
        elif f.default is None:
            raise ValidationError(f"{f.name}: a {type(model).__name__} needs it: {f.description}")
        elif callable(f.default):
            arr = _checked_value(f, f.default(_broadcast(arrays, sizes)))
        else:
            arr = f.default  # checked when the field was made
        arrays[f.name] = arr
    if model.batch_size is not None:
        sizes["model"] = model.batch_size
    if len(set(sizes.values())) > 1:
        first, n_first = next(iter(sizes.items()))
        other, n_other = next((name, size) for name, size in sizes.items() if size != n_first)
        raise ValidationError(f"{other}: a batch of {n_other} does not match the {n_first} of {first}; every "
                              f"batched value (and the model's bodies) must have the same leading length "
                              f"(batch sizes: {', '.join(f'{k} {v}' for k, v in sizes.items())})")
    n = next(iter(sizes.values()), None)
    return _broadcast(arrays, sizes), n


def _checked_value(f: StateField, value: ArrayLike) -> np.ndarray:
    """The value of the field ``f`` as a float64 array (size,) or (N, size): finite, at most
    :data:`_LARGEST_STATE` in magnitude, a quaternion non-zero and normalised."""
    scalar = f.size == 1 and np.ndim(value) == 0  # a number for a field of one component
    # finite checked below with the magnitude (one pass over the values), quaternions here
    arr = as_array(value, f.name, tail=() if scalar else (f.size,), finite=f.quaternion)
    if scalar:
        arr = arr.reshape(1)
    if arr.ndim > 2:
        raise ValidationError(f"{f.name}: a batch has one leading axis, got shape {arr.shape}")
    if not f.quaternion and arr.size and not np.abs(arr).max() <= _LARGEST_STATE:  # NaN fails too
        require_finite(arr, f.name)
        raise ValidationError(f"{f.name}: must be at most {_LARGEST_STATE:g} in magnitude (the energy and "
                              f"momentum square it: float64 would overflow), got {np.abs(arr).max():g}")
    if f.quaternion:
        if not arr.any(axis=-1).all():  # |q| = 0; any other finite q normalises (attitude._normalized scales it)
            raise ValidationError(f"{f.name}: must be a non-zero quaternion [w, x, y, z] (it is normalised here)")
        _warn_non_unit(arr, f.name)
        arr = attitude._normalized(arr)
    return arr


def _warn_non_unit(q: np.ndarray, name: str) -> None:
    """One :class:`~tumble.attitude.NonUnitQuaternionWarning` when a quaternion of ``q`` (…, 4) is further than
    :data:`UNIT_Q0_TOL` from unit length (it is then normalised: the rotation of ``q / |q|`` is meant)."""
    lengths = norm(q.reshape(-1, 4))
    off = np.abs(lengths - 1.0)
    if np.all(off <= UNIT_Q0_TOL):
        return
    k = int(np.argmax(off))
    where = f"[{k}]" if q.ndim == 2 else ""
    warnings.warn(f"{name}: |{name}{where}| = {lengths[k]:.17g} is not 1 (further than "
                  f"{UNIT_Q0_TOL:g}): normalised to {name} / |{name}|; give a unit quaternion [w, x, y, z]",
                  attitude.NonUnitQuaternionWarning, stacklevel=5)  # the caller of simulate


def _broadcast(arrays: dict[str, np.ndarray], sizes: dict[str, int]) -> dict[str, np.ndarray]:
    """The values as read-only (N, size) views (a user's array is never written through them)."""
    n = max(sizes.values(), default=1)
    out = {}
    for name, a in arrays.items():
        view = a.reshape(1, -1) if n == 1 else a.view() if a.shape[0] == n and a.ndim == 2 else None
        if view is None:
            view = np.broadcast_to(a, (n, a.shape[-1]))
        else:
            view.setflags(write=False)
        out[name] = view
    return out


def _trajectory(model: Model, method: str, t: np.ndarray, out: Outputs, info: dict, *, single: bool) -> Trajectory:
    """The :class:`~tumble.Trajectory` of ``out``, without the member axis for a single run.

    ``q`` and ``omega`` are checked finite here, once, and handed over without a copy when ``out`` owns
    them (fresh C-ordered float64 arrays, as the models' outputs are), copied otherwise (a view of the states
    would keep them alive)."""
    def pick(a, name):
        if a is None:
            return None
        if not (a.flags.owndata and a.flags.c_contiguous and a.dtype == np.float64):
            a = np.array(a, dtype=np.float64)
        a.setflags(write=False)  # before picking: a view of a read-only array is read-only
        a = a[:, 0] if single else a
        require_finite(a, name)  # finite states may still give a model's outputs that are not (a singular inertia)
        return a

    inertia = out.inertia
    if single and inertia is not None and inertia.ndim == 3:
        inertia = inertia[0]
    extras = {name: Extra(e.data[:, 0] if single else e.data, e.dims, e.units, e.description)
              for name, e in out.extras.items()}
    totals = {name: value[:, 0] if single else value for name, value in out.totals.items()}
    return Trajectory._of_run(np.array(t), pick(out.q, "q"), pick(out.omega, "omega"), inertia, method, info,
                              extras, totals, type(model).__name__)
