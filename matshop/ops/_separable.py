"""Separable bilateral kernels (numba): a 1-D bilateral along rows, then along columns.

Pham and van Vliet (2005), "Separable bilateral filtering for fast video
preprocessing": the 2-D bilateral is approximated by a 1-D one along each row
followed by a 1-D one along each column of the result. Both passes weigh
neighbours by the range distance of the *original* guide (a joint filter), which
measured closer to the exact 2-D filter on real crops than re-guiding the second
pass by the first's output. The approximation is exact where the guide varies
along one axis only (axis-aligned edges, smooth gradients); on oblique edges a
neighbour reached through a texel of another material is still counted.

Layout: the image is cut into tiles, each filtered down its rows with the row
pass one window ahead of the column pass (ring buffers of the last
``2 radius + 1`` rows, no intermediate image). Within a tile, a row's channels
and guide features are planar, ``(channel, column)``, so that every inner loop
runs along contiguous floats (vectorised by LLVM). The range weight of a pair
of texels is the same for both (``w(x, x + t) = w(x + t, x)``), so each pair is
weighed once: per row, the weights with the ``radius`` texels to its right;
per row of the column pass, those with the ``radius`` rows above it. The sums
take four taps and two channels per sweep along the columns (see
:func:`_sweep4`); the weight sum is one more channel (of ones).
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit

#: every kernel: no zero-division checks (a weight sum includes the texel's own
#: weight, 1), and fused multiply-adds (measured ~4 % faster, and no less exact)
_FLAGS = {"error_model": "numpy", "fastmath": {"contract"}}
#: exp(-q) is evaluated as (1 - q / 2^n)^(2^n) (n squarings, vectorisable without
#: a vector exp): absolute error below e^-q q^2 / 2^(n+1), at most 2.6e-4 for n = 10
_SQUARINGS = 10
_INV_POWER = 1.0 / (1 << _SQUARINGS)
#: exp(-q) is taken as 0 from here on (e^-40 = 4e-18 of the centre tap's weight):
#: the squarings would otherwise pass through subnormal floats, ~100 times slower
_CUTOFF = 40.0
#: tile size in texels: columns (the rows of the column pass's window, 2 radius + 1
#: rows of (channels + guide) x this floats, stay in the second-level cache) and
#: rows (each tile recomputes the row pass on 2 radius rows above and below it)
TILE_COLUMNS = 512
TILE_ROWS = 512


@njit(cache=True, nogil=True, **_FLAGS, inline="always")
def _exp_neg(q):
    """exp(-q) for q >= 0 to within 2.6e-4 absolute (see ``_SQUARINGS``), 0 past ``_CUTOFF``."""
    base = np.float32(1.0) - q * np.float32(_INV_POWER)
    base = base if q < np.float32(_CUTOFF) else np.float32(0.0)
    # written out: a loop here keeps LLVM from vectorising the loop around it
    base *= base
    base *= base
    base *= base
    base *= base
    base *= base
    base *= base
    base *= base
    base *= base
    base *= base
    base *= base
    return base


@njit(cache=True, nogil=True, **_FLAGS)
def _fill(src, y, x0, radius, wrap, pad):
    """Columns ``x0 - radius ...`` of row ``y`` of ``src`` (H, W, C), planar into ``pad``.

    ``pad`` is (>= C, span); texels beyond the image are read through the
    border. Returns whether every value read is finite (``v - v`` is 0 only
    for finite ``v``): the filter's finiteness check rides on its one read of
    the image instead of a serial pass of its own (every texel is read inside
    the image by the tile that holds it; the border reads need no check).
    """
    width, channels = src.shape[1], src.shape[2]
    span = pad.shape[1]
    inside0 = min(max(radius - x0, 0), span)
    inside1 = max(min(width - x0 + radius, span), inside0)
    # texel by texel (reads along the image row; 1.5 of 20 ms per tile faster
    # than channel by channel), then the check over the planar rows (vectorised)
    first = np.uint64(x0 - radius + inside0)
    for j in range(inside1 - inside0):
        x = first + np.uint64(j)
        for c in range(channels):
            pad[c, inside0 + j] = src[y, x, c]
    finite = True
    start = np.uint64(inside0)
    for c in range(channels):
        for j in range(inside1 - inside0):
            v = pad[c, start + np.uint64(j)]
            finite &= v - v == 0.0
    for j in range(span):
        if inside0 <= j < inside1:
            continue
        x = x0 - radius + j
        x = x % width if wrap else min(max(x, 0), width - 1)
        for c in range(channels):
            pad[c, j] = src[y, x, c]
    return finite


@njit(cache=True, nogil=True, **_FLAGS, inline="always")
def _range_weight(spatial_w, dist):
    return spatial_w * _exp_neg(np.float32(0.5) * dist)


@njit(cache=True, nogil=True, **_FLAGS)
def _pairs(feat, sa, oa, sb, ob, count, spatial_w, out, so, row, dist):
    """``out[so, row, j] = spatial_w exp(-|f(sa, j + oa) - f(sb, j + ob)|^2 / 2)``, j < count.

    ``f(s, i) = feat[s, :, i]`` (features planar: (slots, dims, columns)).
    Guides of up to three dimensions take one pass over the columns (the
    distance stays in a register); wider ones add up ``dist`` (>= count) one
    dimension at a time.
    """
    dims = feat.shape[1]
    ua, ub = np.uint64(oa), np.uint64(ob)
    if dims == 1:
        for j in range(count):
            u = np.uint64(j)
            d0 = feat[sa, 0, u + ua] - feat[sb, 0, u + ub]
            out[so, row, j] = _range_weight(spatial_w, d0 * d0)
    elif dims == 2:
        for j in range(count):
            u = np.uint64(j)
            d0 = feat[sa, 0, u + ua] - feat[sb, 0, u + ub]
            d1 = feat[sa, 1, u + ua] - feat[sb, 1, u + ub]
            out[so, row, j] = _range_weight(spatial_w, d0 * d0 + d1 * d1)
    elif dims == 3:
        for j in range(count):
            u = np.uint64(j)
            d0 = feat[sa, 0, u + ua] - feat[sb, 0, u + ub]
            d1 = feat[sa, 1, u + ua] - feat[sb, 1, u + ub]
            d2 = feat[sa, 2, u + ua] - feat[sb, 2, u + ub]
            out[so, row, j] = _range_weight(spatial_w, d0 * d0 + d1 * d1 + d2 * d2)
    else:
        for j in range(count):
            dist[j] = 0.0
        for k in range(dims):
            for j in range(count):
                u = np.uint64(j)
                d0 = feat[sa, k, u + ua] - feat[sb, k, u + ub]
                dist[j] += d0 * d0
        for j in range(count):
            out[so, row, j] = _range_weight(spatial_w, dist[j])


# The sums ``acc[c, x] = sum_t w_t(x) v_t(c, x)``: tap t's weight is
# ``weights[tab[t, 0], tab[t, 1], x + tab[t, 2]]`` and its value
# ``values[tab[t, 3], c, x + tab[t, 4]]``. One sweep along the columns takes four
# taps and two channels at once, so each weight is loaded once per two channels
# and each sum loaded and stored once per four taps (one tap and channel per
# sweep was load/store bound: three loads and a store per multiply-add; this is
# 0.054 against 0.077 ns per tap, texel and channel). Column indices are
# unsigned so that numba does not wrap them (a select per element, or a gather).
# An odd channel out takes sweeps of its own: a pair sweep naming one row twice
# ran scalar (LLVM's overlap check fails), 3x slower; a row of zeros to pair it
# with cost 0.7 of 17 ms per tile more than these.


@njit(cache=True, nogil=True, **_FLAGS, inline="always")
def _tap(tab, t):
    """Tap ``t`` of a table: weight slot, row, offset, value slot, offset (offsets unsigned)."""
    return tab[t, 0], tab[t, 1], np.uint64(tab[t, 2]), tab[t, 3], np.uint64(tab[t, 4])


@njit(cache=True, nogil=True, **_FLAGS)
def _sweep4(acc, c, weights, values, tab, t, n, init):
    """Taps ``t .. t + 3`` into channels ``c`` and ``c + 1`` over ``n`` columns."""
    a0, b0, o0, m0, p0 = _tap(tab, t)
    a1, b1, o1, m1, p1 = _tap(tab, t + 1)
    a2, b2, o2, m2, p2 = _tap(tab, t + 2)
    a3, b3, o3, m3, p3 = _tap(tab, t + 3)
    c1 = c + 1
    for x in range(n):
        u = np.uint64(x)
        w0 = weights[a0, b0, u + o0]
        w1 = weights[a1, b1, u + o1]
        w2 = weights[a2, b2, u + o2]
        w3 = weights[a3, b3, u + o3]
        s0 = w0 * values[m0, c, u + p0] + w1 * values[m1, c, u + p1]
        s0 += w2 * values[m2, c, u + p2] + w3 * values[m3, c, u + p3]
        s1 = w0 * values[m0, c1, u + p0] + w1 * values[m1, c1, u + p1]
        s1 += w2 * values[m2, c1, u + p2] + w3 * values[m3, c1, u + p3]
        if not init:
            s0 += acc[c, x]
            s1 += acc[c1, x]
        acc[c, x] = s0
        acc[c1, x] = s1


@njit(cache=True, nogil=True, **_FLAGS)
def _sweep4_one(acc, c, weights, values, tab, t, n, init):
    """Taps ``t .. t + 3`` into channel ``c`` alone (the last of an odd count)."""
    a0, b0, o0, m0, p0 = _tap(tab, t)
    a1, b1, o1, m1, p1 = _tap(tab, t + 1)
    a2, b2, o2, m2, p2 = _tap(tab, t + 2)
    a3, b3, o3, m3, p3 = _tap(tab, t + 3)
    for x in range(n):
        u = np.uint64(x)
        w0 = weights[a0, b0, u + o0]
        w1 = weights[a1, b1, u + o1]
        w2 = weights[a2, b2, u + o2]
        w3 = weights[a3, b3, u + o3]
        # the pair sweep's expression exactly: a channel's result must not depend on
        # whether it was paired (keep_variance adds channels and asserts bit equality)
        s0 = w0 * values[m0, c, u + p0] + w1 * values[m1, c, u + p1]
        s0 += w2 * values[m2, c, u + p2] + w3 * values[m3, c, u + p3]
        if not init:
            s0 += acc[c, x]
        acc[c, x] = s0


@njit(cache=True, nogil=True, **_FLAGS)
def _sweep1_one(acc, c, weights, values, tab, t, n, init):
    """Tap ``t`` into channel ``c`` alone."""
    a0, b0, o0, m0, p0 = _tap(tab, t)
    for x in range(n):
        u = np.uint64(x)
        s0 = weights[a0, b0, u + o0] * values[m0, c, u + p0]
        if not init:
            s0 += acc[c, x]
        acc[c, x] = s0


@njit(cache=True, nogil=True, **_FLAGS)
def _sweep1(acc, c, weights, values, tab, t, n, init):
    """Tap ``t`` into channels ``c`` and ``c + 1`` over ``n`` columns."""
    a0, b0, o0, m0, p0 = _tap(tab, t)
    c1 = c + 1
    for x in range(n):
        u = np.uint64(x)
        w0 = weights[a0, b0, u + o0]
        s0 = w0 * values[m0, c, u + p0]
        s1 = w0 * values[m0, c1, u + p0]
        if not init:
            s0 += acc[c, x]
            s1 += acc[c1, x]
        acc[c, x] = s0
        acc[c1, x] = s1


@njit(cache=True, nogil=True, **_FLAGS)
def _accumulate(acc, weights, values, tab, n):
    """``acc[c, :n] = sum_t w_t v_t(c)`` for every channel of ``acc`` (see the sweeps)."""
    taps = tab.shape[0]
    rows = acc.shape[0]
    for c in range(0, rows - 1, 2):
        t = 0
        while t + 4 <= taps:
            _sweep4(acc, c, weights, values, tab, t, n, t == 0)
            t += 4
        while t < taps:
            _sweep1(acc, c, weights, values, tab, t, n, t == 0)
            t += 1
    if rows % 2:
        t = 0
        while t + 4 <= taps:
            _sweep4_one(acc, rows - 1, weights, values, tab, t, n, t == 0)
            t += 4
        while t < taps:
            _sweep1_one(acc, rows - 1, weights, values, tab, t, n, t == 0)
            t += 1


@njit(cache=True, nogil=True, **_FLAGS)
def _row(src, y, x0, used, mix, offset, spatial, wrap, pad, gpad, pairs, tab, dist, feat, mid):
    """1-D bilateral along row ``y`` of ``src`` for the ``n`` columns from ``x0``.

    Writes the range features ``feat[k, x] = sum_u src[y, x0 + x, used[u]] mix[u, k]
    - offset[k]`` (K, n) and the filtered channels ``mid[c, x]`` (C + 1, n) with
    ``mid[C] = 1`` (the column pass's weight sum rides along as a channel).
    ``pad`` (C + 1, span) with ``pad[C] = 1``, ``gpad`` (1, K, span), ``pairs``
    (1, radius + 1, span) with ``pairs[0, 0] = 1``, ``dist`` (span): work space;
    ``tab``: the row pass's taps (:func:`_row_taps`). Returns whether the row is finite.
    """
    dims, n = feat.shape
    channels = src.shape[2]
    radius = spatial.shape[0] // 2
    span = n + 2 * radius
    finite = _fill(src, y, x0, radius, wrap, pad)
    for k in range(dims):
        g = gpad[0, k]
        g[:] = -offset[k]
        for u in range(used.shape[0]):
            _scaled_add(g, mix[u, k], pad[used[u]])
        feat[k, :] = g[radius : radius + n]
    # each pair of texels d apart is weighed once, for both of its taps
    for d in range(1, radius + 1):
        _pairs(gpad, 0, 0, 0, d, span - d, spatial[radius + d], pairs, 0, d, dist)
    _accumulate(mid, pairs, pad.reshape(1, pad.shape[0], span), tab, n)
    # channel by channel (vectorised): texel by texel was 0.9 of 18 ms per tile
    for x in range(n):
        dist[x] = np.float32(1.0) / mid[channels, x]
    for c in range(channels):
        for x in range(n):
            mid[c, x] *= dist[x]
    for x in range(n):
        mid[channels, x] = 1.0
    return finite


@njit(cache=True, nogil=True, **_FLAGS)
def _scaled_add(acc, scale, values):
    """``acc += scale values`` element-wise (1-D views)."""
    for x in range(acc.shape[0]):
        acc[x] += scale * values[x]


@njit(cache=True, nogil=True, **_FLAGS)
def _row_taps(radius):
    """The row pass's taps: tap ``e`` of column x weighs ``pairs[0, |e|, x + radius + min(e, 0)]``.

    (The weight of the pair of padded columns ``x + radius`` and ``x + radius + e``.)
    """
    taps = 2 * radius + 1
    tab = np.zeros((taps, 5), dtype=np.int64)
    for t in range(taps):
        e = t - radius
        tab[t, 1] = abs(e)
        tab[t, 2] = radius + min(e, 0)
        tab[t, 4] = t
    return tab


@njit(cache=True, nogil=True, **_FLAGS)
def filter_tile(src, used, mix, offset, spatial, wrap, out, row0, row1, x0, x1):
    """The separable bilateral of ``src`` (H, W, C) for rows ``row0:row1``, columns ``x0:x1``.

    The row pass runs a row ahead of the column pass, down the tile, into ring
    buffers of the last ``2 radius + 1`` rows (filtered channels, range
    features, and the range weights of each row with the ``radius`` rows above
    it), so no intermediate image is stored. Rows beyond the image are read
    through the border like columns. Returns whether every texel read is finite.
    """
    height, width, channels = src.shape
    dims = mix.shape[1]
    taps = spatial.shape[0]
    radius = taps // 2
    n = x1 - x0
    span = n + 2 * radius
    rows = channels + 1  # and the weight sum
    ring_mid = np.empty((taps, rows, n), dtype=np.float32)
    ring_feat = np.empty((taps, dims, n), dtype=np.float32)
    ring_pairs = np.empty((taps, radius + 1, n), dtype=np.float32)
    ring_pairs[:, 0] = 1.0
    pad = np.empty((rows, span), dtype=np.float32)
    pad[channels] = 1.0
    gpad = np.empty((1, dims, span), dtype=np.float32)
    pairs = np.empty((1, radius + 1, span), dtype=np.float32)
    pairs[0, 0] = 1.0
    dist = np.empty(span, dtype=np.float32)
    acc = np.empty((rows, n), dtype=np.float32)
    row_tab = _row_taps(radius)
    col_tab = np.zeros((taps, 5), dtype=np.int64)
    finite = True
    for r in range(row0 - radius, row1 + radius):
        slot = (r - row0 + radius) % taps
        y = r % height if wrap else min(max(r, 0), height - 1)
        finite &= _row(
            src,
            y,
            x0,
            used,
            mix,
            offset,
            spatial,
            wrap,
            pad,
            gpad,
            pairs,
            row_tab,
            dist,
            ring_feat[slot],
            ring_mid[slot],
        )
        # the range weights of row r with the rows above it that a later output row needs
        for d in range(1, min(radius, r - row0 + radius) + 1):
            _pairs(
                ring_feat,
                slot,
                0,
                (slot - d) % taps,
                0,
                n,
                spatial[radius + d],
                ring_pairs,
                slot,
                d,
                dist,
            )
        centre = r - radius  # the output row whose window ends at r
        if centre < row0:
            continue
        mine = (centre - row0 + radius) % taps
        for t in range(taps):
            e = t - radius
            other = (mine + e) % taps
            col_tab[t, 0] = mine if e <= 0 else other
            col_tab[t, 1] = abs(e)
            col_tab[t, 3] = other
        _accumulate(acc, ring_pairs, ring_mid, col_tab, n)
        for x in range(n):
            inv = np.float32(1.0) / acc[channels, x]
            for c in range(channels):
                out[centre, x0 + x, c] = acc[c, x] * inv
    return finite


@njit(cache=True, nogil=True, **_FLAGS)
def filter_tiles(src, used, mix, offset, spatial, wrap, out, start, step):
    """Tiles ``start, start + step, ...`` (row-major, ``TILE_ROWS`` x ``TILE_COLUMNS``).

    Returns whether every texel they read is finite.
    """
    height, width, _ = src.shape
    across = (width + TILE_COLUMNS - 1) // TILE_COLUMNS
    down = (height + TILE_ROWS - 1) // TILE_ROWS
    finite = True
    for tile in range(start, across * down, step):
        row0 = (tile // across) * TILE_ROWS
        x0 = (tile % across) * TILE_COLUMNS
        finite &= filter_tile(
            src,
            used,
            mix,
            offset,
            spatial,
            wrap,
            out,
            row0,
            min(row0 + TILE_ROWS, height),
            x0,
            min(x0 + TILE_COLUMNS, width),
        )
    return finite


def run_separable(
    src: np.ndarray,
    used: np.ndarray,
    mix: np.ndarray,
    offset: np.ndarray,
    sigma_s: float,
    wrap: bool,
    workers: int,
    out: np.ndarray | None = None,
) -> tuple[np.ndarray, bool]:
    """Separable bilateral of ``src`` (H, W, C) float32, each pass cut at ``ceil(3 sigma_s)``.

    Range features ``src[..., used] @ mix - offset`` (already over the range
    sigma). Tiles are taken one at a time by ``workers`` threads (the kernels
    release the GIL): a thread the system holds back leaves its tiles to the
    others instead of delaying the end (dealt round-robin, a loaded machine
    waited on the last thread). Writes into ``out`` (like ``src``) when given.
    Returns the filtered image and whether ``src`` is finite (the image is not
    valid when it is not).
    """
    height, width, _ = src.shape
    radius = math.ceil(3 * sigma_s)
    taps = np.arange(-radius, radius + 1, dtype=np.float64)
    spatial = np.exp(-(taps**2) / (2 * sigma_s**2)).astype(np.float32)
    args = (
        src,
        np.ascontiguousarray(used, dtype=np.int64),
        np.ascontiguousarray(mix, dtype=np.float32),
        np.ascontiguousarray(offset, dtype=np.float32),
        spatial,
        wrap,
        np.empty_like(src) if out is None else out,
    )
    tiles = -(-height // TILE_ROWS) * -(-width // TILE_COLUMNS)
    workers = max(1, min(workers, tiles))
    if workers == 1:
        return args[-1], filter_tiles(*args, 0, 1)
    jobs = [_pool(workers).submit(filter_tiles, *args, tile, tiles) for tile in range(tiles)]
    return args[-1], all([job.result() for job in jobs])


_POOLS: dict[int, ThreadPoolExecutor] = {}


def _pool(workers: int) -> ThreadPoolExecutor:
    """A lasting pool of ``workers`` threads: starting threads per call cost ~7 ms of ~300."""
    pool = _POOLS.get(workers)
    if pool is None:
        pool = _POOLS.setdefault(
            workers, ThreadPoolExecutor(max_workers=workers, thread_name_prefix="matshop-separable")
        )
    return pool
