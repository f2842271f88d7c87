"""The one chunker of batches run piece by piece (tumble.sweeps.chunks): the partition, the default size, a
model's members(lo, hi) and the batch size read from the initial states. Nothing here integrates."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble.rigid_model import RigidBodies
from tumble.sweeps.chunks import SAMPLES_PER_CHUNK, Chunks, batch_members

RNG = np.random.default_rng(11)
N = 23  # a prime: chunks of 5 leave a remainder
INERTIA = np.diag([1.0, 2.0, 3.0]) + np.einsum("n,ij->nij", RNG.uniform(0.0, 0.2, N), np.eye(3))


def test_chunks_cover_the_batch_once_in_order_and_a_chunk_of_bodies_is_those_bodies():
    chunks = Chunks.of(N, 5, n_times=11)
    assert list(chunks) == [(0, 5), (5, 10), (10, 15), (15, 20), (20, 23)] and len(chunks) == 5
    assert chunks.bounds(4) == (20, 23)
    bodies = [tumble.RigidBody(inertia, mass=1.0 + k) for k, inertia in enumerate(INERTIA)]
    batch = RigidBodies.of(bodies)
    for lo, hi in chunks:
        part, alone = batch.members(lo, hi), RigidBodies.of(bodies[lo:hi])
        assert part.batch_size == hi - lo
        for name in ("inertia", "moments", "axes", "q_bp", "masses"):  # the bodies lo..hi-1, bit for bit
            np.testing.assert_array_equal(getattr(part, name), getattr(alone, name), err_msg=name)
    shared = RigidBodies.of(INERTIA[0])
    assert shared.members(3, 7) is shared  # one body for every member: no batch of its own to cut


@pytest.mark.parametrize("members, n_times, parallel, least, size", [
    (N, 11, 1, 1, N),                           # all in one chunk: 23 x 11 member-samples fit
    (10**6, 1000, 1, 1, SAMPLES_PER_CHUNK // 1000),   # 524 members of 1000 times: about 200 MB
    (10**6, 1000, 1, 1024, 1024),               # at least `least` (ensemble statistics fill the cores)
    (N, 11, 4, 1, 6),                           # shared between 4 workers: ceil(23 / 4)
])
def test_the_default_chunk_is_about_200_mb_shared_between_the_runners(members, n_times, parallel, least, size):
    assert Chunks.of(members, None, n_times=n_times, parallel=parallel, least=least).size == size


def test_the_batch_size_is_read_from_the_batched_states_and_the_models_own_batch():
    batch = RigidBodies.of(INERTIA)
    assert batch_members(batch, {"omega0": np.zeros((N, 3)), "q0": [1.0, 0.0, 0.0, 0.0]}) == N
    assert batch_members(RigidBodies.of(INERTIA[0]), {"omega0": [0.0, 0.0, 1.0]}) == 1
    with pytest.raises(tumble.ValidationError, match=r"^q0: a batch of 4 does not match the 23 of omega0"):
        batch_members(batch, {"omega0": np.zeros((N, 3)), "q0": np.ones((4, 4))})
    with pytest.raises(tumble.ValidationError, match=r"^model: a batch of 23 does not match the 5 of omega0"):
        batch_members(batch, {"omega0": np.zeros((5, 3))})
    with pytest.raises(tumble.ValidationError, match=r"^chunk: must be >= 1 member, got 0"):
        Chunks.of(N, 0, n_times=11)
