"""The front door: ``simulate(model, ...)`` runs every model (:class:`tumble.model.Model`).

One function integrates every model of the package: a rigid body (or a batch
of them), a hub with flexible appendages, a sloshing hub, a body whose inertia
changes, a spacecraft with actuators and controllers, a robot arm, a
gyroscope. Everything common to them is written here once, as
``scipy.integrate``'s ``check_arguments`` is: the output times, the solver
options (refused when the method does not read them), the initial state by
name (unknown names refused, quaternions checked and normalised, batches
broadcast), which method applies to which model (:func:`tumble.integrate.check_method`),
progress reporting, the device, and the one result type :class:`~tumble.Trajectory`.

A model implements :class:`tumble.model.Model` once (re-exported here with
:class:`~tumble.model.Outputs` and :class:`~tumble.model.StateField`); a
:class:`~tumble.RigidBody`, a sequence of them or an inertia array is a value,
which :func:`as_model` turns into its model, :class:`tumble.rigid_model.RigidBodies`.
"""

from __future__ import annotations

import difflib
import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
from numpy.typing import ArrayLike

from tumble import _callback, _compiling, integrate
from tumble._validate import ValidationError, output_times, require_finite
from tumble.model import Model, Outputs, StateField
from tumble.rigid_model import RigidBodies
from tumble.trajectory import Extra, Trajectory

if TYPE_CHECKING:
    from tumble.rigid_body import RigidBody
    from tumble.torques import TorqueLike

__all__ = ["Model", "Outputs", "StateField", "as_model", "simulate"]


class SolverOptions(TypedDict, total=False):
    """The solver options of :func:`simulate` as keyword arguments (``**options``): those the method reads.

    dt : fixed step, s; rtol, atol : tolerances of an adaptive method; max_steps : steps per body
    """

    dt: float
    rtol: float
    atol: float
    max_steps: int


