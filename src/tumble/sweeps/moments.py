"""Per-time statistics over the members of a batch, merged chunk by chunk, exactly.

A chunk's part is ``[count, mean, M₂, min, max]`` over its members
(:func:`moments`, ``M₂ = Σ (x − x̄)²``); two disjoint parts merge as

    n = n_a + n_b,   δ = x̄_b − x̄_a,   x̄ = x̄_a + δ n_b/n,
    M₂ = M₂,a + M₂,b + δ² n_a n_b / n           (σ² = M₂ / n)

(T. F. Chan, G. H. Golub & R. J. LeVeque, "Updating formulae and a pairwise
algorithm for computing sample variances", Stanford CS report 79-773, 1979),
with the minimum and maximum merged directly (:func:`merge`). The result does
not depend on the chunk size beyond rounding, and merged in chunk order it is
the same bit for bit whatever order the chunks were computed in. Used by
:func:`tumble.ensemble.ensemble_statistics` and a sweep's store
(:mod:`tumble.sweeps.store`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["STATISTICS", "merge", "moments", "summary"]

#: The statistics of a quantity, in the order of :func:`summary` (and of the ``statistic`` dimension).
STATISTICS = ("mean", "std", "min", "max")


def moments(values: np.ndarray) -> list[np.ndarray]:
    """Statistics ``[count, mean, M₂, min, max]`` of ``values`` (n_times, members, ...) over the members
    (axis 1), ``M₂ = Σ (x − x̄)²``: one chunk's part, merged with :func:`merge`."""
    mean = values.mean(axis=1)
    return [np.full(values.shape[:1] + values.shape[2:], float(values.shape[1])), mean,
            ((values - mean[:, None]) ** 2).sum(axis=1), values.min(axis=1), values.max(axis=1)]


def merge(a: list[np.ndarray], b: list[np.ndarray]) -> list[np.ndarray]:
    """Statistics ``[count, mean, M₂, min, max]`` of the union of two disjoint samples (Chan et al. 1979)."""
    n_a, mean_a, m2_a, low_a, high_a = a
    n_b, mean_b, m2_b, low_b, high_b = b
    n = n_a + n_b
    delta = mean_b - mean_a
    return [n, mean_a + delta * (n_b / n), m2_a + m2_b + delta * delta * (n_a * n_b / n),
            np.minimum(low_a, low_b), np.maximum(high_a, high_b)]


def summary(stats: list[np.ndarray]) -> tuple[np.ndarray, ...]:
    """The :data:`STATISTICS` of merged ``[count, mean, M₂, min, max]``: mean, population standard deviation
    ``√(M₂ / n)`` (``ddof = 0``), minimum and maximum."""
    count, mean, m2, low, high = stats
    return mean, np.sqrt(m2 / count), low, high
