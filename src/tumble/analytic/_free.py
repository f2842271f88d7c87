"""Exact torque-free motion: the public functions.

The closed form itself (Jacobi elliptic functions for the rates, the elliptic
integral of the third kind for the attitude, the care taken near the
separatrix) is compiled in :mod:`tumble._free_flow`, whose docstring and
``docs/exact.md`` give the formulas; :func:`torque_free` runs it through
``tumble.simulate(..., method="exact")``, so inputs, batches and the change to
principal axes are those of :func:`tumble.simulate`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tumble._free_flow import REGIMES, _parameters_batch
from tumble._validate import ValidationError, as_array
from tumble.simulate import simulate
from tumble.trajectory import Trajectory

__all__ = ["REGIMES", "FreeParameters", "free_parameters", "torque_free"]


@dataclass(frozen=True)
class FreeParameters:
    """Constants of the torque-free motion of a body with principal moments ``I₁ ≤ I₂ ≤ I₃``.

    Scalars for one body, arrays of the batch shape for a batch. The formulas
    are those of the module docstring (Landau & Lifshitz §37), with
    ``Δᵢ = L² − 2T Iᵢ``.

    Attributes
    ----------
    moments : (…, 3) ndarray
        Principal moments ``I₁ ≤ I₂ ≤ I₃``, kg·m².
    energy : float or ndarray
        Kinetic energy ``T = ½ Σ Iᵢ ωᵢ²``, J.
    momentum : float or ndarray
        ``|L| = √(Σ Iᵢ² ωᵢ²)``, N·m·s.
    regime : str or ndarray of str
        One of :data:`REGIMES`: ``"major"`` (``L² > 2T I₂``: the polhode
        encircles the axis of the largest moment ``I₃``), ``"minor"``
        (``L² < 2T I₂``: it encircles the axis of ``I₁``), ``"separatrix"``
        (``L² = 2T I₂`` exactly), ``"oblate"`` (``I₁ = I₂``), ``"prolate"``
        (``I₂ = I₃``), ``"sphere"`` (``I₁ = I₃``), ``"rest"`` (``ω = 0``).
    m : float or ndarray
        Elliptic parameter ``k²`` of the Jacobi functions, in [0, 1]:
        ``m = (I₂ − I₁)(2T I₃ − L²) / ((I₃ − I₂)(L² − 2T I₁))`` (major),
        the same with 1 and 3 swapped (minor); 0 for symmetric bodies, 1 on
        the separatrix.
    m1 : float or ndarray
        ``1 − m`` computed without cancellation,
        ``m1 = (I₃ − I₁)(L² − 2T I₂) / ((I₃ − I₂)(L² − 2T I₁))`` (major, and
        1 ↔ 3 for minor), from ``Δ₂`` summed over the rates: it keeps its
        relative accuracy as ``k → 1``, where ``K(m) ≈ ½ ln(16/m1)``.
    lam : float or ndarray
        ``λ``, rad/s, the rate multiplying ``t`` in the argument of the Jacobi
        functions: ``λ² = (I₃ − I₂)(L² − 2T I₁) / (I₁I₂I₃)`` (major, and 1 ↔ 3
        for minor); for a symmetric top ``λ = |I₃ − I₁| |ω_axis| / I_⊥``,
        the precession rate of ``ω`` about the symmetry axis in body axes;
        0 for the sphere and rest.
    quarter_period : float or ndarray
        ``K(m) / λ``, s: the polhode period is ``4K/λ``, and the rate about
        the intermediate axis changes sign every ``2K/λ``; ``inf`` on the
        separatrix and where ``λ = 0``.
    """

    moments: np.ndarray
    energy: float | np.ndarray
    momentum: float | np.ndarray
    regime: str | np.ndarray
    m: float | np.ndarray
    m1: float | np.ndarray
    lam: float | np.ndarray
    quarter_period: float | np.ndarray

    @property
    def period(self) -> float | np.ndarray:
        """Period of the body rate (the polhode), ``4K/λ`` = 4 × :attr:`quarter_period`, s."""
        return 4.0 * self.quarter_period


def free_parameters(moments, omega_p) -> FreeParameters:
    """Energy, momentum, regime and elliptic constants of the torque-free motion.

    Parameters
    ----------
    moments : (3,) or (…, 3) array_like
        Principal moments ``I₁ ≤ I₂ ≤ I₃`` (kg·m², ascending, > 0), as
        :attr:`tumble.RigidBody.moments`.
    omega_p : (3,) or (…, 3) array_like
        Body rate in principal axes, rad/s. Batch axes broadcast with those of
        ``moments``.

    Returns
    -------
    FreeParameters
        Scalars for one body, arrays of the batch shape otherwise.
    """
    moments = as_array(moments, "moments", tail=(3,))
    omega_p = as_array(omega_p, "omega_p", tail=(3,))
    _check_moments(moments)
    try:
        shape = np.broadcast_shapes(moments.shape[:-1], omega_p.shape[:-1])
    except ValueError:
        raise ValidationError(
            f"moments, omega_p: batch shapes must broadcast, got {moments.shape[:-1]} and {omega_p.shape[:-1]}"
        ) from None
    flat_moments = np.ascontiguousarray(np.broadcast_to(moments, shape + (3,))).reshape(-1, 3)
    flat_omega = np.ascontiguousarray(np.broadcast_to(omega_p, shape + (3,))).reshape(-1, 3)
    codes = np.empty(flat_omega.shape[0], dtype=np.int64)
    values = np.empty((flat_omega.shape[0], 6))
    _parameters_batch(flat_moments, flat_omega, codes, values)
    regime: str | np.ndarray = np.asarray(REGIMES)[codes].reshape(shape)
    fields: list[float] | list[np.ndarray] = [values[:, i].reshape(shape) for i in range(6)]
    if not shape:  # one body: numbers
        regime, fields = str(regime), [float(f) for f in fields]
    energy, momentum, m, m1, lam, quarter = fields
    return FreeParameters(
        moments=np.broadcast_to(moments, shape + (3,)).copy(), energy=energy, momentum=momentum,
        regime=regime, m=m, m1=m1, lam=lam, quarter_period=quarter,
    )


def _check_moments(moments: np.ndarray) -> None:
    """Refuse principal moments that are not positive and ascending."""
    if np.any(moments <= 0.0):
        raise ValidationError(f"moments: principal moments must be > 0, got {moments.tolist()}")
    if np.any(np.diff(moments, axis=-1) < 0.0):
        raise ValidationError(
            f"moments: principal moments must be ascending I1 <= I2 <= I3 (as RigidBody.moments), "
            f"got {moments.tolist()}"
        )


def torque_free(body, omega0, q0=None, *, t) -> Trajectory:
    """Exact torque-free motion of a rigid body (or a batch): body rate and attitude at the times ``t``.

    Closed form (no integration): Jacobi elliptic functions for the rate and
    an incomplete elliptic integral of the third kind for the attitude (its
    periodic part summed as a theta-function series in the nome, or by
    Carlson's ``R_J`` within ``1 − m ≲ 7e-8`` of the separatrix), evaluated at
    each output time independently; accurate to rounding over any time span.
    See the module docstring and ``docs/exact.md``.

    Attitude (Celledoni et al. 2008). ``L_N`` is constant; with the unit
    momentum ``l = Iω/|L|`` in principal axes (given by the rates), a fixed
    body axis ``a = ±e_k`` with ``a·l ≥ 0`` throughout the motion, and
    ``p(t)`` the shortest rotation taking ``a`` to ``l``::

        q_NP(t) = q_NP(t0) ⊗ p(t0) ⊗ exp(½ Δψ a) ⊗ p(t)*

    maps ``l(t)`` to the constant ``L_N/|L|`` at all times. Matching
    ``q̇ = ½ q ⊗ ω`` along ``l`` gives ``ψ̇ = (2T/|L| + a·ω) / (1 + a·l)``, which
    integrates to (``a·l = β dn τ``, ``β = I_k A_k / |L|``)::

        ψ(τ) = |L| t / I_j + |L|(I_k − I_j)/(I_j I_k λ) [Π(n; am τ | m) − τ − β G(am τ)],
        n = −I_k |I₂ − I_j| / (I_j |I_k − I₂|),   G(φ) = ∫₀^φ dθ / (1 − n sin²θ)

    and on the separatrix
    ``ψ = |L| t / I₂ − (|L|(I₃ − I₂)/(I₂I₃λ)) (2β/√(1−β²)) atan(κ tanh(τ/2))``,
    ``κ = √((1 − β)/(1 + β))``.

    Parameters
    ----------
    body : RigidBody, (3, 3) or (N, 3, 3) inertia array (kg·m², body axes), or a sequence of RigidBody
        The body, or one body per batch member (as :func:`tumble.simulate`).
    omega0 : (3,) or (N, 3) array_like
        Rate at ``t[0]``, rad/s, body axes; a leading axis of length N gives
        a batch.
    q0 : (4,) or (N, 4) array_like, optional
        Attitude at ``t[0]``, unit quaternion ``[w, x, y, z]``, body →
        inertial (normalised here; default: identity).
    t : (n,) array_like
        Output times, s, strictly increasing; ``t[0]`` is the initial time.

    Returns
    -------
    Trajectory
        ``method="exact"``; ``t`` (n,), ``q`` (n, [N,] 4), ``omega`` (n, [N,] 3).
    """
    return simulate(body, omega0, q0=q0, t=t, method="exact")
