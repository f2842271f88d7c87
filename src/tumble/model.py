"""The model interface of the front door: what every model implements once, below :func:`tumble.simulate`.

A model is an immutable, validated description (MuJoCo's ``MjModel``,
Pinocchio's ``Model``) that implements :class:`Model` once:

* :meth:`Model.state_fields`: the named parts of its initial state
  (:class:`StateField`: the keywords of :func:`~tumble.simulate`, e.g.
  ``omega0``, ``q0``, ``wheel_speeds0``);
* :meth:`Model.compile`: its compiled kernel (:mod:`tumble.kernels`) under a
  torque, which says which methods it provides for (``provides``);
* :meth:`Model.initial_states`: the state vectors from the named values;
* :meth:`Model.outputs`: the :class:`Outputs` the :class:`~tumble.Trajectory`
  is made of (attitude, body rate, named extras, the system's totals);
* :meth:`Model.invariants`: what its exact motion keeps constant on a run.

Sweeps, the viewer, scenario files and the command line work on any model
through this interface. :mod:`tumble.simulate` re-exports these names.
"""

from __future__ import annotations

import abc
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._validate import ValidationError, as_array, require_finite
from tumble._vec import norm

if TYPE_CHECKING:
    from tumble.integrate import Method
    from tumble.trajectory import Trajectory

__all__ = ["Model", "Outputs", "StateField"]

#: The largest |component| of an initial state (quaternions aside: normalised): its square stays finite in float64.
_LARGEST_STATE = 1e150

#: An initial quaternion whose length is within this of 1 is normalised silently (a unit quaternion typed to 7
#: digits, or rounded by a computation); one further off is normalised with a NonUnitQuaternionWarning.
UNIT_Q0_TOL = 1e-6


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
            default = np.array(self.check(self.default))  # its own copy, shared by every run: read-only
            default.setflags(write=False)
            object.__setattr__(self, "default", default)

    def check(self, value: ArrayLike) -> np.ndarray:
        """The value of this field as a float64 array (size,) or (N, size): finite, at most
        :data:`_LARGEST_STATE` in magnitude, a quaternion non-zero and normalised."""
        scalar = self.size == 1 and np.ndim(value) == 0  # a number for a field of one component
        # finite checked below with the magnitude (one pass over the values), quaternions here
        arr = as_array(value, self.name, tail=() if scalar else (self.size,), finite=self.quaternion)
        if scalar:
            arr = arr.reshape(1)
        if arr.ndim > 2:
            raise ValidationError(f"{self.name}: a batch has one leading axis, got shape {arr.shape}")
        if not self.quaternion and arr.size and not np.abs(arr).max() <= _LARGEST_STATE:  # NaN fails too
            require_finite(arr, self.name)
            raise ValidationError(f"{self.name}: must be at most {_LARGEST_STATE:g} in magnitude (the energy and "
                                  f"momentum square it: float64 would overflow), got {np.abs(arr).max():g}")
        if self.quaternion:
            if not arr.any(axis=-1).all():  # |q| = 0; any other finite q normalises (attitude._normalized scales it)
                raise ValidationError(f"{self.name}: must be a non-zero quaternion [w, x, y, z] (it is normalised "
                                      "here)")
            _warn_non_unit(arr, self.name)
            arr = attitude._normalized(arr)
        return arr


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

    #: Whether the trajectory's ``q`` is the state's quaternion ``Y[0:4]`` (body → inertial) and its ``omega``
    #: the kernel's ``body_rate`` (:mod:`tumble._protocol`): then both are made on the GPU from states left
    #: there (``simulate(..., output="device")``, :mod:`tumble.integrate._cuda_outputs`), the other outputs on
    #: the host when the trajectory is copied back (:meth:`tumble.Trajectory.to_host`).
    attitude_in_state: bool = False

    @property
    def kind(self) -> str:
        """The name of the model kind, as a :class:`~tumble.Trajectory` (``traj.model``), its file and the
        messages of :func:`~tumble.simulate` say it: the class name unless the model says otherwise."""
        return type(self).__name__

    @property
    def batch_size(self) -> int | None:
        """Members of a batch carried by the model itself (one inertia per body), or None."""
        return None

    def members(self, lo: int, hi: int) -> Model:
        """The members ``lo`` to ``hi − 1`` of the model's own batch, a model of the same kind (what the
        sweeps' chunker runs a chunk on, :mod:`tumble.sweeps.chunks`). A model without a batch of its own is
        every member's: itself; one with a :attr:`batch_size` overrides this."""
        return self

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

    def check_run(self, method: Method, t: np.ndarray, dt: float | None) -> None:  # noqa: B027
        """Refuse a run this model cannot make (e.g. output times outside its data); nothing by default."""

    def step_ends(self, t: np.ndarray, dt: float | None) -> np.ndarray | None:
        """Times (s) between the output times ``t`` at which a fixed step of at most ``dt`` must end (a
        discrete event the steps would otherwise straddle), or None: the run is integrated through them as
        well and only ``t`` is kept. None by default."""
        return None

    def invariants(self, traj: Trajectory) -> dict[str, np.ndarray]:
        """What the exact motion keeps constant on the run ``traj`` (name → samples (n, [N,] ...)).

        By default: the total energy and the inertial angular momentum of the
        system when the run had no torque. Models with internal work or
        dissipation say what remains.
        """
        if traj.info.get("torque") != "none":
            return {}
        return {"energy": traj.energy, "momentum_inertial": traj.momentum_inertial}


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
                  attitude.NonUnitQuaternionWarning, stacklevel=5)  # simulate's caller: simulate, its state, check
