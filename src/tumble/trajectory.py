"""The result of a simulation, for every model: sampled attitude and body rate, named extras, invariants.

A :class:`Trajectory` holds one run, or a batch of ``N`` runs, at the output
times ``t`` (``n`` samples); every model of :func:`tumble.simulate` returns
one:

==========  ================  ====================================================
field       shape             meaning
==========  ================  ====================================================
``t``       (n,)              output times, s
``q``       (n, [N,] 4)       attitude: unit Hamilton quaternion, scalar first
                              ``[w, x, y, z]``, body → inertial
                              (``v_I = q ⊗ v_B ⊗ q*``)
``omega``   (n, [N,] 3)       angular velocity relative to inertial, rad/s,
                              body axes
``inertia`` ([N,] 3, 3)       inertia tensor about the centre of mass, kg m²,
                              body axes (one tensor may serve a whole batch)
==========  ================  ====================================================

A model larger than a rigid body adds its own sampled states as named
*extras* (wheel speeds, modal coordinates, joint angles, ...), readable as
attributes (``traj.wheel_speed``), and gives the *totals* of the whole system:
its energy and its angular momentum (hub and wheels, appendages, slosh mass,
damper, limbs). A model with no single attitude (a robot arm on a fixed base)
has ``q``, ``omega`` and ``inertia`` set to ``None``. Without totals the
invariants are those of a rigid body (kinetic energy ``T = ½ ω·Iω``, angular
momentum ``L = I ω``), derived on demand with :mod:`tumble.dynamics`. A
trajectory converts to an :class:`xarray.Dataset`, saves to NetCDF-4
atomically and plots with matplotlib's object-oriented API. The layout is
described in ``docs/trajectory.md``.
"""

from __future__ import annotations

import datetime
import operator
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, Final, NamedTuple, cast

import numpy as np

from ._files import require_regular, write_atomic
from ._validate import ValidationError, as_array
from .attitude import rotate
from .dynamics import angular_momentum, kinetic_energy

if TYPE_CHECKING:
    import pandas
    import xarray
    from matplotlib.figure import Figure

__all__ = ["Extra", "Trajectory", "load", "write_atomic"]

CONVENTIONS = (
    "quaternion: Hamilton, scalar-first [w,x,y,z], body->inertial; omega in body axes; SI units"
)
_ENGINE: Final = "h5netcdf"  # NetCDF-4 (HDF5) reader and writer used by save() and load()
_INFO_PREFIX = "solver_"  # global attributes of the NetCDF file that hold Trajectory.info
_EXTRA_ATTR = "tumble_extra"  # variable attribute that marks a Trajectory.extras entry in a dataset
_TOTAL_ATTR = "tumble_total"  # variable attribute that marks a model's total (energy, momentum_body)
_TOTALS = {"energy": 0, "momentum_body": 1}  # the totals a model may give, and their trailing axes
_AXES = ["x", "y", "z"]
_COMPONENTS = ["w", "x", "y", "z"]
# Panel (b) of plot() shows |drift| on a symlog scale, linear below this value
# (under float64's rounding, 2.2e-16) and logarithmic above: exact zeros stay
# on the plot and every drift above rounding gets its own decade.
_DRIFT_LINTHRESH = 1e-16


def _readonly(a: np.ndarray) -> np.ndarray:
    """Return ``a`` marked read-only (``a`` must be owned by the caller)."""
    a.setflags(write=False)
    return a


