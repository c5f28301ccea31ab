"""Object-space symmetry for painting on a mesh: a mirror plane and a dab's image across it.

Painter's way: the plane is one of the mesh's own axis planes (``x``, ``y`` or
``z`` in object space), through the centre of the mesh's bounding box or at
an offset along the axis. A dab at surface point ``p`` also paints at the
point of the surface nearest to ``p``'s reflection ``R p``: on a symmetric
mesh that is ``R p`` itself, on a nearly symmetric one the closest point
still lands on the surface. The image has its own texture coordinate (the
surface's there, in whatever UV chart the mirrored side lies, mirrored
layouts and separate islands alike) and its own texel size, so it is the
dab an independent stroke at ``R p`` would paint. The brush's frame is
mirrored with it: the normal is reflected (then the surface's own normal at
the image point, turned to agree with it, decides which side is painted),
and a 3D dab is a ball, the same in every direction, so nothing else of the
frame needs turning.

Pure numpy (no GL): the meshes are :class:`~.mesh_data.MeshData`; the
nearest-point search is a KD-tree over triangle centroids (scipy), then the
exact closest point on each candidate triangle.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ...errors import InvalidValue
from .mesh_data import MeshData
from .picking import SurfaceHit

AXES = ("x", "y", "z")
#: triangles whose centroids are nearest to a point, tried one at a time first
_NEAREST = 8


@dataclass(frozen=True)
class MirrorPlane:
    """The plane ``axis = centre + offset`` of a mesh's object space.

    ``offset`` is along the axis from the mesh's bounding-box centre, in the
    mesh's units as shown (an opened mesh is scaled into the unit sphere, so
    there it is a fraction of the mesh's bounding radius).
    """

    axis: str = "x"
    offset: float = 0.0

    def __post_init__(self) -> None:
        if self.axis not in AXES:
            raise InvalidValue(f"mirror axis must be x, y or z, got {self.axis!r}")
        if not np.isfinite(self.offset):
            raise InvalidValue(f"mirror offset must be finite, got {self.offset!r}")

    @property
    def normal(self) -> np.ndarray:
        return np.eye(3)[AXES.index(self.axis)]

    def point(self, mesh: MeshData) -> np.ndarray:
        """A point of the plane: the bounding box's centre moved by ``offset`` along the axis."""
        positions = mesh.positions.astype(np.float64)
        centre = 0.5 * (positions.min(axis=0) + positions.max(axis=0))
        return centre + self.offset * self.normal

    def reflect(self, points: np.ndarray, through: np.ndarray) -> np.ndarray:
        """``points (..., 3)`` reflected across the plane through point ``through``
        (:meth:`point`, computed once per mesh by the caller)."""
        k = AXES.index(self.axis)
        out = np.array(points, dtype=np.float64)
        out[..., k] = 2.0 * through[k] - out[..., k]
        return out

    def reflect_vector(self, vectors: np.ndarray) -> np.ndarray:
        """Directions ``(..., 3)`` reflected (the plane's point does not matter)."""
        out = np.array(vectors, dtype=np.float64)
        out[..., AXES.index(self.axis)] *= -1.0
        return out