def as_model(model: Model | RigidBody | Sequence[RigidBody] | ArrayLike) -> Model:
    """``model`` itself when it is a :class:`Model`; a rigid body (a value), a sequence of them or an inertia
    array (3, 3) or (N, 3, 3) (kg·m², body axes) as the rigid-body model, :class:`~tumble.rigid_model.RigidBodies`."""
    if isinstance(model, Model):
        return model
    return RigidBodies.of(model)


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
    output: str = "host",
    store: str | os.PathLike[str] | None = None,
    **initial_state: ArrayLike | None,
) -> Trajectory:
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
        (compiled torques and laws; ``docs/gpu.md``). Rigid bodies are set up there too: the principal
        axes of a batch of inertia tensors (N, 3, 3), which may be a device array, and the changes of axes.
    output : {"host", "device"}
        ``"device"`` (with ``device="cuda"``): the Trajectory's ``q`` and ``omega`` (and a rigid body's
        ``inertia``) stay on the GPU as device arrays (``__cuda_array_interface__``: CuPy and DLPack
        consumers take them without a copy); ``traj.to_host()`` copies them back. For a spacecraft, a
        flexible, slosh, fluid or variable body (``Model.attitude_in_state``) the other outputs are made on
        the host by ``to_host()``, from the states kept on the GPU; other models are refused (docs/gpu.md).
    store : path of a Zarr store, optional
        Deprecated (to be removed in 0.5): use
        :func:`tumble.sweeps.simulate_to_store`, which this then calls and
        whose ``xarray.Dataset`` it returns. A run whose states and outputs
        cannot fit in the memory available is refused before they are
        allocated, with the bytes it needs.
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
    if device not in ("cpu", "cuda"):
        raise ValidationError(f"device: must be 'cpu' or 'cuda', got {device!r}")
    if output not in ("host", "device") or (output == "device" and device != "cuda"):
        raise ValidationError(f"output: must be 'host', or 'device' with device='cuda'; got output={output!r} "
                              f"with device={device!r}")
    if device == "cuda":
        from tumble import _rigid_cuda  # imports numba.cuda: only when asked for

        model = _rigid_cuda.as_device_model(model, method)
    else:
        model = as_model(model)
    # output="device": rigid bodies' outputs are made on the GPU; a model whose attitude is its state's has its
    # q and omega made there, the rest on the host by Trajectory.to_host()
    deferred = output == "device" and not isinstance(model, _rigid_cuda.DeviceRigidBodies)
    if deferred and not model.attitude_in_state:
        raise ValidationError(f"output: 'device' keeps on the GPU the results of rigid bodies and the q and omega of "
                              f"the models whose attitude is their state's (docs/gpu.md); a {model.kind}'s outputs "
                              "are made on the host: use output='host'")
    times = output_times(t)
    if omega0 is not None:
        initial_state["omega0"] = omega0
    if store is not None:
        warnings.warn("simulate(store=...) is deprecated and will be removed in tumble 0.5: use "
                      "tumble.sweeps.simulate_to_store(model, ..., store=...), which returns the xarray.Dataset",
                      DeprecationWarning, stacklevel=2)
        from tumble.sweeps.stream import simulate_to_store

        state: dict[str, Any] = initial_state  # initial states by name, as simulate_to_store takes them
        # the deprecated path's Dataset, typed as the supported result
        return simulate_to_store(model, store=store, t=times, method=method,  # type: ignore[return-value]
                                 dt=dt, rtol=rtol, atol=atol, max_steps=max_steps, torque=torque, device=device,
                                 progress=progress, **state)
    m, options = _solver_options(model, method, dict(dt=dt, rtol=rtol, atol=atol, max_steps=max_steps))
    if torque is not None and model.torque is None:
        raise ValidationError(f"torque: a {model.kind} takes no torque argument")
    values, n = _initial_values(model, initial_state)
    model.check_run(m, times, options.get("dt"))
    # Python functions wrapped while compiling live through the run, outputs included (a model may
    # evaluate its torque law at the samples)
    with _callback.keep_alive(), _compiling.notice(f"the {m.name} path of {model.kind}"):
        kernel = model.compile(torque, float(times[0]))
        who = f"a {model.kind}" + (f" under torque={torque!r}" if torque is not None else "")
        integrate.check_method(m.name, kernel.provides, who)
        if device == "cuda":
            from tumble.integrate import _cuda  # imports numba.cuda: only when asked for

            _cuda.check(kernel, m.name, who)
            if progress is not None:
                raise ValidationError("progress: device='cuda' reports no progress; got a progress callback")
        y0 = model.initial_states(kernel, values, float(times[0]))
        if deferred:
            y0 = _cuda.on_device(y0)  # the states stay on the GPU
        grid, kept = _with_step_ends(times, model.step_ends(times, options.get("dt")))
        _check_memory(grid.size, y0)
        try:
            solution = integrate.solve(kernel, y0, grid, method=m.name, progress=progress, device=device,
                                       overwrite_y0=True, **options)
        except integrate.Diverged as diverged:
            raise _divergence(model, kernel, grid, diverged) from None
        states: Any = solution.states if kept is None else solution.states[kept]  # on the GPU where deferred
        if deferred:
            from tumble.integrate import _cuda_outputs

            q, omega = _cuda_outputs.attitude_and_rate(kernel, states)
            out = Outputs(q=q, omega=omega, inertia=None, extras={}, totals={}, info={})
        else:
            out = model.outputs(kernel, times, states)
        if output == "host" and device == "cuda":
            out = _rigid_cuda.to_host(out)
    info = {**out.info, "torque": _describe(torque), **solution.statistics(), **options}
    info.pop("max_steps", None)
    if deferred:
        def host() -> Trajectory:
            """The whole trajectory, its outputs made on the host from the states copied back."""
            states_on_host = states.copy_to_host()
            whole = model.outputs(kernel, times, states_on_host)
            return _trajectory(model, m.name, times, whole, {**whole.info, **info}, single=n is None)

        return _trajectory(model, m.name, times, out, info, single=n is None, host=host)
    return _trajectory(model, m.name, times, out, info, single=n is None)


