"""A batch larger than memory, run in chunks and streamed to a Zarr store: :func:`simulate_to_store`.

The batch's members are cut into chunks (:mod:`tumble.sweeps.chunks`); each
chunk is one :func:`tumble.simulate` call (in parallel over the cores, as any
batch) whose trajectory (:meth:`tumble.Trajectory.to_xarray`: ``q``,
``omega``, the extras and the totals, dimensions ``(time, body, ...)``) is
written to the store's region of those members before the next chunk starts.
The peak memory is that of one chunk (about 400 bytes per member and output
time, plus the compressor's buffers), whatever the batch. The store is written
under a temporary name and renamed onto ``store`` when complete, so the name
never points at a half-written run; the result opens lazily with xarray
(:func:`xarray.open_zarr`), chunked by member as written. The solver
statistics ``n_steps``, ``n_rejected`` and ``n_rhs`` are summed over the
chunks (as they are over a batch).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from tumble._validate import ValidationError, output_times
from tumble.simulate import as_model
from tumble.sweeps.chunks import Chunks, batch_members, simulate_chunks
from tumble.sweeps.store import temporary, writing

if TYPE_CHECKING:
    import xarray
    from numpy.typing import ArrayLike

    from tumble.rigid_body import RigidBody
    from tumble.simulate import Model
    from tumble.torques import TorqueLike

__all__ = ["simulate_to_store"]

_SUMMED = ("solver_n_steps", "solver_n_rejected", "solver_n_rhs")


def _template(ds: xarray.Dataset, n: int, chunk: int) -> xarray.Dataset:
    """The whole store of ``n`` members laid out from the first chunk's ``ds``: the members' arrays empty
    (Dask zeros, written as their chunks come, chunked by ``chunk`` members), the others whole."""
    import dask.array as da
    import xarray as xr

    def members(var):
        shape = tuple(n if d == "body" else size for d, size in zip(var.dims, var.shape, strict=True))
        chunks = tuple(chunk if d == "body" else size for d, size in zip(var.dims, var.shape, strict=True))
        return var.dims, da.zeros(shape, chunks=chunks), var.attrs

    template = xr.Dataset({name: members(var) for name, var in ds.data_vars.items() if "body" in var.dims},
                          coords={**{name: c for name, c in ds.coords.items() if name != "body"},
                                  "body": ("body", np.arange(n), ds["body"].attrs)},
                          attrs=ds.attrs)
    return template.assign({name: var for name, var in ds.data_vars.items() if "body" not in var.dims})


def simulate_to_store(
    model: Model | RigidBody | Sequence[RigidBody] | ArrayLike,
    omega0: ArrayLike | None = None,
    *,
    store: str | os.PathLike[str],
    t: ArrayLike,
    method: str = "dop853",
    dt: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int | None = None,
    torque: TorqueLike | ArrayLike = None,
    device: str = "cpu",
    chunk: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    **initial_state: ArrayLike | None,
) -> xarray.Dataset:
    """:func:`tumble.simulate` of a batch, run in chunks of ``chunk`` members, each written to the Zarr store
    ``store`` (a directory that must not exist) as it completes; return the run as a lazily opened
    :class:`xarray.Dataset` (dimensions ``(time, body, ...)``, chunked by member).

    ``model``, ``omega0``, ``t``, the solver options, ``torque``, ``device`` and ``**initial_state`` are those
    of :func:`tumble.simulate` (SI units; rates in rad/s, body axes); ``chunk`` defaults to
    :data:`~tumble.sweeps.chunks.SAMPLES_PER_CHUNK` ``// len(t)`` members (about 200 MB a chunk);
    ``progress(done, total)`` counts members.
    """
    import xarray as xr

    path = os.fspath(store)
    if os.path.exists(path):
        raise ValidationError(f"store: {path} exists; give a new path (a run is never written over another)")
    model = as_model(model)
    if omega0 is not None:
        initial_state["omega0"] = omega0
    values = {name: np.asarray(v) for name, v in initial_state.items() if v is not None}
    n = batch_members(model, values)
    if n < 1:
        raise ValidationError("store: the batch has no members (initial states of shape (0, size)): nothing to write")
    t = output_times(t)
    chunks = Chunks.of(n, chunk, n_times=t.size)
    options = dict(method=method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps, torque=torque, device=device)
    with writing(path):  # one writer at a time; the temporaries of killed runs removed
        tmp = None
        summed: dict[str, int] = {}  # the solver statistics, summed over the chunks
        try:
            for lo, hi, traj in simulate_chunks(model, chunks, t=t, initial_state=values, **options):
                ds = traj.to_xarray()
                # labels as variable-length strings: Zarr 3 specifies those, not NumPy's fixed-width ones
                ds = ds.assign_coords({name: c.astype(object) for name, c in ds.coords.items()
                                       if c.dtype.kind == "U"})
                if "body" not in ds.dims:
                    ds = ds.expand_dims(body=[0], axis=1).transpose("time", "body", ...)
                if tmp is None:  # the whole store, laid out from the first chunk
                    tmp = temporary(path)
                    template = _template(ds, n, chunks.size)
                    template.to_zarr(tmp, mode="a", compute=False, consolidated=False, zarr_format=3)
                region = ds.drop_vars([name for name, var in ds.variables.items() if "body" not in var.dims])
                region = region.assign_coords(body=np.arange(lo, hi))
                region.to_zarr(tmp, region={"body": slice(lo, hi)}, consolidated=False, zarr_format=3)
                for key in _SUMMED:
                    summed[key] = summed.get(key, 0) + int(ds.attrs.get(key, 0))
                if progress is not None:
                    progress(hi, n)
            import zarr

            assert tmp is not None  # n >= 1: the first chunk made it
            zarr.open_group(tmp, mode="r+", zarr_format=3).attrs.update(summed)
            os.rename(tmp, path)
        except BaseException:
            if tmp is not None:
                shutil.rmtree(tmp, ignore_errors=True)
            raise
    return xr.open_zarr(path, consolidated=False, zarr_format=3)
