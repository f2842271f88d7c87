"""The file format of a trajectory: the xarray dataset and NetCDF-4 file it is written as, and the checks of one read.

:class:`tumble.Trajectory` converts itself with :func:`dataset` (``to_xarray``)
and :func:`fields` (``from_xarray``), writes with :func:`write` (``save``) and
reads with :func:`read` and :func:`check_physics` (``tumble.load``). This module
sees a trajectory through its fields only (``t``, ``q``, ``omega``,
``inertia``, ``extras``, ``totals``, its invariants), so it sits below the
result type. The layout is described in ``docs/trajectory.md``; the checks of a
file read in ``docs/reliability.md``.

Dimensions ``time``, ``body`` (batches only), ``axis`` (x, y, z), ``axis2``
(x, y, z: the column index of ``inertia``) and ``component`` (w, x, y, z).
Every variable has ``units`` and ``description`` attributes, and ``frame``
where it has one. Global attributes: ``conventions``, ``method``, ``model``,
``solver_<key>`` for each entry of ``info``, ``tumble_version`` and
``created`` (ISO 8601, UTC).
"""

from __future__ import annotations

import datetime
import os
from typing import TYPE_CHECKING, Any, Final

import numpy as np

from tumble._validate import ValidationError, require_finite, require_memory

if TYPE_CHECKING:
    import xarray

    from tumble.trajectory import Trajectory

__all__ = ["CONVENTIONS", "UNIT_Q_TOL", "check_physics", "dataset", "fields", "read", "write"]

CONVENTIONS = (
    "quaternion: Hamilton, scalar-first [w,x,y,z], body->inertial; omega in body axes; SI units"
)
#: Largest ``||q| − 1|`` a trajectory file may hold: every method keeps ``|q| = 1`` to ~1e-13 over 1e8 steps
#: (rounding, 1e-16 per step, adds like a random walk); a file past it was altered or damaged.
UNIT_Q_TOL = 1e-9

_ENGINE: Final = "h5netcdf"  # NetCDF-4 (HDF5) reader and writer used by save() and load()
_INFO_PREFIX = "solver_"  # global attributes of the NetCDF file that hold Trajectory.info
_EXTRA_ATTR = "tumble_extra"  # variable attribute that marks a Trajectory.extras entry in a dataset
_TOTAL_ATTR = "tumble_total"  # variable attribute that marks a model's total (energy, momentum_body)
_AXES = ["x", "y", "z"]
_COMPONENTS = ["w", "x", "y", "z"]
#: The units :func:`dataset` writes; a file that says other units for them is refused.
_UNITS = {"q": "1", "omega": "rad/s", "inertia": "kg m2", "energy": "J", "momentum_body": "N m s",
          "momentum_inertial": "N m s"}
#: Seconds per unit of time, by the UDUNITS names a NetCDF file may give (``time:units``).
_SECONDS = {**dict.fromkeys(("s", "sec", "secs", "second", "seconds"), 1.0),
            **dict.fromkeys(("ms", "msec", "millisecond", "milliseconds"), 1e-3),
            **dict.fromkeys(("us", "microsecond", "microseconds"), 1e-6),
            **dict.fromkeys(("min", "minute", "minutes"), 60.0),
            **dict.fromkeys(("h", "hr", "hour", "hours"), 3600.0),
            **dict.fromkeys(("d", "day", "days"), 86400.0)}
_LABELS = {"axis", "axis2", "component"}  # the coordinates of names (x, y, z; w, x, y, z)


