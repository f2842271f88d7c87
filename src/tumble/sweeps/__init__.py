"""Monte-Carlo and parameter sweeps of any model of :func:`tumble.simulate`, on Dask, streamed to Zarr.

The package holds the chunker (:mod:`tumble.sweeps.chunks`), the dispersions,
the outcomes, the stores and the Dask runner; its function :func:`sweep` is
also ``tumble.sweep``, and :func:`simulate_to_store` streams a batch larger
than memory to a Zarr store.

    >>> import numpy as np, tumble
    >>> from tumble.sweeps import Normal, UniformAttitude, NutationAngle, Final
    >>> ds = tumble.sweep(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])),
    ...                   {"omega0": Normal([0.0, 0.0, 1.0], 0.05), "q0": UniformAttitude()},
    ...                   samples=10_000, seed=1, t=np.linspace(0, 10, 101), method="rk4", dt=0.01,
    ...                   outcomes={"nutation": Final(NutationAngle([0, 0, 1]))}, store="mc.zarr")
    >>> ds.nutation_percentiles.sel(percentile=99).item()       # rad

Sample ``i`` draws its dispersed inputs from its own part of one
counter-based random stream keyed by ``SeedSequence(seed)``
(:func:`tumble.sweeps.dispersions.sample_uniforms`), so
every input and result of sample ``i`` depends on ``(seed, i)`` alone, never
on the chunk size or the number of workers. The samples run in chunks, one
Dask task per chunk, each chunk one batched call of :func:`tumble.simulate`
where the model allows it (:mod:`tumble.sweeps.plan`); the results are written
to a Zarr store as the chunks complete (:mod:`tumble.sweeps.store`) and a
sweep run again on the same store resumes, computing only what is missing.
See ``docs/sweeps.md``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, cast

from tumble._validate import ValidationError, output_times, require_memory
from tumble.simulate import _solver_options, as_model
from tumble.sweeps.dispersions import (
    Dispersion,
    Grid,
    Inertia,
    Misalignment,
    NoiseSeed,
    Normal,
    TruncatedNormal,
    Uniform,
    UniformAttitude,
)
from tumble.sweeps.outcomes import (
    Component,
    CrossingTime,
    Final,
    Max,
    NutationAngle,
    PointingError,
    SettlingTime,
)
from tumble.sweeps.plan import _is_builder, make_plan
from tumble.sweeps.runner import gpu_workers, local_cluster, run_chunks
from tumble.sweeps.store import StoreMismatchError, SweepStore, stored_chunk, writing
from tumble.sweeps.stream import simulate_to_store

if TYPE_CHECKING:
    import xarray
    from distributed import Client
    from numpy.typing import ArrayLike

    from tumble.rigid_body import RigidBody
    from tumble.simulate import Model
    from tumble.torques import TorqueLike

__all__ = ["sweep", "open_sweep", "simulate_to_store", "local_cluster", "StoreMismatchError",
           "Dispersion", "Normal",
           "Uniform", "TruncatedNormal", "Grid",
           "UniformAttitude", "Inertia", "Misalignment", "NoiseSeed", "PointingError", "NutationAngle",
           "Component", "Max", "Final", "SettlingTime", "CrossingTime"]

#: Percentiles kept by default, of every outcome and (per output time) of every series.
PERCENTILES = (1.0, 5.0, 50.0, 95.0, 99.0)


def sweep(
    model: Model | RigidBody | Sequence[RigidBody] | ArrayLike | Callable[..., Any],
    dispersions: Mapping | None = None,
    *,
    samples: int | None = None,
    seed: int = 0,
    t: ArrayLike,
    method: str = "dop853",
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    torque: TorqueLike | ArrayLike = None,
    outcomes: Mapping[str, Callable] | None = None,
    statistics: Mapping[str, Callable] | None = None,
    percentiles: Iterable[float] = PERCENTILES,
    trajectories: bool = False,
    chunk: int | None = None,
    store: str | os.PathLike[str] | None = None,
    client: Client | None = None,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    retries: int = 2,
    device: str = "cpu",
    **initial_state: ArrayLike,
) -> xarray.Dataset:
    """Run ``samples`` simulations of ``model`` with dispersed inputs on Dask; return their outcomes.

    Parameters
    ----------
    model : Model (what :func:`tumble.simulate` takes), or a callable ``build(**parameters) -> Model``
        What to simulate. With a ``build`` function, the dispersions named
        after its parameters (inertia, wheel axes, gains, noise seeds, ...)
        are passed to it per sample; a rigid body's ``inertia`` may be
        dispersed directly (:class:`Inertia`).
    dispersions : mapping name → :class:`Dispersion` or a fixed value
        The inputs that vary: initial states of the model (``omega0``,
        ``q0``, ``wheel_speeds0``, ...; units of :func:`tumble.simulate`) and
        parameters of ``build``. Random ones draw in the mapping's order from
        the sample's stream; :class:`Grid` ones form a Cartesian product.
    samples : int
        Number of samples (default: one per grid point when every dispersion is a grid).
    seed : int
        The sweep's seed: sample ``i``'s variates are the words ``i W …`` of Philox keyed by ``SeedSequence(seed)``.
    t, method, dt, rtol, atol, max_steps, torque
        As :func:`tumble.simulate` (output times in s; the options the method reads).
    outcomes : mapping name → ``f(traj) -> (m, ...)``
        Per-sample results from a chunk's batched trajectory (:mod:`tumble.sweeps.outcomes`).
    statistics : mapping name → ``f(traj) -> (n, m)``
        Series kept per sample and output time, with their per-time mean, std,
        min, max and ``percentiles``.
    percentiles : sequence of numbers in [0, 100]
        Kept for every outcome and, per output time, for every series.
    trajectories : bool
        Also keep every sample's trajectory: ``q`` (sample, time, 4), ``omega``
        (sample, time, 3), the model's extras and totals, chunked by sample
        (with a store, they go to disk as the chunks come).
    chunk : int
        Samples per Dask task. Default: the samples shared evenly between the
        workers (``ceil(samples / W)``, ``W`` the cluster's worker threads; 1
        with ``workers=0``), so that a small sweep uses every worker, and at
        most :data:`tumble.sweeps.chunks.SAMPLES_PER_CHUNK` member-samples (a chunk's run
        takes about 200 MB); resuming a store, the store's.
    store : path of a Zarr store (directory), or None
        Where the results are written as they come; an existing store of the
        same sweep is resumed (only missing chunks are computed), one of
        another sweep is refused. None: in memory.
    client : ``distributed.Client``, optional
        Run on this cluster. Default: a :class:`~distributed.LocalCluster` of
        ``workers`` processes (default one per core) started for the sweep;
        ``workers=0`` runs the chunks in this process without Dask.
    progress : callable ``progress(done, total)``, optional
        Called with the number of chunks done (the store's included).
    retries : int
        Retries of a task that raised (a killed worker's tasks are rescheduled by Dask regardless).
    device : {"cpu", "cuda"}
        ``"cuda"``: each chunk is simulated on a GPU (``method="rk4"`` or ``"cf4"``; ``docs/gpu.md``): with
        several GPUs on a local cluster of one worker per GPU, each seeing its own (those of
        ``CUDA_VISIBLE_DEVICES`` where set; ``workers=N``: the first N, at most as many as there are), with
        one GPU (or ``workers=0``) in this process, or on ``client``'s workers; the statistics and
        percentiles are reduced on this process's GPU (:mod:`tumble.sweeps.device`: the percentiles bit for
        bit those of the reduction on the CPU).
    **initial_state
        Initial states shared by every sample (e.g. ``q0=[1, 0, 0, 0]``).

    Returns
    -------
    xarray.Dataset
        Dimensions ``sample``, ``time``, ``percentile``: each dispersed input
        and outcome per sample, each series per sample and time, with
        ``NAME_mean``/``_std``/``_min``/``_max`` (time) and ``NAME_percentiles``;
        opened lazily from the store (loaded when in memory); attribute
        ``chunks_computed``: the chunks this call computed.
    """
    times = output_times(t)
    if _is_scenario(model):
        raise ValidationError("model: a scenario sweeps with tumble.scenario.sweep_scenario(scenario, ...) (its [sweep] table "
                              "gives the dispersions, times and solver)")
    if not _is_builder(model):
        as_model(cast(Any, model))  # refuse what is not a model before anything else
    m, options = _solver_options(as_model(cast(Any, model)) if not _is_builder(model) else None, method,
                                 dict(dt=dt, rtol=rtol, atol=atol, max_steps=max_steps))
    if workers is not None and int(workers) < 0:
        raise ValidationError(f"workers: must be >= 0 (0: in this process), got {workers}")
    gpus: list[str] = []
    if device not in ("cpu", "cuda"):
        raise ValidationError(f"device: must be 'cpu' or 'cuda', got {device!r}")
    if device == "cuda":
        if m.name not in ("rk4", "cf4"):
            raise ValidationError(f"device: 'cuda' runs the methods 'rk4', 'cf4'; got method={m.name!r}")
        if client is None:  # one worker per GPU, or this process with one GPU
            gpus = gpu_workers(workers)
            workers = len(gpus)
    percentiles = tuple(float(p) for p in percentiles)
    if any(not 0.0 <= p <= 100.0 for p in percentiles):
        raise ValidationError(f"percentiles: must lie in [0, 100], got {list(percentiles)}")
    if chunk is None and store is not None:
        chunk = stored_chunk(store)  # resuming: the store's, whatever the cluster now
    plan = make_plan(model, dispersions or {}, samples=samples, seed=seed, chunk=chunk, t=times, method=m.name,
                     options=options, torque=torque, outcomes=dict(outcomes or {}), series=dict(statistics or {}),
                     fixed=initial_state, trajectories=trajectories, parallel=_parallel(client, workers),
                     device=device)
    require_memory(plan.client_bytes(in_memory=store is None), "samples",
                   f"{plan.samples} samples (the store's sample index and the outcomes' percentiles"
                   f"{'; in memory, every value kept' if store is None else ''})")
    with writing(store):  # one writer at a time; the temporaries of killed runs removed
        result = SweepStore(store, plan)
        computed = run_chunks(plan, result, client=client, workers=workers, gpus=gpus, progress=progress,
                              retries=retries)
        if computed or not result.complete or not result.has_percentiles(percentiles):
            result.finalize(percentiles, device)
    ds = result.dataset()
    ds.attrs["chunks_computed"] = computed
    return ds


def _parallel(client: Client | None, workers: int | None) -> int:
    """The chunks a sweep can run at once: the client's worker threads, ``workers`` of a local cluster (default
    one per core), 1 in this process."""
    if client is not None:
        return max(1, sum(client.nthreads().values()))
    return (os.cpu_count() or 1) if workers is None else max(1, int(workers))


def _is_scenario(model) -> bool:
    """Whether ``model`` is a :class:`tumble.scenario.Scenario`, known by its classes' names (the scenario
    layer sits above the sweeps)."""
    return any(c.__module__ == "tumble.scenario._base" and c.__name__ == "Scenario" for c in type(model).__mro__)


def open_sweep(path: str | os.PathLike[str]) -> xarray.Dataset:
    """The sweep stored at ``path`` as an :class:`xarray.Dataset`, opened lazily (Dask arrays)."""
    import xarray as xr

    from tumble.sweeps.store import SETTINGS_ATTR

    ds = xr.open_zarr(path, consolidated=False, zarr_format=3)
    if SETTINGS_ATTR not in ds.attrs:
        raise ValidationError(f"path: {path} is not a tumble sweep store")
    return ds


def __getattr__(name: str):
    if name == "sweep_scenario":  # deprecated in 0.4.0, removed in 0.5
        import warnings

        from tumble.scenario import sweep_scenario

        warnings.warn("tumble.sweeps.sweep_scenario is deprecated and will be removed in tumble 0.5: use "
                      "tumble.scenario.sweep_scenario", DeprecationWarning, stacklevel=2)
        return sweep_scenario
    raise AttributeError(f"module 'tumble.sweeps' has no attribute {name!r}")
