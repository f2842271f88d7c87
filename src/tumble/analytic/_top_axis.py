"""The symmetry axis of a simulated top, measured: its Euler angles sample by sample, and the nutation.

What :class:`~tumble.analytic.HeavyTop` predicts, read off a trajectory of
``tumble.simulate`` (one body) in the same conventions: the nutation angle θ
of the axis from the upward vertical, its azimuth φ (precession), their rates
and the spin ω₃ (Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed.,
§5.7); the turning points of ``u = cos θ``, refined between samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tumble import attitude
from tumble._validate import ValidationError, as_array
from tumble.trajectory import Trajectory

__all__ = ["AxisMotion", "NutationMeasurement", "axis_motion", "measure_nutation"]


@dataclass(frozen=True)
class AxisMotion:
    """The symmetry axis of a simulated top, sample by sample (see :func:`axis_motion`).

    ``t`` (s), ``theta`` (rad, from the upward vertical), ``phi`` (rad,
    unwrapped along time), ``theta_dot``, ``phi_dot``, ``spin`` (rad/s), each (n,).
    """

    t: np.ndarray
    theta: np.ndarray
    phi: np.ndarray
    theta_dot: np.ndarray
    phi_dot: np.ndarray
    spin: np.ndarray

    @property
    def u(self) -> np.ndarray:
        """``cos θ``."""
        return np.cos(self.theta)


def axis_motion(trajectory: Trajectory, *, com, g) -> AxisMotion:
    """Euler angles of the symmetry axis ``e = com/|com|`` along a simulated trajectory (one body).

    Up is ``ẑ = −g/|g|``; the horizontal reference axes are ``x̂`` = the
    inertial x axis made perpendicular to ``ẑ`` (the y axis if x is within
    about 25° of the vertical) and ``ŷ = ẑ × x̂``, so that for ``g ∥ −z`` they
    are the inertial x, y axes. With ``e_N = R(q) e = (sin θ sin φ,
    −sin θ cos φ, cos θ)`` in (x̂, ŷ, ẑ) and ``ė_N = ω_N × e_N``:
    ``θ = atan2(|ẑ × e_N|, ẑ·e_N)``, ``θ̇ = −ė_N·ẑ / sin θ``,
    ``φ̇ = ė_N·(ẑ × e_N) / sin²θ``, ``ω₃ = ω·e``.
    """
    if trajectory.batch_size is not None:
        raise ValidationError("trajectory: axis_motion takes a single body (use trajectory.member(i))")
    com, g = nonzero_vector(com, "com"), nonzero_vector(g, "g")
    up = -g / np.linalg.norm(g)
    state = axis_state(trajectory.q, trajectory.omega, com / np.linalg.norm(com), up)
    x_ref = np.eye(3)[0] if abs(up[0]) < 0.9 else np.eye(3)[1]
    x_ref = x_ref - (x_ref @ up) * up
    x_ref /= np.linalg.norm(x_ref)
    y_ref = np.cross(up, x_ref)
    phi = np.unwrap(np.arctan2(state["axis"] @ x_ref, -(state["axis"] @ y_ref)))
    return AxisMotion(trajectory.t, state["theta"], phi, state["theta_dot"], state["phi_dot"], state["spin"])


@dataclass(frozen=True)
class NutationMeasurement:
    """Nutation read off a sampled motion (see :func:`measure_nutation`).

    ``t_theta_min``, ``u_max``: times (s) and values of the maxima of
    ``u = cos θ`` (minima of θ); ``t_theta_max``, ``u_min``: the same for the
    minima of ``u``; ``period`` (s): mean spacing of the θ minima;
    ``mean_precession_rate`` (rad/s): φ advance from the first to the last
    θ minimum over the time between them (``nan`` with fewer than two minima).
    """

    t_theta_min: np.ndarray
    u_max: np.ndarray
    t_theta_max: np.ndarray
    u_min: np.ndarray
    period: float
    mean_precession_rate: float


def measure_nutation(trajectory: Trajectory, *, com, g) -> NutationMeasurement:
    """Turning points of ``u = cos θ`` along a simulated top, refined between samples.

    Each interior local extremum of the samples is refined by the parabola
    through it and its two neighbours (vertex time and value). ``u`` is even
    about a turning point, so the vertex value is off by O(λ⁴h⁴ (u₂ − u₁)) for
    a sample spacing ``h`` (``λ`` of :attr:`HeavyTop.rate`): sample a few
    hundred times per nutation period or more. φ is read at the refined
    times by cubic Hermite interpolation of the sampled φ and φ̇.
    """
    motion = axis_motion(trajectory, com=com, g=g)
    t, u = motion.t, motion.u
    t_max, u_max = _turning_points(t, u, sign=1.0)
    t_min, u_min = _turning_points(t, u, sign=-1.0)
    if t_max.size >= 2:
        phi_max = _hermite(t, motion.phi, motion.phi_dot, t_max[[0, -1]])
        period = float((t_max[-1] - t_max[0]) / (t_max.size - 1))
        mean_rate = float((phi_max[-1] - phi_max[0]) / (t_max[-1] - t_max[0]))
    else:
        period = mean_rate = math.nan
    return NutationMeasurement(t_max, u_max, t_min, u_min, period, mean_rate)


# -- the axis from a state, and samples refined ------------------------------------


def nonzero_vector(value, name: str) -> np.ndarray:
    """A non-zero finite (3,) vector."""
    v = as_array(value, name, tail=(3,))
    if v.ndim != 1 or not np.any(v):
        raise ValidationError(f"{name}: must be a non-zero vector of shape (3,), got {v.tolist()}")
    return v


def axis_state(q, omega, axis_body: np.ndarray, up: np.ndarray) -> dict:
    """θ, θ̇, φ̇, ω₃ and ``e_N`` of the unit body axis ``axis_body`` for states ``q`` (…, 4), ``omega`` (…, 3)."""
    e = attitude.rotate(q, axis_body)
    e_dot = np.cross(attitude.rotate(q, omega), e)
    horizontal = np.cross(up, e)                      # ẑ × e, |ẑ × e| = sin θ
    sin = np.linalg.norm(horizontal, axis=-1)
    cos = e @ up
    moving = np.linalg.norm(e_dot, axis=-1)
    on_pole = sin == 0.0
    safe = np.where(on_pole, 1.0, sin)
    # On a pole φ is undefined; θ̇ is then the rate of leaving it (sign: towards the other pole).
    theta_dot = np.where(on_pole, np.sign(cos) * moving, -(e_dot @ up) / safe)
    phi_dot = np.where(on_pole, 0.0, np.einsum("...i,...i->...", e_dot, horizontal) / safe**2)
    return {"axis": e, "theta": np.arctan2(sin, cos), "theta_dot": theta_dot, "phi_dot": phi_dot,
            "spin": np.asarray(omega) @ axis_body}


def _turning_points(t, y, *, sign: float):
    """Local maxima of ``sign·y`` at interior samples, refined to the vertex of the parabola through three samples.

    Newton form ``p(t) = y₀ + d₀₁(t − t₀) + c(t − t₀)(t − t₁)``; ``p'(t*) = 0``.
    Returns the vertex times and values.
    """
    s = sign * y
    k = 1 + np.flatnonzero((s[1:-1] >= s[:-2]) & (s[1:-1] > s[2:]))
    t0, t1, t2 = t[k - 1], t[k], t[k + 1]
    y0, y1, y2 = y[k - 1], y[k], y[k + 1]
    d01, d12 = (y1 - y0) / (t1 - t0), (y2 - y1) / (t2 - t1)
    c = (d12 - d01) / (t2 - t0)
    t_star = 0.5 * (t0 + t1) - d01 / (2.0 * c)
    return t_star, y0 + d01 * (t_star - t0) + c * (t_star - t0) * (t_star - t1)


def _hermite(t, y, y_dot, at):
    """Cubic Hermite interpolation of samples ``y`` with derivatives ``y_dot`` at the times ``at``."""
    k = np.clip(np.searchsorted(t, at) - 1, 0, t.size - 2)
    h = t[k + 1] - t[k]
    s = (at - t[k]) / h
    h00, h10, h01, h11 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2, s * s * (3 - 2 * s), s * s * (s - 1)
    return h00 * y[k] + h10 * h * y_dot[k] + h01 * y[k + 1] + h11 * h * y_dot[k + 1]
