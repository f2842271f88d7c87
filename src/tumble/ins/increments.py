"""Sensor increments: what a strapdown IMU delivers, from a true trajectory or a CSV file.

An :class:`Increments` holds ``K`` consecutive samples of a uniform sample
interval ``dt`` (s) starting at ``t0`` (s): sample ``k`` covers
``[t0 + k dt, t0 + (k + 1) dt]`` and holds

* the angle increment ``Δθ_k = ∫ ω dt`` (rad, body axes; ``ω`` the body rate
  relative to inertial space), and optionally
* the velocity increment ``Δv_k = ∫ f dt`` (m/s, body axes; ``f`` the
  specific force, i.e. the non-gravitational acceleration, at the sensor).

:func:`from_trajectory` integrates them exactly enough from a trajectory of
``tumble.simulate`` sampled on a finer uniform grid; :func:`read_csv` and
:func:`write_csv` exchange them as text.

CSV layout (comma separated, one header row, ``#`` starts a comment line):

=============================================  =====================================================
columns                                        meaning
=============================================  =====================================================
``t``                                          end of the sample interval, s (uniformly spaced;
                                               ``dt`` is the spacing, ``t0 = t[0] − dt``)
``dtheta_x, dtheta_y, dtheta_z``               angle increments over the interval, rad, body axes
  *or* ``omega_x, omega_y, omega_z``           mean body rate over the interval, rad/s (``Δθ = ω dt``)
``dv_x, dv_y, dv_z`` (optional)                velocity increments, m/s, body axes
  *or* ``f_x, f_y, f_z``                       mean specific force, m/s² (``Δv = f dt``)
=============================================  =====================================================
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._files import read_input
from tumble._validate import ValidationError, as_array, require_positive
from tumble._files import write_atomic
from tumble.trajectory import Trajectory

__all__ = ["Increments", "from_trajectory", "read_csv", "write_csv"]

#: Relative tolerance on the spacing of sample times: a trajectory grid or the
#: ``t`` column of a CSV file (written with 17 digits, or fewer by hand) is
#: uniform when every step is within 1e-6 of the mean step.
UNIFORM_RTOL = 1e-6

_ANGLE_COLUMNS = {"dtheta": ("dtheta_x", "dtheta_y", "dtheta_z"), "omega": ("omega_x", "omega_y", "omega_z")}
_VELOCITY_COLUMNS = {"dv": ("dv_x", "dv_y", "dv_z"), "f": ("f_x", "f_y", "f_z")}


@dataclass(frozen=True)
class Increments:
    """Angle (and velocity) increments over ``K`` uniform sample intervals.

    t0 : float            start of the first interval, s
    dt : float            sample interval, s (> 0)
    delta_theta : (K, 3)  angle increments ``∫ ω dt``, rad, body axes
    delta_v : (K, 3) or None   velocity increments ``∫ f dt``, m/s, body axes
    """

    t0: float
    dt: float
    delta_theta: np.ndarray
    delta_v: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "t0", float(as_array(self.t0, "t0")))
        object.__setattr__(self, "dt", require_positive(self.dt, "dt"))
        dtheta = as_array(self.delta_theta, "delta_theta", tail=(3,))
        if dtheta.ndim != 2:
            raise ValidationError(f"delta_theta: must have shape (K, 3), got {dtheta.shape}")
        object.__setattr__(self, "delta_theta", dtheta)
        if self.delta_v is not None:
            dv = as_array(self.delta_v, "delta_v", tail=(3,))
            if dv.shape != dtheta.shape:
                raise ValidationError(f"delta_v: must have the shape of delta_theta {dtheta.shape}, got {dv.shape}")
            object.__setattr__(self, "delta_v", dv)

    def __len__(self) -> int:
        return self.delta_theta.shape[0]

    @property
    def t(self) -> np.ndarray:
        """Ends of the sample intervals, s: ``t0 + (k + 1) dt``, shape (K,)."""
        return self.t0 + self.dt * np.arange(1, len(self) + 1)

    @property
    def rate(self) -> np.ndarray:
        """Mean body rate over each interval, ``Δθ/dt`` (rad/s), shape (K, 3)."""
        return self.delta_theta / self.dt


def from_trajectory(trajectory: Trajectory, *, oversample: int = 2, specific_force: ArrayLike | None = None,
                    lever_arm: ArrayLike | None = None) -> Increments:
    """The exact increments of a sampled true motion, one sample per ``oversample`` trajectory steps.

    ``trajectory`` (one body, e.g. from ``tumble.simulate``) must be sampled on
    a uniform grid ``t`` whose number of steps is a multiple of ``oversample``
    (even, ≥ 2); the sample interval is ``dt = oversample (t[1] − t[0])``.
    ``Δθ_k = ∫ ω dt`` over each interval by the composite Simpson rule on the
    trajectory's samples (error ``h⁴ (t₁ − t₀) max|ω⁗| / 180``, ``h`` the grid
    step: at ``h = 1 ms`` and rates varying at 1 rad/s, 1e-14 of ``|ω|``).

    With ``specific_force`` (m/s², inertial axes: a (3,) constant or one row per
    trajectory sample), velocity increments are made too, for an accelerometer
    at ``lever_arm`` (m, body axes, from the centre of mass; default the centre
    of mass)::

        f_B = R(q)ᵀ f_N + ω̇ × r + ω × (ω × r),   ∫ ω̇ × r dt = (ω(t_{k+1}) − ω(t_k)) × r

    ``f_N = a_N − g_N`` is the specific force of the centre of mass (e.g.
    ``(0, 0, 9.80665)`` for a body held against gravity ``(0, 0, −9.80665)``).
    """
    if not isinstance(trajectory, Trajectory) or trajectory.batch_size is not None:
        raise ValidationError("trajectory: must be a Trajectory of one body (use trajectory.member(i))")
    if trajectory.q is None or trajectory.omega is None:
        raise ValidationError("trajectory: must have an attitude (q and omega) for a gyro to measure, not the "
                              f"{trajectory.model or 'model'} trajectory given")
    oversample = int(oversample)
    if oversample < 2 or oversample % 2:
        raise ValidationError(f"oversample: must be an even number >= 2 (Simpson's rule), got {oversample}")
    t = trajectory.t
    steps = t.size - 1
    if steps < oversample or steps % oversample:
        raise ValidationError(f"trajectory: its {steps} time steps must be a positive multiple of "
                              f"oversample = {oversample}")
    h = _uniform_step(t, "trajectory.t")
    weights = np.ones(oversample + 1)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    weights *= h / 3.0

    def integrate(values):  # (n, 3) samples -> (steps / oversample, 3) Simpson integrals, one per interval
        windows = np.lib.stride_tricks.sliding_window_view(values, oversample + 1, axis=0)[::oversample]
        return windows @ weights

    omega = trajectory.omega
    delta_theta = integrate(omega)
    delta_v = None
    if specific_force is not None:
        f_n = as_array(specific_force, "specific_force", tail=(3,))
        if f_n.shape not in ((3,), (t.size, 3)):
            raise ValidationError(f"specific_force: must have shape (3,) or ({t.size}, 3), got {f_n.shape}")
        r = np.zeros(3) if lever_arm is None else as_array(lever_arm, "lever_arm", tail=(3,))
        if r.shape != (3,):
            raise ValidationError(f"lever_arm: must have shape (3,), got {r.shape}")
        f_b = attitude.rotate_inverse(trajectory.q, np.broadcast_to(f_n, (t.size, 3)))
        f_b = f_b + np.cross(omega, np.cross(omega, r))
        delta_v = integrate(f_b) + np.cross(omega[oversample::oversample] - omega[:-1:oversample], r)
    return Increments(t0=t[0], dt=oversample * h, delta_theta=delta_theta, delta_v=delta_v)


def _uniform_step(t: np.ndarray, name: str) -> float:
    steps = np.diff(t)
    h = (t[-1] - t[0]) / steps.size
    bad = np.flatnonzero(np.abs(steps - h) > UNIFORM_RTOL * abs(h))
    if bad.size:
        k = int(bad[0])
        raise ValidationError(f"{name}: must be uniformly spaced (step {k} is {float(steps[k])!r}, the mean "
                              f"step {float(h)!r}; tolerance {UNIFORM_RTOL:g} relative)")
    if h <= 0.0:
        raise ValidationError(f"{name}: must be increasing")
    return float(h)


def read_csv(path: str | os.PathLike) -> Increments:
    """Read increments from a CSV file (layout in the module docstring).

    A malformed file raises :class:`ValidationError` naming the file, the line
    and the column.
    """
    path = os.fspath(path)
    text = read_input(path).decode("utf-8")
    rows = [(number, row) for number, row in enumerate(csv.reader(io.StringIO(text, newline="")), start=1)
            if row and not row[0].lstrip().startswith("#")]
    if not rows:
        raise ValidationError(f"{path}: no header row (expected e.g. 't,dtheta_x,dtheta_y,dtheta_z')")
    header_line, header = rows[0]
    header = [name.strip() for name in header]
    columns = _layout(path, header_line, header)
    if len(rows) < 3:
        raise ValidationError(f"{path}: needs at least two data rows (the sample interval is their spacing)")
    data = np.empty((len(rows) - 1, len(header)))
    for i, (number, row) in enumerate(rows[1:]):
        if len(row) != len(header):
            raise ValidationError(f"{path} line {number}: has {len(row)} columns, the header has {len(header)}")
        for j, cell in enumerate(row):
            try:
                data[i, j] = float(cell)
            except ValueError:
                raise ValidationError(f"{path} line {number}, column {j + 1} ({header[j]!r}): "
                                      f"{cell.strip()!r} is not a number") from None
            if not np.isfinite(data[i, j]):
                raise ValidationError(f"{path} line {number}, column {j + 1} ({header[j]!r}): must be finite")
    t = data[:, header.index("t")]
    steps = np.diff(t)
    bad = np.flatnonzero(~(np.abs(steps - steps[0]) <= UNIFORM_RTOL * abs(steps[0])) | (steps <= 0.0))
    if bad.size:
        k = int(bad[0])
        raise ValidationError(f"{path} line {rows[k + 2][0]}, column {header.index('t') + 1} ('t'): sample times "
                              f"must increase uniformly (step {float(steps[k])!r}, the first step "
                              f"{float(steps[0])!r}; tolerance {UNIFORM_RTOL:g} relative)")
    dt = (t[-1] - t[0]) / steps.size
    kind, names = columns["angle"]
    delta_theta = data[:, [header.index(c) for c in names]] * (dt if kind == "omega" else 1.0)
    delta_v = None
    if "velocity" in columns:
        kind, names = columns["velocity"]
        delta_v = data[:, [header.index(c) for c in names]] * (dt if kind == "f" else 1.0)
    return Increments(t0=t[0] - dt, dt=dt, delta_theta=delta_theta, delta_v=delta_v)


def _layout(path, line, header) -> dict:
    known = {"t"} | {c for group in (_ANGLE_COLUMNS, _VELOCITY_COLUMNS) for cs in group.values() for c in cs}
    for j, name in enumerate(header):
        if name not in known:
            raise ValidationError(f"{path} line {line}, column {j + 1}: unknown column {name!r} "
                                  f"(known: {', '.join(sorted(known))})")
        if header.count(name) > 1:
            raise ValidationError(f"{path} line {line}, column {j + 1}: column {name!r} appears twice")
    if "t" not in header:
        raise ValidationError(f"{path} line {line}: the header has no column 't'")
    found = {}
    for role, groups in (("angle", _ANGLE_COLUMNS), ("velocity", _VELOCITY_COLUMNS)):
        present = [(kind, names) for kind, names in groups.items() if any(c in header for c in names)]
        if len(present) > 1:
            raise ValidationError(f"{path} line {line}: give either {' or '.join(k + '_*' for k, _ in present)}, "
                                  "not both")
        if present:
            kind, names = present[0]
            missing = [c for c in names if c not in header]
            if missing:
                raise ValidationError(f"{path} line {line}: missing column(s) {', '.join(missing)}")
            found[role] = (kind, names)
    if "angle" not in found:
        raise ValidationError(f"{path} line {line}: needs the columns dtheta_x, dtheta_y, dtheta_z "
                              "(or omega_x, omega_y, omega_z)")
    return found


def write_csv(path: str | os.PathLike, increments: Increments) -> None:
    """Write increments as CSV (``t, dtheta_*[, dv_*]``, 17 significant digits), atomically."""
    columns = [increments.t[:, None], increments.delta_theta]
    header = "t,dtheta_x,dtheta_y,dtheta_z"
    if increments.delta_v is not None:
        columns.append(increments.delta_v)
        header += ",dv_x,dv_y,dv_z"
    table = np.hstack(columns)
    write_atomic(path, lambda tmp: np.savetxt(tmp, table, fmt="%.17g", delimiter=",", header=header,
                                              comments=""))
