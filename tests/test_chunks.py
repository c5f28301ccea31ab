"""Chunks handed out by a shared counter (``matshop.parallel_chunks``): each exactly once."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from numba import njit, prange

from matshop.parallel_chunks import next_chunk


@njit(parallel=True)
def _take_all(chunks, workers, takes, taken_by, counter):
    """Each worker takes chunks until none is left; ``takes[c]`` counts chunk c's takers."""
    for worker in prange(workers):
        chunk = next_chunk(counter)
        while chunk < chunks:
            takes[chunk] += 1
            taken_by[chunk] = worker
            # some work, so the workers overlap
            total = 0.0
            for i in range(2000):
                total += np.sqrt(i + chunk)
            takes[chunk] += total < 0.0
            chunk = next_chunk(counter)


@pytest.mark.parametrize(("chunks", "workers"), [(64, 2), (1000, 2), (3, 8), (0, 2), (5, 1)])
def test_every_chunk_is_taken_once(chunks: int, workers: int) -> None:
    threads = numba.get_num_threads()
    takes = np.zeros(chunks, dtype=np.int64)
    taken_by = np.full(chunks, -1, dtype=np.int64)
    counter = np.zeros(1, dtype=np.int64)
    _take_all(chunks, workers, takes, taken_by, counter)
    assert np.all(takes == 1)
    assert np.all((taken_by >= 0) & (taken_by < workers))
    # every worker's last take found the chunks used up: one take each past the end
    assert counter[0] == chunks + workers
    assert numba.get_num_threads() == threads
