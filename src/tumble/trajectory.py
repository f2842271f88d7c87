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
atomically and reads back validated (:func:`load`). Its figure, viewer page,
notebook view and table are drawn by :mod:`tumble.viz.trajectory`. The layout
is described in ``docs/trajectory.md``.

The module is one unit (about 500 lines): the checks of the fields, the
invariants derived from them and the members of a batch all read the same
shapes (``lead``), and its file format is :mod:`tumble._netcdf`.
"""

from __future__ import annotations

import operator
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, NamedTuple, cast

import numpy as np

from . import _netcdf
from ._files import require_regular, write_atomic
from ._netcdf import CONVENTIONS, UNIT_Q_TOL
from ._validate import ValidationError, as_array

if TYPE_CHECKING:
    import pandas
    import xarray
    from matplotlib.figure import Figure

__all__ = ["CONVENTIONS", "UNIT_Q_TOL", "VIEWS", "Extra", "Trajectory", "load", "write_atomic"]

_TOTALS = {"energy": 0, "momentum_body": 1}  # the totals a model may give, and their trailing axes
#: The views of a trajectory drawn above the result type, by name: ``plot``, ``to_html``, ``notebook_html`` and
#: ``to_dataframe``, the functions of :mod:`tumble.viz.trajectory`, which fills this table when ``import tumble``
#: loads it. The methods of the same names read it, so that this module imports nothing above it (no figure, no
#: viewer, no pandas: ``docs/architecture.md``).
VIEWS: dict[str, Callable[..., Any]] = {}


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
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, str, np.integer, np.floating)):
            raise ValidationError(f"info[{key!r}]: must be a float, an int or a string, got {type(value).__name__}")
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
                method: str, info: dict, extras: dict, totals: dict, model: str,
                host: Callable[[], Trajectory] | None = None) -> Trajectory:
        """The trajectory of a run of :func:`tumble.simulate`, whose ``t``, ``q`` and ``omega`` were checked
        there: ``t`` (n,) strictly increasing and finite, ``q`` (n, [N,] 4) and ``omega`` (n, [N,] 3) finite
        float64 of the shapes of a run, arrays the caller owns and hands over. They are marked
        read-only, not copied nor checked again; ``inertia`` is shared when read-only (a model's own), copied
        otherwise; ``info``, ``extras`` and ``totals`` are checked as by the constructor. ``q``, ``omega`` and
        ``inertia`` may be device arrays (``simulate(..., output="device")``), kept as they are; ``host``, for
        such a run of a model whose other outputs are made on the host, makes the whole trajectory there
        (:meth:`to_host`)."""
        self = object.__new__(cls)
        self.__dict__["_host"] = host
        if isinstance(inertia, np.ndarray) and inertia.flags.writeable:
            inertia = np.array(inertia, dtype=np.float64)
        for name, value in (("t", t), ("q", q), ("omega", omega), ("inertia", inertia)):  # device arrays as given
            object.__setattr__(self, name, _readonly(value) if isinstance(value, np.ndarray) else value)
        for name, given in (("method", method), ("info", info), ("extras", extras), ("totals", totals),
                            ("model", model)):
            object.__setattr__(self, name, given)
        self._check_rest(q.shape[:-1] if q is not None else np.shape(totals["energy"]))
        return self

    @property
    def on_device(self) -> bool:
        """Whether ``q``, ``omega`` and ``inertia`` are GPU device arrays (``simulate(..., output="device")``):
        numba.cuda's, which implement ``__cuda_array_interface__`` (``cupy.asarray(traj.q)`` takes them
        without a copy). The invariants, views and files read host arrays: :meth:`to_host` first."""
        return self.q is not None and not isinstance(self.q, np.ndarray)

    @property
    def rest_on_host(self) -> bool:
        """Whether this device trajectory holds ``q`` and ``omega`` alone, of a model whose other outputs (its
        extras, inertia, and the system's energy and momentum) are made on the host by :meth:`to_host` from
        the states left on the GPU (``simulate(..., output="device")`` of a spacecraft, a flexible body, ...:
        docs/gpu.md)."""
        return self.__dict__.get("_host") is not None

    def to_host(self) -> Trajectory:
        """This trajectory with its device arrays copied to the host (itself when they are there already); for
        one whose other outputs are made on the host (:attr:`rest_on_host`), the whole trajectory, made there
        from its states copied back: the trajectory of the same run with ``output="host"``."""
        if not self.on_device:
            return self
        if self.rest_on_host:
            return self.__dict__["_host"]()

        def host(a):
            return a.copy_to_host() if hasattr(a, "copy_to_host") else np.array(a, dtype=np.float64)

        return Trajectory._of_run(self.t, host(self.q), host(self.omega), host(self.inertia), self.method,
                                  dict(self.info), self.extras, self.totals, self.model)

    def __getattr__(self, name: str):
        """``traj.NAME`` is ``traj.extras[NAME].data`` for the model's named outputs (e.g. ``traj.wheel_speed``)."""
        extras = self.__dict__.get("extras", {})
        if name in extras:
            return extras[name].data
        if self.__dict__.get("_host") is not None and not name.startswith("_"):
            raise AttributeError(f"{name}: this trajectory holds q and omega on the GPU; its other outputs are made "
                                 "on the host: traj.to_host()." + name)
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
        from .dynamics import kinetic_energy  # compiled: loaded on first use, so that `import tumble` stays light

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
        from .dynamics import angular_momentum

        return _readonly(angular_momentum(cast(np.ndarray, self.inertia), cast(np.ndarray, self.omega)))

    @cached_property
    def momentum_inertial(self) -> np.ndarray:
        """Angular momentum ``L_I = R(q) L_B``, N m s, inertial axes, shape (n, [N,] 3).

        Constant when no external torque acts.
        """
        from .attitude import rotate

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
        """Return the trajectory as an :class:`xarray.Dataset` that shares its read-only arrays: dimensions
        ``time``, ``body`` (batches only), ``axis``, ``axis2`` and ``component``; units, descriptions and frames
        as attributes (:func:`tumble._netcdf.dataset`, ``docs/trajectory.md``)."""
        return _netcdf.dataset(self)

    @classmethod
    def from_xarray(cls, ds: xarray.Dataset) -> Trajectory:
        """Rebuild a trajectory from a dataset made by :meth:`to_xarray`: ``time``, ``q``, ``omega`` and ``inertia``
        exactly (the rigid-body invariants are recomputed), the totals, ``method``, ``model``, ``info``, the extras."""
        fields = _netcdf.fields(ds)
        fields["extras"] = {name: Extra(*extra) for name, extra in fields["extras"].items()}
        return cls(**fields)

    def save(self, path: str | os.PathLike) -> None:
        """Write the trajectory to ``path`` as NetCDF-4 (HDF5, via h5netcdf), atomically: under a temporary name
        in the same directory, renamed onto ``path`` only when complete (:func:`write_atomic`), so an interrupted
        save leaves any previous file at ``path`` untouched. Read it back with :func:`tumble.load`."""
        write_atomic(path, self._write_netcdf)

    def _write_netcdf(self, path: str) -> None:
        """Write the NetCDF-4 file to ``path`` in place, not atomically: the writer that :meth:`save` hands to
        :func:`write_atomic`, and a command writing several files to :func:`tumble._files.write_atomic_all`
        (:func:`tumble._netcdf.write`: checksummed variables, made in memory)."""
        _netcdf.write(self, path)

    # -- views: figure, page, notebook, table (tumble.viz.trajectory) -------------------

    def plot(self, *, title: str | None = None) -> Figure:
        """A matplotlib figure of the trajectory, nothing shown or saved (:func:`tumble.viz.trajectory.plot`):
        (a) body rates (rad/s, body axes), (b) relative drifts of the energy and |L| (symlog scale), (c) direction
        of the inertial angular momentum; body 0 of a batch. Save it atomically with :func:`write_atomic`."""
        return VIEWS["plot"](self, title=title)

    def to_html(self, path: str | os.PathLike, **options: Any) -> None:
        """Write the offline 3-D viewer of this trajectory to ``path``: one self-contained HTML file, atomically;
        ``options`` (``model=``, ``frames=``, ``axis=``, ``shape=``): :func:`tumble.viz.viewer.write_html`."""
        VIEWS["to_html"](self, path, **options)

    def _repr_html_(self) -> str:
        """A notebook cell's view: the table of the run, then the viewer (an ``<iframe>``) where the trajectory
        can be drawn without its model (:func:`tumble.viz.trajectory.notebook_html`)."""
        return VIEWS["notebook_html"](self)

    def to_dataframe(self) -> pandas.DataFrame:
        """The samples as a pandas DataFrame indexed by ``t`` (s), or by ``(t, body)`` for a batch; one column per
        component of ``q``, ``omega``, the invariants and each extra (:func:`tumble.viz.trajectory.to_dataframe`)."""
        return VIEWS["to_dataframe"](self)


def load(path: str | os.PathLike) -> Trajectory:
    """Read a trajectory written by :meth:`Trajectory.save` (arrays bitwise equal), validated as it is built.

    Refused with a :class:`ValidationError` naming the file: a path that is not a regular file (a FIFO, a
    device: reading it could block for ever), variables larger than the memory can hold (checked from the
    header, before reading them), any file the NetCDF/HDF5 readers cannot read, variables that do not hold
    real numbers (complex, strings), units other than those :meth:`save` writes (``time`` excepted: any unit
    of time, read in seconds), extras that are not finite, and contents that
    break the rules of construction (shapes, finite values) or of physics: ``||q| − 1| ≤``
    :data:`UNIT_Q_TOL`, an inertia tensor that is symmetric, positive semi-definite and meets the triangle
    inequality (:func:`tumble._inertia.principal_axes`), and an energy and angular momentum within float64's
    range. A missing or unreadable path raises :class:`OSError`.
    """
    name = os.fspath(path)
    require_regular(path)
    try:
        with np.errstate(all="ignore"):
            traj = Trajectory.from_xarray(_netcdf.read(path))
            _netcdf.check_physics(traj)
    except ValidationError as exc:  # the file named first; the field's own error stays as the cause
        raise ValidationError(f"{name}: {exc}") from exc
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - a hostile file may make h5py/xarray raise anything
        if isinstance(exc, OSError) and exc.errno is not None:  # the system's own error (permission, I/O)
            raise
        raise ValidationError(f"{name}: not a readable tumble trajectory ({type(exc).__name__}: {exc})") from None
    return traj