def _with_step_ends(times: np.ndarray, ends: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """The times to integrate through: the output ``times`` and the model's step ``ends`` (s) between them (an
    end within round-off, 1e-12 of the largest |t|, of an output time or of another end counted as that one), and the
    indices of ``times`` in them (None without ends)."""
    if ends is None or ends.size == 0:
        return times, None
    tolerance = 1e-12 * max(abs(times[0]), abs(times[-1]), np.finfo(float).tiny)
    ends = np.sort(ends)
    ends = ends[np.r_[True, np.diff(ends) > tolerance]]
    near = np.searchsorted(times, ends)
    gap = np.minimum(np.abs(ends - times[np.minimum(near, times.size - 1)]),
                     np.abs(ends - times[np.maximum(near - 1, 0)]))
    grid = np.union1d(times, ends[(gap > tolerance) & (ends > times[0]) & (ends < times[-1])])
    return grid, np.searchsorted(grid, times)


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
    suggests :func:`tumble.sweeps.simulate_to_store`. Runs under :data:`_UNCHECKED_BYTES` are not checked."""
    members, size = y0.shape
    need = 8 * n_times * members * (size + _OUTPUT_WORDS)
    if need < _UNCHECKED_BYTES:
        return
    import psutil

    available = psutil.virtual_memory().available
    if need > available:
        raise ValidationError(f"store: {members} members x {n_times} output times need at least {need:,} bytes "
                              f"({need / 2**30:.1f} GiB) of memory, more than the {available:,} available; "
                              "tumble.sweeps.simulate_to_store(..., store='run.zarr') streams it to a Zarr store "
                              "in chunks")


def _describe(torque) -> str:
    """``Trajectory.info["torque"]``: "none", a torque model's repr, or the name of a Python function."""
    if torque is None:
        return "none"
    if callable(torque) and hasattr(torque, "__name__"):
        return f"Python function {torque.__name__}"
    return repr(torque)


def _solver_options(model: Model | None, method, given: dict) -> tuple[integrate.Method, dict]:
    """The :class:`~tumble.integrate.Method` and the options it reads (its defaults filled in, checked by its
    rules, :meth:`~tumble.integrate.Method.resolve`); an option given that the method does not read is refused."""
    m = integrate.method(method)
    return m, m.resolve(given)


def _initial_values(model: Model, given: Mapping) -> tuple[dict[str, np.ndarray], int | None]:
    """Validate the initial state by name: each value (size,) or (N, size), one N for all (and the model's
    own batch); returns the values broadcast to (N, size) and N (None for a single run)."""
    fields = model.state_fields()
    names = [f.name for f in fields]
    for name in given:
        if name not in names:
            close = difflib.get_close_matches(name, names, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ValidationError(f"{name}: a {model.kind} has no initial state {name!r}{hint}; it takes "
                                  + ", ".join(f"{f.name} ({f.description})" for f in fields))
    arrays: dict[str, np.ndarray] = {}
    sizes: dict[str, int] = {}
    for f in fields:
        value = given.get(f.name)
        if value is not None:
            arr = f.check(value)
            if arr.ndim == 2:
                sizes[f.name] = arr.shape[0]
        elif f.default is None:
            raise ValidationError(f"{f.name}: a {model.kind} needs it: {f.description}")
        elif callable(f.default):
            arr = f.check(f.default(_broadcast(arrays, sizes)))
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


def _trajectory(model: Model, method: str, t: np.ndarray, out: Outputs, info: dict, *, single: bool,
                host: Callable[[], Trajectory] | None = None) -> Trajectory:
    """The :class:`~tumble.Trajectory` of ``out``, without the member axis for a single run; ``host``, for a run
    whose ``q`` and ``omega`` alone are on the GPU, makes the whole trajectory on the host (``to_host()``).

    ``q`` and ``omega`` are checked finite here, once, and handed over without a copy when ``out`` owns
    them (fresh C-ordered float64 arrays, as the models' outputs are), copied otherwise (a view of the states
    would keep them alive)."""
    def pick(a, name):
        if a is None or not isinstance(a, np.ndarray):  # None, or a device array (checked finite there)
            return None if a is None else a[:, 0] if single else a
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
                              extras, totals, model.kind, host=host)
