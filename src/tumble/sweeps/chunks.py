"""One chunker: a batch of members cut into chunks, each run as one batch of :func:`tumble.simulate`.

A batch that outgrows memory (:func:`tumble.sweeps.stream.simulate_to_store`),
the statistics of a huge batch (:func:`tumble.ensemble.ensemble_statistics`)
and the samples of a sweep (:class:`tumble.sweeps.plan.Plan`, one Dask task per
chunk) are cut the same way: ``N`` members in :class:`Chunks` of ``c``,

    [0, c), [c, 2c), …, [(K − 1) c, N),    K = ⌈N / c⌉,

by default ``c`` such that one chunk's run takes about 200 MB
(:data:`SAMPLES_PER_CHUNK` member-samples, a member-sample being one member at
one output time, some 400 bytes with its states, trajectory and statistics).

A chunk of a batch is the model's :meth:`tumble.Model.members` ``(lo, hi)``
(a batch of rigid bodies sliced; a model without a batch of its own is every
member's) with the rows ``lo:hi`` of the batched initial states. A member of a
compiled batch integrates on its own, so each member of a chunk gets the very
numbers it gets in the whole batch.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError
from tumble.simulate import Model, simulate
from tumble.trajectory import Trajectory

__all__ = ["Chunks", "SAMPLES_PER_CHUNK", "batch_members", "simulate_chunks"]

#: Default chunk size in member-samples (members × output times): states, trajectory and statistics of a chunk
#: take about 400 bytes per member-sample, so about 200 MB.
SAMPLES_PER_CHUNK = 2**19


@dataclass(frozen=True)
class Chunks:
    """``members`` members cut into chunks of ``size``: chunk ``k`` holds the members ``k·size`` to
    ``min(members, (k + 1)·size) − 1``."""

    members: int
    size: int

    @classmethod
    def of(cls, members: int, size: int | None = None, *, n_times: int, parallel: int = 1,
           least: int = 1) -> Chunks:
        """The chunks of ``members`` members of ``size`` each (checked ``>= 1``), or by default the members
        shared evenly between ``parallel`` runners, ``⌈members / parallel⌉``, at most
        :data:`SAMPLES_PER_CHUNK` ``// n_times`` (about 200 MB a chunk) and at least ``least``."""
        if size is None:
            size = max(least, min(math.ceil(members / parallel), SAMPLES_PER_CHUNK // max(1, n_times)))
        if int(size) < 1:
            raise ValidationError(f"chunk: must be >= 1 member, got {size}")
        return cls(int(members), int(size))

    def __len__(self) -> int:
        return math.ceil(self.members / self.size)

    def bounds(self, k: int) -> tuple[int, int]:
        """The members ``[lo, hi)`` of chunk ``k``."""
        return k * self.size, min(self.members, (k + 1) * self.size)

    def __iter__(self) -> Iterator[tuple[int, int]]:
        return (self.bounds(k) for k in range(len(self)))


def batch_members(model: Model, initial_state: Mapping[str, Any]) -> int:
    """The members ``N`` of a batch: the leading length of the batched (two-dimensional) initial states and of
    the model's own batch, which must agree; 1 when nothing is batched."""
    sizes = {name: np.shape(v)[0] for name, v in initial_state.items() if v is not None and np.ndim(v) == 2}
    if model.batch_size is not None:
        sizes["model"] = model.batch_size
    first, n_first = next(iter(sizes.items()), ("", 1))
    for name, n in sizes.items():
        if n != n_first:
            raise ValidationError(f"{name}: a batch of {n} does not match the {n_first} of {first}; every "
                                  "batched value (and the model's bodies) must have the same leading length")
    return n_first


def simulate_chunks(model: Model, chunks: Chunks, *, t: ArrayLike, initial_state: Mapping[str, Any],
                    **options: Any) -> Iterator[tuple[int, int, Trajectory]]:
    """``(lo, hi, trajectory)`` of each chunk in turn: ``simulate(model.members(lo, hi), t=t, **options,
    **initial_state)`` with the rows ``lo:hi`` of the batched (two-dimensional) initial states, a shared value
    as it is."""
    for lo, hi in chunks:
        part = {name: v[lo:hi] if np.ndim(v) == 2 else v for name, v in initial_state.items()}
        yield lo, hi, simulate(model.members(lo, hi), t=t, **options, **part)