def closest_on_triangles(
    point: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Closest points of triangles ``a, b, c (N, 3)`` to ``point``: ``(points, barycentric)``.

    Ericson's region test (Real-Time Collision Detection, 5.1.5), vectorised:
    the vertex, edge or face region the point projects into decides the answer.
    """
    p = np.asarray(point, dtype=np.float64)[None, :]
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.sum(ab * ap, 1), np.sum(ac * ap, 1)
    bp = p - b
    d3, d4 = np.sum(ab * bp, 1), np.sum(ac * bp, 1)
    cp = p - c
    d5, d6 = np.sum(ab * cp, 1), np.sum(ac * cp, 1)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v_face = vb / denom
        w_face = vc / denom
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        bary = np.stack([1.0 - v_face - w_face, v_face, w_face], axis=1)  # the face region
    n = len(a)
    regions = [  # (where, barycentric), later rows win: vertices before edges before face
        ((vc <= 0) & (d1 - d3 != 0) & (d1 >= 0) & (d3 <= 0), _bary(n, 0, 1, t_ab)),
        ((vb <= 0) & (d2 - d6 != 0) & (d2 >= 0) & (d6 <= 0), _bary(n, 0, 2, t_ac)),
        (
            (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0) & (d4 - d3 + d5 - d6 != 0),
            _bary(n, 1, 2, t_bc),
        ),
        ((d1 <= 0) & (d2 <= 0), _bary(n, 0, 0, 0.0)),
        ((d3 >= 0) & (d4 <= d3), _bary(n, 1, 1, 0.0)),
        ((d6 >= 0) & (d5 <= d6), _bary(n, 2, 2, 0.0)),
    ]
    for where, value in regions:
        bary[where] = value[where]
    bary = np.nan_to_num(bary, nan=1.0 / 3.0)  # degenerate triangles: their centroid
    points = bary[:, :1] * a + bary[:, 1:2] * b + bary[:, 2:] * c
    return points, bary


def _dot(u: Sequence[float], v: Sequence[float]) -> float:
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _less(u: Sequence[float], v: Sequence[float]) -> tuple[float, float, float]:
    return (u[0] - v[0], u[1] - v[1], u[2] - v[2])


def closest_on_triangle(
    p: Sequence[float], a: Sequence[float], b: Sequence[float], c: Sequence[float]
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """:func:`closest_on_triangles` of one triangle in plain floats: ``(point, barycentric)``.

    The same operations in the same order, so the same bits; numpy's dozens of
    calls on a handful of triangles cost far more than their arithmetic, and
    the mirror asks for a few triangles a dab. The regions are tried in the
    order in which the vectorised form lets them win.
    """
    ab, ac, ap = _less(b, a), _less(c, a), _less(p, a)
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = _less(p, b)
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = _less(p, c)
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    if d6 >= 0 and d5 <= d6:
        bary = (0.0, 0.0, 1.0)
    elif d3 >= 0 and d4 <= d3:
        bary = (0.0, 1.0, 0.0)
    elif d1 <= 0 and d2 <= 0:
        bary = (1.0, 0.0, 0.0)
    elif va <= 0 and (d4 - d3) >= 0 and (d5 - d6) >= 0 and d4 - d3 + d5 - d6 != 0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        bary = (0.0, 1.0 - t, t)
    elif vb <= 0 and d2 - d6 != 0 and d2 >= 0 and d6 <= 0:
        t = d2 / (d2 - d6)
        bary = (1.0 - t, 0.0, t)
    elif vc <= 0 and d1 - d3 != 0 and d1 >= 0 and d3 <= 0:
        t = d1 / (d1 - d3)
        bary = (1.0 - t, t, 0.0)
    else:
        denom = va + vb + vc
        if denom == 0 or not math.isfinite(denom):  # degenerate: what numpy's NaNs give
            points, barys = closest_on_triangles(
                np.asarray(p), *(np.asarray([v]) for v in (a, b, c))
            )
            return tuple(points[0].tolist()), tuple(barys[0].tolist())
        v, w = vb / denom, vc / denom
        bary = (1.0 - v - w, v, w)
    point = tuple(bary[0] * a[k] + bary[1] * b[k] + bary[2] * c[k] for k in range(3))
    return point, bary


def _bary(n: int, i: int, j: int, t) -> np.ndarray:
    """Barycentric coordinates of the point ``t`` of the way from corner ``i`` to ``j``."""
    out = np.zeros((n, 3))
    t = np.broadcast_to(np.asarray(t, dtype=np.float64), (n,))
    out[:, i] += 1.0 - t
    out[:, j] += t
    return out


class MeshMirror:
    """Finds the image of a surface point across ``plane`` on ``mesh`` (see the module doc)."""

    def __init__(
        self, mesh: MeshData, plane: MirrorPlane, *, uv_scale: tuple[float, float] = (1.0, 1.0)
    ) -> None:
        self.mesh = mesh
        self.plane = plane
        self.uv_scale = np.asarray(uv_scale, dtype=np.float64)
        self._through = plane.point(mesh)
        corners = mesh.positions.astype(np.float64)[mesh.indices.astype(np.int64)]
        self._corners = corners  # (T, 3, 3)
        centroids = corners.mean(axis=1)
        self._tree = cKDTree(centroids)
        # a triangle's points all lie within this of its centroid
        self._reach = float(np.linalg.norm(corners - centroids[:, None, :], axis=2).max())

    def closest(self, point: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
        """``(triangle, closest point, barycentric)`` of the surface nearest to ``point``.

        The triangles of the nearest centroids first, one at a time, until the
        next centroid is so far that none of its triangle's points (all within
        ``reach`` of it) can be nearer; only when the few nearest centroids do
        not settle it, every triangle within reach at once.
        """
        count = min(_NEAREST, len(self._corners))
        distances, order = self._tree.query(point, k=count)
        p = tuple(np.asarray(point, dtype=np.float64).tolist())
        best, best_squared = None, math.inf
        for distance, triangle in zip(np.atleast_1d(distances), np.atleast_1d(order), strict=True):
            if distance - self._reach >= math.sqrt(best_squared):
                break
            # one triangle's corners as floats (a list of every triangle's took 0.37 s
            # to build for a 65k-triangle mesh)
            a, b, c = self._corners[triangle].tolist()
            found, bary = closest_on_triangle(p, a, b, c)
            offset = _less(found, p)
            squared = _dot(offset, offset)
            if squared < best_squared:
                best, best_squared = (int(triangle), found, bary), squared
        else:
            if count < len(self._corners):
                best = None  # the triangles past the nearest few are not ruled out
        if best is None:  # that, or no finite distance at all
            return self._closest_among_all(point, float(np.atleast_1d(distances)[0]))
        triangle, found, bary = best
        return triangle, np.array(found), np.array(bary)

    def _closest_among_all(
        self, point: np.ndarray, nearest: float
    ) -> tuple[int, np.ndarray, np.ndarray]:
        """:meth:`closest` over every triangle whose centroid is within reach, vectorised."""
        # no triangle with every centroid farther than this can hold a nearer point
        bound = nearest + self._reach
        candidates = np.asarray(self._tree.query_ball_point(point, bound), dtype=np.int64)
        tris = self._corners[candidates]
        points, bary = closest_on_triangles(point, tris[:, 0], tris[:, 1], tris[:, 2])
        best = int(np.argmin(np.sum((points - point) ** 2, axis=1)))
        return int(candidates[best]), points[best], bary[best]

    def image(self, hit: SurfaceHit) -> SurfaceHit:
        """The dab frame of ``hit`` mirrored: on the surface nearest to its reflection."""
        target = self.plane.reflect(hit.position, self._through)
        triangle, position, bary = self.closest(target)
        corners = self.mesh.indices[triangle].astype(np.int64)
        normal = bary @ self.mesh.normals[corners].astype(np.float64)
        normal /= max(float(np.linalg.norm(normal)), 1e-12)
        if normal @ self.plane.reflect_vector(hit.normal) < 0.0:
            normal = -normal  # a two-sided surface: paint the side the mirrored dab faces
        uv = (bary @ self.mesh.uvs[corners].astype(np.float64)) * self.uv_scale
        return SurfaceHit(position=position, normal=normal, uv=uv)
