"""Triangle meshes for the glTF export: a Wavefront OBJ reader and a UV sphere.

Vertices are split per distinct (position, uv, normal) triple, polygons are
fanned into triangles, and ``v`` is flipped because glTF's texture origin is
the upper-left corner while OBJ's is the lower-left. Tangents follow the
texture's ``u`` direction (Lengyel's per-triangle method, orthogonalised per
vertex) with the handedness in ``w``, as glTF's ``TANGENT`` wants.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MatshopError


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
    """Read the polygons of an OBJ file (``v``, ``vt``, ``vn``, ``f``)."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise MatshopError(f"cannot read mesh: {exc.strerror or exc}", path) from None
    pools: dict[str, list[list[float]]] = {"v": [], "vt": [], "vn": []}
    corners: dict[tuple[int, int, int], int] = {}
    order: list[tuple[int, int, int]] = []
    triangles: list[int] = []
    for number, line in enumerate(lines, 1):
        parts = line.split()
        if not parts or parts[0] not in ("v", "vt", "vn", "f"):
            continue
        try:
            if parts[0] != "f":
                pools[parts[0]].append([float(x) for x in parts[1:4]])
                continue
            face = [_corner(token, pools) for token in parts[1:]]
        except (ValueError, IndexError):
            raise MatshopError(f"line {number}: cannot parse {line.strip()!r}", path) from None
        ids = []
        for corner in face:
            if corner not in corners:
                corners[corner] = len(order)
                order.append(corner)
            ids.append(corners[corner])
        for k in range(1, len(ids) - 1):  # fan: polygons are convex in practice
            triangles += [ids[0], ids[k], ids[k + 1]]
    if not triangles:
        raise MatshopError("no faces in this OBJ file", path)
    table = np.asarray(order, dtype=np.int64)
    if (table[:, 1] < 0).any():
        raise MatshopError("faces without texture coordinates (vt): cannot map textures", path)
    positions = np.asarray(pools["v"], dtype=np.float32)[table[:, 0]]
    uv = np.asarray(pools["vt"], dtype=np.float32)[table[:, 1], :2]
    indices = np.asarray(triangles, dtype=np.uint32)
    if (table[:, 2] >= 0).all():
        normals = np.asarray(pools["vn"], dtype=np.float32)[table[:, 2]]
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


def _corner(token: str, pools: dict[str, list[list[float]]]) -> tuple[int, int, int]:
    fields = (token.split("/") + ["", ""])[:3]
    out = []
    for text, pool in zip(fields, ("v", "vt", "vn"), strict=True):
        if not text:
            out.append(-1)
            continue
        index = int(text)
        index = index - 1 if index > 0 else len(pools[pool]) + index
        if not 0 <= index < len(pools[pool]):
            raise IndexError(index)
        out.append(index)
    if out[0] < 0:
        raise ValueError("a face corner needs a vertex index")
    return out[0], out[1], out[2]


def _smooth_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    tri = indices.reshape(-1, 3)
    p = positions[tri]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    normals = np.zeros_like(positions)
    for k in range(3):
        np.add.at(normals, tri[:, k], face)
    return normals


def tangents(mesh: Mesh) -> np.ndarray:
    """Per-vertex ``(N, 4)`` tangents along ``+u`` with handedness ``w = +-1``.

    Vertices whose triangles give no usable ``u`` direction get any unit
    vector perpendicular to their normal (the validator wants unit tangents).
    """
    tri = mesh.indices.reshape(-1, 3)
    p = mesh.positions[tri].astype(np.float64)
    uv = mesh.uvs[tri].astype(np.float64)
    # glTF v points down the image: derivatives use v_up = -v
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    du1, du2 = uv[:, 1, 0] - uv[:, 0, 0], uv[:, 2, 0] - uv[:, 0, 0]
    dv1, dv2 = -(uv[:, 1, 1] - uv[:, 0, 1]), -(uv[:, 2, 1] - uv[:, 0, 1])
    det = du1 * dv2 - du2 * dv1
    scale = np.where(np.abs(det) > 1e-20, 1.0 / np.where(det == 0, 1.0, det), 0.0)[:, None]
    t_face = (e1 * dv2[:, None] - e2 * dv1[:, None]) * scale
    b_face = (e2 * du1[:, None] - e1 * du2[:, None]) * scale
    t_acc = np.zeros((len(mesh.positions), 3))
    b_acc = np.zeros((len(mesh.positions), 3))
    for k in range(3):
        np.add.at(t_acc, tri[:, k], t_face)
        np.add.at(b_acc, tri[:, k], b_face)
    n = mesh.normals.astype(np.float64)
    t = t_acc - n * np.sum(n * t_acc, axis=1, keepdims=True)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    fallback = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
    fallback = np.cross(fallback, n)
    fallback /= np.linalg.norm(fallback, axis=1, keepdims=True)
    t = np.where(length > 1e-12, t / np.maximum(length, 1e-300), fallback)
    w = np.where(np.sum(np.cross(n, t) * b_acc, axis=1) < 0.0, -1.0, 1.0)
    return np.concatenate([t, w[:, None]], axis=1).astype(np.float32)
