"""The buffer pool: memory is reused only once nothing refers to it.

Truth: numpy's own record of which memory an array uses (``np.shares_memory``,
the data pointers), and the values a live array holds, which a reuse would
overwrite.
"""

from __future__ import annotations

import gc

import numpy as np

from matshop.buffers import MIN_BYTES, BufferPool

SHAPE = (512, 512, 3)  # 3 MiB of float32: pooled


def _address(array: np.ndarray) -> int:
    return array.__array_interface__["data"][0]


def test_a_dropped_result_lends_its_memory_to_the_next_one() -> None:
    pool = BufferPool()
    first = pool.empty(SHAPE)
    address = _address(first)
    del first
    second = pool.empty(SHAPE)
    assert _address(second) == address
    assert second.shape == SHAPE and second.dtype == np.float32 and second.flags.c_contiguous


def test_memory_a_live_array_or_any_view_of_it_uses_is_never_handed_out() -> None:
    pool = BufferPool()
    first = pool.empty(SHAPE)
    first[...] = 7.0
    crop = first[10:20, 5:9, 1]  # a view keeps the memory in use after the array goes
    flat = first.reshape(-1)
    del first
    others = [pool.empty(SHAPE) for _ in range(3)]
    for other in others:
        other[...] = -1.0
        assert not np.shares_memory(other, crop) and not np.shares_memory(other, flat)
    assert np.all(crop == 7.0) and np.all(flat == 7.0)
    del flat, others
    gc.collect()
    # the crop alone still holds it
    again = pool.empty(SHAPE)
    assert not np.shares_memory(again, crop)
    del crop, again
    reused = pool.empty(SHAPE)
    assert pool.idle_bytes() > 0  # one of the earlier buffers waits for a taker
    del reused


def test_only_the_same_size_is_reused_and_small_arrays_are_not_pooled() -> None:
    pool = BufferPool()
    big = pool.empty(SHAPE)
    address = _address(big)
    del big
    other = pool.empty((512, 512, 4))
    assert _address(other) != address
    small = pool.empty((8, 8))
    assert small.nbytes < MIN_BYTES and small.base is None


def test_free_buffers_beyond_the_limit_are_dropped_oldest_first() -> None:
    size = int(np.prod(SHAPE)) * 4
    pool = BufferPool(idle_limit=2 * size)
    arrays = [pool.empty(SHAPE) for _ in range(4)]
    del arrays
    assert pool.idle_bytes() == 4 * size  # nothing asked since they went free
    kept = pool.empty((1024, 1024))  # another size: a new buffer; the oldest free ones go
    assert pool.idle_bytes() == 2 * size
    assert pool.release() == 2 * size and pool.idle_bytes() == 0
    assert kept.shape == (1024, 1024)


def test_touched_buffers_are_mapped_and_other_dtypes_fit() -> None:
    pool = BufferPool()
    out = pool.empty((300, 1000), np.float64, touched=True)
    assert out.dtype == np.float64 and out.shape == (300, 1000)
    out[...] = 1.5
    assert float(out.sum()) == 1.5 * out.size
