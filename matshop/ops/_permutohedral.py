"""Permutohedral-lattice Gaussian filtering kernels (numba), for the bilateral filter.

The algorithm is the one of Adams, Baek and Davis (2010), "Fast
High-Dimensional Filtering Using the Permutohedral Lattice": every texel's
position in feature space (its two pixel coordinates over the spatial sigma,
then its range guide over the range sigma) is lifted onto the hyperplane
``H_d`` of ``R^(d+1)``, its enclosing simplex of the permutohedral lattice is
found, and its value (with a homogeneous 1 appended) is *splatted* onto the
simplex's ``d + 1`` vertices with barycentric weights. The lattice values are
then *blurred* with ``[1 2 1] / 4`` along each of the ``d + 1`` lattice
directions, and *sliced* back at every texel with the same weights; dividing by
the homogeneous channel normalises.

Implementation notes (the code is ours, the maths is the paper's):

* Lattice points are identified by a 64-bit *linear* hash of their integer
  coordinates, ``key = sum_i x_i P_i mod 2^64`` with fixed random odd ``P_i``.
  Because it is linear, a vertex's key follows from the simplex's remainder-0
  key by adding constants, and a blur neighbour's key is the point's key plus
  a constant per direction, so no coordinates are ever stored or compared.
  Two distinct points of a tile share a key only if a small integer
  combination of the ``P_i`` vanishes mod 2^64 (probability ~2^-55 per pair,
  ~2^-25 per tile at worst); that would merely merge two lattice points.
* The hash table (open addressing, linear probing, load <= 1/3) stores the
  point index and 32 bits of the key per 8-byte slot, so a probe that does
  not match costs one memory access; the first probes of a lookup are
  evaluated without branches, because whether a neighbour exists is a coin
  flip the branch predictor cannot learn.
* The image is cut into tiles processed independently in parallel, each with
  its own hash table and a margin of texels around it (read through the wrap
  or clamp border, so no padded copy of the image is made). Positions are
  global, so every tile builds a piece of the *same* lattice and the tiled
  result equals the untiled one up to the lattice mass beyond the margin.
* Per tile: :func:`locate` finds every texel's simplex, a row at a time with
  the texels on the inner (vectorised) axis, and only looks up the vertices
  that the texel's left and upper neighbours do not share (about one in ten);
  :func:`neighbours` finds the neighbouring pairs along each lattice
  direction once; then the channels go through splat, blur and slice
  ``_CHANNELS`` at a time (plus the homogeneous 1), so wide images keep the
  lattice values cache-sized.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Fibonacci hashing multiplier (2^64 / golden ratio), as a signed int64
_GOLDEN = np.int64(-7046029254386353131)
_LOW32 = np.int64(0xFFFFFFFF)
#: the hash table grows when more than 1/_LOAD full
_LOAD = 3
#: floats per lattice point (a 64-byte row): image channels sent through
#: the lattice at a time, their homogeneous weight, zero padding
_LANES = 16
_CHANNELS = _LANES - 1


def key_primes(dims: int, seed: int = 0x5EED) -> np.ndarray:
    """``dims`` random odd 64-bit multipliers (as int64) for the linear lattice key."""
    rng = np.random.default_rng(seed)
    primes = rng.integers(0, 2**63 - 1, size=max(dims, 1), dtype=np.int64)
    return primes | np.int64(1)


@njit(cache=True, nogil=True)
def _slot(key, shift, mask):
    return ((key * _GOLDEN) >> shift) & mask


@njit(cache=True, nogil=True)
def _entry(j, key):
    # a table slot: the point index in the high half, the key's low 32 bits
    # as a fingerprint in the low half (so mismatches cost no second access)
    return (np.int64(j) << 32) | (key & _LOW32)


@njit(cache=True, nogil=True)
def _find(key, table, keys, shift, mask):
    """Index of the lattice point with ``key``, or -1.

    ``table`` is open addressing with linear probing; a slot is -1 (empty)
    or an :func:`_entry`; ``keys`` holds the points' keys.
    """
    s = _slot(key, shift, mask)
    fingerprint = key & _LOW32
    while True:
        v = table[s]
        if v < 0:
            return -1
        if (v & _LOW32) == fingerprint:
            j = v >> 32
            if keys[j] == key:
                return j
        s = (s + 1) & mask


@njit(cache=True, nogil=True)
def _find_fast(key, table, keys, shift, mask):
    """:func:`_find` with the first two probes branch-free.

    Blur lookups miss (no such neighbour) about as often as they hit, so a
    probing loop mispredicts constantly; here the first two slots are read
    and the answer selected without branches, and only a probe sequence that
    runs past them (rare at the table's load) or a fingerprint collision
    takes the loop.
    """
    s = _slot(key, shift, mask)
    fingerprint = key & _LOW32
    v0 = table[s]
    v1 = table[(s + 1) & mask]
    r1 = np.int64(-2)  # -2: undecided
    r1 = -1 if v1 < 0 else r1
    r1 = v1 >> 32 if (v1 >= 0) & ((v1 & _LOW32) == fingerprint) else r1
    r0 = -1 if v0 < 0 else r1
    r0 = v0 >> 32 if (v0 >= 0) & ((v0 & _LOW32) == fingerprint) else r0
    # bitwise, not short-circuit: no branch on whether the point exists
    slow = (r0 == -2) | ((r0 >= 0) & (keys[max(r0, 0)] != key))
    if slow:
        return _find(key, table, keys, shift, mask)
    return r0


@njit(cache=True, nogil=True)
def _insert(key, table, keys, count, shift, mask):
    """Index of ``key`` in the table, adding it as point ``count`` if new."""
    s = _slot(key, shift, mask)
    fingerprint = key & _LOW32
    while True:
        v = table[s]
        if v < 0:
            keys[count] = key
            table[s] = _entry(count, key)
            return count
        if (v & _LOW32) == fingerprint:
            j = v >> 32
            if keys[j] == key:
                return j
        s = (s + 1) & mask


@njit(cache=True, nogil=True)
def _grow(table, keys, count):
    """Twice the capacity, re-inserting the ``count`` points of ``keys``."""
    capacity = 2 * table.shape[0]
    mask = capacity - 1
    shift = 64 - _log2(capacity)
    table = np.full(capacity, -1, dtype=np.int64)
    for j in range(count):
        s = _slot(keys[j], shift, mask)
        while table[s] >= 0:
            s = (s + 1) & mask
        table[s] = _entry(j, keys[j])
    bigger = np.empty(capacity // 2, dtype=np.int64)
    bigger[:count] = keys[:count]
    return table, bigger


@njit(cache=True, nogil=True)
def _log2(n):
    b = 0
    while (1 << b) < n:
        b += 1
    return b


@njit(cache=True, nogil=True)
def _source(i, n, wrap):
    """Index into an axis of length ``n`` for padded index ``i`` (wrap or clamp)."""
    if wrap:
        return i % n
    return min(max(i, 0), n - 1)


@njit(cache=True, nogil=True)
def locate(
    feat,
    used,
    top,
    left,
    rows,
    cols,
    wrap,
    lift0,
    lift_r,
    lift_c,
    lift_g,
    primes,
    idx,
    bw,
    table,
    keys,
):
    """Find every texel's simplex: vertex indices ``idx`` and barycentric weights ``bw``.

    A texel at padded position ``(r, c)`` with range channels ``f =
    feat[r, c, used]`` (read through the border) sits at ``lift0 + r lift_r +
    c lift_c + f @ lift_g`` on the hyperplane ``H_d`` of ``R^(d+1)``: its
    features (over their sigmas, rotated, lattice-scaled) times the
    elevation matrix, folded into one affine map. Inserts the vertices in the
    hash ``table``, their keys in point order in ``keys``; returns ``(count,
    table, keys)``, the arrays replaced when they had to grow.

    Works a row at a time with the texels on the inner, vectorisable axis, in
    float32 relative to a lattice point near the tile (so magnitudes stay
    small); only the hash-table work is per texel, and only for vertices
    that neither the left nor the upper neighbour already has.
    """
    height, width, _ = feat.shape
    nfeat = used.shape[0]
    d1 = lift0.shape[0]
    d = d1 - 1
    fd1 = np.float32(d1)
    fd = np.float32(d)
    inv = np.float32(1.0 / d1)
    half = np.float32(0.5)
    one = np.float32(1.0)

    capacity = table.shape[0]
    mask = capacity - 1
    shift = 64 - _log2(capacity)
    table[:] = -1
    count = 0

    # a remainder-0 lattice point near the tile's corner: positions are taken
    # relative to it, and its key is added back (keys are linear)
    origin = np.empty(d1, dtype=np.int64)
    total = np.int64(0)
    for i in range(d1):
        q = np.int64(np.floor((lift0[i] + top * lift_r[i] + left * lift_c[i]) / d1 + 0.5))
        origin[i] = q
        total += q
    origin[0] -= total
    key0 = np.int64(0)
    psum = np.int64(0)
    step = np.zeros(d1, dtype=np.int64)  # key change per unit of coordinate / (d + 1)
    for i in range(d):
        key0 += origin[i] * d1 * primes[i]
        psum += primes[i]
        step[i] = d1 * primes[i]

    colsrc = np.empty(cols, dtype=np.int64)
    tpos = np.empty(cols, dtype=np.float32)
    for t in range(cols):
        colsrc[t] = _source(left + t, width, wrap)
        tpos[t] = t
    lc = lift_c.astype(np.float32)
    lg = np.ascontiguousarray(lift_g.T).astype(np.float32)

    f_rows = np.empty((nfeat, cols), dtype=np.float32)
    el = np.empty((d1, cols), dtype=np.float32)
    quot = np.empty((d1, cols), dtype=np.float32)
    diff = np.empty((d1, cols), dtype=np.float32)
    rank = np.empty((d1, cols), dtype=np.float32)
    tot = np.empty(cols, dtype=np.float32)
    sorted_v = np.empty((d1, cols), dtype=np.float32)
    base = np.empty(cols, dtype=np.int64)
    key = np.empty((d1, cols), dtype=np.int64)
    key_up = np.empty((d1, cols), dtype=np.int64)
    fresh_key = np.empty(cols * d1, dtype=np.int64)
    fresh_at = np.empty(cols * d1, dtype=np.int64)
    back = np.empty((d1, cols), dtype=np.int64)
    found = np.empty(cols * d1, dtype=np.int64)
    lost = np.empty(cols * d1, dtype=np.int64)
    flat_idx = idx.reshape(-1)

    for lr in range(rows):
        r = top + lr
        sr = _source(r, height, wrap)
        p0 = lr * cols
        # range channels of the row
        for t in range(cols):
            sc = colsrc[t]
            for u in range(nfeat):
                f_rows[u, t] = feat[sr, sc, used[u]]
        # positions on H_d, relative to the origin
        for i in range(d1):
            b = np.float32(lift0[i] + r * lift_r[i] + left * lift_c[i] - origin[i] * d1)
            ci = lc[i]
            row = el[i]
            for t in range(cols):
                row[t] = b + tpos[t] * ci
            for u in range(nfeat):
                coef = lg[i, u]
                fu = f_rows[u]
                for t in range(cols):
                    row[t] += coef * fu[t]
        # nearest remainder-0 point (coordinates quot * (d + 1))
        tot[:] = 0.0
        for i in range(d1):
            for t in range(cols):
                q = np.floor(el[i, t] * inv + half)
                quot[i, t] = q
                diff[i, t] = el[i, t] - q * fd1
                tot[t] += q
        # rank of each differential: how many are larger (ties: the lower
        # index counts as larger)
        for i in range(d1):
            ri = rank[i]
            di = diff[i]
            ri[:] = 0.0
            for j in range(i):
                dj = diff[j]
                for t in range(cols):
                    ri[t] += np.float32(dj[t] >= di[t])
            for j in range(i + 1, d1):
                dj = diff[j]
                for t in range(cols):
                    ri[t] += np.float32(dj[t] > di[t])
        # move the remainder-0 point onto H_d (coordinate sum zero): ranks
        # shift by the sum, the coordinates that wrap around move by d + 1
        for i in range(d1):
            for t in range(cols):
                rr = rank[i, t] + tot[t]
                delta = np.float32(rr < 0) - np.float32(rr > fd)
                rank[i, t] = rr + fd1 * delta
                quot[i, t] += delta
                diff[i, t] -= fd1 * delta
        # differentials sorted by rank (decreasing), then barycentric weights:
        # the coordinate ranked m adds to vertex d - m, removes from d + 1 - m
        for m in range(d1):
            sm = sorted_v[m]
            fm = np.float32(m)
            sm[:] = 0.0
            for i in range(d1):
                ri = rank[i]
                di = diff[i]
                for t in range(cols):
                    sm[t] += np.float32(ri[t] == fm) * di[t]
        for t in range(cols):
            p = p0 + t
            bw[p, 0] = one + (sorted_v[d, t] - sorted_v[0, t]) * inv
            for k in range(1, d1):
                bw[p, k] = (sorted_v[d - k, t] - sorted_v[d + 1 - k, t]) * inv
        # vertex keys: vertex k adds k to every coordinate, minus d + 1 on the
        # coordinates ranked above d - k; keys are linear in the coordinates
        for t in range(cols):
            base[t] = key0
        for i in range(d):
            si = step[i]
            qi = quot[i]
            for t in range(cols):
                base[t] += np.int64(qi[t]) * si
        for k in range(d1):
            kk = key[k]
            thr = np.float32(d - k)
            off = k * psum
            for t in range(cols):
                kk[t] = base[t] + off
            for i in range(d):
                ri = rank[i]
                si = step[i]
                for t in range(cols):
                    if ri[t] > thr:
                        kk[t] -= si
        # a vertex the left, upper, upper-left or upper-right neighbour
        # also has takes its index from there (``back``: how many texels
        # back); the others (``fresh``) need the hash table
        for k in range(d1):
            kk = key[k]
            ku = key_up[k]
            bk = back[k]
            bk[0] = 0
            if lr == 0:
                for t in range(1, cols):
                    bk[t] = 1 if kk[t] == kk[t - 1] else 0
                continue
            bk[0] = cols if kk[0] == ku[0] else (cols - 1 if kk[0] == ku[min(1, cols - 1)] else 0)
            for t in range(1, cols - 1):
                kt = kk[t]
                b = cols - 1 if kt == ku[t + 1] else 0
                b = cols + 1 if kt == ku[t - 1] else b
                b = cols if kt == ku[t] else b
                bk[t] = 1 if kt == kk[t - 1] else b
            if cols > 1:
                t = cols - 1
                kt = kk[t]
                b = cols + 1 if kt == ku[t - 1] else 0
                b = cols if kt == ku[t] else b
                bk[t] = 1 if kt == kk[t - 1] else b
        n = 0
        for t in range(cols):
            for k in range(d1):
                fresh_key[n] = key[k, t]
                fresh_at[n] = (p0 + t) * d1 + k
                n += back[k, t] == 0
        # look them all up (mostly branch-free), then insert the missing ones
        missing = 0
        for m in range(n):
            j = _find_fast(fresh_key[m], table, keys, shift, mask)
            found[m] = j
            lost[missing] = m
            missing += j < 0
        for i in range(missing):
            m = lost[i]
            j = _insert(fresh_key[m], table, keys, count, shift, mask)
            found[m] = j
            count += j == count
            if _LOAD * count >= capacity:
                # keep the load factor low: most probes end at the first slot
                table, keys = _grow(table, keys, count)
                capacity = table.shape[0]
                mask = capacity - 1
                shift = 64 - _log2(capacity)
        for m in range(n):
            flat_idx[fresh_at[m]] = found[m]
        for t in range(cols):
            p = p0 + t
            for k in range(d1):
                idx[p, k] = idx[p - back[k, t], k]
        key, key_up = key_up, key
    return count, table, keys


@njit(cache=True, nogil=True)
def neighbours(count, keys, table, primes, lo, hi):
    """The lattice's neighbouring pairs along each direction, found once per tile.

    Pairs ``(lo[i], hi[i])`` for ``i`` in ``start[axis]:start[axis + 1]``
    have ``hi`` one step along ``axis`` from ``lo``. Returns ``(start, lo,
    hi)``, the pair arrays replaced when they had to grow. The lookups go in
    chunks whose table slots are touched first, so cache misses overlap.
    """
    d = primes.shape[0]
    d1 = d + 1
    capacity = table.shape[0]
    mask = capacity - 1
    shift = 64 - _log2(capacity)
    psum = np.int64(0)
    for i in range(d):
        psum += primes[i]
    start = np.empty(d1 + 1, dtype=np.int64)
    chunk = 2048
    touched = 0
    n = 0
    for axis in range(d1):
        start[axis] = n
        # neighbour along ``axis``: -1 on every coordinate, +d+1 on ``axis``
        off = -psum
        if axis < d:
            off += d1 * primes[axis]
        for first in range(0, count, chunk):
            last = min(first + chunk, count)
            if n + (last - first) > lo.shape[0]:
                bigger = max(2 * lo.shape[0], n + count)
                lo2 = np.empty(bigger, dtype=np.int32)
                hi2 = np.empty(bigger, dtype=np.int32)
                lo2[:n] = lo[:n]
                hi2[:n] = hi[:n]
                lo, hi = lo2, hi2
            for j in range(first, last):
                touched += table[_slot(keys[j] + off, shift, mask)]
            for j in range(first, last):
                a = _find_fast(keys[j] + off, table, keys, shift, mask)
                lo[n] = j
                hi[n] = a
                n += a >= 0
    start[d1] = n
    if touched == -(1 << 62):  # keep the touching loop alive
        start[0] = 0
    return start, lo, hi


@njit(cache=True, nogil=True)
def _splat(image, first, width, top, left, rows, cols, wrap, idx, bw, vals, count):
    """Accumulate channels ``first:first + width`` and a 1, times the weights, on the vertices.

    ``vals`` rows hold ``_LANES`` floats: the channels, the homogeneous
    weight at ``width``, zeros after. (The loops run over explicitly bounded
    1-D slices, which LLVM vectorises; indexing the 2-D arrays stays scalar.)
    """
    height, image_width, _ = image.shape
    d1 = idx.shape[1]
    vals[:count] = 0.0
    p = 0
    for lr in range(rows):
        sr = _source(top + lr, height, wrap)
        for lc in range(cols):
            sc = _source(left + lc, image_width, wrap)
            src = image[sr, sc, first : first + width]
            for k in range(d1):
                j = idx[p, k]
                w = bw[p, k]
                row = vals[j, :width]
                for ch in range(width):
                    row[ch] += w * src[ch]
                vals[j, width] += w
            p += 1


@njit(cache=True, nogil=True)
def _blur(vals, tmp, count, start, lo, hi, passes):
    """[1 2 1] / 4 along each lattice direction; returns ``(result, spare)``.

    The kernel is symmetric, so each neighbouring pair (from
    :func:`neighbours`) gives each end a quarter of the other.
    """
    d1 = start.shape[0] - 1
    for _ in range(passes):
        for axis in range(d1):
            for j in range(count):
                src = vals[j]
                dst = tmp[j]
                for ch in range(_LANES):
                    dst[ch] = 0.5 * src[ch]
            for i in range(start[axis], start[axis + 1]):
                j = lo[i]
                a = hi[i]
                src_j = vals[j]
                src_a = vals[a]
                dst_j = tmp[j]
                dst_a = tmp[a]
                for ch in range(_LANES):
                    # (float64 constants: measurably faster code than float32 here)
                    dst_j[ch] += 0.25 * src_a[ch]
                    dst_a[ch] += 0.25 * src_j[ch]
            vals, tmp = tmp, vals
    return vals, tmp


@njit(cache=True, nogil=True)
def _slice(image, out, first, width, row0, row1, col0, col1, margin, cols, idx, bw, vals):
    """Interpolate the blurred lattice at the core texels and normalise."""
    d1 = idx.shape[1]
    acc = np.empty(_LANES, dtype=np.float32)
    for r in range(row0, row1):
        p = (r - row0 + margin) * cols + margin
        for c in range(col0, col1):
            for ch in range(_LANES):
                acc[ch] = 0.0
            for k in range(d1):
                j = idx[p, k]
                w = bw[p, k]
                row = vals[j]
                for ch in range(_LANES):
                    acc[ch] += w * row[ch]
            norm = acc[width]
            dst = out[r, c, first : first + width]
            if norm > 0:
                inv = 1.0 / norm
                for ch in range(width):
                    dst[ch] = acc[ch] * inv
            else:
                dst[:] = image[r, c, first : first + width]
            p += 1


@njit(cache=True, nogil=True)
def filter_tiles(
    image,
    feat,
    used,
    lift0,
    lift_r,
    lift_c,
    lift_g,
    out,
    tile,
    margin,
    wrap,
    passes,
    primes,
    worker,
    workers,
    counts,
):
    """Gaussian-filter tiles ``worker, worker + workers, ...`` of ``image`` into ``out``.

    ``image`` is (H, W, C); a texel's lattice position is ``lift0 + row
    lift_r + col lift_c + feat[row, col, used] @ lift_g`` (see
    :func:`locate`). Tiles are ``tile`` x ``tile`` texels (row-major), each
    read with ``margin`` more texels around it; the buffers are reused from
    tile to tile. ``counts[t]`` receives tile t's number of lattice points.
    The GIL is released, so several workers run in parallel threads. Wide
    images go through the lattice ``_CHANNELS`` channels at a time (plus the
    homogeneous 1), so a tile's lattice values stay cache-sized; the lattice
    itself and its neighbour pairs are built once per tile.
    """
    height, width, channels = image.shape
    d1 = lift0.shape[0]
    group = min(channels, _CHANNELS)
    tiles_y = (height + tile - 1) // tile
    tiles_x = (width + tile - 1) // tile
    ntiles = tiles_y * tiles_x
    side = tile + 2 * margin
    idx = np.empty((side * side, d1), dtype=np.int32)
    bw = np.empty((side * side, d1), dtype=np.float32)
    table = np.empty(1 << 14, dtype=np.int64)
    keys = np.empty(1 << 13, dtype=np.int64)
    lo = np.empty(1 << 16, dtype=np.int32)
    hi = np.empty(1 << 16, dtype=np.int32)
    vals = np.empty((0, _LANES), dtype=np.float32)
    tmp = np.empty((0, _LANES), dtype=np.float32)
    for t in range(worker, ntiles, workers):
        ty = t // tiles_x
        tx = t - ty * tiles_x
        row0 = ty * tile
        col0 = tx * tile
        row1 = min(row0 + tile, height)
        col1 = min(col0 + tile, width)
        top = row0 - margin
        left = col0 - margin
        rows = row1 - row0 + 2 * margin
        cols = col1 - col0 + 2 * margin
        count, table, keys = locate(
            feat,
            used,
            top,
            left,
            rows,
            cols,
            wrap,
            lift0,
            lift_r,
            lift_c,
            lift_g,
            primes,
            idx,
            bw,
            table,
            keys,
        )
        counts[t] = count
        start, lo, hi = neighbours(count, keys, table, primes, lo, hi)
        if count > vals.shape[0]:
            vals = np.empty((count + count // 4, _LANES), dtype=np.float32)
            tmp = np.empty((count + count // 4, _LANES), dtype=np.float32)
        for first in range(0, channels, group):
            n = min(group, channels - first)
            _splat(image, first, n, top, left, rows, cols, wrap, idx, bw, vals, count)
            result, _ = _blur(vals, tmp, count, start, lo, hi, passes)
            _slice(image, out, first, n, row0, row1, col0, col1, margin, cols, idx, bw, result)
