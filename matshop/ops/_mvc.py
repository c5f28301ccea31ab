"""numba kernels behind :mod:`matshop.ops.clone` (mean-value seamless cloning).

Polygon rasterization, the boundary hierarchy and its hierarchical
mean-value weights, the adaptive mesh layout, triangle rasterization
(pixel -> triangle + barycentric weights), a parallel CSR x dense product
and the fused "copy the target, paste source + interpolated membrane" pass.
The math is described in ``clone.py``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..parallel_chunks import next_chunk

# ---------------------------------------------------------------- polygon -> mask


@njit(cache=True, nogil=True)
def rasterize_polygon(xs, ys, height, width):
    """Pixels whose centre lies inside or on the closed polygon (even-odd rule).

    Pixel (row, col) has its centre at (x=col, y=row). Interior by scanline
    crossings (half-open in y so a vertex is counted once); pixels whose
    centre lies on an edge (within 1e-9 px) are added by walking every edge,
    so the rasterization is the closed polygon and a polygon along pixel
    centres (a rectangle, a diamond) covers the same pixels as its mask.
    """
    mask = np.zeros((height, width), dtype=np.bool_)
    n = xs.shape[0]
    eps = 1e-9
    ymin = max(0, int(math.ceil(ys.min() - eps)))
    ymax = min(height - 1, int(math.floor(ys.max() + eps)))
    crossings = np.empty(n, dtype=np.float64)
    for row in range(ymin, ymax + 1):
        y = float(row)
        count = 0
        for i in range(n):
            x0, y0 = xs[i], ys[i]
            x1, y1 = xs[(i + 1) % n], ys[(i + 1) % n]
            if (y0 <= y < y1) or (y1 <= y < y0):
                crossings[count] = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
                count += 1
        for k in range(1, count):  # insertion sort: a handful of crossings
            v = crossings[k]
            i = k - 1
            while i >= 0 and crossings[i] > v:
                crossings[i + 1] = crossings[i]
                i -= 1
            crossings[i + 1] = v
        c = crossings
        for k in range(0, count - 1, 2):
            lo = max(0, int(math.ceil(c[k] - eps)))
            hi = min(width - 1, int(math.floor(c[k + 1] + eps)))
            for col in range(lo, hi + 1):
                mask[row, col] = True
    # centres on an edge: walk the edge along its longer axis
    for i in range(n):
        x0, y0 = xs[i], ys[i]
        x1, y1 = xs[(i + 1) % n], ys[(i + 1) % n]
        if abs(x1 - x0) >= abs(y1 - y0):
            lo, hi = (x0, x1) if x0 <= x1 else (x1, x0)
            for col in range(max(0, int(math.ceil(lo - eps))), min(width - 1, int(hi + eps)) + 1):
                y = y0 if x1 == x0 else y0 + (col - x0) * (y1 - y0) / (x1 - x0)
                row = int(round(y))
                if abs(y - row) <= eps and 0 <= row < height:
                    mask[row, col] = True
        else:
            lo, hi = (y0, y1) if y0 <= y1 else (y1, y0)
            for row in range(max(0, int(math.ceil(lo - eps))), min(height - 1, int(hi + eps)) + 1):
                x = x0 + (row - y0) * (x1 - x0) / (y1 - y0)
                col = int(round(x))
                if abs(x - col) <= eps and 0 <= col < width:
                    mask[row, col] = True
    return mask


# ---------------------------------------------------------------- boundary hierarchy


@njit(cache=True, nogil=True)
def hierarchy_nodes(bx, by, levels):
    """Per level k, nodes at boundary indices j * 2**k; per edge (k, j) a bounding circle.

    Edge (k, j) runs from node j to node j + 1 (the last one back to index 0)
    and covers the boundary pixels between them. Returns the node offsets per
    level, each node's boundary index, and the centre and radius of a circle
    holding every boundary pixel its outgoing edge covers.
    """
    n = bx.shape[0]
    offsets = np.zeros(levels + 2, dtype=np.int64)
    for k in range(levels + 1):
        step = 1 << k
        offsets[k + 1] = offsets[k] + (n + step - 1) // step
    total = offsets[levels + 1]
    index = np.empty(total, dtype=np.int64)
    cx = np.empty(total, dtype=np.float64)
    cy = np.empty(total, dtype=np.float64)
    radius = np.empty(total, dtype=np.float64)
    for k in range(levels + 1):
        step = 1 << k
        m = offsets[k + 1] - offsets[k]
        for j in range(m):
            a = j * step
            b = min(a + step, n)
            sx = 0.0
            sy = 0.0
            for i in range(a, b + 1):
                sx += bx[i % n]
                sy += by[i % n]
            sx /= b - a + 1
            sy /= b - a + 1
            r = 0.0
            for i in range(a, b + 1):
                d = math.hypot(bx[i % n] - sx, by[i % n] - sy)
                r = max(r, d)
            node = offsets[k] + j
            index[node] = a
            cx[node] = sx
            cy[node] = sy
            radius[node] = r
    return offsets, index, cx, cy, radius


@njit(cache=True, nogil=True)
def edge_moment_entries(bx, by, offsets, index):
    """Moments of the boundary values over each coarse edge (levels >= 1), as COO rows.

    Coarse edge c = (k, j) covers boundary indices a..b (t = (i - a) / (b - a));
    its rows ``3 c + q`` hold ``M_q = sum_i c_i t_i**q f_i`` for q = 0, 1, 2 with
    the trapezoid factor c_i = 1/2 at both ends (an end pixel is shared with
    the neighbouring edge). A far point weighs the edge's pixels by a
    quadratic density in t (``_far_edge``), i.e. by a combination of these
    three moments. Also returns the same moments of f = 1.
    """
    n = bx.shape[0]
    levels = offsets.shape[0] - 2
    first_coarse = offsets[1]
    n_coarse = offsets[levels + 1] - first_coarse
    count = 0
    for k in range(1, levels + 1):
        m = offsets[k + 1] - offsets[k]
        count += 3 * m * ((1 << k) + 1)
    rows = np.empty(count, dtype=np.int64)
    cols = np.empty(count, dtype=np.int64)
    vals = np.empty(count, dtype=np.float64)
    ones = np.zeros((n_coarse, 3), dtype=np.float64)
    pos = 0
    for k in range(1, levels + 1):
        first = offsets[k]
        m = offsets[k + 1] - first
        for j in range(m):
            e = first + j
            ce = e - first_coarse
            a = index[e]
            b = a + (1 << k) if j < m - 1 else n
            span = b - a
            for i in range(a, b + 1):
                c = 0.5 if (i == a or i == b) else 1.0
                t = (i - a) / span
                v = c
                for q in range(3):
                    rows[pos] = 3 * ce + q
                    cols[pos] = i % n
                    vals[pos] = v
                    ones[ce, q] += v
                    pos += 1
                    v *= t
    return rows[:pos], cols[:pos], vals[:pos], ones


@njit(cache=True, inline="always", nogil=True)
def _edge_weight(x, y, ax, ay, bx_, by_):
    """tan(alpha/2) / |a - x| and tan(alpha/2) / |b - x| for the edge a -> b seen from x."""
    dax = ax - x
    day = ay - y
    dbx = bx_ - x
    dby = by_ - y
    ra = math.sqrt(dax * dax + day * day)
    rb = math.sqrt(dbx * dbx + dby * dby)
    cross = dax * dby - day * dbx
    dot = dax * dbx + day * dby
    # tan(alpha/2) = sin / (1 + cos); stable for every angle but pi (x on the edge)
    t = cross / (ra * rb + dot)
    return t / ra, t / rb


@njit(cache=True, nogil=True)
def far_edge_geometry(bx, by, offsets, index):
    """Per coarse edge: its two end pixels and middle pixel with their tangents, and the
    map from the density at those three pixels to the coefficients of ``1, t, t**2``.

    The edge's pixels are modelled by the parabola through the three (at
    t = 0, s, 1, s = the middle pixel's t); tangents are its derivative per
    pixel. Returns ``geo`` (E, 12): (x, y, tx, ty) of the start, middle and
    end pixel, and ``lagrange`` (E, 9): row-major 3x3 matrix.
    """
    n = bx.shape[0]
    levels = offsets.shape[0] - 2
    first_coarse = offsets[1]
    n_coarse = offsets[levels + 1] - first_coarse
    geo = np.zeros((n_coarse, 12), dtype=np.float64)
    lagrange = np.zeros((n_coarse, 9), dtype=np.float64)
    for k in range(1, levels + 1):
        first = offsets[k]
        m = offsets[k + 1] - first
        for j in range(m):
            e = first + j
            ce = e - first_coarse
            a = index[e]
            span = (1 << k) if j < m - 1 else n - a
            if span < 2:
                continue  # handled as a finest edge
            half = span // 2
            s = half / span
            u = 1.0 / span
            xs = (bx[a], bx[(a + half) % n], bx[(a + span) % n])
            ys = (by[a], by[(a + half) % n], by[(a + span) % n])
            # derivative of the Lagrange basis l0 = (t-s)(t-1)/s, l1 = -t(t-1)/(s(1-s)),
            # l2 = t(t-s)/(1-s) at t = 0, s, 1 (rows) for each basis function (columns)
            h = 1.0 / (s * (1.0 - s))
            d = (
                (-(1.0 + s) / s, h, -s / (1.0 - s)),
                ((s - 1.0) / s, (1.0 - 2.0 * s) * h, s / (1.0 - s)),
                ((1.0 - s) / s, -h, (2.0 - s) / (1.0 - s)),
            )
            for node in range(3):
                row = d[node]
                geo[ce, 4 * node] = xs[node]
                geo[ce, 4 * node + 1] = ys[node]
                geo[ce, 4 * node + 2] = (row[0] * xs[0] + row[1] * xs[1] + row[2] * xs[2]) * u
                geo[ce, 4 * node + 3] = (row[0] * ys[0] + row[1] * ys[1] + row[2] * ys[2]) * u
            # W(t) = wa l0 + wm l1 + wb l2 = q0 + q1 t + q2 t^2
            lagrange[ce, 0] = 1.0
            lagrange[ce, 3] = -(1.0 + s) / s
            lagrange[ce, 4] = h
            lagrange[ce, 5] = -s / (1.0 - s)
            lagrange[ce, 6] = 1.0 / s
            lagrange[ce, 7] = -h
            lagrange[ce, 8] = 1.0 / (1.0 - s)
    return geo, lagrange


@njit(cache=True, inline="always", nogil=True)
def _density(x, y, geo, e, o):
    """Mean-value weight per boundary pixel at ``geo[e, o:o+2]``, tangent ``geo[e, o+2:o+4]``.

    The continuous limit of ``(tan(a_(i-1)/2) + tan(a_i/2)) / r_i`` seen from
    x: the angle the pixel subtends, ``cross(p - x, t) / r**2``, over ``r``.
    """
    dx = geo[e, o] - x
    dy = geo[e, o + 1] - y
    r2 = dx * dx + dy * dy
    return (dx * geo[e, o + 3] - dy * geo[e, o + 2]) / (r2 * math.sqrt(r2))


@njit(cache=True, nogil=True)
def _traverse(x, y, tree, bx, by, geo, lagrange, ones, far2, stack, cols, vals, at):
    """Adaptive boundary of the point (x, y): accept coarse edges that are far, refine the rest.

    ``tree`` = (offsets, level, start, end, cx, cy, radius2) of the edge
    hierarchy. An edge is accepted when its bounding circle is more than
    ``far`` radii away (``far2``, ``radius2`` squared), i.e. it subtends a
    small angle, or when it is a finest edge. A finest edge adds its exact
    mean-value terms on the two boundary values; a coarse edge its
    quadratic weight density on its three moments. Entries are written from
    ``at`` on when ``cols`` is not empty. Returns (entries, sum of the
    weights applied to the constant 1).
    """
    offsets, level, start, end, cx, cy, radius2 = tree
    levels = offsets.shape[0] - 2
    n = bx.shape[0]
    first_coarse = offsets[1]
    write = cols.shape[0] > 0
    size = 0
    for node in range(offsets[levels + 1] - 1, offsets[levels] - 1, -1):
        stack[size] = node
        size += 1
    count = at
    total = 0.0
    while size > 0:
        size -= 1
        node = stack[size]
        k = level[node]
        a = start[node]
        b = end[node]
        span = b - a if b > a else n - a
        if k > 0:
            dx = x - cx[node]
            dy = y - cy[node]
            if dx * dx + dy * dy <= far2 * radius2[node]:
                # refine: children 2j and, if it lies before the end, 2j + 1
                child = offsets[k - 1] + 2 * (node - offsets[k])
                if child + 1 < offsets[k]:
                    stack[size] = child + 1
                    size += 1
                stack[size] = child
                size += 1
                continue
        if span < 2:
            # a finest edge: its exact mean-value terms on the boundary values
            if write:
                wa, wb = _edge_weight(x, y, bx[a], by[a], bx[b], by[b])
                cols[count] = a
                vals[count] = wa
                cols[count + 1] = b
                vals[count + 1] = wb
                total += wa + wb
            count += 2
        else:
            if write:
                ce = node - first_coarse
                wa = _density(x, y, geo, ce, 0)
                wm = _density(x, y, geo, ce, 4)
                wb = _density(x, y, geo, ce, 8)
                q0 = wa
                q1 = lagrange[ce, 3] * wa + lagrange[ce, 4] * wm + lagrange[ce, 5] * wb
                q2 = lagrange[ce, 6] * wa + lagrange[ce, 7] * wm + lagrange[ce, 8] * wb
                base = n + 3 * ce
                cols[count] = base
                vals[count] = q0
                cols[count + 1] = base + 1
                vals[count + 1] = q1
                cols[count + 2] = base + 2
                vals[count + 2] = q2
                total += q0 * ones[ce, 0] + q1 * ones[ce, 1] + q2 * ones[ce, 2]
            count += 3
    return count - at, total


@njit(cache=True, nogil=True)
def _tree(bx, by, offsets, index, cx, cy, radius):
    """The hierarchy as ``_traverse`` reads it, and the far-edge geometry."""
    levels = offsets.shape[0] - 2
    nodes = offsets[levels + 1]
    level = np.empty(nodes, dtype=np.int64)
    end = np.empty(nodes, dtype=np.int64)
    for k in range(levels + 1):
        m = offsets[k + 1] - offsets[k]
        for j in range(m):
            level[offsets[k] + j] = k
            end[offsets[k] + j] = index[offsets[k] + (j + 1) % m]
    geo, lagrange = far_edge_geometry(bx, by, offsets, index)
    return (offsets, level, index, end, cx, cy, radius * radius), geo, lagrange


@njit(cache=True, nogil=True)
def _weights_block(lo, hi, qx, qy, tree, bx, by, geo, lagrange, ones, far2, out):
    """Points lo..hi: their entry counts (``out`` = counts), or their rows (``out`` = CSR)."""
    offsets = tree[0]
    levels = offsets.shape[0] - 2
    stack = np.empty(offsets[levels + 1] - offsets[levels] + 2 * levels + 2, dtype=np.int64)
    counts, indptr, cols, vals64, vals = out
    for p in range(lo, hi):
        if cols.shape[0] == 0:
            counts[p] = _traverse(
                qx[p], qy[p], tree, bx, by, geo, lagrange, ones, far2, stack, cols, vals64, 0
            )[0]
            continue
        at = indptr[p]
        total = _traverse(
            qx[p], qy[p], tree, bx, by, geo, lagrange, ones, far2, stack, cols, vals64, at
        )[1]
        inv = 1.0 / total
        for e in range(at, indptr[p + 1]):
            vals[e] = vals64[e] * inv


@njit(cache=True, parallel=True, nogil=True)
def hierarchical_weights(
    qx, qy, bx, by, offsets, index, cx, cy, radius, ones, far, workers, taken
):
    """CSR rows (int64 indptr, int32 columns, float32 values) of hierarchical MVC of each point.

    Columns: the n boundary values, then the coarse-edge moments of
    ``edge_moment_entries``. Applied to the values and moments of a constant
    a row gives that constant (mean-value coordinates reproduce constants).
    Two passes over blocks of points: count, then fill. The blocks go to
    ``workers`` as each asks (:mod:`matshop.parallel_chunks`; ``taken``: int64
    ``[0, 0]``, a counter per pass): a point's cost depends on where it lies,
    and the clone triangulates on another thread meanwhile.
    """
    q = qx.shape[0]
    tree, geo, lagrange = _tree(bx, by, offsets, index, cx, cy, radius)
    far2 = far * far
    counts = np.empty(q, dtype=np.int64)
    indptr = np.zeros(q + 1, dtype=np.int64)
    none = (counts, indptr, np.empty(0, np.int32), np.empty(0), np.empty(0, np.float32))
    _weights_blocks(qx, qy, tree, bx, by, geo, lagrange, ones, far2, none, workers, taken[0:])
    for p in range(q):
        indptr[p + 1] = indptr[p] + counts[p]
    rows = (
        counts,
        indptr,
        np.empty(indptr[q], dtype=np.int32),
        np.empty(indptr[q], dtype=np.float64),
        np.empty(indptr[q], dtype=np.float32),
    )
    _weights_blocks(qx, qy, tree, bx, by, geo, lagrange, ones, far2, rows, workers, taken[1:])
    return indptr, rows[2], rows[4]


@njit(inline="always", parallel=True, nogil=True)
def _weights_blocks(qx, qy, tree, bx, by, geo, lagrange, ones, far2, out, workers, taken):
    """:func:`_weights_block` over every block of 64 points, as the workers ask."""
    block = 64
    q = qx.shape[0]
    nblocks = (q + block - 1) // block
    for _worker in prange(workers):
        b = next_chunk(taken)
        while b < nblocks:
            lo = b * block
            hi = min(q, lo + block)
            _weights_block(lo, hi, qx, qy, tree, bx, by, geo, lagrange, ones, far2, out)
            b = next_chunk(taken)


# ---------------------------------------------------------------- mesh


@njit(cache=True, nogil=True)
def mesh_layout(filled, on_chain, dist, band, density, top):
    """Classify a component's pixels and place the mesh vertices.

    ``filled``: the component (holes filled) on a local grid with a zero
    border; ``on_chain``: its boundary pixels; ``dist``: distance to the
    nearest outside pixel. Interior pixels closer than ``band`` px are mesh
    vertices (kind 0); further in, lattice points of spacing 2**level with
    ``level = clip(floor(log2(dist / density)), 1, top)`` are vertices (kind 1)
    and the other pixels are interpolated (kind 2).

    Returns per interior pixel (row-major): local x, y and kind; its vertex
    number (-1 if interpolated); per vertex its pixel; and which vertices
    the triangulation needs (every lattice vertex, and the band vertices
    next to a non-band pixel).
    """
    h, w = filled.shape
    kind = np.full((h, w), -1, dtype=np.int8)
    npix = 0
    nvert = 0
    for r in range(h):
        for c in range(w):
            if filled[r, c] and not on_chain[r, c]:
                d = dist[r, c]
                if d < band:
                    k = 0
                else:
                    level = int(math.floor(math.log2(max(d, 1.0) / density)))
                    level = min(max(level, 1), top)
                    step = 1 << level
                    k = 1 if (r % step == 0 and c % step == 0) else 2
                kind[r, c] = k
                npix += 1
                if k < 2:
                    nvert += 1
    px = np.empty(npix, dtype=np.int32)
    py = np.empty(npix, dtype=np.int32)
    pkind = np.empty(npix, dtype=np.int8)
    pvert = np.empty(npix, dtype=np.int64)
    vpix = np.empty(nvert, dtype=np.int64)
    vtri = np.zeros(nvert, dtype=np.bool_)
    p = 0
    v = 0
    for r in range(h):
        for c in range(w):
            k = kind[r, c]
            if k < 0:
                continue
            px[p] = c
            py[p] = r
            pkind[p] = k
            if k < 2:
                pvert[p] = v
                vpix[v] = p
                if k == 1:
                    vtri[v] = True
                else:  # the band's inner rim: next to a non-band pixel
                    vtri[v] = (
                        (r > 0 and kind[r - 1, c] > 0)
                        or (r + 1 < h and kind[r + 1, c] > 0)
                        or (c > 0 and kind[r, c - 1] > 0)
                        or (c + 1 < w and kind[r, c + 1] > 0)
                    )
                v += 1
            else:
                pvert[p] = -1
            p += 1
    return px, py, pkind, pvert, vpix, vtri


@njit(cache=True, nogil=True)
def locate_pixels(vx, vy, triangles, vertex_rows, pixel_of, tri_out, bary_out):
    """Triangle and barycentric weights of every pixel marked in ``pixel_of`` (>= 0).

    Triangles are rasterized over their bounding boxes; the first one
    holding a pixel centre (all weights >= -1e-9) claims it and writes the
    table rows of its vertices (``vertex_rows``) and the weights into row
    ``pixel_of[r, c]`` of ``tri_out`` / ``bary_out``. Returns how many
    pixels were claimed.
    """
    h, w = pixel_of.shape
    claimed = 0
    eps = -1e-9
    for t in range(triangles.shape[0]):
        i0 = triangles[t, 0]
        i1 = triangles[t, 1]
        i2 = triangles[t, 2]
        x0, y0 = vx[i0], vy[i0]
        x1, y1 = vx[i1], vy[i1]
        x2, y2 = vx[i2], vy[i2]
        det = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)
        if det == 0.0:
            continue
        inv = 1.0 / det
        c_lo = max(0, int(math.ceil(min(x0, x1, x2))))
        c_hi = min(w - 1, int(math.floor(max(x0, x1, x2))))
        r_lo = max(0, int(math.ceil(min(y0, y1, y2))))
        r_hi = min(h - 1, int(math.floor(max(y0, y1, y2))))
        for r in range(r_lo, r_hi + 1):
            for c in range(c_lo, c_hi + 1):
                p = pixel_of[r, c]
                if p < 0:
                    continue
                l0 = ((y1 - y2) * (c - x2) + (x2 - x1) * (r - y2)) * inv
                l1 = ((y2 - y0) * (c - x2) + (x0 - x2) * (r - y2)) * inv
                l2 = 1.0 - l0 - l1
                if l0 >= eps and l1 >= eps and l2 >= eps:
                    pixel_of[r, c] = -1
                    claimed += 1
                    tri_out[p, 0] = vertex_rows[i0]
                    tri_out[p, 1] = vertex_rows[i1]
                    tri_out[p, 2] = vertex_rows[i2]
                    bary_out[p, 0] = l0
                    bary_out[p, 1] = l1
                    bary_out[p, 2] = l2
    return claimed


# ---------------------------------------------------------------- per-clone kernels


@njit(cache=True, inline="always", nogil=True)
def _csr_row(indptr, indices, data, dense, out, r):
    channels = dense.shape[1]
    for c in range(channels):
        out[r, c] = 0.0
    for e in range(indptr[r], indptr[r + 1]):
        v = data[e]
        col = indices[e]
        for c in range(channels):
            out[r, c] += v * dense[col, c]


@njit(cache=True, nogil=True)
def csr_matmul(indptr, indices, data, dense, out):
    """``out = A @ dense`` for CSR ``A`` (duplicate columns add); one thread, for small ``A``."""
    for r in range(indptr.shape[0] - 1):
        _csr_row(indptr, indices, data, dense, out, r)


@njit(cache=True, parallel=True, nogil=True)
def csr_matmul_parallel(indptr, indices, data, dense, out):
    """``out = A @ dense`` for CSR ``A``, rows in parallel."""
    for r in prange(indptr.shape[0] - 1):
        _csr_row(indptr, indices, data, dense, out, r)


@njit(cache=True, parallel=True, nogil=True)
def clone_rows(out, target, source, sx, row_start, y0, dx, dy, wrap, tri, bary, table):
    """``out = target`` with ``source + membrane`` pasted, one target row per task.

    Pixels are sorted by source row: those of source row ``y0 + i`` are
    ``row_start[i]:row_start[i + 1]``, with x ``sx``. Pixel p lands on
    (sx + dx, y + dy), wrapped around the image or dropped when outside, and
    gets ``source + sum_k bary[p, k] * table[tri[p, k]]``. Copying and pasting
    row by row keeps the pasted row in cache and spreads the copy (and the
    page faults of a fresh ``out``) over the threads.
    """
    height, width, channels = out.shape
    rows = row_start.shape[0] - 1
    for ty in prange(height):
        for tx in range(width):
            for c in range(channels):
                out[ty, tx, c] = target[ty, tx, c]
        # the source rows landing here: y + dy == ty (mod height when wrapping)
        first = ty - dy - y0
        if wrap:
            first %= height
        while first < rows:
            if first >= 0:
                sy = y0 + first
                for p in range(row_start[first], row_start[first + 1]):
                    x = sx[p] + dx
                    if wrap:
                        x %= width
                    elif x < 0 or x >= width:
                        continue
                    i0 = tri[p, 0]
                    i1 = tri[p, 1]
                    i2 = tri[p, 2]
                    b0 = bary[p, 0]
                    b1 = bary[p, 1]
                    b2 = bary[p, 2]
                    for c in range(channels):
                        out[ty, x, c] = source[sy, sx[p], c] + (
                            b0 * table[i0, c] + b1 * table[i1, c] + b2 * table[i2, c]
                        )
            if not wrap:
                break
            first += height
