"""Per-vertex tangent frames the MikkTSpace way: the one tangent rule of the
exporters (glTF ``TANGENT``, USD ``primvars:tangents``) and the GL viewport.

Normal maps are baked against MikkTSpace tangents (Blender, Substance,
xNormal; glTF's default when ``TANGENT`` is absent), so a mesh's written
tangents follow its accumulation (Mikkelsen 2008, ``mikktspace.c``):

1. per triangle, ``dP/du`` and ``dP/dv`` from the positions and ``uv``;
2. at each corner, both projected onto the plane of the vertex normal and
   normalised, then weighted by the corner's angle in that plane (so neither
   a sliver nor a big triangle dominates a vertex);
3. the vertex tangent is the normalised sum; the handedness ``w = +-1`` says
   whether the summed ``dP/dv`` lies along ``cross(N, T)`` (mirrored ``uv``
   give ``-1``).

Like MikkTSpace, corners with equal position, normal and ``uv`` values are one
vertex even when the mesh lists them twice, and triangles of opposite ``uv``
handedness are never summed together (a mirror seam's two sides). Two cases
where MikkTSpace gives one mesh vertex several frames cannot be written per
vertex and keep one: a vertex whose own triangles disagree in handedness (the
majority, angle-weighted, wins) and a vertex whose triangles form fans not
joined by edges around it. Measured against ``mikktspace.c`` (see
``tests/data/mikktspace_reference.npz``): within 0.04 degrees elsewhere.
``uv`` here has ``v`` up (OBJ, USD, OpenGL).
"""

from __future__ import annotations

import numpy as np


def _unit(vectors: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(vectors, axis=-1, keepdims=True)
    return np.where(length > 1e-20, vectors / np.maximum(length, 1e-300), 0.0)


def _in_plane(vectors: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """``vectors`` projected onto the planes of unit ``normals``, normalised (0 if degenerate)."""
    return _unit(vectors - normals * np.sum(vectors * normals, axis=-1, keepdims=True))


def mikktspace_tangents(
    positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray, triangles: np.ndarray
) -> np.ndarray:
    """``(V, 4)`` float32 unit tangents along ``+u`` and handedness ``w = +-1``.

    ``positions``/``normals`` ``(V, 3)``, ``uvs`` ``(V, 2)`` with ``v`` up,
    ``triangles`` ``(T, 3)`` vertex indices. A vertex whose triangles give no
    ``u`` direction (a pole, a collapsed island) gets a unit vector
    perpendicular to its normal.
    """
    # corners with equal position, normal and uv are one vertex to MikkTSpace (it welds
    # by value), even when a mesh lists them twice: accumulate over those groups
    keys = np.concatenate([positions, normals, uvs], axis=1).astype(np.float32)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    group = group.reshape(-1)
    tri = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    p = np.asarray(positions, dtype=np.float64)[tri]
    t = np.asarray(uvs, dtype=np.float64)[tri]
    n_all = _unit(np.asarray(normals, dtype=np.float64))
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    sign = np.where(det < 0.0, -1.0, 1.0)[:, None]
    live = (np.abs(det) > 1e-20)[:, None]
    # dP/du and dP/dv up to the positive factor |det|
    dpdu = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * sign
    dpdv = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * sign
    # sums per (welded vertex, uv orientation): MikkTSpace never mixes the two handednesses
    flipped = (det < 0.0).astype(np.int64)
    sum_u = np.zeros((2 * len(n_all), 3))
    sum_v = np.zeros((2 * len(n_all), 3))
    handed = np.zeros(len(n_all))  # per mesh vertex: angle-weighted orientation of its corners
    for k in range(3):
        vertex = tri[:, k]
        n = n_all[vertex]
        to_next = _in_plane(p[:, (k + 1) % 3] - p[:, k], n)
        to_prev = _in_plane(p[:, (k + 2) % 3] - p[:, k], n)
        angle = np.arccos(np.clip(np.sum(to_next * to_prev, axis=1), -1.0, 1.0))[:, None]
        weight = np.where(live, angle, 0.0)
        key = 2 * group[vertex] + flipped
        np.add.at(sum_u, key, _in_plane(dpdu, n) * weight)
        np.add.at(sum_v, key, _in_plane(dpdv, n) * weight)
        np.add.at(handed, vertex, weight[:, 0] * sign[:, 0])
    own = 2 * group + (handed < 0.0)  # a vertex takes the orientation most of its corners have
    sum_u, sum_v = sum_u[own], sum_v[own]
    tangent = _in_plane(sum_u, n_all)
    # degenerate uv: any vector orthogonal to n
    axis = np.where(np.abs(n_all[:, 1:2]) < 0.9, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
    fallback = _unit(np.cross(n_all, axis))
    missing = np.linalg.norm(tangent, axis=1, keepdims=True) < 0.5
    tangent = np.where(missing, fallback, tangent)
    w = np.where(np.sum(np.cross(n_all, tangent) * sum_v, axis=1) < 0.0, -1.0, 1.0)
    return np.concatenate([tangent, w[:, None]], axis=1).astype(np.float32)
