"""A sweep's Zarr store: results written chunk by chunk as they come, resumable, opened lazily with xarray.

Layout (Zarr format 3, one group; ``S`` samples, ``n`` output times):

==========================  =======================  ==========================================
variable                    dimensions               what
==========================  =======================  ==========================================
``sample``, ``time``        (S,), (n,)               sample index; output times, s
each dispersed input        (sample, NAME_dim0, ...) the sample's value (SI units)
each outcome                (sample, ...)            one value per sample
each series                 (sample, time)           one value per sample and output time
``q``, ``omega``, extras    (sample, time, ...)      with ``trajectories=True``: every sample's run
``done``                    (chunk,)                 True once the chunk's results are written
``NAME_mean`` ... ``_max``  (time,)                  per-time mean, std (ddof 0), min, max of a series
``NAME_percentiles``        (percentile, time)       per-time percentiles of a series
``OUTCOME_percentiles``     (percentile, ...)        percentiles of an outcome over the samples with a value
``OUTCOME_count``           (...)                    the samples with a value (not NaN)
==========================  =======================  ==========================================

The store's arrays are chunked along ``sample`` exactly as the sweep is, so a
chunk's results are whole Zarr chunks, each written atomically by Zarr's
local store (a temporary file, then a rename). A chunk counts as done only
when its flag in ``done`` is set, after its data: an interruption (Ctrl-C, a
killed client) loses at most the chunks in flight, and running the same sweep
on the store computes only the chunks not done. Resuming checks that each
chunk marked done has its file in every per-sample array, and computes again
a chunk whose file is gone (every chunk is written, even one whose values are
all the fill value, NaN, so a missing file is always a lost chunk).

The sweep's settings (:meth:`tumble.sweeps.plan.Plan.settings`) are the
group's attribute ``tumble_sweep``, and a digest of its whole content
(:meth:`~tumble.sweeps.plan.Plan.digest`: the model's data, a tabulated
torque's values, a scenario's every table, ...) the attribute
``tumble_sweep_digest``; a store written with other settings or content is
refused with :class:`StoreMismatchError`, naming the first setting that
differs, rather than mixed with this sweep's chunks.

One process writes a store at a time: it holds the lock ``.NAME.lock`` beside
it (:func:`tumble.trajectory.write_atomic`'s lock) while it runs, and a second
writer is refused. The store is created under a temporary name
``.NAME.XXXXXXXX.tmp`` and renamed into place, so its name never points at a
half-made store; holding the lock, a writer removes the temporaries that a
killed run left (:func:`writing`).

The per-time statistics merge the chunks' moments in chunk order with
:mod:`tumble.sweeps.moments`' exact pairwise update (Chan, Golub & LeVeque 1979),
so they are the same bit for bit whatever the number of workers or the order
in which chunks finished; the percentiles are exact (``numpy.percentile``,
linear interpolation), read from the stored series in blocks of output times,
each block's times shared between threads (one per core: NumPy's partition
releases the GIL, and each time's percentiles are computed alone, so they are
the same whatever the split).
An outcome is NaN where its event did not happen within the run (a
:class:`~tumble.sweeps.CrossingTime` never crossed, a
:class:`~tumble.sweeps.SettlingTime` not settled at the end): its percentiles
are those of the samples with a value (``numpy.nanpercentile``; NaN when none
has one), and ``OUTCOME_count`` says how many of the samples that is.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import warnings
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import xarray
    import zarr

from tumble._validate import ValidationError
from tumble.sweeps.moments import STATISTICS, merge, moments, summary
from tumble.sweeps.plan import ChunkResult, Plan

__all__ = ["SweepStore", "StoreMismatchError", "stored_chunk", "temporary", "writing", "SETTINGS_ATTR", "DIGEST_ATTR",
           "COMPLETE_ATTR"]

#: Group attributes: the sweep's settings, the digest of its content, and whether its statistics are written.
SETTINGS_ATTR = "tumble_sweep"
DIGEST_ATTR = "tumble_sweep_digest"
COMPLETE_ATTR = "tumble_sweep_complete"


class StoreMismatchError(ValidationError):
    """The store given to a sweep was written by another sweep (other settings, or other model or torque data
    under the same settings): resuming on it would mix the two."""


@contextlib.contextmanager
def writing(path: str | os.PathLike[str] | None) -> Iterator[None]:
    """Hold the writer's lock of the Zarr store ``path`` (``.NAME.lock`` beside it) while the block runs, after
    removing the temporaries ``.NAME.XXXXXXXX.tmp`` of killed runs (no live writer owns them: a writer holds the
    lock).
    Another process writing ``path`` now: :class:`FileExistsError`. ``None`` (in memory): nothing to hold."""
    if path is None:
        yield
        return
    from tumble._files import _exclusive, _remove_stale

    path = os.fspath(path)
    directory, name = os.path.split(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise FileNotFoundError(f"store: directory {directory!r} does not exist")
    with _exclusive(os.path.join(directory, f".{name}.lock"), path):
        _remove_stale(directory, name)
        yield


def stored_chunk(path: str | os.PathLike[str]) -> int | None:
    """The chunk of the sweep stored at ``path``, or None where there is no readable sweep store."""
    import zarr

    try:
        settings = dict(zarr.open_group(os.fspath(path), mode="r", zarr_format=3).attrs).get(SETTINGS_ATTR)
    except Exception:  # noqa: BLE001 - not a store: the sweep refuses it in SweepStore, naming why
        return None
    chunk = settings.get("chunk") if isinstance(settings, dict) else None
    return chunk if isinstance(chunk, int) and not isinstance(chunk, bool) else None


def temporary(path: str) -> str:
    """A new empty directory beside the store ``path`` (``.NAME.XXXXXXXX.tmp``), to be renamed onto it when
    whole."""
    from tumble._files import new_temporary_directory

    return new_temporary_directory(path)


#: Values of a series read at once when taking its percentiles (float64 words): 256 MB.
_BLOCK_WORDS = 2**25


class SweepStore:
    """The results of one sweep in a Zarr store at ``path`` (a directory), or in memory when ``path`` is None.

    In memory the store is an :class:`xarray.Dataset` of NumPy arrays laid out as the Zarr store would be (the
    same variables, dimensions, coordinates and attributes, read back as JSON would give them): chunks are
    written into it in place, and :meth:`dataset` returns it without a copy."""

    def __init__(self, path: str | os.PathLike[str] | None, plan: Plan) -> None:
        self.path = None if path is None else os.fspath(path)
        self.plan = plan
        self._memory: xarray.Dataset | None = None  # the store when path is None, once made
        self._writable: zarr.Group | None = None  # the group open for writing once the store exists, and its arrays
        self._arrays: dict[str, zarr.Array] = {}
        self._done = np.zeros(len(plan.chunks), dtype=bool)
        if self.path is not None and os.path.exists(self.path):
            self._check()

    # -- opening ----------------------------------------------------------------------

    def _group(self, mode="r+"):
        import zarr

        if mode == "r+" and self._writable is not None:
            return self._writable
        group = zarr.open_group(self.path, mode=mode, zarr_format=3)
        if mode == "r+":
            self._writable = group
        return group

    def _readable(self):
        """The store to read: the in-memory dataset, or the Zarr group opened read-only (both take ``name in``,
        ``[name]`` and ``.attrs``)."""
        return self._memory if self._memory is not None else self._group("r")

    @property
    def exists(self) -> bool:
        return self._memory is not None or (self.path is not None and os.path.exists(self.path))

    def _check(self) -> None:
        """Refuse a store that is not this sweep's; read which chunks are done, and mark again as not done
        each chunk whose file is missing from one of the per-sample arrays."""
        try:
            group = self._group("r")
            attrs = dict(group.attrs)
        except Exception as exc:  # noqa: BLE001 - any unreadable directory is "not a sweep store"
            raise ValidationError(f"store: {self.path} exists and is not a tumble sweep store ({exc})") from None
        stored = attrs.get(SETTINGS_ATTR)
        if not isinstance(stored, dict):
            raise ValidationError(f"store: {self.path} exists and is not a tumble sweep store (no {SETTINGS_ATTR} "
                                  "attribute); give a new path")
        here = self.plan.settings()
        for key in here:
            if stored.get(key) != here[key]:
                raise StoreMismatchError(f"store: {self.path} was written with other settings: {key} = "
                                         f"{stored.get(key)!r} there, {here[key]!r} here; give a new path, the "
                                         "same settings, or delete the store to start again")
        if DIGEST_ATTR not in attrs:
            raise StoreMismatchError(f"store: {self.path} was written by an earlier tumble, which did not record "
                                     "the sweep's content: it cannot be checked to be this sweep's; give a new "
                                     "path, or delete the store to start again")
        if attrs[DIGEST_ATTR] != self._digest():
            raise StoreMismatchError(f"store: {self.path} was written by another sweep: the settings agree but not "
                                     "the content (the model's or a torque's data, a scenario's tables, a "
                                     "function's code); give a new path, or delete the store to start again")
        self._done = np.asarray(group["done"][:], dtype=bool)
        lost = [k for k in np.flatnonzero(self._done) if not self._chunk_on_disk(group, int(k))]
        if lost:
            writable = self._group()
            for k in lost:
                writable["done"][k] = False
            writable.attrs[COMPLETE_ATTR] = False
            self._done[lost] = False

    def _chunk_on_disk(self, group, k: int) -> bool:
        """Whether chunk ``k`` of every per-sample array has its (non-empty) file in the store."""
        assert self.path is not None  # a store on disk: one in memory is never resumed
        for name, array in group.arrays():
            dims = array.metadata.dimension_names or ()
            if name == "sample" or not dims or dims[0] != "sample":  # the coordinate: one chunk, written whole
                continue
            key = array.metadata.encode_chunk_key((k,) + (0,) * (array.ndim - 1))
            file = os.path.join(self.path, name, *key.split("/"))
            if not os.path.isfile(file) or os.path.getsize(file) == 0:
                return False
        return True

    def _digest(self) -> str:
        """The plan's content digest, strict for a store on disk (it must be found again on resuming)."""
        return self.plan.digest(strict=self.path is not None)

    @property
    def complete(self) -> bool:
        return self.exists and bool(dict(self._readable().attrs).get(COMPLETE_ATTR, False))

    def has_percentiles(self, percentiles: Iterable[float]) -> bool:
        """Whether the store's statistics are those of ``percentiles``."""
        group = self._readable()
        return "percentile" in group and np.array_equal(group["percentile"][:], np.asarray(percentiles, float))

    def missing(self) -> list[int]:
        """The chunks whose results are not in the store."""
        return [int(k) for k in np.flatnonzero(~self._done)]

    # -- writing ----------------------------------------------------------------------

    def _layout(self, first: ChunkResult) -> tuple[dict[str, tuple], dict, dict]:
        """The store's variables (name → dims, shape, dtype), coordinates and attributes, shaped from the first
        chunk's results (on disk each variable is then chunked along its first dimension as the sweep is)."""
        plan = self.plan
        s = plan.samples
        variables: dict[str, tuple] = {}
        for name, v in {**first.inputs, **first.outcomes}.items():
            variables[name] = (("sample", *(f"{name}_dim{k}" for k in range(v.ndim - 1))), (s, *v.shape[1:]),
                               v.dtype)
        for name in first.series:
            variables[name] = ("sample", "time"), (s, len(plan.t)), np.dtype(np.float64)
        for name, v in first.trajectories.items():
            variables[name] = (("sample", "time", *(f"{name}_dim{k}" for k in range(v.ndim - 2))),
                               (s, *v.shape[1:]), np.dtype(np.float64))
        variables["done"] = ("chunk",), (len(plan.chunks),), np.dtype(bool)
        coords = {"sample": np.arange(s), "time": ("time", plan.t, {"units": "s"})}
        # as Zarr's JSON gives them back: lists for tuples
        attrs = json.loads(json.dumps({SETTINGS_ATTR: plan.settings(), DIGEST_ATTR: self._digest(),
                                       COMPLETE_ATTR: False}))
        return variables, coords, attrs

    def _create(self, first: ChunkResult) -> None:
        """Make the empty store (arrays shaped from the first chunk's results), under a temporary name first."""
        import xarray as xr

        variables, coords, attrs = self._layout(first)
        if self.path is None:
            self._memory = xr.Dataset({name: (dims, np.zeros(shape, dtype))
                                       for name, (dims, shape, dtype) in variables.items()}, coords=coords,
                                      attrs=attrs)
            return
        import dask.array as da

        c = self.plan.chunk
        ds = xr.Dataset({name: (dims, da.zeros(shape, chunks=(1 if name == "done" else c, *shape[1:]), dtype=dtype))
                         for name, (dims, shape, dtype) in variables.items()}, coords=coords, attrs=attrs)
        encoding = {name: {"fill_value": None} for name in ds.data_vars}
        tmp = temporary(self.path)
        try:
            ds.to_zarr(tmp, mode="a", compute=False, consolidated=False, encoding=encoding, zarr_format=3)
            os.rename(tmp, self.path)  # atomic; fails if the name appeared meanwhile
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise

    def write(self, k: int, result: ChunkResult) -> None:
        """Write chunk ``k``'s results, then mark it done."""
        if not self.exists:
            self._create(result)
        for name, value in {**result.inputs, **result.outcomes, **result.series, **result.trajectories}.items():
            self._array(name)[result.lo:result.hi] = value
        self._array("done")[k] = True
        self._done[k] = True

    def _array(self, name):
        """The store's array ``name`` (a NumPy array in memory, a Zarr array on disk), opened once."""
        if name not in self._arrays:
            # on disk every chunk is written, even one all of fill values (NaN): a missing file is a lost chunk
            self._arrays[name] = (self._memory[name].values if self._memory is not None else
                                  self._group()[name].with_config({"write_empty_chunks": True}))
        return self._arrays[name]

    # -- statistics -------------------------------------------------------------------

    def finalize(self, percentiles: Iterable[float], device: str = "cpu") -> None:
        """Write the per-time statistics and the percentiles once every chunk is done (idempotent); with
        ``device="cuda"``, reduced on the GPU (:mod:`tumble.sweeps.device`: the same percentiles bit for bit,
        the moments to rounding)."""
        import xarray as xr

        plan = self.plan
        p = np.asarray(percentiles, dtype=np.float64)
        data: dict[str, tuple] = {}  # name → (dims, values)
        gpu: Any = None
        if device == "cuda":
            from tumble.sweeps import device as gpu  # imports numba.cuda: only when asked for
        for name in plan.series:
            series = self._array(name)
            if gpu is not None:
                values = series[:]
                stats, band = gpu.moments(values), gpu.percentiles(values, p)
            else:
                stats, band = self._moments(series), self._percentiles(series, p)
            for stat, value in zip(STATISTICS, summary(stats), strict=True):
                data[f"{name}_{stat}"] = ("time", value)
            data[f"{name}_percentiles"] = ("percentile", "time"), band
        for name in plan.outcomes:
            values = self._array(name)[:]
            dims = tuple(f"{name}_dim{k}" for k in range(values.ndim - 1))
            if gpu is not None:
                band = gpu.percentiles(values.reshape(values.shape[0], -1), p, ignore_nan=True)
                data[f"{name}_percentiles"] = ("percentile", *dims), band.reshape(p.size, *values.shape[1:])
            else:
                with warnings.catch_warnings():  # an outcome no sample reached: NaN percentiles, said by its count
                    warnings.simplefilter("ignore", RuntimeWarning)
                    data[f"{name}_percentiles"] = ("percentile", *dims), np.nanpercentile(values, p, axis=0)
            data[f"{name}_count"] = dims, np.count_nonzero(~np.isnan(values), axis=0)
        ds = xr.Dataset(data, coords={"percentile": p})
        if self._memory is not None:
            self._memory = self._memory.drop_vars(list(ds.variables), errors="ignore").merge(ds)
        else:  # statistics of other percentiles (a resumed sweep may ask for others) are replaced whole
            group = self._group()
            for name in ds.variables:
                if name in group:
                    del group[name]
            ds.to_zarr(self.path, mode="a", consolidated=False, zarr_format=3)
        (self._memory if self._memory is not None else self._group()).attrs[COMPLETE_ATTR] = True

    def _moments(self, series) -> list[np.ndarray]:
        """``[count, mean, M₂, min, max]`` per output time of the stored ``series`` (S, n), the chunks' moments
        merged in chunk order."""
        stats: list[np.ndarray] | None = None
        for lo, hi in self.plan.chunks:
            part = moments(series[lo:hi].T)
            stats = part if stats is None else merge(stats, part)
        assert stats is not None  # a sweep has at least one chunk
        return stats

    def _percentiles(self, series, p: np.ndarray) -> np.ndarray:
        """The percentiles ``p`` per output time of the stored ``series`` (S, n), read in blocks of times."""
        block = max(1, _BLOCK_WORDS // self.plan.samples)
        return np.concatenate([_percentiles(series[:, a:a + block], p) for a in range(0, len(self.plan.t), block)],
                              axis=1)

    def dataset(self) -> xarray.Dataset:
        """The store as an :class:`xarray.Dataset`: lazily (Dask arrays) for a store on disk; in memory, the
        store itself."""
        import xarray as xr

        if self._memory is not None:
            return self._memory
        return xr.open_zarr(self.path, consolidated=False, zarr_format=3)


def _percentiles(values: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``numpy.percentile(values, p, axis=0)``, the columns (output times) split between one thread per core."""
    from concurrent.futures import ThreadPoolExecutor

    parts = [c for c in np.array_split(np.arange(values.shape[1]), os.cpu_count() or 1) if c.size]
    if len(parts) < 2:
        return np.percentile(values, p, axis=0)
    with ThreadPoolExecutor(len(parts)) as pool:
        return np.concatenate(list(pool.map(lambda c: np.percentile(values[:, c[0]:c[-1] + 1], p, axis=0), parts)),
                              axis=1)