def dataset(traj: Trajectory) -> xarray.Dataset:
    """The trajectory as an :class:`xarray.Dataset` (``Trajectory.to_xarray``), sharing its read-only arrays."""
    import xarray as xr

    lead = ("time",) if traj.batch_size is None else ("time", "body")

    def variable(dims, data, units, description, frame=None, **marks):
        attrs = {"units": units, "description": description, **marks}
        if frame is not None:
            attrs["frame"] = frame
        return xr.Variable(dims, data, attrs)

    data_vars: dict[str, xr.Variable] = {}
    if traj.q is not None:
        assert traj.inertia is not None  # with q (checked by the constructor)
        inertia_dims = ("axis", "axis2") if traj.inertia.ndim == 2 else ("body", "axis", "axis2")
        data_vars.update(
            omega=variable(lead + ("axis",), traj.omega, "rad/s",
                           "angular velocity of the body relative to inertial space", "body"),
            q=variable(lead + ("component",), traj.q, "1",
                       "attitude: unit Hamilton quaternion, scalar first, v_I = q v_B q*", "body->inertial"),
            inertia=variable(inertia_dims, traj.inertia, "kg m2", "inertia tensor about the centre of mass",
                             "body"),
        )
    totals = {_TOTAL_ATTR: 1} if "energy" in traj.totals else {}
    data_vars["energy"] = variable(
        lead, traj.energy, "J",
        "energy of the whole system" if totals else "rotational kinetic energy T = 1/2 omega.I omega", **totals)
    if traj.q is not None or "momentum_body" in traj.totals:
        totals = {_TOTAL_ATTR: 1} if "momentum_body" in traj.totals else {}
        data_vars["momentum_body"] = variable(
            lead + ("axis",), traj.momentum_body, "N m s",
            "angular momentum of the whole system" if totals else "angular momentum L = I omega", "body",
            **totals)
    if traj.q is not None:
        data_vars["momentum_inertial"] = variable(lead + ("axis",), traj.momentum_inertial, "N m s",
                                                  "angular momentum L_I = R(q) L_B", "inertial")
    for name, extra in traj.extras.items():
        if name in data_vars:
            raise ValidationError(f"extras[{name!r}]: the name is taken by a trajectory variable")
        data_vars[name] = xr.Variable(lead + extra.dims, extra.data, {
            "units": extra.units, "description": extra.description, _EXTRA_ATTR: 1})
    coords = {
        "time": ("time", traj.t, {"units": "s", "description": "output time"}),
        "axis": ("axis", _AXES),
        "axis2": ("axis2", _AXES),
        "component": ("component", _COMPONENTS),
    }
    if traj.batch_size is not None:
        coords["body"] = ("body", np.arange(traj.batch_size), {"description": "index in the batch"})
    attrs = {
        "conventions": CONVENTIONS,
        "method": traj.method,
        "model": traj.model,
        **{_INFO_PREFIX + key: value for key, value in traj.info.items()},
        "tumble_version": _tumble_version(),
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
    return xr.Dataset(data_vars, coords, attrs)


def fields(ds: xarray.Dataset) -> dict[str, Any]:
    """The constructor arguments of the trajectory a dataset made by :func:`dataset` holds
    (``Trajectory.from_xarray``): ``t``, ``q``, ``omega`` and ``inertia`` exactly, the model's totals, ``method``,
    ``model``, the ``solver_*`` attributes (as ``info``) and each extra as ``(data, dims, units, description)``."""
    attitude = [name for name in ("q", "omega", "inertia") if name in ds.variables]
    if "time" not in ds.variables or (len(attitude) < 3 and (attitude or "energy" not in ds.variables)):
        missing = [name for name in ("time", "q", "omega", "inertia") if name not in ds.variables]
        raise ValidationError(f"ds: not a tumble trajectory (missing {', '.join(missing)})")
    ds = ds.sel(axis=_AXES, axis2=_AXES, component=_COMPONENTS)

    def values(name, *tail):
        return ds[name].transpose("time", ..., *tail).values if name in ds.variables else None

    return dict(
        t=ds["time"].values,
        q=values("q", "component"),
        omega=values("omega", "axis"),
        inertia=ds["inertia"].transpose(..., "axis", "axis2").values if attitude else None,
        method=str(ds.attrs.get("method", "")),
        info={key[len(_INFO_PREFIX):]: value for key, value in ds.attrs.items() if key.startswith(_INFO_PREFIX)},
        extras={
            str(name): (var.values, tuple(str(d) for d in var.dims[1 + ("body" in var.dims):]),
                        str(var.attrs.get("units", "1")), str(var.attrs.get("description", "")))
            for name, var in ds.data_vars.items()
            if var.attrs.get(_EXTRA_ATTR) == 1
        },
        totals={str(name): values(name, *(("axis",) if "axis" in var.dims else ()))
                for name, var in ds.data_vars.items() if var.attrs.get(_TOTAL_ATTR) == 1},
        model=str(ds.attrs.get("model", "")),
    )


def write(traj: Trajectory, path: str) -> None:
    """Write the NetCDF-4 file of ``traj`` to ``path`` in place, not atomically: the writer that
    ``Trajectory.save`` hands to :func:`tumble._files.write_atomic`, and that a command writing several files
    hands to :func:`tumble._files.write_atomic_all`. Every numeric variable carries HDF5's Fletcher-32
    checksum, verified on each read, so that a damaged byte of the data is refused, not read as another number.

    The file is made in memory and written with plain file I/O, so that a full disk is one
    :class:`OSError` (``ENOSPC``): HDF5 writing to the disk itself left its file open after the error,
    and the process died of SIGSEGV when the garbage collector closed it.
    """
    ds = dataset(traj)
    checksums = {name: {"fletcher32": True} for name, var in ds.variables.items() if var.dtype.kind in "fiu"}
    contents = ds.to_netcdf(engine=_ENGINE, encoding=checksums)
    with open(path, "wb") as fh:
        fh.write(contents)


def _tumble_version() -> str:
    """``tumble.__version__``."""
    from tumble._version import __version__

    return __version__


def read(path: str | os.PathLike) -> xarray.Dataset:
    """The dataset of the NetCDF file ``path``, its times in seconds, once every variable holds real numbers
    (no complex part to drop, no strings), tumble's own variables say tumble's units, and every extra is
    finite; its variables loaded only once their size is known to fit in memory."""
    return _checked_dataset(_read_dataset(path))


def _read_dataset(path: str | os.PathLike) -> xarray.Dataset:
    """The variables of the NetCDF file ``path``, loaded once their size is known to fit in memory; times
    left as the numbers stored (their units are read by :func:`_time_in_seconds`)."""
    import h5py
    import xarray as xr

    # Every object's header and attributes read first, in a file that is closed on any error: h5netcdf leaves
    # a file it fails to open to the garbage collector, which prints "Exception ignored ..." tracebacks.
    with h5py.File(path, "r") as f:
        dict(f.attrs)
        f.visititems(lambda name, obj: dict(obj.attrs))
    with xr.open_dataset(path, engine=_ENGINE, decode_times=False, decode_timedelta=False,
                         phony_dims="access") as lazy:
        nbytes = sum(var.size * var.dtype.itemsize for var in lazy.variables.values())
        require_memory(nbytes, "variables", f"the {len(lazy.variables)} variable(s) it declares")
        return lazy.load()


def _checked_dataset(ds: xarray.Dataset) -> xarray.Dataset:
    """``ds`` with its times in seconds, once every variable holds real numbers (no complex part to drop,
    no strings), tumble's own variables say tumble's units, and every extra is finite."""
    for name, var in ds.variables.items():
        if name in _LABELS:
            continue
        if var.dtype.kind not in "fiu":
            raise ValidationError(f"{name}: must hold real numbers, got {var.dtype} values")
        units = var.attrs.get("units")
        if name in _UNITS and units is not None and str(units) != _UNITS[name]:
            raise ValidationError(f"{name}: units must be {_UNITS[name]!r} (as tumble writes them), got {units!r}")
        if var.attrs.get(_EXTRA_ATTR) == 1:
            require_finite(var.values, str(name))
    if "time" not in ds.variables:
        return ds
    return ds.assign_coords(time=("time", _time_in_seconds(ds["time"]), ds["time"].attrs))


def _time_in_seconds(time: xarray.DataArray) -> np.ndarray:
    """The output times in seconds: the stored numbers times the seconds of their ``units`` (``"s"`` when
    absent); CF's ``"UNIT since EPOCH"`` gives the times from the epoch (the origin of a trajectory's times
    is its own). Units that are not a unit of time are refused."""
    units = str(time.attrs.get("units", "s"))
    unit = units.partition(" since ")[0].strip()
    if unit not in _SECONDS:
        raise ValidationError(f"time: units must be a unit of time ({', '.join(sorted(set(_SECONDS)))}, "
                              f"optionally 'UNIT since EPOCH'), got {units!r}")
    seconds = np.asarray(time.values, dtype=np.float64)
    return seconds if _SECONDS[unit] == 1.0 else seconds * _SECONDS[unit]


def check_physics(traj: Trajectory) -> None:
    """Refuse what a run cannot make: ``||q| − 1| >`` :data:`UNIT_Q_TOL`, an inertia that is not physical,
    an energy or angular momentum past float64's range."""
    from tumble._inertia import principal_axes

    if traj.q is not None:
        error = np.abs(np.linalg.norm(traj.q, axis=-1) - 1.0)
        if error.max(initial=0.0) > UNIT_Q_TOL:
            k = tuple(int(i) for i in np.unravel_index(np.argmax(error), error.shape))
            raise ValidationError(f"q: must be unit quaternions (||q| - 1| <= {UNIT_Q_TOL:g}), "
                                  f"|q{list(k)}| = {np.linalg.norm(traj.q[k]):.17g}")
        principal_axes(traj.inertia, "inertia", definite=False)
    require_finite(traj.energy, "energy")
    if traj.q is not None or "momentum_body" in traj.totals:
        require_finite(traj.momentum_body, "momentum_body")
