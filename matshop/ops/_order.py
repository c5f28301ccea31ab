"""Order statistics of float planes: a radix select, or numpy's vectorised sort.

A tone range needs three percentiles (six order statistics) of each channel
of a sample of texels. Which way is faster depends on the CPU, by a factor
of three to five either way (measured on the real 10-channel set's planes of
2^16 values):

- numpy's sort on an Intel CPU with AVX-512 (x86-simd-sort's 512-bit
  quicksort): on a Sapphire Rapids 0.05-0.3 ms a plane, where the radix
  select takes 0.4-1.2;
- the radix select on an AMD Zen 4, though it has AVX-512 too (its
  compressing stores, which that quicksort partitions with, are slow): the
  sort 0.5-1.4 ms a plane, the select 0.18-0.5; on a Zen 3 (AVX2) at 2^18
  values the sort took three times the select. The select reads each plane
  twice: a histogram of the values' top 16 bits (as sortable integers), then
  the values of the few buckets that hold a wanted rank, which are sorted
  alone.

So the choice is measured, once per process, on a plane of random values
(:func:`_faster_method`), not read from the CPU's features. Both give the
same values, bit for bit (a sort's order statistics).
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit, prange

#: "sort" or "radix": the faster way on this CPU, measured on first use
#: (:func:`_faster_method`); tests set it to run either
METHOD: str | None = None
#: values in the plane the two ways are timed on: the size of a tone range's sample
_TRIAL_VALUES = 1 << 16

#: the histogram's buckets: the top bits of the sortable key
_BUCKET_BITS = 16
#: the first and last bucket of finite values: the keys of -max and +max float32
#: (infinities and NaNs sort outside them)
_FINITE_BUCKETS = (0x00800000 >> (32 - _BUCKET_BITS), 0xFF7FFFFF >> (32 - _BUCKET_BITS))


@njit(inline="always", nogil=True)
def _bucket(value):
    """The histogram bucket of ``value``: never smaller for a larger value.

    The top bits of the value rounded to float32 (rounding keeps the order, so
    float64 planes work too), read as an unsigned integer that orders like the
    float: negatives have every bit flipped, others only the sign bit.
    """
    bits = np.int64(np.float32(value).view(np.int32))
    flip = (bits >> 31) | 0x80000000  # all ones for negatives, the sign bit else
    # unsigned: an index known not to be negative needs no wraparound check
    return np.uint64(((bits ^ flip) & 0xFFFFFFFF) >> (32 - _BUCKET_BITS))


@njit(inline="always", nogil=True, error_model="numpy")
def _wanted_buckets(plane, ranks, values, first, slot, before, flat):
    """The values of the buckets that hold ``ranks`` (ascending), bucket by bucket,
    into ``values`` (at least the plane's length); the number of buckets, or -1
    when the plane holds an infinity or a NaN (or, as float32, a float64 beyond
    its range).

    Bucket ``s`` is ``values[first[s]:first[s + 1]]``, all one value when
    ``flat[s]``; rank ``j`` lies in bucket ``slot[j]`` with ``before[j]``
    smaller values in the buckets below it.
    """
    # two histograms, even and odd places: a run of equal values (a flat area) then
    # makes two chains of increments of one counter, not one twice as long
    halves = np.zeros((2, 1 << _BUCKET_BITS), dtype=np.int32)
    pairs = plane.shape[0] // 2
    for i in range(pairs):
        halves[0, _bucket(plane[2 * i])] += 1
        halves[1, _bucket(plane[2 * i + 1])] += 1
    if plane.shape[0] % 2:
        halves[0, _bucket(plane[-1])] += 1
    counts = halves[0].astype(np.int64) + halves[1]
    if counts[: _FINITE_BUCKETS[0]].sum() + counts[_FINITE_BUCKETS[1] + 1 :].sum() > 0:
        return -1
    # ascending ranks give ascending buckets: one walk assigns the slots
    slot_of = np.full(1 << _BUCKET_BITS, -1, dtype=np.int32)
    first[0] = 0
    bucket, below, slots = 0, 0, 0
    for j in range(ranks.shape[0]):
        while below + counts[bucket] <= ranks[j]:
            below += counts[bucket]
            bucket += 1
        if slot_of[bucket] < 0:
            slot_of[bucket] = slots
            first[slots + 1] = first[slots] + counts[bucket]
            slots += 1
        slot[j], before[j] = slot_of[bucket], below
    filled = first[:slots].copy()
    for v in plane:
        s = slot_of[_bucket(v)]
        if s >= 0:
            values[filled[s]] = v
            filled[s] += 1
    for s in range(slots):
        bucket_values = values[first[s] : first[s + 1]]
        flat[s] = bucket_values.min() == bucket_values.max()
    return slots


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def _wanted_buckets_of_planes(planes, rows, ranks, values, first, slot, before, flat, slots):
    """:func:`_wanted_buckets` of ``planes[rows[i]]`` into row i of each output, a
    plane per thread at a time (``slots[i]``: its return value)."""
    for i in prange(rows.shape[0]):
        slots[i] = _wanted_buckets(
            planes[rows[i]], ranks, values[i], first[i], slot[i], before[i], flat[i]
        )


def order_statistics(
    planes: np.ndarray, ranks: np.ndarray, rows: np.ndarray | None = None
) -> np.ndarray | None:
    """``np.sort(planes[rows], axis=1)[:, ranks]`` for ``planes`` (k, n) of floats
    (``rows``: all by default) and ascending ``ranks`` in ``[0, n)``; None when a
    value is not finite (the caller decides which values to drop), found on the
    way: by a sort's ends (NaN sorts last, infinities outermost), or by the radix
    select's histogram at no extra pass.
    """
    ranks = np.asarray(ranks, dtype=np.int64)
    rows = np.arange(planes.shape[0]) if rows is None else np.asarray(rows, dtype=np.int64)
    by = _by_radix if _method() == "radix" else _by_sort
    return by(planes, rows, ranks)


def _by_sort(planes: np.ndarray, rows: np.ndarray, ranks: np.ndarray) -> np.ndarray | None:
    out = np.empty((rows.size, ranks.size), dtype=planes.dtype)
    for i, row in enumerate(rows):
        ordered = np.sort(planes[row])
        if not (np.isfinite(ordered[0]) and np.isfinite(ordered[-1])):
            return None
        out[i] = ordered[ranks]
    return out


def _by_radix(planes: np.ndarray, rows: np.ndarray, ranks: np.ndarray) -> np.ndarray | None:
    """The wanted buckets of every plane in one parallel pass, then those that are
    not one value partitioned by numpy at the wanted places: on real maps most
    values can share one bucket (the flat three quarters of the chessboard's
    normals, metallic's zeros), and numba's own sort took 6-8 ms on such a
    bucket, numpy's 1.
    """
    count, wanted = rows.size, ranks.size
    values = np.empty((count, planes.shape[1]), dtype=planes.dtype)
    first = np.empty((count, wanted + 1), dtype=np.int64)
    slot = np.empty((count, wanted), dtype=np.int64)
    before = np.empty((count, wanted), dtype=np.int64)
    flat = np.empty((count, wanted), dtype=np.bool_)
    slots = np.empty(count, dtype=np.int64)
    _wanted_buckets_of_planes(
        np.ascontiguousarray(planes), rows, ranks, values, first, slot, before, flat, slots
    )
    if (slots < 0).any():
        return None
    at = first[np.arange(count)[:, None], slot] + ranks - before
    for i in range(count):
        for s in np.flatnonzero(~flat[i, : slots[i]]):
            start, stop = first[i, s], first[i, s + 1]
            # only the wanted places in order: a partition, not a sort (a frame's
            # magnitudes put 30 000 values of a few levels in one bucket)
            values[i, start:stop].partition(at[i, slot[i] == s] - start)
    return np.take_along_axis(values, at, axis=1)


def _method() -> str:
    global METHOD
    if METHOD is None:
        METHOD = _faster_method()
    return METHOD


def _faster_method(repeats: int = 3) -> str:
    """"sort" or "radix", whichever found the order statistics of one plane of
    random normal values faster (the best of ``repeats`` runs each, after one
    run each to load the code): about 5 ms, once."""
    plane = np.random.default_rng(0).normal(size=_TRIAL_VALUES).astype(np.float32)
    ranks = np.array([_TRIAL_VALUES // 200, _TRIAL_VALUES // 2, _TRIAL_VALUES - 1])
    planes, rows = plane[None], np.zeros(1, dtype=np.int64)
    best = {}
    for name, by in (("sort", _by_sort), ("radix", _by_radix)):
        by(planes, rows, ranks)
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            by(planes, rows, ranks)
            times.append(time.perf_counter() - start)
        best[name] = min(times)
    return min(best, key=best.get)
