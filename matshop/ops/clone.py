"""Seamless cloning by mean-value coordinates (Farbman et al. 2009, "Coordinates for instant
image cloning").

A region of ``source`` is pasted into ``target`` at ``offset`` and corrected
by a smooth *membrane* that takes up the difference along the seam::

    result(x + offset) = source(x) + r(x)
    r(x) = sum_i lambda_i(x) (target(b_i + offset) - source(b_i))

over the boundary pixels ``b_i`` of the region, ``lambda_i(x)`` the mean-value
coordinates of ``x`` with respect to the boundary polygon (Floater 2003;
Hormann & Floater 2006 for non-convex polygons). The membrane is linear in
the edit values and its coordinates depend only on the region's shape, so
every edit channel is cloned at once, and :class:`CloneCoordinates` is built
once per shape: dragging the region to a new offset only gathers the
boundary differences again.

The region
    A boolean mask in source pixel coordinates, or a polygon of (x, y)
    vertices rasterized to the pixels whose centre lies inside or on it (a
    polygon and the mask of the same pixels clone identically). Each
    8-connected component is cloned on its own. **Holes are filled**: a
    component's region is everything inside its outer boundary, so a hole in
    the mask is pasted from the source like the rest (an island inside a
    hole belongs to that region). The boundary of a component is its closed
    chain of border pixels (``cv2.findContours``); they keep the target's
    values exactly, the other pixels get ``source + membrane``.

Acceleration (the paper's section 4)
    * *Adaptive mesh*: the membrane is evaluated only at mesh vertices:
      the boundary pixels, every pixel closer than ``mesh_density`` px to
      the boundary, and further in, lattice points whose spacing is the
      largest power of two <= distance / ``mesh_density`` (at least 2, at
      most 64 px): about 6 % of the pixels of a 512 px disc. The other pixels
      interpolate linearly in a Delaunay triangle (OpenCV's Subdiv2D) of the
      lattice and the band's inner rim.
    * *Hierarchical boundary*: the boundary chain is a binary hierarchy of
      edges (level k joins every 2**k-th boundary pixel). For each mesh
      vertex an edge is refined while its bounding circle is closer than
      ``far`` radii; finest edges add their exact mean-value terms, a far
      coarse edge adds ``sum_i w(t_i) f_i`` over the pixels it covers with
      ``w`` the continuous mean-value weight density (subtended angle over
      distance) interpolated quadratically along the edge -- a combination
      of three moments ``sum_i t_i**q f_i`` of the boundary values, so far
      boundary is neither point-sampled (no aliasing of a rough seam) nor
      visited pixel by pixel. Rows are normalized with the same
      approximation applied to a constant: constants are reproduced exactly.
    Both are linear, so the precomputed part is two sparse matrices (edge
    moments of the boundary values; hierarchical coordinates of the mesh
    vertices) and, per pixel, three table rows and barycentric weights. A
    clone is one gather of the boundary differences, two sparse products
    with the (Nb, C) differences and one fused pass that copies the target
    and pastes ``source + membrane``.

Accuracy, against brute-force mean-value coordinates (all boundary pixels,
every pixel), as max error / range of the boundary differences: ~2 % for
white-noise differences (the worst case; the largest errors sit 4-8 px
from the seam, where the lattice starts and the membrane is still as rough
as the seam; the rms error is ~0.2 %), <= 0.7 % for smooth ones.
``tests/test_clone.py`` asserts 3 % and 1 % on a 40 px disc;
``benchmarks/clone.py`` measures 1-2 % on real data at 512 px. Raising
``mesh_density`` and ``far`` trades speed for accuracy; ``exact=True`` is the
brute force.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import cv2
import numba
import numpy as np

from ..material import Schema
from . import _mvc
from .selection import Selection
from .spec import WHOLE_IMAGE, OpError, OpSpec, OpTarget, ParamSpec, Reach

BORDERS = ("wrap", "clamp", "error")

#: largest lattice spacing of the adaptive mesh: 2**_TOP_LEVEL px
_TOP_LEVEL = 6
#: coarsest level of the boundary hierarchy has at least this many edges
_TOP_EDGES = 8
#: OpenCV's Delaunay of a component's vertices runs here, beside the weights (one
#: thread: it is one call, and the weights keep the other cores busy)
_TRIANGULATOR = ThreadPoolExecutor(max_workers=1, thread_name_prefix="matshop-delaunay")


class CloneError(OpError, ValueError):
    """A region or an input that cannot be cloned (one line naming the problem)."""


# ---------------------------------------------------------------- regions


def region_mask(region: np.ndarray | Sequence, shape: tuple[int, int]) -> np.ndarray:
    """A boolean (Hs, Ws) mask from a mask (checked) or an (N, 2) polygon of (x, y) vertices.

    A polygon covers the pixels whose centre (x=col, y=row) lies inside or
    on it (even-odd rule for self-intersections); parts outside the source
    are dropped.
    """
    array = np.asarray(region)
    height, width = int(shape[0]), int(shape[1])
    if array.dtype == np.bool_ or array.shape == (height, width):
        if array.shape != (height, width):
            raise CloneError(
                f"clone: region mask is {array.shape[1]}x{array.shape[0]}, "
                f"the source is {width}x{height}"
            )
        if array.dtype == np.bool_:
            return array
        if not np.issubdtype(array.dtype, np.number):
            raise CloneError(f"clone: region mask must be boolean, got {array.dtype}")
        return array != 0
    if array.ndim == 2 and array.shape[1] == 2 and np.issubdtype(array.dtype, np.number):
        if array.shape[0] < 3:
            raise CloneError(f"clone: a region polygon needs 3 or more vertices, got {len(array)}")
        vertices = array.astype(np.float64)
        if not np.all(np.isfinite(vertices)):
            raise CloneError("clone: region polygon vertices must be finite")
        xs = np.ascontiguousarray(vertices[:, 0])
        ys = np.ascontiguousarray(vertices[:, 1])
        return _mvc.rasterize_polygon(xs, ys, height, width)
    raise CloneError(
        f"clone: region must be a ({height}, {width}) mask like the source or an (N, 2) "
        f"polygon of (x, y) vertices, got shape {array.shape}"
    )


@dataclass(frozen=True)
class _Component:
    """One 8-connected component of the region, holes filled, on a local grid."""

    filled: np.ndarray  # (h, w) bool with a zero border
    chain: np.ndarray  # (n, 2) int32 local (x, y) boundary pixels, closed chain order
    origin: tuple[int, int]  # source (x, y) of local (0, 0)


def _components(mask: np.ndarray) -> list[_Component]:
    rows = np.flatnonzero(mask.any(axis=1))
    if rows.size == 0:
        raise CloneError("clone: the region is empty (no pixel selected)")
    cols = np.flatnonzero(mask.any(axis=0))
    y0, y1, x0, x1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    crop = np.pad(mask[y0:y1, x0:x1], 1).view(np.uint8)
    # outer borders only (RETR_EXTERNAL): a hole's border is not a boundary,
    # and drawing a chain filled gives its component with the holes filled
    chains, _ = cv2.findContours(crop, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    out = []
    for chain in chains:
        chain = chain.reshape(-1, 2)
        cx0, cy0 = chain.min(axis=0) - 1
        cx1, cy1 = chain.max(axis=0) + 2
        local = chain - np.array([cx0, cy0])
        filled = np.zeros((cy1 - cy0, cx1 - cx0), dtype=np.uint8)
        cv2.drawContours(filled, [local.reshape(-1, 1, 2).astype(np.int32)], 0, 1, cv2.FILLED)
        out.append(
            _Component(
                filled=filled.view(bool),
                chain=np.ascontiguousarray(local, dtype=np.int32),
                origin=(int(x0 + cx0 - 1), int(y0 + cy0 - 1)),
            )
        )
    return out


# ---------------------------------------------------------------- coordinates


def _levels(n: int) -> int:
    levels = 0
    while (n + (2 << levels) - 1) // (2 << levels) >= _TOP_EDGES:
        levels += 1
    return levels


@dataclass
class _Part:
    """The coordinates of one component, in its own numbering."""

    boundary: np.ndarray  # (n, 2) int32 source (x, y)
    pixels: np.ndarray  # (m, 2) int32 source (x, y), row-major
    moments: tuple[np.ndarray, np.ndarray, np.ndarray]  # COO (moments x n)
    n_moments: int
    weights: tuple[np.ndarray, np.ndarray, np.ndarray]  # CSR (vertices x (n + moments))
    tri: np.ndarray  # (m, 3) rows: < n boundary, else n + vertex
    bary: np.ndarray  # (m, 3) float32


def _build(comp: _Component, density: float, far: float, exact: bool) -> _Part:
    """Mesh, hierarchical coordinates and pixel interpolation of one component."""
    ox, oy = comp.origin
    chain = comp.chain
    n = len(chain)
    on_chain = np.zeros_like(comp.filled)
    on_chain[chain[:, 1], chain[:, 0]] = True
    dist = cv2.distanceTransform(comp.filled.view(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    band = np.inf if exact else float(density)
    px, py, kind, pvert, vpix, vtri = _mvc.mesh_layout(
        comp.filled, on_chain, dist, band, float(density), _TOP_LEVEL
    )
    m = len(px)
    origin = np.array([ox, oy], dtype=np.int32)
    part = _Part(
        boundary=chain + origin,
        pixels=np.stack([px + ox, py + oy], axis=1),
        moments=(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)),
        n_moments=0,
        weights=(np.zeros(1, np.int64), np.zeros(0, np.int64), np.zeros(0)),
        tri=np.zeros((m, 3), dtype=np.int32),
        bary=np.zeros((m, 3), dtype=np.float32),
    )
    if m == 0:  # all boundary: nothing to correct
        return part

    # hierarchical mean-value coordinates of the mesh vertices
    bx = part.boundary[:, 0].astype(np.float64)
    by = part.boundary[:, 1].astype(np.float64)
    levels = _levels(n)
    offsets, index, cx, cy, radius = _mvc.hierarchy_nodes(bx, by, levels)
    mrow, mcol, mval, ones = _mvc.edge_moment_entries(bx, by, offsets, index)
    vx = px[vpix].astype(np.float64)
    vy = py[vpix].astype(np.float64)
    # the vertices' triangles (OpenCV, one thread) while the weights take the others
    is_vertex = kind < 2
    points = np.stack([vx[vtri], vy[vtri]], axis=1)
    triangles_soon = (
        None if is_vertex.all() else _TRIANGULATOR.submit(_delaunay_cv2, points, comp.filled.shape)
    )
    part.weights = _mvc.hierarchical_weights(
        vx + ox, vy + oy, bx, by, offsets, index, cx, cy, radius, ones,
        1e300 if exact else far, numba.get_num_threads(), np.zeros(2, dtype=np.int64),
    )  # fmt: skip
    part.moments = (mrow, mcol, mval)
    part.n_moments = len(ones) * 3

    # vertices are their own table row; the other pixels interpolate in a triangle
    part.tri[is_vertex] = (n + pvert[is_vertex])[:, None]
    part.bary[is_vertex, 0] = 1.0
    if triangles_soon is None:
        return part
    loose = np.flatnonzero(~is_vertex)
    rows = n + np.flatnonzero(vtri)
    pixel_of = np.full(comp.filled.shape, -1, dtype=np.int64)
    pixel_of[py[loose], px[loose]] = loose
    claimed = 0
    for triangles in _triangulations(triangles_soon, points, comp.filled.shape):
        claimed += _mvc.locate_pixels(
            np.ascontiguousarray(points[:, 0]),
            np.ascontiguousarray(points[:, 1]),
            triangles,
            rows,
            pixel_of,
            part.tri,
            part.bary,
        )
        if claimed == len(loose):
            return part
    # never seen (the triangles cover the convex hull); be exact rather than wrong
    return _build(comp, density, far, exact=True)  # pragma: no cover


def _triangulations(
    first: Future[np.ndarray], points: np.ndarray, shape: tuple[int, int]
) -> Iterator[np.ndarray]:
    """OpenCV's triangles (under way), then Qhull's for the pixels they left out."""
    yield first.result()
    yield _delaunay_qhull(points, shape)


def _delaunay_cv2(points: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """(T, 3) vertex indices of the Delaunay triangles of integer points (OpenCV's Subdiv2D)."""
    height, width = shape
    subdiv = cv2.Subdiv2D((-1, -1, width + 2, height + 2))
    subdiv.insert(points.astype(np.float32))
    corners = subdiv.getTriangleList().reshape(-1, 3, 2)
    # drop the triangles on Subdiv2D's virtual outer vertices
    inside = ((corners >= 0) & (corners <= [width - 1, height - 1])).all(axis=(1, 2))
    corners = np.rint(corners[inside]).astype(np.int64)
    vertex_at = np.full(shape, -1, dtype=np.int64)
    vertex_at[points[:, 1].astype(np.int64), points[:, 0].astype(np.int64)] = np.arange(len(points))
    triangles = vertex_at[corners[..., 1], corners[..., 0]]
    return triangles[(triangles >= 0).all(axis=1)]


def _delaunay_qhull(points: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The same with Qhull (the fallback): a tiny fixed jitter avoids the lattice's degeneracies."""
    from scipy.spatial import Delaunay, QhullError  # here: 0.1-0.5 s to import, a fallback

    jitter = np.random.default_rng(0).uniform(-1e-3, 1e-3, points.shape)
    try:
        return Delaunay(points + jitter).simplices.astype(np.int64)
    except QhullError:  # too few or collinear vertices
        return np.zeros((0, 3), dtype=np.int64)


def _assemble(shape: tuple[int, int], parts: list[_Part]) -> CloneCoordinates:
    """Concatenate the components: block-diagonal matrices, one table, pixels by row."""
    sizes = [len(p.boundary) for p in parts]
    starts = np.cumsum([0, *sizes])
    nb = int(starts[-1])
    mom_starts = np.cumsum([0] + [p.n_moments for p in parts])
    n_mom = int(mom_starts[-1])
    vert_starts = np.cumsum([0] + [len(p.weights[0]) - 1 for p in parts])

    # moments COO -> CSR (moments x boundary)
    mrow = np.concatenate([p.moments[0] + mom_starts[i] for i, p in enumerate(parts)])
    mcol = np.concatenate([p.moments[1] + starts[i] for i, p in enumerate(parts)])
    mval = np.concatenate([p.moments[2] for p in parts])
    order = np.argsort(mrow, kind="stable")
    m_indptr = np.zeros(n_mom + 1, dtype=np.int64)
    np.cumsum(np.bincount(mrow, minlength=n_mom), out=m_indptr[1:])
    moments = (m_indptr, mcol[order].astype(np.int32), mval[order].astype(np.float32))

    # weights (vertices x [boundary values, moments]), and pixel rows of the
    # table [boundary values; vertices]
    indptrs = [np.zeros(1, dtype=np.int64)]
    cols = []
    tris = []
    entries = 0
    for i, p in enumerate(parts):
        indptr, col, _ = p.weights
        indptrs.append(indptr[1:] + entries)
        entries += indptr[-1]
        n = sizes[i]
        if len(parts) == 1:
            cols.append(col)
            tris.append(p.tri)
            continue
        cols.append(np.where(col < n, col + starts[i], col - n + nb + mom_starts[i]))
        tris.append(np.where(p.tri < n, p.tri + starts[i], p.tri - n + nb + vert_starts[i]))
    weights = (
        np.concatenate(indptrs),
        np.concatenate(cols),
        np.concatenate([p.weights[2] for p in parts]).astype(np.float32),
    )
    pixels = np.concatenate([p.pixels for p in parts])
    tri = np.concatenate(tris).astype(np.int32)
    bary = np.concatenate([p.bary for p in parts])
    if len(parts) > 1:  # components interleave by rows
        order = np.lexsort((pixels[:, 0], pixels[:, 1]))
        pixels, tri, bary = pixels[order], tri[order], bary[order]
    if len(pixels):
        y0 = int(pixels[0, 1])
        row_start = np.searchsorted(pixels[:, 1], np.arange(y0, pixels[-1, 1] + 2))
    else:
        y0, row_start = 0, np.zeros(1, dtype=np.int64)
    return CloneCoordinates(
        source_shape=shape,
        boundary=np.concatenate([p.boundary for p in parts]),
        component_starts=starts.astype(np.int64),
        interior=pixels,
        _moments=moments,
        _weights=weights,
        _tri=tri,
        _bary=bary,
        _y0=y0,
        _row_start=row_start.astype(np.int64),
    )


@dataclass(frozen=True, eq=False)
class CloneCoordinates:
    """The precomputed, offset-independent part of a seamless clone of one region shape.

    Build it with :meth:`from_region`; :meth:`clone` (or
    :func:`seamless_clone` with ``region=coordinates``) then costs one
    gather of the boundary differences, two small sparse products and one
    pass over the target, whatever the number of channels.
    """

    #: (Hs, Ws) of the source the region lives in
    source_shape: tuple[int, int]
    #: (Nb, 2) int32 (x, y) boundary pixels, each component's closed chain in turn
    boundary: np.ndarray
    #: (Nc + 1,) start of each component's chain in ``boundary``
    component_starts: np.ndarray
    #: (Ni, 2) int32 (x, y) of the pixels that get ``source + membrane``, by rows
    interior: np.ndarray
    _moments: tuple[np.ndarray, np.ndarray, np.ndarray]  # CSR (edge moments x Nb)
    _weights: tuple[np.ndarray, np.ndarray, np.ndarray]  # CSR (vertices x (Nb + moments))
    _tri: np.ndarray  # (Ni, 3) int32 rows of the membrane table
    _bary: np.ndarray  # (Ni, 3) float32
    _y0: int  # source row of interior[0]
    _row_start: np.ndarray  # interior pixels of source row y0 + i: [i] .. [i + 1]

    @classmethod
    def from_region(
        cls,
        region: np.ndarray | Sequence,
        source_shape: tuple[int, ...],
        *,
        mesh_density: float = 4.0,
        far: float = 5.0,
        exact: bool = False,
    ) -> CloneCoordinates:
        """Coordinates of ``region`` (a mask or an (N, 2) polygon) in a source of ``source_shape``.

        ``mesh_density``: pixels closer than this to the boundary are all
        mesh vertices; further in the mesh spacing is <= distance / density
        (higher is finer and slower). ``far``: a coarse boundary edge is
        used whole once the point is ``far`` times its radius away (> 1;
        higher is more accurate and slower). ``exact=True`` evaluates the
        mean-value coordinates over all boundary pixels at every pixel (the
        brute-force reference; quadratic cost, for small regions).
        """
        if not mesh_density >= 1.0:
            raise CloneError(f"clone: mesh_density must be >= 1, got {mesh_density}")
        if not far > 1.0:
            raise CloneError(f"clone: far must be > 1, got {far}")
        shape = (int(source_shape[0]), int(source_shape[1]))
        mask = region_mask(region, shape)
        parts = [_build(comp, mesh_density, far, exact) for comp in _components(mask)]
        return _assemble(shape, parts)

    # -------------------------------------------------- per clone

    @property
    def bbox(self) -> tuple[int, int, int, int]:
        """(x0, y0, x1, y1) of the region in source pixels, end exclusive."""
        x0, y0 = self.boundary.min(axis=0)
        x1, y1 = self.boundary.max(axis=0) + 1
        return int(x0), int(y0), int(x1), int(y1)

    @property
    def mesh_vertices(self) -> int:
        """Points where the membrane is evaluated: boundary pixels and mesh vertices."""
        return len(self.boundary) + len(self._weights[0]) - 1

    def boundary_differences(
        self,
        target: np.ndarray,
        source: np.ndarray,
        offset: tuple[int, int],
        border: str = "wrap",
    ) -> np.ndarray:
        """(Nb, C) ``target(b + offset) - source(b)`` at the boundary pixels.

        Target positions outside the image wrap (``"wrap"``) or read the
        nearest edge pixel (``"clamp"``, ``"error"``).
        """
        height, width = target.shape[:2]
        tx = self.boundary[:, 0] + offset[0]
        ty = self.boundary[:, 1] + offset[1]
        if border == "wrap":
            tx, ty = tx % width, ty % height
        else:
            tx, ty = np.clip(tx, 0, width - 1), np.clip(ty, 0, height - 1)
        return target[ty, tx] - source[self.boundary[:, 1], self.boundary[:, 0]]

    def membrane_table(self, diffs: np.ndarray) -> np.ndarray:
        """Membrane at the boundary pixels (= ``diffs``) then at every mesh vertex."""
        diffs = np.ascontiguousarray(diffs)
        nb, channels = diffs.shape
        moments = np.empty((nb + len(self._moments[0]) - 1, channels), dtype=diffs.dtype)
        moments[:nb] = diffs
        _mvc.csr_matmul(*self._moments, diffs, moments[nb:])
        table = np.empty((self.mesh_vertices, channels), dtype=diffs.dtype)
        table[:nb] = diffs
        _mvc.csr_matmul_parallel(*self._weights, moments, table[nb:])
        return table

    def membrane(self, diffs: np.ndarray) -> np.ndarray:
        """(Ni, C) membrane at the ``interior`` pixels from (Nb, C) boundary differences."""
        table = self.membrane_table(diffs)
        return np.einsum("pk,pkc->pc", self._bary.astype(table.dtype), table[self._tri])

    def clone(
        self,
        target: np.ndarray,
        source: np.ndarray,
        offset: tuple[int, int],
        border: str = "wrap",
        *,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """``target`` with this region of ``source`` pasted at ``offset`` and made seamless.

        ``out``: write the result there (shaped and typed like ``target``,
        sharing memory with neither input) instead of a new array -- a drag
        that reuses one buffer skips allocating (and page-faulting) a
        full-size image per move.
        """
        target, source, squeeze = _check_images(target, source, self.source_shape)
        dx, dy = _check_offset(offset)
        _check_border(border)
        check_placement(
            self.bbox,
            lambda: np.concatenate([self.boundary, self.interior]),
            target.shape[:2],
            (dx, dy),
            border,
        )
        if out is None:
            result = np.empty_like(target)
        else:
            result = out[..., None] if squeeze and out.ndim == 2 else out
            if result.shape != target.shape or result.dtype != target.dtype:
                raise CloneError(
                    f"clone: out is {out.shape} {out.dtype}, the target {target.shape} "
                    f"{target.dtype}"
                )
            if np.may_share_memory(result, target) or np.may_share_memory(result, source):
                raise CloneError("clone: out must not share memory with the target or source")
        table = self.membrane_table(self.boundary_differences(target, source, (dx, dy), border))
        _mvc.clone_rows(
            result,
            target,
            source,
            self.interior[:, 0],
            self._row_start,
            self._y0,
            dx,
            dy,
            border == "wrap",
            self._tri,
            self._bary,
            table,
        )
        if out is not None:
            return out
        return result[..., 0] if squeeze else result


# ---------------------------------------------------------------- checks


def check_placement(
    bbox: tuple[int, int, int, int],
    pixels: Callable[[], np.ndarray],
    shape: tuple[int, ...],
    offset: tuple[int, int],
    border: str,
) -> None:
    """Refuse a region (``bbox`` x0, y0, x1, y1 and its ``(N, 2)`` (x, y) ``pixels``,
    asked for only when the box does not settle it) that cannot land at ``offset``."""
    height, width = shape[:2]
    x0, y0, x1, y1 = bbox
    dx, dy = offset
    if border == "wrap":
        if x1 - x0 > width or y1 - y0 > height:
            texels = pixels().astype(np.int64)
            keys = (texels[:, 1] + dy) % height * width + (texels[:, 0] + dx) % width
            if np.unique(keys).size < np.unique(texels[:, 1] << 32 | texels[:, 0]).size:
                raise CloneError(
                    f"clone: the region ({x1 - x0}x{y1 - y0} px) wraps onto itself in the "
                    f"{width}x{height} target"
                )
        return
    if x0 + dx >= 0 and y0 + dy >= 0 and x1 + dx <= width and y1 + dy <= height:
        return
    if border == "error":
        raise CloneError(
            f"clone: the region (x {x0 + dx}..{x1 + dx - 1}, y {y0 + dy}..{y1 + dy - 1} "
            f"in the target) leaves the {width}x{height} target (border='error')"
        )
    texels = pixels() + np.array([dx, dy])
    hit = (
        (texels[:, 0] >= 0) & (texels[:, 0] < width) & (texels[:, 1] >= 0) & (texels[:, 1] < height)
    )
    if not hit.any():
        raise CloneError(
            f"clone: the region lies entirely outside the {width}x{height} target "
            f"at offset ({dx}, {dy})"
        )


def check_region(values: Mapping[str, Any], target: OpTarget) -> None:
    """With the image size known: the region is a mask of that size or a polygon
    covering some of it, and lands (partly) in it at ``offset``.

    A precomputed :class:`CloneCoordinates` was checked when it was built.
    """
    region = values["region"]
    if target.size is None or isinstance(region, CloneCoordinates):
        return
    mask = region_mask(region, target.size)
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        raise CloneError("clone: the region is empty (no pixel selected)")
    bbox = (int(cols.min()), int(rows.min()), int(cols.max()) + 1, int(rows.max()) + 1)
    check_placement(
        bbox,
        lambda: np.stack([cols, rows], axis=1),
        target.size,
        values["offset"],
        values["border"],
    )


def clone_reach(values: Mapping[str, Any], target: OpTarget) -> Reach:
    """Every texel inside the region reads the whole boundary: the whole image."""
    return WHOLE_IMAGE


def _check_border(border: str) -> None:
    if border not in BORDERS:
        raise CloneError(f"clone: border={border!r}: choose one of {', '.join(BORDERS)}")


def _check_offset(offset) -> tuple[int, int]:
    try:
        dx, dy = offset
        if int(dx) != dx or int(dy) != dy:
            raise ValueError
        return int(dx), int(dy)
    except (TypeError, ValueError):
        raise CloneError(
            f"clone: offset must be two whole numbers (dx, dy), got {offset!r}"
        ) from None


def _check_images(target, source, source_shape=None):
    target = np.ascontiguousarray(target)
    source = np.ascontiguousarray(source)
    squeeze = target.ndim == 2
    if squeeze:
        target = target[..., None]
        source = source[..., None] if source.ndim == 2 else source
    if target.ndim != 3 or source.ndim != 3:
        raise CloneError(
            f"clone: target and source must be (H, W, C) arrays, got {target.shape} and "
            f"{source.shape}"
        )
    if target.shape[2] != source.shape[2]:
        raise CloneError(
            f"clone: target has {target.shape[2]} channels, source has {source.shape[2]}"
        )
    if target.dtype not in (np.float32, np.float64):
        raise CloneError(f"clone: target must be float32 (or float64) values, got {target.dtype}")
    if source.dtype != target.dtype:
        source = np.ascontiguousarray(source, dtype=target.dtype)
    if source_shape is not None and tuple(source.shape[:2]) != tuple(source_shape):
        raise CloneError(
            f"clone: the region was built for a {source_shape[1]}x{source_shape[0]} source, "
            f"got {source.shape[1]}x{source.shape[0]}"
        )
    return target, source, squeeze


# ---------------------------------------------------------------- public function


def seamless_clone(
    target: np.ndarray,
    source: np.ndarray,
    *,
    region: np.ndarray | Sequence | CloneCoordinates,
    offset: tuple[int, int],
    border: str = "wrap",
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Paste ``region`` of ``source`` into ``target`` at ``offset``, seamlessly.

    Parameters
    ----------
    target : (H, W, C) float32 ndarray
        The image cloned into (any number of edit channels).
    source : (Hs, Ws, C) ndarray
        Where the region is taken from; may be ``target`` itself.
    region : (Hs, Ws) bool ndarray, (N, 2) array of (x, y) vertices, or CloneCoordinates
        The cloned region in source pixel coordinates; pass a
        :class:`CloneCoordinates` to reuse the precomputed coordinates
        (dragging the region only changes ``offset``).
    offset : (dx, dy)
        Source pixel (x, y) lands on target pixel (x + dx, y + dy).
    border : {"wrap", "clamp", "error"}
        Target positions outside the image: ``"wrap"`` around (tiling
        textures), ``"clamp"`` (pixels outside are dropped and the seam
        there reads the nearest edge pixel of the target), or ``"error"``.
    out : ndarray, optional
        Write the result into this array (shaped and typed like ``target``,
        sharing memory with neither input) and return it: a caller that keeps
        one buffer skips allocating and page-faulting a full-size image.

    Returns
    -------
    (H, W, C) ndarray
        A new array (or ``out``): ``target`` outside the pasted region and on
        its boundary pixels, ``source + membrane`` inside.

    Raises
    ------
    CloneError (a ValueError)
        Empty region, region entirely outside the target (or partly, with
        ``border="error"``), channel or shape mismatch, bad offset or border.
    """
    target, source, squeeze = _check_images(target, source)
    _check_border(border)
    _check_offset(offset)
    if not isinstance(region, CloneCoordinates):
        region = CloneCoordinates.from_region(region, source.shape[:2])
    if out is not None:
        return region.clone(target, source, offset, border, out=out)
    result = region.clone(target, source, offset, border)
    return result[..., 0] if squeeze else result


def clone(
    edit: np.ndarray,
    *,
    region: np.ndarray | Sequence | CloneCoordinates,
    offset: tuple[int, int],
    border: str = "wrap",
    source: np.ndarray | None = None,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """The op form: clone the selected edit channels from ``source`` (default: ``edit`` itself).

    schema, params, mask : selection and blending, see :mod:`matshop.ops.selection`.
    """
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="clone")
    src = selection.take(edit if source is None else np.asarray(source, dtype=np.float32))
    cloned = seamless_clone(selection.take(edit), src, region=region, offset=offset, border=border)
    return selection.put(edit, cloned)


SPECS = (
    OpSpec(
        name="clone",
        label="Seamless clone",
        summary="paste a region at an offset, corrected by a mean-value membrane (no seam)",
        function=clone,
        params=(
            ParamSpec("region", "region", None, "mask or polygon in source pixels", required=True),
            ParamSpec("offset", "offset", (0, 0), "translation dx,dy source -> target", unit="px"),
            ParamSpec(
                "border",
                "choice",
                "wrap",
                "target positions outside the image: wrap (tiling), clamp or error",
                choices=BORDERS,
            ),
        ),
        linear=True,
        neighbourhood=True,
        optional_inputs=("source",),
        checks=(check_region,),
        reach=clone_reach,
    ),
)
