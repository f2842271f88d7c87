"""The plan of a sweep: what sample ``i`` is, and how a chunk of samples runs through :func:`tumble.simulate`.

A :class:`Plan` is a plain, picklable value: the model (or a function that
builds one from dispersed parameters), the dispersions, the seed, the output
times and solver options, and the outcome and series functions. A Dask task
calls :meth:`Plan.run` on a chunk ``[lo, hi)`` of samples; it draws the
samples' inputs from their own part of the random stream (:func:`tumble.sweeps.dispersions.sample_uniforms`),
simulates the chunk as **one batch** where the model allows it, and reduces
the batched trajectory to per-sample outcomes and series. Nothing in a chunk's
result depends on the chunk's bounds: sample ``i`` is a function of ``(seed,
i)`` (a member of a compiled batch integrates on its own, so its result does
not depend on the batch around it either).

How a chunk is batched:

* dispersed initial states (``omega0``, ``q0``, ``wheel_speeds0``, ...): one
  :func:`~tumble.simulate` call with a leading axis of ``m`` members;
* a dispersed ``inertia`` of a rigid body, or a ``build`` function returning
  rigid bodies: one call on the batch of bodies (:class:`tumble.rigid_model.RigidBodies`);
* a ``build`` function returning other models (a spacecraft with dispersed
  inertia or wheel axes): one call per sample inside the chunk's task (the
  compiled kernel is shared; such a model has no batched form of its
  parameters), the trajectories then stacked into one batch.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import json
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TypeGuard

import numpy as np
from numpy.typing import ArrayLike

from tumble._inertia import principal_axes
from tumble._validate import ValidationError
from tumble.rigid_body import RigidBody
from tumble.rigid_model import RigidBodies
from tumble.simulate import Model, as_model, simulate
from tumble.sweeps.chunks import Chunks
from tumble.sweeps.dispersions import Dispersion, Grid, Inertia, as_dispersion, sample_uniforms
from tumble.sweeps.outcomes import describe
from tumble.trajectory import Extra, Trajectory

if TYPE_CHECKING:
    from tumble.torques import TorqueLike

__all__ = ["Plan", "ChunkResult", "make_plan"]


@dataclass(frozen=True)
class ChunkResult:
    """What one chunk ``[lo, hi)`` gives: per-sample ``inputs``, ``outcomes`` (name → (m, ...)) and
    ``series`` (name → (m, n): one row per sample, one column per output time) and, when asked, the
    ``trajectories`` (``q``, ``omega``, the extras and totals: name → (m, n, ...))."""

    lo: int
    hi: int
    inputs: dict
    outcomes: dict
    series: dict
    trajectories: dict


@dataclass(frozen=True)
class Plan:
    """A sweep, fully described (see the module docstring); made and checked by :func:`tumble.sweeps.sweep`.

    model       : a :class:`~tumble.simulate.Model` (or what :func:`~tumble.simulate.as_model` takes), or a
                  function ``build(**parameters) -> Model`` of the dispersed parameters
    dispersions : name → :class:`~tumble.sweeps.dispersions.Dispersion`, in drawing order
    states      : the dispersed names that are initial states of the model (the others are parameters)
    fixed       : initial states given as one value shared by every sample
    seed, samples, chunk : the random seed, the number of samples, the samples per chunk (a Dask task)
    t, method, options, torque : the arguments of :func:`tumble.simulate`
    outcomes, series : name → function of a chunk's trajectory (:mod:`tumble.sweeps.outcomes`)
    trajectories : keep every sample's trajectory (``q``, ``omega``, the extras and totals) too
    device : where the chunks are simulated (``"cpu"`` or ``"cuda"``, :func:`tumble.simulate`'s ``device``)
    """

    model: object
    dispersions: dict
    states: tuple
    fixed: dict
    seed: int
    samples: int
    chunk: int
    t: np.ndarray
    method: str
    options: dict
    torque: object
    outcomes: dict
    series: dict
    trajectories: bool = False
    device: str = "cpu"
    grid: tuple = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "grid", tuple(len(d) for d in self.dispersions.values() if isinstance(d, Grid)))

    # -- what sample i is -------------------------------------------------------------

    @property
    def chunks(self) -> Chunks:
        """The samples cut into chunks of :attr:`chunk` (:mod:`tumble.sweeps.chunks`): chunk ``k`` is a Dask
        task."""
        return Chunks(self.samples, self.chunk)

    def inputs(self, lo: int, hi: int) -> dict[str, np.ndarray]:
        """The dispersed inputs of samples ``lo`` to ``hi − 1`` (name → (m, *shape)), each a function of
        ``(seed, i)`` only."""
        u = sample_uniforms(self.seed, lo, hi, sum(d.n_raw for d in self.dispersions.values()))
        columns = np.cumsum([0] + [d.n_raw for d in self.dispersions.values()])
        index = np.arange(lo, hi) % math.prod(self.grid)
        points = iter(np.unravel_index(index, self.grid)) if self.grid else iter(())
        out = {}
        for (name, d), start, stop in zip(self.dispersions.items(), columns[:-1], columns[1:]):
            p = next(points) if isinstance(d, Grid) else index
            out[name] = d.values(u[:, start:stop], p)
        return out

    # -- one chunk --------------------------------------------------------------------

    def run(self, k: int) -> ChunkResult:
        """Simulate chunk ``k`` and reduce it (what a Dask task does)."""
        lo, hi = self.chunks.bounds(k)
        inputs = self.inputs(lo, hi)
        traj = self.simulate(inputs, output="device" if self.device == "cuda" else "host")
        host = functools.cache(traj.to_host)  # the results on the host, copied once where they are on a GPU
        m = hi - lo
        outcomes = {}
        for name, f in self.outcomes.items():
            value = np.asarray(_evaluated("outcome", f, traj, host))
            if value.ndim < 1 or value.shape[0] != m:
                raise ValidationError(f"outcomes[{name!r}]: must give one value per sample ({m}, ...), "
                                      f"got shape {value.shape}")
            outcomes[name] = value
        series = {}
        for name, f in self.series.items():
            value = np.asarray(_evaluated("series", f, traj, host), dtype=np.float64)
            if value.shape != (len(self.t), m):
                raise ValidationError(f"statistics[{name!r}]: must give one value per output time and sample "
                                      f"({len(self.t)}, {m}), got shape {value.shape}")
            series[name] = np.ascontiguousarray(value.T)
        kept = {}
        if self.trajectories:  # sample-major, as the store is chunked
            traj = host()
            momentum = traj.momentum_body if traj.q is not None or "momentum_body" in traj.totals else None
            fields = {"q": traj.q, "omega": traj.omega, **{name: e.data for name, e in traj.extras.items()},
                      "energy": traj.energy, "momentum_body": momentum}
            kept = {name: np.ascontiguousarray(np.swapaxes(v, 0, 1)) for name, v in fields.items() if v is not None}
        return ChunkResult(lo, hi, inputs, outcomes, series, kept)

    def simulate(self, inputs: Mapping[str, np.ndarray], output: str = "host") -> Trajectory:
        """The batched trajectory (axes (time, member, ...)) of the samples whose inputs are ``inputs``; with
        ``output="device"`` (and ``device="cuda"``), its results left on the GPU where :func:`tumble.simulate`
        keeps them there (rigid bodies; the ``q`` and ``omega`` of a spacecraft, ...), on the host otherwise."""
        m = len(next(iter(inputs.values()))) if inputs else 0
        state = {**self.fixed, **{name: inputs[name].reshape(m, -1) for name in self.states}}
        parameters = {name: v for name, v in inputs.items() if name not in self.states}
        run = dict(t=self.t, method=self.method, torque=self.torque, device=self.device, **self.options)
        if not _is_builder(self.model):
            model: Any = self.model  # not a builder: anything tumble.simulate takes as a model
            if "inertia" in parameters:  # on a GPU, the tensors are set up there
                model = parameters["inertia"] if self.device == "cuda" else RigidBodies.of(parameters["inertia"])
            elif not any(np.ndim(v) == 2 for v in state.values()):
                state = {name: np.broadcast_to(v, (m, np.size(v))) for name, v in state.items()}
            model, kept = _kept_on_device(model, self.method, output)
            return simulate(model, **run, output=kept, **state)
        models = [self.model(**{name: v[j] for name, v in parameters.items()}) for j in range(m)]
        if all(isinstance(b, RigidBody) for b in models):
            bodies, kept = _kept_on_device(RigidBodies.of(models), self.method, output)
            return simulate(bodies, **run, output=kept, **_members(state, m))
        members = [simulate(model, **run, **{name: v[j:j + 1] if np.ndim(v) == 2 else v for name, v in
                                             _members(state, m).items()}) for j, model in enumerate(models)]
        return _stack(members)

    def client_bytes(self, *, in_memory: bool) -> float:
        """A lower bound of the bytes the client process holds at once for the whole sweep (float64 words):
        the store's sample index, and each outcome read whole for its percentiles (its values and NumPy's
        partitioned copy); in memory, also every value kept per sample (the dispersed inputs, the outcomes,
        the series per output time and, with ``trajectories``, at least 11 words per output time)."""
        words = 1 + 2 * len(self.outcomes)
        if in_memory:
            words += (sum(math.prod(d.shape) for d in self.dispersions.values()) + len(self.outcomes)
                      + len(self.t) * (len(self.series) + (11 if self.trajectories else 0)))
        return 8.0 * float(self.samples) * words

    # -- what the store records -------------------------------------------------------

    def settings(self) -> dict:
        """Everything the samples' results depend on, as JSON values: a store written with other settings is
        refused (naming the one that differs) rather than mixed."""
        t = np.ascontiguousarray(self.t)
        return {
            "model": _describe_model(self.model),
            "dispersions": [[name, repr(d)] for name, d in self.dispersions.items()],
            "fixed": {name: np.asarray(v).tolist() for name, v in self.fixed.items()},
            "seed": int(self.seed),
            "samples": int(self.samples),
            "chunk": int(self.chunk),
            "t": f"{t.size} times from {float(t[0])!r} to {float(t[-1])!r} s, sha256 {hashlib.sha256(t.tobytes()).hexdigest()}",
            "method": self.method,
            "options": {k: float(v) for k, v in self.options.items()},
            "torque": "none" if self.torque is None else describe(self.torque) if inspect.isfunction(
                self.torque) else repr(self.torque),
            "outcomes": {name: describe(f) for name, f in self.outcomes.items()},
            "statistics": {name: describe(f) for name, f in self.series.items()},
            "trajectories": self.trajectories,
            **({"device": self.device} if self.device != "cpu" else {}),  # a GPU's results differ in the last bits
        }

    def token(self) -> str:
        """A short digest of :meth:`settings` (it names this sweep's Dask tasks)."""
        return hashlib.sha256(json.dumps(self.settings(), sort_keys=True).encode()).hexdigest()[:16]

    def digest(self, *, strict: bool = True) -> str:
        """A digest of everything the samples' results depend on, the same in every process: the whole plan
        through :func:`dask.base.tokenize` (arrays by their bytes, dataclasses by their fields, other objects
        and functions by their pickle: a model's data, a tabulated torque's values, a scenario's every table,
        a lambda's code). :meth:`settings` shows what a person reads; this catches what it leaves out.

        A plan that Dask cannot tokenize (an object whose pickle does not load back in this process) is
        digested from its pickle's bytes (SHA-256 of :func:`cloudpickle.dumps`), when two of them agree.

        ``strict``: refuse a plan that does not pickle the same way twice (what a store records must be
        found again when the sweep resumes); otherwise such a plan gets a digest of its own, never repeated."""
        import cloudpickle
        from dask.base import tokenize
        from dask.tokenize import TokenizationError

        try:
            return tokenize(self, ensure_deterministic=strict)
        except TokenizationError as exc:
            pickled = [cloudpickle.dumps(self) for _ in range(2)]
            if pickled[0] == pickled[1]:
                return hashlib.sha256(pickled[0]).hexdigest()
            raise ValidationError(f"store: this sweep cannot be recorded for resuming (its model, torque or "
                                  f"functions do not pickle the same way twice: {exc}); run it without a store"
                                  ) from None


def _is_builder(model: object) -> TypeGuard[Callable[..., Any]]:
    """True for a function of the parameters that builds the model (not a model, nor an inertia array)."""
    return callable(model) and not isinstance(model, (Model, np.ndarray))


def _members(state: dict, m: int) -> dict:
    """Initial states with one row per member: a shared value broadcast to (m, size)."""
    return {name: v if np.ndim(v) == 2 else np.broadcast_to(v, (m, np.size(v))) for name, v in state.items()}


def _describe_model(model) -> str:
    if _is_builder(model):
        return describe(model)
    model = as_model(model)
    inertia = getattr(model, "inertia", None)
    extra = "" if inertia is None or not isinstance(inertia, np.ndarray) else f", inertia {inertia.tolist()}"
    return repr(model) + extra


def _kept_on_device(model: Any, method: str, output: str) -> tuple[Any, str]:
    """``(model, output)`` for :func:`tumble.simulate`: with ``output="device"``, the model set up on the GPU
    (:func:`tumble._rigid_cuda.as_device_model`) and ``"device"`` where its results stay there (rigid bodies,
    and the ``q`` and ``omega`` of a model whose attitude is its state's: a spacecraft, ...), ``"host"`` for
    any other model (its outputs are made on the host)."""
    if output != "device":
        return model, output
    from tumble import _rigid_cuda  # imports numba.cuda: only for a sweep on a GPU

    model = _rigid_cuda.as_device_model(model, method)
    kept = isinstance(model, _rigid_cuda.DeviceRigidBodies) or model.attitude_in_state
    return model, "device" if kept else "host"


def _evaluated(kind: str, f: Callable[[Trajectory], np.ndarray], traj: Trajectory,
               host: Callable[[], Trajectory]) -> Any:
    """The outcome or series (``kind``) ``f`` of a chunk's trajectory: on the GPU where ``traj``'s results are
    there and ``f`` is a built-in that runs there (:mod:`tumble.sweeps.device`), otherwise ``f`` of the
    host's copy ``host()``."""
    if traj.on_device:
        from tumble.sweeps import device

        if kind == "outcome":
            value = device.outcome(f, traj)
            if value is not None:
                return value
        else:
            table = device.series(f, traj)  # a device array
            if table is not None:
                return table.copy_to_host()
    return f(host())


def _inertia_of(member: Trajectory) -> np.ndarray:
    """The (3, 3) inertia of a single-member run of a model with an attitude."""
    assert member.inertia is not None
    return member.inertia if member.inertia.ndim == 2 else member.inertia[0]


def _stack(members: list[Trajectory]) -> Trajectory:
    """One batched trajectory (member axis 1) from single-member runs (each with a member axis of 1)."""
    first = members[0]

    def cat(get):
        parts = [get(tr) for tr in members]
        return None if parts[0] is None else np.concatenate(parts, axis=1)

    inertia = None if first.inertia is None else np.stack([_inertia_of(tr) for tr in members])
    extras = {name: Extra(cat(lambda tr, name=name: tr.extras[name].data), e.dims, e.units, e.description)
              for name, e in first.extras.items()}
    totals = {name: cat(lambda tr, name=name: tr.totals[name]) for name in first.totals}
    return Trajectory(t=first.t, q=cat(lambda tr: tr.q), omega=cat(lambda tr: tr.omega), inertia=inertia,
                      method=first.method, info=first.info, extras=extras, totals=totals, model=first.model)


def make_plan(model: Any, dispersions: Mapping[str, Dispersion | ArrayLike], *, samples: int | None, seed: int,
              chunk: int | None, t: np.ndarray, method: str, options: dict[str, Any], torque: TorqueLike | ArrayLike,
              outcomes: dict[str, Callable[[Trajectory], np.ndarray]],
              series: dict[str, Callable[[Trajectory], np.ndarray]], fixed: Mapping[str, ArrayLike],
              trajectories: bool = False, parallel: int = 1, device: str = "cpu") -> Plan:
    """Check a sweep's inputs and make its :class:`Plan` (see :func:`tumble.sweeps.sweep`); ``parallel``: the
    chunks the cluster runs at once (for the default chunk)."""
    if not isinstance(dispersions, Mapping):
        raise ValidationError(f"dispersions: must be a mapping of name -> dispersion, got {type(dispersions).__name__}")
    drawn = {str(name): as_dispersion(d, name) for name, d in dispersions.items()}
    samples, chunk = _sizes(drawn, samples, chunk, len(t), parallel)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValidationError(f"seed: must be an integer >= 0, got {seed!r}")
    builder = _is_builder(model)
    parameters = _parameters(model, drawn)
    probe = model(**{n: d.values(np.full((1, d.n_raw), 0.5), np.zeros(1, dtype=int))[0]
                     for n, d in drawn.items() if n in parameters}) if builder else model
    fields = {f.name: f for f in as_model(probe).state_fields()}
    for name in list(drawn) + list(fixed):
        if name not in fields and name not in parameters:
            known = ", ".join(sorted(fields) + sorted(parameters))
            raise ValidationError(f"dispersions[{name!r}]: not an initial state or a parameter of the "
                                  f"{'model built by ' + describe(model) if builder else type(probe).__name__}; "
                                  f"it takes {known}")
        if name in fixed and name in drawn:
            raise ValidationError(f"{name}: given both as a dispersion and as a fixed value")
    states = tuple(n for n in drawn if n in fields and n not in parameters)
    for name in states:
        _check_state(name, drawn[name], fields[name])
    if "inertia" in drawn and not builder:
        _check_inertia(drawn["inertia"])
    _check_reductions(outcomes, series, drawn, trajectories)
    return Plan(model=model if builder or "inertia" in drawn else as_model(model),
                dispersions=drawn, states=states, fixed=dict(fixed), seed=int(seed), samples=samples,
                chunk=chunk, t=np.asarray(t, dtype=np.float64), method=method, options=options, torque=torque,
                outcomes=dict(outcomes), series=dict(series), trajectories=bool(trajectories), device=device)


def _sizes(dispersions: dict, samples, chunk, n_times: int, parallel: int) -> tuple[int, int]:
    """The number of samples (default: one per grid point when every dispersion is a grid) and the chunk
    (default: the samples shared evenly between ``parallel`` workers, and at most
    :data:`~tumble.sweeps.chunks.SAMPLES_PER_CHUNK` member-samples, :meth:`tumble.sweeps.chunks.Chunks.of`)."""
    if samples is None:
        if not any(isinstance(d, Grid) for d in dispersions.values()) or any(d.n_raw for d in dispersions.values()):
            raise ValidationError("samples: needed unless every dispersion is a grid (then one sample per point)")
        samples = math.prod(len(d) for d in dispersions.values() if isinstance(d, Grid))
    samples = int(samples)
    if samples < 1:
        raise ValidationError(f"samples: must be >= 1, got {samples}")
    return samples, Chunks.of(samples, chunk, n_times=n_times, parallel=parallel).size


def _parameters(model, dispersions: dict) -> set:
    """The parameters a sweep may disperse besides the initial state: a build function's (a scenario's
    model names its dotted keys), ``inertia`` for a rigid body; a build function's required ones must be
    given."""
    if not _is_builder(model):
        return {"inertia"} if isinstance(model, (RigidBody, list, np.ndarray)) else set()
    named = getattr(model, "parameters", None)
    if named is not None:
        return set(named)
    signature = inspect.signature(model).parameters
    required = [p.name for p in signature.values() if p.default is inspect.Parameter.empty and p.name not in
                dispersions]
    if required:
        raise ValidationError(f"dispersions: the model's build function {describe(model)} needs "
                              f"{', '.join(map(repr, required))} (a dispersion, or a fixed value)")
    return set(signature)


def _check_state(name: str, d: Dispersion, state) -> None:
    """A dispersed initial state: the shape of its field; no zero quaternion in a grid."""
    want = (state.size,)
    if d.shape != want and not (want == (1,) and d.shape == ()):
        raise ValidationError(f"dispersions[{name!r}]: a value of shape {want} ({state.description}), got {d.shape}")
    if state.quaternion and isinstance(d, Grid) and np.any(np.linalg.norm(d.points, axis=-1) == 0):
        raise ValidationError(f"dispersions[{name!r}]: a zero quaternion")


def _check_inertia(d: Dispersion) -> None:
    """A rigid body's dispersed inertia: an :class:`Inertia` (physical by its rule) or a grid of tensors
    that pass :func:`tumble._inertia.principal_axes` here, so that no sample can be refused later."""
    if isinstance(d, Grid) and d.shape == (3, 3):
        principal_axes(d.points, "dispersions['inertia']")
    elif not isinstance(d, Inertia):
        raise ValidationError(f"dispersions['inertia']: must be a tumble.sweeps.Inertia (it stays physical) or a "
                              f"Grid of (3, 3) tensors (kg m^2), got {type(d).__name__} of shape {d.shape}")


#: Names of the store's own variables and dimensions, and the suffixes of the variables it derives from an
#: outcome or a series (:mod:`tumble.sweeps.store`): no outcome or series may take them.
STORE_NAMES = ("sample", "time", "percentile", "chunk", "done")
DERIVED_SUFFIXES = ("_percentiles", "_count", "_mean", "_std", "_min", "_max")


def store_name_problem(name: str) -> str | None:
    """Why ``name`` cannot name an outcome or a series (it is, or may become, another variable of the store),
    or None."""
    if not str(name).isidentifier():
        return "must be an identifier"
    if name in STORE_NAMES:
        return f"{name!r} is a variable of the store itself ({', '.join(STORE_NAMES)})"
    if name.endswith(DERIVED_SUFFIXES) or re.search(r"_dim\d+$", name):
        return (f"names ending in {', '.join(DERIVED_SUFFIXES)} or _dimN are the store's statistics and "
                f"dimensions of other outcomes")
    return None


def _check_reductions(outcomes: dict, series: dict, dispersions: dict, trajectories: bool) -> None:
    """Outcome and series names: identifiers, none a name of the store's own (:func:`store_name_problem`), of
    a dispersed input, of each other or of a kept trajectory field; each function describable in the store."""
    taken = set(dispersions) | ({"q", "omega", "energy", "momentum_body"} if trajectories else set())
    for group, kind in ((outcomes, "outcomes"), (series, "statistics")):
        for name, f in group.items():
            problem = store_name_problem(name)
            if problem is not None:
                raise ValidationError(f"{kind}[{name!r}]: {problem}; give another name")
            if name in taken or (kind == "statistics" and name in outcomes):
                raise ValidationError(f"{kind}[{name!r}]: names must be different from the dispersed inputs "
                                      f"and from each other")
            describe(f)
