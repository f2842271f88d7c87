"""Lyapunov exponents of a heavy top: tangent equations integrated with the motion, QR re-orthonormalisation.

The Euler–Poisson equations of the top and their linearisation
(:mod:`tumble.kernels.tangent`) carry ``k`` tangent vectors ``δⱼ`` with the
state ``x = (ω, γ)`` (6 values). At each time ``tₙ`` of ``t`` the tangent
vectors are re-orthonormalised by modified Gram–Schmidt (the QR
decomposition ``[δ₁ … δ_k] = Q R``, ``δ ← Q``) and the logarithms of the
diagonal of ``R`` are summed (G. Benettin, L. Galgani, A. Giorgilli &
J.-M. Strelcyn, *Meccanica* 15 (1980) 9 and 21; K. Geist, U. Parlitz &
W. Lauterborn, *Prog. Theor. Phys.* 83 (1990) 875). The finite-time exponents

    λⱼ(tₙ) = (1 / (tₙ − t₀)) Σ_{m ≤ n} ln R_jj(t_m)          (1/s)

tend to the Lyapunov exponents ``λ₁ ≥ … ≥ λ_k`` as ``tₙ → ∞``. With ``k = 1``
this is the largest exponent; ``k = 6`` gives the full spectrum, which sums to
zero (the flow preserves volume) and comes in pairs ``±λ`` (``(λ, 0, 0, 0, 0,
−λ)``: the flow direction, the energy and the two Casimirs ``|γ|``, ``L_z``
give zeros). For an integrable top (Euler, Lagrange, Kovalevskaya) tangent
vectors grow at most linearly in time, so ``λ₁(t) ≈ ln(a t)/t → 0``.

The state and the tangents are integrated together through the engine
(:class:`tumble.integrate.Run`, the driver :func:`tumble.simulate` uses), by
any method whose needs the tangent kernel provides: ``dop853`` (adaptive; its
error control includes the tangents; its step size carries over from one
``tₙ`` to the next) or ``rk4`` (fixed step that lands on each ``tₙ``). The run
advances one interval ``[tₙ₋₁, tₙ]`` at a time and the tangent vectors are
re-orthonormalised in place between intervals. A batch of initial states (a
chaos map over a grid) runs in one call, in parallel over the cores from
:data:`PARALLEL_MEMBERS` members on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from tumble import attitude, integrate
from tumble._inertia import principal_axes
from tumble._validate import ValidationError, as_array, output_times
from tumble.integrate import MAX_STEPS, Run, SolverError
from tumble.integrate._fixed import LANES
from tumble.kernels.tangent import TangentModel

__all__ = ["LyapunovExponents", "lyapunov_exponents"]

#: The smallest batch run in parallel over the cores: the run starts a parallel region for every interval
#: between re-orthonormalisations, which a smaller batch does not repay (a block of lanes per region).
PARALLEL_MEMBERS = LANES

#: ``rtol`` and ``atol`` of an adaptive method when not given.
TOLERANCE = 1e-10

#: Seed of the fixed random orthonormal basis whose first ``count`` columns are the initial tangent vectors
#: (a generic direction: a coordinate axis may lie in an invariant subspace of a symmetric top).
TANGENT_SEED = 20


@dataclass(frozen=True)
class LyapunovExponents:
    """Finite-time Lyapunov exponents (see :func:`lyapunov_exponents`).

    t          : (n,) s, the re-orthonormalisation times after the start
    finite_time: (n, [N,] k) λⱼ(t), 1/s, descending in ``j`` at large ``t``
    method     : the integration method
    """

    t: np.ndarray
    finite_time: np.ndarray
    method: str

    @property
    def exponents(self) -> np.ndarray:
        """([N,] k) the estimates at the last time, 1/s."""
        return self.finite_time[-1]

    @property
    def largest(self) -> np.ndarray:
        """([N]) the largest exponent's estimate at the last time, 1/s."""
        return self.exponents[..., 0]