def _relative(change: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``change / |reference|``, or ``change`` itself where ``reference == 0``."""
    scale = np.abs(reference)
    return _readonly(np.divide(change, scale, out=np.array(change, dtype=np.float64), where=scale > 0))


def _check_info(info: Any) -> dict:
    """Copy ``info``, checking that it maps non-empty strings to floats, ints or strings."""
    if not isinstance(info, Mapping):
        raise ValidationError(f"info: must be a dict, got {type(info).__name__}")
    out = {}
    for key, value in info.items():
        if type(key) is str and key and type(value) in (int, float, str):  # the usual entries, at once
            out[key] = value
            continue
        if not isinstance(key, str) or not key:
            raise ValidationError(f"info: keys must be non-empty strings, got {key!r}")
        if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (int, float, str, np.integer, np.floating)
        ):
            raise ValidationError(
                f"info[{key!r}]: must be a float, an int or a string, got {type(value).__name__}"
            )
        out[key] = value.item() if isinstance(value, np.generic) else value
    return out


class Extra(NamedTuple):
    """A sampled state beyond ``q`` and ``omega`` (wheel speeds, modal coordinates, ...).

    data        : array of shape (n, [N,] *sizes): one row per output time (and body),
                  then one axis per name in ``dims``
    dims        : names of the trailing axes, e.g. ``("wheel",)``; ``()`` for a scalar
    units       : UDUNITS-style units, e.g. ``"rad/s"``
    description : what the quantity is, with its frame where it has one
    """

    data: np.ndarray
    dims: tuple[str, ...] = ()
    units: str = "1"
    description: str = ""


_RESERVED_DIMS = {"time", "body", "axis", "axis2", "component"}


def _check_extras(extras: Any, lead: tuple[int, ...]) -> dict:
    """Validate ``extras`` (name -> :class:`Extra`) against the leading shape ``(n, [N])``; copy read-only."""
    if type(extras) is dict and not extras:  # a rigid body's: nothing to check
        return {}
    if not isinstance(extras, Mapping):
        raise ValidationError(f"extras: must be a dict of name -> Extra, got {type(extras).__name__}")
    out = {}
    for name, extra in extras.items():
        where = f"extras[{name!r}]"
        if not isinstance(name, str) or not name.isidentifier():
            raise ValidationError(f"extras: names must be identifiers, got {name!r}")
        if not isinstance(extra, Extra):
            raise ValidationError(f"{where}: must be a tumble.trajectory.Extra, got {type(extra).__name__}")
        dims = tuple(extra.dims)
        if any(not isinstance(d, str) or d in _RESERVED_DIMS for d in dims):
            raise ValidationError(f"{where}.dims: must be names other than {sorted(_RESERVED_DIMS)}, got {dims}")
        data = np.array(extra.data, dtype=np.float64)
        if data.shape[:len(lead)] != lead or data.ndim != len(lead) + len(dims):
            raise ValidationError(f"{where}.data: must have shape {lead} + one axis per dim {dims}, "
                                  f"got {data.shape}")
        out[name] = Extra(_readonly(data), dims, str(extra.units), str(extra.description))
    return out


def _check_totals(totals: Any, lead: tuple[int, ...]) -> dict:
    """Validate a model's ``totals`` (``energy`` (n, [N]), ``momentum_body`` (n, [N,] 3)); copy read-only."""
    if type(totals) is dict and not totals:  # a rigid body's: nothing to check
        return {}
    if not isinstance(totals, Mapping):
        raise ValidationError(f"totals: must be a dict of name -> array, got {type(totals).__name__}")
    out = {}
    for name, value in totals.items():
        if name not in _TOTALS:
            raise ValidationError(f"totals: names must be among {sorted(_TOTALS)}, got {name!r}")
        data = as_array(value, f"totals[{name!r}]")
        want = lead + (3,) * _TOTALS[name]
        if data.shape != want:
            raise ValidationError(f"totals[{name!r}]: must have shape {want}, got {data.shape}")
        out[name] = _readonly(np.array(data, dtype=np.float64))
    return out


@dataclass(frozen=True, eq=False, repr=False)
class Trajectory:
    """Samples of the rotational state of one rigid body or a batch of bodies.

    Parameters
    ----------
    t : array_like, shape (n,)
        Output times, s, strictly monotonic (``t[0]`` is the start).
    q : array_like, shape (n, 4) or (n, N, 4), or None
        Attitude, unit Hamilton quaternion, scalar first ``[w, x, y, z]``,
        mapping body to inertial axes: ``v_I = q ⊗ v_B ⊗ q*``. ``None`` for a
        model with no single attitude (a robot arm), with ``omega`` and
        ``inertia`` None too and the totals given.
    omega : array_like, shape (n, 3) or (n, N, 3), or None
        Angular velocity of the body relative to inertial space, rad/s, in
        body axes.
    inertia : array_like, shape (3, 3) or (N, 3, 3), or None
        Inertia tensor about the centre of mass, kg m², in body axes. A single
        (3, 3) tensor is shared by every body of a batch.
    method : str
        How the samples were made: ``"rk4"``, ``"dop853"``, ``"exact"``, ...
    info : dict
        Solver settings and statistics (``rtol``, ``atol``, ``dt``,
        ``n_steps``, ...); values are floats, ints or strings.
    extras : dict of str to :class:`Extra`
        States of models larger than a rigid body (wheel speeds, modal
        coordinates, ...), sampled at ``t``; ``traj.NAME`` reads
        ``traj.extras[NAME].data``.
    totals : dict of str to array_like
        The model's own invariants of the whole system: ``"energy"`` (n, [N])
        in J and ``"momentum_body"`` (n, [N,] 3) in N·m·s, body axes (angular
        momentum about the centre of mass, or the fixed point). Without them
        :attr:`energy` and :attr:`momentum_body` are those of ``omega`` and
        ``inertia`` (a rigid body).
    model : str
        The kind of model that made the samples (``"RigidBody"``, ``"Spacecraft"``, ...).

    The arrays are copied as float64 and stored read-only. Invalid input
    raises :class:`tumble.ValidationError` naming the field.
    """

    t: np.ndarray
    q: np.ndarray | None
    omega: np.ndarray | None
    inertia: np.ndarray | None
    method: str = ""
    info: dict = field(default_factory=dict)
    extras: dict = field(default_factory=dict)
    totals: dict = field(default_factory=dict)
    model: str = ""

    def __post_init__(self) -> None:
        t = as_array(self.t, "t")
        if t.ndim != 1 or t.size == 0:
            raise ValidationError(f"t: must be a 1-D array of at least one time, got shape {t.shape}")
        step = np.diff(t)
        if not (np.all(step > 0) or np.all(step < 0)):
            raise ValidationError("t: must be strictly increasing or strictly decreasing")
        n = t.size
        if self.q is None:
            q = omega = inertia = None
            if self.omega is not None or self.inertia is not None:
                raise ValidationError("omega, inertia: must be None when q is None (a model with no single attitude)")
            if "energy" not in (self.totals if isinstance(self.totals, Mapping) else {}):
                raise ValidationError("totals: a trajectory without an attitude (q = None) must give "
                                      "totals['energy']")
            lead = np.shape(self.totals["energy"])
            if len(lead) not in (1, 2) or lead[0] != n:
                raise ValidationError(f"totals['energy']: must have shape (n,) or (n, N) with n = len(t) = {n}, "
                                      f"got {lead}")
        else:
            q = as_array(self.q, "q", tail=(4,))
            if q.ndim not in (2, 3) or q.shape[0] != n:
                raise ValidationError(
                    f"q: must have shape (n, 4) or (n, N, 4) with n = len(t) = {n}, got {q.shape}"
                )
            omega = as_array(self.omega, "omega", tail=(3,))
            if omega.shape[:-1] != q.shape[:-1]:
                raise ValidationError(
                    f"omega: must have shape {q.shape[:-1] + (3,)} to match q, got {omega.shape}"
                )
            inertia = as_array(self.inertia, "inertia", tail=(3, 3))
            batch = q.shape[1:-1]
            if inertia.shape[:-2] not in ((), batch):
                allowed = "(3, 3)" + (f" or ({batch[0]}, 3, 3)" if batch else "")
                raise ValidationError(f"inertia: must have shape {allowed}, got {inertia.shape}")
            lead = q.shape[:-1]
        if not isinstance(self.method, str):
            raise ValidationError(f"method: must be a string, got {type(self.method).__name__}")
        if not isinstance(self.model, str):
            raise ValidationError(f"model: must be a string, got {type(self.model).__name__}")
        for name, value in (("t", t), ("q", q), ("omega", omega), ("inertia", inertia)):
            object.__setattr__(self, name, None if value is None else _readonly(np.array(value, dtype=np.float64)))
        self._check_rest(lead)

    def _check_rest(self, lead: tuple[int, ...]) -> None:
        """Check and store ``info``, ``extras`` and ``totals`` against the leading shape ``lead``."""
        object.__setattr__(self, "info", _check_info(self.info))
        object.__setattr__(self, "extras", _check_extras(self.extras, lead))
        object.__setattr__(self, "totals", _check_totals(self.totals, lead))

    @classmethod
    def _of_run(cls, t: np.ndarray, q: np.ndarray | None, omega: np.ndarray | None, inertia: np.ndarray | None,
                method: str, info: dict, extras: dict, totals: dict, model: str) -> Trajectory:
        """The trajectory of a run of :func:`tumble.simulate`, whose ``t``, ``q`` and ``omega`` were checked
        there: ``t`` (n,) strictly increasing and finite, ``q`` (n, [N,] 4) and ``omega`` (n, [N,] 3) finite
        float64 of the shapes of a run, arrays the caller owns and hands over. They are marked
        read-only, not copied nor checked again; ``inertia`` is shared when read-only (a model's own), copied
        otherwise; ``info``, ``extras`` and ``totals`` are checked as by the constructor."""
        self = object.__new__(cls)
        if inertia is not None and inertia.flags.writeable:
            inertia = np.array(inertia, dtype=np.float64)
        for name, value in (("t", t), ("q", q), ("omega", omega), ("inertia", inertia)):
            object.__setattr__(self, name, None if value is None else _readonly(value))
        for name, given in (("method", method), ("info", info), ("extras", extras), ("totals", totals),
                            ("model", model)):
            object.__setattr__(self, name, given)
        self._check_rest(q.shape[:-1] if q is not None else np.shape(totals["energy"]))
        return self

    def __getattr__(self, name: str):
        """``traj.NAME`` is ``traj.extras[NAME].data`` for the model's named outputs (e.g. ``traj.wheel_speed``)."""
        extras = self.__dict__.get("extras", {})
        if name in extras:
            return extras[name].data
        raise AttributeError(f"{type(self).__name__!r} has no attribute {name!r}"
                             + (f" (extras: {', '.join(extras)})" if extras else ""))

    def __len__(self) -> int:
        """Number of output times ``n``."""
        return self.t.size

    def __repr__(self) -> str:
        bodies = "" if self.batch_size is None else f", batch_size={self.batch_size}"
        return (
            f"Trajectory(method={self.method!r}, n={len(self)}, "
            f"t=[{self.t[0]:g}, {self.t[-1]:g}] s{bodies})"
        )

    @property
    def batch_size(self) -> int | None:
        """Number ``N`` of bodies in a batch, or ``None`` for a single body."""
        lead = self._lead
        return None if len(lead) == 1 else lead[1]

    @property
    def _lead(self) -> tuple[int, ...]:
        """The leading shape ``(n,)`` or ``(n, N)`` of every sampled array."""
        return self.q.shape[:-1] if self.q is not None else self.totals["energy"].shape

    def member(self, i: int) -> Trajectory:
        """The trajectory of member ``i`` of a batch (negative ``i`` counts from the end): one body, spacecraft
        or robot of the batch, as a Trajectory of its own."""
        n_members = self.batch_size
        if n_members is None:
            raise ValidationError("i: member(i) needs a batch; this Trajectory holds a single run")
        i = operator.index(i)
        if not -n_members <= i < n_members:
            raise IndexError(f"i: member {i} is out of range for a batch of {n_members}")
        def pick(a):
            return None if a is None else a[:, i]

        inertia = self.inertia if self.inertia is None or self.inertia.ndim == 2 else self.inertia[i]
        extras = {name: e._replace(data=e.data[:, i]) for name, e in self.extras.items()}
        totals = {name: value[:, i] for name, value in self.totals.items()}
        return Trajectory(self.t, pick(self.q), pick(self.omega), inertia, self.method, self.info, extras, totals,
                          self.model)

    def body(self, i: int) -> Trajectory:
        """Deprecated alias of :meth:`member` (a batch member need not be a body)."""
        import warnings

        warnings.warn("Trajectory.body(i) is deprecated: use Trajectory.member(i)", DeprecationWarning, stacklevel=2)
        return self.member(i)

    def at(self, index: int | slice | Sequence[int] | np.ndarray) -> Trajectory:
        """The trajectory at the output samples ``index`` only: a slice or integer indices along time, kept
        in order (an int gives one sample, ``at(-1)`` the last); every sampled array, extra and total is
        cut the same way, the inertia and ``info`` are kept."""
        pick: slice | np.ndarray
        if isinstance(index, slice):
            pick = index
        else:
            indices = np.atleast_1d(np.asarray(index))
            if indices.ndim != 1 or indices.dtype.kind not in "iu":
                raise ValidationError(f"index: must be a slice or integer indices along time, got {index!r}")
            if indices.size and not (-len(self) <= indices.min() and indices.max() < len(self)):
                raise IndexError(f"index: output samples out of range for n = {len(self)}: {indices.tolist()}")
            pick = indices

        def cut(a):
            return None if a is None else a[pick]

        extras = {name: e._replace(data=e.data[pick]) for name, e in self.extras.items()}
        totals = {name: value[pick] for name, value in self.totals.items()}
        return Trajectory(self.t[pick], cut(self.q), cut(self.omega), self.inertia, self.method, self.info, extras,
                          totals, self.model)

    # -- invariants ------------------------------------------------------------------

    @cached_property
    def energy(self) -> np.ndarray:
        """Energy of the whole system, J, shape (n, [N]).

        The model's total where it gives one (``totals["energy"]``: hub and wheels,
        appendages, slosh, damper, limbs; kinetic plus potential for a robot),
        otherwise the rotational kinetic energy ``T = ½ ω·Iω`` of the rigid body.
        """
        if "energy" in self.totals:
            return self.totals["energy"]
        return _readonly(kinetic_energy(cast(np.ndarray, self.inertia), cast(np.ndarray, self.omega)))

    @cached_property
    def momentum_body(self) -> np.ndarray:
        """Angular momentum of the whole system about the centre of mass, N m s, body axes, (n, [N,] 3).

        The model's total where it gives one (``totals["momentum_body"]``),
        otherwise ``L = I ω`` of the rigid body.
        """
        if "momentum_body" in self.totals:
            return self.totals["momentum_body"]
        if self.q is None:
            raise ValidationError(f"momentum_body: this {self.model or 'model'} trajectory has no angular momentum "
                                  "(no single attitude; see its extras and energy)")
        return _readonly(angular_momentum(cast(np.ndarray, self.inertia), cast(np.ndarray, self.omega)))

    @cached_property
    def momentum_inertial(self) -> np.ndarray:
        """Angular momentum ``L_I = R(q) L_B``, N m s, inertial axes, shape (n, [N,] 3).

        Constant when no external torque acts.
        """
        body = self.momentum_body
        return _readonly(rotate(cast(np.ndarray, self.q), body))

    @cached_property
    def momentum_norm(self) -> np.ndarray:
        """Magnitude ``|L|`` of the angular momentum (the same in every frame), N m s, (n, [N])."""
        return _readonly(np.linalg.norm(self.momentum_body, axis=-1))

    @cached_property
    def energy_drift(self) -> np.ndarray:
        """Relative change of kinetic energy from the first sample, ``(T - T₀) / T₀``.

        Dimensionless, shape (n, [N]). Where ``T₀ = 0`` (a body at rest) the
        absolute change ``T - T₀`` (J) is returned instead.
        """
        return _relative(self.energy - self.energy[0], self.energy[0])

    @cached_property
    def momentum_norm_drift(self) -> np.ndarray:
        """Relative change of ``|L|`` from the first sample, ``(|L| - |L₀|) / |L₀|``.

        Dimensionless, shape (n, [N]); the absolute change (N m s) where ``|L₀| = 0``.
        """
        return _relative(self.momentum_norm - self.momentum_norm[0], self.momentum_norm[0])

    @cached_property
    def momentum_inertial_drift(self) -> np.ndarray:
        """Relative change of the inertial momentum vector, ``|L_I - L_I₀| / |L_I₀|``.

        Dimensionless and ≥ 0, shape (n, [N]). It sees errors of direction
        (attitude) as well as of magnitude. Where ``L_I₀ = 0`` the absolute
        change ``|L_I - L_I₀|`` (N m s) is returned instead.
        """
        change = np.linalg.norm(self.momentum_inertial - self.momentum_inertial[0], axis=-1)
        return _relative(change, np.linalg.norm(self.momentum_inertial[0], axis=-1))

    # -- xarray and NetCDF ------------------------------------------------------------

    def to_xarray(self) -> xarray.Dataset:
        """Return the trajectory as an :class:`xarray.Dataset`.

        Dimensions ``time``, ``body`` (batches only), ``axis`` (x, y, z),
        ``axis2`` (x, y, z: the column index of ``inertia``) and ``component``
        (w, x, y, z). Every variable has ``units`` and ``description``
        attributes, and ``frame`` where it has one. Global attributes:
        ``conventions``, ``method``, ``solver_<key>`` for each entry of
        ``info``, ``tumble_version`` and ``created`` (ISO 8601, UTC). The
        dataset shares this trajectory's read-only arrays.
        """
        import xarray as xr

        lead = ("time",) if self.batch_size is None else ("time", "body")

        def variable(dims, data, units, description, frame=None, **marks):
            attrs = {"units": units, "description": description, **marks}
            if frame is not None:
                attrs["frame"] = frame
            return xr.Variable(dims, data, attrs)

        data_vars: dict[str, xr.Variable] = {}
        if self.q is not None:
            assert self.inertia is not None  # with q (checked in __post_init__)
            inertia_dims = ("axis", "axis2") if self.inertia.ndim == 2 else ("body", "axis", "axis2")
            data_vars.update(
                omega=variable(lead + ("axis",), self.omega, "rad/s",
                               "angular velocity of the body relative to inertial space", "body"),
                q=variable(lead + ("component",), self.q, "1",
                           "attitude: unit Hamilton quaternion, scalar first, v_I = q v_B q*", "body->inertial"),
                inertia=variable(inertia_dims, self.inertia, "kg m2", "inertia tensor about the centre of mass",
                                 "body"),
            )
        totals = {_TOTAL_ATTR: 1} if "energy" in self.totals else {}
        data_vars["energy"] = variable(
            lead, self.energy, "J",
            "energy of the whole system" if totals else "rotational kinetic energy T = 1/2 omega.I omega", **totals)
        if self.q is not None or "momentum_body" in self.totals:
            totals = {_TOTAL_ATTR: 1} if "momentum_body" in self.totals else {}
            data_vars["momentum_body"] = variable(
                lead + ("axis",), self.momentum_body, "N m s",
                "angular momentum of the whole system" if totals else "angular momentum L = I omega", "body",
                **totals)
        if self.q is not None:
            data_vars["momentum_inertial"] = variable(lead + ("axis",), self.momentum_inertial, "N m s",
                                                      "angular momentum L_I = R(q) L_B", "inertial")
        for name, extra in self.extras.items():
            if name in data_vars:
                raise ValidationError(f"extras[{name!r}]: the name is taken by a trajectory variable")
            data_vars[name] = xr.Variable(lead + extra.dims, extra.data, {
                "units": extra.units, "description": extra.description, _EXTRA_ATTR: 1})
        coords = {
            "time": ("time", self.t, {"units": "s", "description": "output time"}),
            "axis": ("axis", _AXES),
            "axis2": ("axis2", _AXES),
            "component": ("component", _COMPONENTS),
        }
        if self.batch_size is not None:
            coords["body"] = ("body", np.arange(self.batch_size), {"description": "index in the batch"})
        attrs = {
            "conventions": CONVENTIONS,
            "method": self.method,
            "model": self.model,
            **{_INFO_PREFIX + key: value for key, value in self.info.items()},
            "tumble_version": _tumble_version(),
            "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        }
        return xr.Dataset(data_vars, coords, attrs)

    @classmethod
    def from_xarray(cls, ds: xarray.Dataset) -> Trajectory:
        """Rebuild a trajectory from a dataset made by :meth:`to_xarray`.

        Reads ``time``, ``q``, ``omega`` and ``inertia`` exactly (the rigid-body
        invariants are recomputed), the model's totals, ``method``, ``model``,
        the ``solver_*`` attributes (into ``info``) and the extras.
        """
        attitude = [name for name in ("q", "omega", "inertia") if name in ds.variables]
        if "time" not in ds.variables or (len(attitude) < 3 and (attitude or "energy" not in ds.variables)):
            missing = [name for name in ("time", "q", "omega", "inertia") if name not in ds.variables]
            raise ValidationError(f"ds: not a tumble trajectory (missing {', '.join(missing)})")
        ds = ds.sel(axis=_AXES, axis2=_AXES, component=_COMPONENTS)
        info = {
            key[len(_INFO_PREFIX):]: value
            for key, value in ds.attrs.items()
            if key.startswith(_INFO_PREFIX)
        }

        def values(name, *tail):
            return ds[name].transpose("time", ..., *tail).values if name in ds.variables else None

        return cls(
            t=ds["time"].values,
            q=values("q", "component"),
            omega=values("omega", "axis"),
            inertia=ds["inertia"].transpose(..., "axis", "axis2").values if attitude else None,
            method=str(ds.attrs.get("method", "")),
            info=info,
            extras={
                str(name): Extra(var.values, tuple(str(d) for d in var.dims[1 + ("body" in var.dims):]),
                                 str(var.attrs.get("units", "1")), str(var.attrs.get("description", "")))
                for name, var in ds.data_vars.items()
                if var.attrs.get(_EXTRA_ATTR) == 1
            },
            totals={name: values(name, *(("axis",) * _TOTALS[name])) for name in _TOTALS
                    if name in ds.variables and ds[name].attrs.get(_TOTAL_ATTR) == 1},
            model=str(ds.attrs.get("model", "")),
        )

    def save(self, path: str | os.PathLike) -> None:
        """Write the trajectory to ``path`` as NetCDF-4 (HDF5, via h5netcdf), atomically.

        The file is written under a temporary name in the same directory and
        renamed onto ``path`` only when complete (:func:`write_atomic`), so an
        interrupted save leaves any previous file at ``path`` untouched. Read it
        back with :func:`tumble.load`.
        """
        write_atomic(path, self._write_netcdf)

    def _write_netcdf(self, path: str) -> None:
        """Write the NetCDF-4 file to ``path`` in place, not atomically: the writer that :meth:`save` hands
        to :func:`write_atomic`, and that a command writing several files hands to
        :func:`tumble._files.write_atomic_all`. Every numeric variable carries HDF5's Fletcher-32 checksum,
        verified on each read, so that a damaged byte of the data is refused, not read as another number.

        The file is made in memory and written with plain file I/O, so that a full disk is one
        :class:`OSError` (``ENOSPC``): HDF5 writing to the disk itself left its file open after the error,
        and the process died of SIGSEGV when the garbage collector closed it.
        """
        ds = self.to_xarray()
        checksums = {name: {"fletcher32": True} for name, var in ds.variables.items() if var.dtype.kind in "fiu"}
        contents = ds.to_netcdf(engine=_ENGINE, encoding=checksums)
        with open(path, "wb") as fh:
            fh.write(contents)

    # -- viewer ------------------------------------------------------------------------

    def to_html(self, path: str | os.PathLike, **options: Any) -> None:
        """Write the offline 3-D viewer of this trajectory to ``path``: one self-contained HTML file, atomically.

        ``options`` (``model=``, ``frames=``, ``axis=``, ``shape=``) and what the page shows:
        :func:`tumble.viewer.write_html` (``docs/viewer.md``).
        """
        from tumble.viewer import write_html

        write_html(self, path, **options)

    def _repr_html_(self) -> str:
        """A notebook cell's view: the table of the run (model, method, samples, time span, solver statistics,
        largest drifts of energy and angular momentum), then the viewer (an ``<iframe>``;
        :func:`tumble.viewer.notebook_html`) where the trajectory can be drawn without its model."""
        from tumble.viz._notebook import summary_html
        from tumble.viewer import notebook_html

        return summary_html(self) + (notebook_html(self) or "")

    def to_dataframe(self) -> pandas.DataFrame:
        """The samples as a pandas DataFrame indexed by ``t`` (s), or by ``(t, body)`` for a batch.

        Columns ``q_w … q_z``, ``omega_x … omega_z`` (rad/s, body axes), ``energy`` (J),
        ``momentum_body_x …`` (N m s, body axes) and one per component of each extra
        (:func:`tumble.viz._notebook.to_dataframe`). pandas comes with xarray; it is imported on the first call.
        """
        from tumble.viz._notebook import to_dataframe

        return to_dataframe(self)

    # -- figure ------------------------------------------------------------------------

    def plot(self, *, title: str | None = None) -> Figure:
        """Return a matplotlib figure of the trajectory (nothing is shown or saved).

        Panels, against time (s): (a) body rates ω_x, ω_y, ω_z (rad/s, body
        axes); (b) absolute values of the relative drifts of the energy and
        |L| (symlog scale, linear below 1e-16, so exact zeros show); (c)
        direction of the inertial angular momentum, ``L_I / |L_I|`` (inertial
        axes). A model without an attitude (a robot) shows its first two
        vector extras in (a) and (c) (joint coordinates and rates).
        For a batch, body 0 is plotted and the title says so.
        Save the figure with ``fig.savefig(path)``, or atomically with
        :func:`write_atomic`.
        """
        from matplotlib.figure import Figure

        traj = self if self.batch_size is None else self.member(0)
        if title is None:
            title = f"tumble trajectory ({self.method or 'unknown method'})"
        if self.batch_size is not None:
            title += f" — body 0 of {self.batch_size}"

        fig = Figure(figsize=(8.0, 9.0), layout="constrained")
        ax_rate, ax_drift, ax_direction = fig.subplots(3, 1, sharex=True)
        vectors = [(name, e) for name, e in traj.extras.items() if len(e.dims) == 1]
        if traj.omega is not None:
            for k, name in enumerate(_AXES):
                ax_rate.plot(traj.t, traj.omega[:, k], label=rf"$\omega_{name}$")
            ax_rate.set_title("(a) body rates", loc="left")
            ax_rate.set_ylabel("ω, body axes (rad/s)")
        else:  # no attitude (a robot): its first sampled vector, e.g. the joint coordinates
            _plot_extra(ax_rate, traj.t, *vectors[0], "(a)")

        ax_drift.plot(traj.t, np.abs(traj.energy_drift), label=r"$|E - E_0|/E_0$")
        if traj.q is not None or "momentum_body" in traj.totals:
            ax_drift.plot(traj.t, np.abs(traj.momentum_norm_drift), label=r"$||L| - |L_0||/|L_0|$")
        ax_drift.set_yscale("symlog", linthresh=_DRIFT_LINTHRESH)
        ax_drift.set_ylim(bottom=0.0)
        ax_drift.set_title(
            f"(b) drift of energy and momentum (symlog scale, linear below {_DRIFT_LINTHRESH:g})", loc="left"
        )
        ax_drift.set_ylabel("|relative drift| (1)")

        if traj.q is not None:
            momentum = traj.momentum_inertial
            norm = np.linalg.norm(momentum, axis=-1, keepdims=True)
            direction = np.divide(momentum, norm, out=np.zeros_like(momentum), where=norm > 0)
            for k, name in enumerate(_AXES):
                ax_direction.plot(traj.t, direction[:, k], label=rf"$L_{name}/|L|$")
            ax_direction.set_title("(c) direction of the angular momentum", loc="left")
            ax_direction.set_ylabel("$L_I/|L_I|$, inertial axes (1)")
        else:
            _plot_extra(ax_direction, traj.t, *vectors[1], "(c)")
        ax_direction.set_xlabel("time t (s)")

        for ax in (ax_rate, ax_drift, ax_direction):
            ax.grid(True, alpha=0.3)
            ax.legend(loc="best", fontsize="small")
        fig.suptitle(title)
        return fig


def _plot_extra(ax, t, name: str, extra: Extra, panel: str) -> None:
    """One line per component of a vector extra (n, m) against time, labelled with its dimension."""
    dim = extra.dims[0]
    for k in range(extra.data.shape[-1]):
        ax.plot(t, extra.data[:, k], label=f"{dim} {k}")
    ax.set_title(f"{panel} {name.replace('_', ' ')}", loc="left")
    ax.set_ylabel(f"{name} ({extra.units})")


def _tumble_version() -> str:
    """``tumble.__version__``."""
    from tumble._version import __version__

    return __version__


#: Largest ``||q| − 1|`` a trajectory file may hold: every method keeps ``|q| = 1`` to ~1e-13 over 1e8 steps
#: (rounding, 1e-16 per step, adds like a random walk); a file past it was altered or damaged.
UNIT_Q_TOL = 1e-9


def load(path: str | os.PathLike) -> Trajectory:
    """Read a trajectory written by :meth:`Trajectory.save` (arrays bitwise equal), validated as it is built.

    Refused with a :class:`ValidationError` naming the file: a path that is not a regular file (a FIFO, a
    device: reading it could block for ever), variables larger than the memory can hold (checked from the
    header, before reading them), any file the NetCDF/HDF5 readers cannot read, variables that do not hold
    real numbers (complex, strings), units other than those :meth:`save` writes (``time`` excepted: any unit
    of time, read in seconds, see :func:`_time_in_seconds`), extras that are not finite, and contents that
    break the rules of construction (shapes, finite values) or of physics: ``||q| − 1| ≤``
    :data:`UNIT_Q_TOL`, an inertia tensor that is symmetric, positive semi-definite and meets the triangle
    inequality (:func:`tumble._inertia.principal_axes`), and an energy and angular momentum within float64's
    range. A missing or unreadable path raises :class:`OSError`.
    """
    name = os.fspath(path)
    require_regular(path)
    try:
        with np.errstate(all="ignore"):
            traj = Trajectory.from_xarray(_checked_dataset(_read_dataset(path)))
            _check_physics(traj)
    except ValidationError as exc:  # the file named first; the field's own error stays as the cause
        raise ValidationError(f"{name}: {exc}") from exc
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - a hostile file may make h5py/xarray raise anything
        if isinstance(exc, OSError) and exc.errno is not None:  # the system's own error (permission, I/O)
            raise
        raise ValidationError(f"{name}: not a readable tumble trajectory ({type(exc).__name__}: {exc})") from None
    return traj


def _read_dataset(path: str | os.PathLike) -> xarray.Dataset:
    """The variables of the NetCDF file ``path``, loaded once their size is known to fit in memory; times
    left as the numbers stored (their units are read by :func:`_time_in_seconds`)."""
    import h5py
    import xarray as xr

    from ._validate import require_memory

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


#: The units :meth:`Trajectory.to_xarray` writes; a file that says other units for them is refused.
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


def _checked_dataset(ds: xarray.Dataset) -> xarray.Dataset:
    """``ds`` with its times in seconds, once every variable holds real numbers (no complex part to drop,
    no strings), tumble's own variables say tumble's units, and every extra is finite."""
    from ._validate import require_finite

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


def _check_physics(traj: Trajectory) -> None:
    """Refuse what a run cannot make: ``||q| − 1| >`` :data:`UNIT_Q_TOL`, an inertia that is not physical,
    an energy or angular momentum past float64's range."""
    from ._inertia import principal_axes
    from ._validate import require_finite

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
