"""Triangle meshes for the glTF export: a Wavefront OBJ reader and a UV sphere.

Vertices are split per distinct (position, uv, normal) triple, polygons are
fanned into triangles, and ``v`` is flipped because glTF's texture origin is
the upper-left corner while OBJ's is the lower-left. Tangents are MikkTSpace's
(:mod:`matshop.render.tangent_space`) with the handedness in ``w``, as glTF's
``TANGENT`` wants.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Mesh:
    positions: np.ndarray  #: (N, 3) float32
    normals: np.ndarray  #: (N, 3) float32, unit
    uvs: np.ndarray  #: (N, 2) float32, glTF orientation (v down)
    indices: np.ndarray  #: (T * 3,) uint32, counter-clockwise triangles


def uv_sphere(*, segments: int = 64, rings: int = 32, radius: float = 1.0) -> Mesh:
    """A UV sphere with the seam duplicated so ``u`` runs 0..1 around it."""
    theta = np.linspace(0.0, np.pi, rings + 1)  # from the north pole
    phi = np.linspace(0.0, 2 * np.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(t) * np.cos(p), np.cos(t), -np.sin(t) * np.sin(p)], axis=-1)
    uvs = np.stack([p / (2 * np.pi), t / np.pi], axis=-1)
    cols = segments + 1
    r, s = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    a = (r * cols + s).ravel()
    b, c, d = a + cols, a + cols + 1, a + 1
    indices = np.stack([a, b, c, a, c, d], axis=-1).reshape(-1)
    return Mesh(
        (normals * radius).reshape(-1, 3).astype(np.float32),
        normals.reshape(-1, 3).astype(np.float32),
        uvs.reshape(-1, 2).astype(np.float32),
        _drop_degenerate(indices.astype(np.uint32), normals.reshape(-1, 3)),
    )


def _drop_degenerate(indices: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """Remove zero-area triangles (the fans at a sphere's poles)."""
    tri = positions[indices.reshape(-1, 3)]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return indices.reshape(-1, 3)[area > 1e-12].reshape(-1).astype(np.uint32)


def read_obj(path: str | os.PathLike) -> Mesh:
    """The triangles of an OBJ file, one vertex per distinct (position, uv, normal) corner.

    Parsing is :func:`matshop.render.mesh.load_obj`'s (one OBJ reader for the
    renderer, the viewport and the exporter); vertices keep the order in which
    the faces first use them.
    """
    from ..render.mesh import load_obj

    obj = load_obj(path)
    normal_ids = obj.tri_nrm if obj.tri_nrm is not None else np.full_like(obj.tri_pos, -1)
    keys = np.stack([obj.tri_pos, obj.tri_uv, normal_ids], axis=-1).reshape(-1, 3)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # first use, not sorted keys
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    table = keys[first[order]]
    indices = rank[inverse.reshape(-1)].astype(np.uint32)
    positions = obj.positions[table[:, 0]].astype(np.float32)
    uv = obj.uvs[table[:, 1]].astype(np.float32)
    if obj.normals is not None:
        normals = obj.normals[table[:, 2]].astype(np.float32)
    else:
        normals = _smooth_normals(positions, indices)
    normals = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    uv = np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1)
    return Mesh(
        positions,
        normals.astype(np.float32),
        uv.astype(np.float32),
        _drop_degenerate(indices, positions),
    )


def _smooth_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    tri = indices.reshape(-1, 3)
    p = positions[tri]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    normals = np.zeros_like(positions)
    for k in range(3):
        np.add.at(normals, tri[:, k], face)
    return normals


def tangents(mesh: Mesh) -> np.ndarray:
    """Per-vertex ``(N, 4)`` MikkTSpace tangents along ``+u`` with handedness ``w = +-1``
    (:func:`matshop.render.tangent_space.mikktspace_tangents`, with ``v`` back up)."""
    from ..render.tangent_space import mikktspace_tangents

    v_up = np.stack([mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1]], axis=1)
    return mikktspace_tangents(mesh.positions, mesh.normals, v_up, mesh.indices.reshape(-1, 3))