def lyapunov_exponents(body, gravity=None, *, omega0, q0=None, t, count: int = 1, method: str = "dop853",
                       dt=None, rtol=None, atol=None, max_steps=MAX_STEPS) -> LyapunovExponents:
    """Finite-time Lyapunov exponents of a heavy top (or of a free body, ``gravity=None``).

    body    : the :class:`tumble.RigidBody` simulated (its inertia about the pivot), or a (3, 3) tensor, kg·m²
    gravity : the :class:`tumble.torques.Gravity` torque of the simulation, or None for the Euler top
    omega0  : (3,) or (N, 3) initial body rates, rad/s, body axes (N: a batch, e.g. a chaos map)
    q0      : (4,) or (N, 4) initial attitude, body → inertial (default identity)
    t       : (n + 1,) increasing times, s: ``t[0]`` the start, then the re-orthonormalisation times
    count   : the number of exponents, 1 (the largest) to 6 (the full spectrum)
    method  : ``"dop853"`` (``rtol``, ``atol``: default 1e-10; the error control includes the tangents) or
              ``"rk4"`` (``dt``, s): the methods of :data:`tumble.integrate.METHODS` that need no more than a
              right-hand side
    max_steps : the most steps of one member over the whole run

    Returns :class:`LyapunovExponents`. The initial tangent vectors are the
    first ``count`` columns of a fixed random orthogonal 6×6 matrix (seed
    :data:`TANGENT_SEED`).
    """
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or not 1 <= count <= 6:
        raise ValidationError(f"count: must be a whole number from 1 to 6, got {count!r}")
    t = output_times(t)
    if t.size < 2:
        raise ValidationError("t: give the start and at least one re-orthonormalisation time")
    model, y0, single = _initial(body, gravity, omega0, q0, int(count))
    if integrate.method(method).adaptive:  # the tolerances of the tangents when not given
        rtol, atol = (TOLERANCE if rtol is None else rtol), (TOLERANCE if atol is None else atol)
    run = Run(model, y0, t, method=method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps,
              parallel=y0.shape[0] >= PARALLEL_MEMBERS)
    logs = np.zeros((t.size, y0.shape[0], count))
    interval = np.empty((2, *y0.shape))
    for n in range(1, t.size):
        run.advance(n, interval)
        _orthonormalise(run.y, int(count), logs[n - 1], logs[n])
    if not np.isfinite(logs).all():
        raise SolverError("the tangent vectors stopped being finite: re-orthonormalise more often (denser t)")
    exponents = logs[1:] / (t[1:] - t[0])[:, None, None]
    return LyapunovExponents(t[1:], exponents[:, 0] if single else exponents, method)


def _initial(body, gravity, omega0, q0, count):
    """The tangent kernel and the initial states (N, 6 + 6k) in principal axes; whether one state was given."""
    inertia = as_array(getattr(body, "inertia", body), "body", tail=(3, 3))
    if inertia.shape != (3, 3):
        raise ValidationError(f"body: must be one body (an inertia of shape (3, 3)), got {inertia.shape}")
    _, moments, axes = principal_axes(inertia, "body")
    omega0 = as_array(omega0, "omega0", tail=(3,))
    if omega0.ndim > 2:
        raise ValidationError(f"omega0: must have shape (3,) or (N, 3), got {omega0.shape}")
    single = omega0.ndim == 1
    omega0 = np.atleast_2d(omega0)
    q0 = attitude.identity() if q0 is None else attitude.normalize(as_array(q0, "q0", tail=(4,)))
    if q0.ndim > 2 or (q0.ndim == 2 and q0.shape[0] not in (1, omega0.shape[0])):
        raise ValidationError(f"q0: must have shape (4,) or ({omega0.shape[0]}, 4), got {q0.shape}")
    if gravity is None:
        up, weight = np.array([0.0, 0.0, 1.0]), np.zeros(3)
    else:
        g = float(np.linalg.norm(gravity.g))
        if g == 0.0:
            raise ValidationError("gravity.g: must be non-zero (it fixes the vertical)")
        up, weight = -gravity.g / g, gravity.mass * g * np.asarray(gravity.com, dtype=np.float64)
    gamma = attitude.rotate_inverse(q0, up)
    y0 = np.zeros((omega0.shape[0], 6 + 6 * count))
    y0[:, 0:3] = omega0 @ axes
    y0[:, 3:6] = np.broadcast_to(gamma @ axes, (omega0.shape[0], 3))
    basis, _ = np.linalg.qr(np.random.default_rng(TANGENT_SEED).standard_normal((6, 6)))
    y0[:, 6:] = basis[:, :count].T.ravel()
    model = TangentModel(np.ascontiguousarray(moments, dtype=np.float64),
                         np.ascontiguousarray(axes.T @ weight), count)
    return model, y0, single


@njit(cache=True)
def _orthonormalise(y, count, before, after):
    """Modified Gram–Schmidt on the tangent vectors ``δⱼ = y[b, 6 + 6j : 12 + 6j]`` of every member ``b``, in
    place: ``after[b, j] = before[b, j] + ln R_jj``, the running sums of the logarithms of the diagonal of ``R``."""
    for b in range(y.shape[0]):
        for j in range(count):
            sj = 6 + 6 * j
            for k in range(j):
                sk = 6 + 6 * k
                dot = 0.0
                for i in range(6):
                    dot += y[b, sj + i] * y[b, sk + i]
                for i in range(6):
                    y[b, sj + i] -= dot * y[b, sk + i]
            norm = 0.0
            for i in range(6):
                norm += y[b, sj + i] * y[b, sj + i]
            norm = math.sqrt(norm)
            for i in range(6):
                y[b, sj + i] /= norm
            after[b, j] = before[b, j] + math.log(norm)
