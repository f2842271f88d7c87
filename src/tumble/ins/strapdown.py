"""Strapdown attitude (and velocity) integration from angle (and velocity) increments.

A strapdown navigation computer keeps the attitude ``q`` (body → inertial,
scalar first) by composing, at each *update* of interval ``T``, the rotation
of the body over that interval::

    q_{k+1} = q_k ⊗ exp(φ_k)                     (exp: rotation vector → quaternion)

where ``φ_k`` is the rotation vector of ``q_k* ⊗ q_{k+1}``. It obeys Bortz's
equation (J. E. Bortz, IEEE Trans. AES-7(1), 1971)::

    φ̇ = ω + ½ φ × ω + (1/φ²) (1 − φ sin φ / (2 (1 − cos φ))) φ × (φ × ω),   φ(t_k) = 0

and to the order the algorithms keep, ``φ_k = Δθ + δφ`` with ``Δθ = ∫ ω dt``
the angle increment over the update and the *coning* term
``δφ = ½ ∫ θ(t) × ω(t) dt`` (``θ(t)`` = the increment since ``t_k``).
The gyro delivers ``n`` increments ``Δθ₁ … Δθ_n`` per update (the sample
interval is ``T/n``), from which the coning term is estimated:

===============  ===  ==============================================================  =========================
algorithm        n    coning term ``δφ``                                              coning drift (small α)
===============  ===  ==============================================================  =========================
``none``         1    0                                                               ½ α² Ω (1 − sin ΩT/(ΩT))
``one-sample``   1    (1/12) Δθ_{k−1} × Δθ_k  (uses the previous update's increment)  α² Ω (ΩT)⁴ / 60
``two-sample``   2    (2/3) Δθ₁ × Δθ₂                                                 α² Ω (ΩT)⁴ / 960
``three-sample`` 3    (9/20) Δθ₁ × Δθ₃ + (27/40) Δθ₂ × (Δθ₃ − Δθ₁)                    α² Ω (ΩT)⁶ / 204120
===============  ===  ==============================================================  =========================

(Δθ = Δθ₁ + … + Δθ_n. ``none`` is uncompensated, ``φ = Δθ``: its drift is
≈ α² Ω (ΩT)²/12 at small ΩT, second order in T; ``one-sample`` compensates
with the previous update's increment. The two- and three-sample
coefficients are those of R. B. Miller, "A new strapdown attitude
algorithm", J. Guidance 6(4), 1983; the one-sample-plus-previous form and the
drift laws: M. B. Ignagni, "Optimal strapdown attitude integration
algorithms", J. Guidance 13(2), 1990; P. G. Savage, *Strapdown Analytics*,
2nd ed., 2007, ch. 7; D. H. Titterton, J. L. Weston, *Strapdown Inertial
Navigation Technology*, 2nd ed., 2004, ch. 11.) ``T`` in the drift laws is the
*update* interval; ``docs/ins.md`` derives them and :mod:`tumble.ins.coning`
measures them.

Velocity (optional, from accelerometer velocity increments ``Δv_i = ∫ f dt``,
``f`` the specific force in body axes, m/s): in an inertial frame with a
constant gravity ``g_N`` (no Earth rate, no transport rate)::

    v_{k+1} = v_k + R(q_k) (Δv + ½ Δθ × Δv + ⅙ Δθ × (Δθ × Δv) + δv) + g_N T

with the rotation compensation ``½ Δθ × Δv + ⅙ Δθ × (Δθ × Δv)`` (the terms
of first and second order in Δθ of ``∫ exp([θ(t)×]) f dt`` at constant rate
and specific force) and the *sculling*
term ``δv``, an estimate of ``½ ∫ (θ × f + υ × ω) dt`` (``υ(t)`` the velocity
increment since ``t_k``) whose coefficients are those of the coning term
with each ``Δθ_i × Δθ_j`` replaced by ``Δθ_i × Δv_j + Δv_i × Δθ_j``
(M. B. Ignagni, "Duality of optimal strapdown sculling and coning
compensation algorithms", Navigation 45(2), 1998; Savage ch. 7). The
second-order rotation term matters as much as sculling: for a body turning
at a steady rate under a specific force fixed in inertial space it is −2
times the sculling term, so keeping sculling without it doubles the
velocity error (measured, ``docs/ins.md``). With ``sculling=False`` ``δv = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from tumble import _quat, attitude
from tumble._vec import cross
from tumble._validate import ValidationError, as_array
from tumble.ins.increments import Increments
from tumble.trajectory import Trajectory

__all__ = ["ALGORITHMS", "Navigation", "strapdown"]

#: Coning algorithms and their gyro samples per update.
ALGORITHMS = {"none": 1, "one-sample": 1, "two-sample": 2, "three-sample": 3}
_CODES = {name: code for code, name in enumerate(ALGORITHMS)}  # the branches of _update_terms


@dataclass(frozen=True)
class Navigation:
    """Result of :func:`strapdown`.

    attitude : Trajectory
        ``t`` the update times (s), ``q`` the attitude (body → inertial, scalar
        first), ``omega`` the mean body rate over the update that ends at each
        time, ``Δθ/T`` (rad/s, body axes; the first row repeats the second), and
        the ``inertia`` given to :func:`strapdown` (a navigation computer does
        not know it: identity by default). Comparable sample by sample with a
        true trajectory sampled at the same times.
    velocity : (n, 3) array or None
        Velocity in inertial axes at the update times (m/s), when velocity
        increments were given.
    algorithm : str
        The coning algorithm used.
    """

    attitude: Trajectory
    velocity: np.ndarray | None
    algorithm: str


def strapdown(increments: Increments, *, q0: ArrayLike | None = None, algorithm: str = "three-sample",
              v0: ArrayLike = (0.0, 0.0, 0.0), g: ArrayLike = (0.0, 0.0, 0.0), sculling: bool = True,
              inertia: ArrayLike | None = None) -> Navigation:
    """Integrate gyro (and accelerometer) increments into attitude (and velocity).

    Parameters
    ----------
    increments : Increments
        Angle increments ``delta_theta`` (rad, body axes) over consecutive
        sample intervals ``dt`` starting at ``t0``, optionally velocity
        increments ``delta_v`` (m/s, body axes). Their number must be a
        multiple of the samples per update of ``algorithm``.
    q0 : (4,) array_like
        Attitude at ``t0`` (body → inertial, scalar first; default identity).
    algorithm : {"none", "one-sample", "two-sample", "three-sample"}
        Coning compensation (module docstring); it fixes the samples per update.
    v0, g : (3,) array_like
        Initial velocity (m/s) and gravity (m/s²), inertial axes.
    sculling : bool
        Apply the sculling term of ``algorithm`` to the velocity.
    inertia : (3, 3) array_like, optional
        Inertia stored in the returned Trajectory (kg·m²; default identity).

    Returns
    -------
    Navigation
        Attitude at ``t0 + k T`` (``T = n dt``, ``k = 0 … K``) as a Trajectory,
        and the velocity when ``delta_v`` was given.
    """
    if algorithm not in ALGORITHMS:
        raise ValidationError(f"algorithm: must be one of {sorted(ALGORITHMS)}, got {algorithm!r}")
    if not isinstance(increments, Increments):
        raise ValidationError(f"increments: must be an Increments, got {type(increments).__name__}")
    n = ALGORITHMS[algorithm]
    count = increments.delta_theta.shape[0]
    if count == 0 or count % n:
        raise ValidationError(f"increments: {algorithm!r} takes {n} samples per update; got {count} samples, "
                              f"not a positive multiple of {n}")
    q0 = attitude.identity() if q0 is None else as_array(q0, "q0", tail=(4,))
    if q0.shape != (4,) or np.linalg.norm(q0) == 0.0:
        raise ValidationError(f"q0: must be one non-zero quaternion [w, x, y, z], got {q0.tolist()}")
    v0, g = as_array(v0, "v0", tail=(3,)), as_array(g, "g", tail=(3,))
    inertia = np.eye(3) if inertia is None else as_array(inertia, "inertia", tail=(3, 3))

    updates = count // n
    dtheta = np.ascontiguousarray(increments.delta_theta)
    q = np.empty((updates + 1, 4))
    q[0] = q0 / np.linalg.norm(q0)
    _attitude_loop(dtheta, n, _CODES[algorithm], q)

    T = n * increments.dt
    t = increments.t0 + T * np.arange(updates + 1)
    mean_rate = dtheta.reshape(updates, n, 3).sum(axis=1) / T
    omega = np.concatenate([mean_rate[:1], mean_rate])
    info = {"algorithm": algorithm, "samples_per_update": n, "dt": float(T)}
    trajectory = Trajectory(t=t, q=q, omega=omega, inertia=inertia, method="strapdown", info=info)

    velocity = None
    if increments.delta_v is not None:
        velocity = np.empty((updates + 1, 3))
        velocity[0] = v0
        _velocity_loop(dtheta, np.ascontiguousarray(increments.delta_v), n,
                       _CODES[algorithm] if sculling else 0, q, g * T, velocity)
    return Navigation(attitude=trajectory, velocity=velocity, algorithm=algorithm)


@njit(cache=True)
def _update_terms(a, b, k, n, code):
    """Sum of the increments of ``a`` over update ``k`` (rows ``k n … k n + n − 1``) and the
    compensation term ``Σ c_ij a_i × b_j`` of algorithm ``code`` (coning when ``b`` is ``a``)."""
    i0 = k * n
    s0 = s1 = s2 = 0.0
    for i in range(i0, i0 + n):
        s0 += a[i, 0]
        s1 += a[i, 1]
        s2 += a[i, 2]
    if code == 1:  # (1/12) a_{k-1} × b_k, none at the first update
        if k == 0:
            return s0, s1, s2, 0.0, 0.0, 0.0
        c = cross(a[i0 - 1, 0], a[i0 - 1, 1], a[i0 - 1, 2], b[i0, 0], b[i0, 1], b[i0, 2])
        return s0, s1, s2, c[0] / 12.0, c[1] / 12.0, c[2] / 12.0
    if code == 2:  # (2/3) a1 × b2
        c = cross(a[i0, 0], a[i0, 1], a[i0, 2], b[i0 + 1, 0], b[i0 + 1, 1], b[i0 + 1, 2])
        return s0, s1, s2, 2.0 / 3.0 * c[0], 2.0 / 3.0 * c[1], 2.0 / 3.0 * c[2]
    if code == 3:  # (9/20) a1 × b3 + (27/40) (a1 × b2 + a2 × b3)
        c13 = cross(a[i0, 0], a[i0, 1], a[i0, 2], b[i0 + 2, 0], b[i0 + 2, 1], b[i0 + 2, 2])
        c12 = cross(a[i0, 0], a[i0, 1], a[i0, 2], b[i0 + 1, 0], b[i0 + 1, 1], b[i0 + 1, 2])
        c23 = cross(a[i0 + 1, 0], a[i0 + 1, 1], a[i0 + 1, 2], b[i0 + 2, 0], b[i0 + 2, 1], b[i0 + 2, 2])
        return (s0, s1, s2,
                0.45 * c13[0] + 0.675 * (c12[0] + c23[0]),
                0.45 * c13[1] + 0.675 * (c12[1] + c23[1]),
                0.45 * c13[2] + 0.675 * (c12[2] + c23[2]))
    return s0, s1, s2, 0.0, 0.0, 0.0


@njit(cache=True)
def _attitude_loop(dtheta, n, code, q):
    """``q[k+1] = q[k] ⊗ exp(Δθ_k + δφ_k)``, normalised (rows of ``q`` after the first are written)."""
    for k in range(q.shape[0] - 1):
        s0, s1, s2, c0, c1, c2 = _update_terms(dtheta, dtheta, k, n, code)
        e = _quat.qexp(s0 + c0, s1 + c1, s2 + c2)
        r = _quat.qmul(q[k, 0], q[k, 1], q[k, 2], q[k, 3], e[0], e[1], e[2], e[3])
        norm = _quat.qnorm(r[0], r[1], r[2], r[3])
        for i in range(4):
            q[k + 1, i] = r[i] / norm


@njit(cache=True)
def _velocity_loop(dtheta, dv, n, code, q, g_step, v):
    """``v[k+1] = v[k] + R(q_k)(Δv + ½ Δθ × Δv + ⅙ Δθ × (Δθ × Δv) + δv) + g T``, ``δv`` of ``code``."""
    for k in range(v.shape[0] - 1):
        a0, a1, a2, p0, p1, p2 = _update_terms(dtheta, dv, k, n, code)  # Δθ and Σ c_ij Δθ_i × Δv_j
        u0, u1, u2, m0, m1, m2 = _update_terms(dv, dtheta, k, n, code)  # Δv and Σ c_ij Δv_i × Δθ_j
        r0, r1, r2 = cross(a0, a1, a2, u0, u1, u2)      # Δθ × Δv
        s0, s1, s2 = cross(a0, a1, a2, r0, r1, r2)      # Δθ × (Δθ × Δv)
        b0 = u0 + 0.5 * r0 + s0 / 6.0 + p0 + m0
        b1 = u1 + 0.5 * r1 + s1 / 6.0 + p1 + m1
        b2 = u2 + 0.5 * r2 + s2 / 6.0 + p2 + m2
        w0, w1, w2 = _quat.qrotate(q[k, 0], q[k, 1], q[k, 2], q[k, 3], b0, b1, b2)
        v[k + 1, 0] = v[k, 0] + w0 + g_step[0]
        v[k + 1, 1] = v[k, 1] + w1 + g_step[1]
        v[k + 1, 2] = v[k, 2] + w2 + g_step[2]
