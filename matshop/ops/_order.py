"""Order statistics of float planes: a radix select, or numpy's vectorised sort.

A tone range needs three percentiles (six order statistics) of each channel
of a sample of texels. Which way is faster depends on the CPU, by a factor
of three either way (measured on the real 10-channel set's planes):

- numpy's sort on a CPU with AVX-512 (x86-simd-sort's 512-bit quicksort):
  on a Sapphire Rapids 0.05-0.3 ms a plane of 2^16 values, where the radix
  select takes 0.4-1.2 (at 2^18 values 0.12-1.3 against 1.2-2.1; the
  select's second pass, a scattered write, is bound by the dependence
  through its fill counters);
- elsewhere the radix select: on an AMD Zen3 (AVX2) sorting a plane of 2^18
  values took 2.2 ms, three times the radix select. It reads each plane twice: a
  histogram of the values' top 16 bits (as sortable integers), then the
  values of the few buckets that hold a wanted rank, which are sorted alone.

Both give the same values, bit for bit (a sort's order statistics).
"""

from __future__ import annotations

import numpy as np
from numba import njit

try:  # numpy's own record of the CPU features its kernels dispatch on
    from numpy._core._multiarray_umath import __cpu_features__ as _NUMPY_CPU
except ImportError:  # numpy 1.x
    from numpy.core._multiarray_umath import __cpu_features__ as _NUMPY_CPU

#: numpy's sort runs its AVX-512 quicksort here (numpy >= 1.25 on such a CPU)
SORT_IS_VECTORISED = (
    bool(_NUMPY_CPU.get("AVX512_SKX")) and np.lib.NumpyVersion(np.__version__) >= "1.25.0"
)

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


@njit(cache=True, nogil=True, error_model="numpy")
def _wanted_buckets(plane, ranks):
    """The values of the buckets that hold ``ranks`` (ascending), bucket by bucket.

    Returns ``(values, first, slot, before)``: bucket ``s`` is
    ``values[first[s]:first[s + 1]]``, rank ``j`` lies in bucket ``slot[j]``
    with ``before[j]`` smaller values in the buckets below it; None when the
    plane holds an infinity or a NaN (or, as float32, a float64 beyond its range).
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
        return None
    # ascending ranks give ascending buckets: one walk assigns the slots
    wanted = ranks.shape[0]
    slot_of = np.full(1 << _BUCKET_BITS, -1, dtype=np.int64)
    slot = np.empty(wanted, dtype=np.int64)
    before = np.empty(wanted, dtype=np.int64)
    first = np.zeros(wanted + 1, dtype=np.int64)
    bucket, below, slots = 0, 0, 0
    for j in range(wanted):
        while below + counts[bucket] <= ranks[j]:
            below += counts[bucket]
            bucket += 1
        if slot_of[bucket] < 0:
            slot_of[bucket] = slots
            first[slots + 1] = first[slots] + counts[bucket]
            slots += 1
        slot[j], before[j] = slot_of[bucket], below
    values = np.empty(first[slots], dtype=plane.dtype)
    filled = first[:slots].copy()
    for v in plane:
        s = slot_of[_bucket(v)]
        if s >= 0:
            values[filled[s]] = v
            filled[s] += 1
    return values, first[: slots + 1], slot, before


def order_statistics(planes: np.ndarray, ranks: np.ndarray) -> np.ndarray | None:
    """``np.sort(planes, axis=1)[:, ranks]`` for ``planes`` (k, n) of floats and
    ascending ``ranks`` in ``[0, n)``; None when a value is not finite (the
    caller decides which values to drop), found on the way: by a sort's ends
    (NaN sorts last, infinities outermost), or by the radix select's histogram
    at no extra pass.
    """
    ranks = np.asarray(ranks, dtype=np.int64)
    out = np.empty((planes.shape[0], ranks.size), dtype=planes.dtype)
    for row, plane in zip(out, planes, strict=True):
        found = _by_sort(plane, ranks) if SORT_IS_VECTORISED else _by_radix(plane, ranks)
        if found is None:
            return None
        row[:] = found
    return out


def _by_sort(plane: np.ndarray, ranks: np.ndarray) -> np.ndarray | None:
    ordered = np.sort(plane)
    if not (np.isfinite(ordered[0]) and np.isfinite(ordered[-1])):
        return None
    return ordered[ranks]


def _by_radix(plane: np.ndarray, ranks: np.ndarray) -> np.ndarray | None:
    """The wanted buckets are sorted by numpy: on real maps most values can share
    one bucket (the flat three quarters of the chessboard's normals, metallic's
    zeros), and numba's own sort took 6-8 ms on such a bucket, numpy's 1.
    """
    wanted = _wanted_buckets(np.ascontiguousarray(plane), ranks)
    if wanted is None:
        return None
    values, first, slot, before = wanted
    for start, stop in zip(first[:-1], first[1:], strict=True):
        bucket = values[start:stop]
        if bucket.min() != bucket.max():  # a flat area's one value needs no sort
            bucket.sort()
    return values[first[slot] + ranks - before]
