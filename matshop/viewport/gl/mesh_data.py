"""Meshes as flat vertex arrays ready for a VAO: OBJ, glTF, or a procedural sphere.

A :class:`MeshData` has one vertex per distinct (position, uv, normal) corner,
so UV seams and hard edges split vertices the way a GPU needs. Missing
normals are computed (area-weighted, smooth per position); missing tangents
are computed per vertex from the UV derivatives of the adjacent triangles
(the MikkTSpace idea without its tie-breaking rules): ``dP/du`` and ``dP/dv``
of each triangle are accumulated, Gram-Schmidt'ed against the normal, and the
handedness ``w = sign((n x t) . dP/dv)`` is stored so mirrored UVs keep the
bitangent along ``+v`` (the convention of :mod:`matshop.render.scenes`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import MatshopError
from ...render.tangent_space import mikktspace_tangents


@dataclass
class MeshData:
    """Per-vertex ``positions (V, 3)``, ``normals (V, 3)``, ``tangents (V, 4)``, ``uvs (V, 2)``
    float32 and triangle ``indices (T, 3)`` uint32."""

    positions: np.ndarray
    normals: np.ndarray
    tangents: np.ndarray
    uvs: np.ndarray
    indices: np.ndarray
    name: str = "mesh"

    @property
    def triangle_count(self) -> int:
        return int(self.indices.shape[0])

    def corners(self, attribute: np.ndarray) -> np.ndarray:
        """``attribute`` at the corners of every triangle: ``(T, 3, C)``."""
        return attribute[self.indices]


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-20)


def smooth_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals ``(V, 3)`` (the cross product's length is twice the area)."""
    tri = positions[indices]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    out = np.zeros_like(positions, dtype=np.float64)
    for k in range(3):
        np.add.at(out, indices[:, k], face)
    return _unit(out)


def compute_tangents(
    positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray, indices: np.ndarray
) -> np.ndarray:
    """Per-vertex tangents ``(V, 4)``: MikkTSpace's, as the exporters write them."""
    return mikktspace_tangents(positions, normals, uvs, indices)


def build(
    positions: np.ndarray,
    uvs: np.ndarray,
    indices: np.ndarray,
    *,
    normals: np.ndarray | None = None,
    tangents: np.ndarray | None = None,
    name: str = "mesh",
    normalize: bool = False,
) -> MeshData:
    """A :class:`MeshData` from per-vertex arrays, filling in normals and tangents."""
    positions = np.asarray(positions, dtype=np.float64)
    if normalize:
        # into the unit sphere, as the reference renderer's mesh scene does
        centre = 0.5 * (positions.min(axis=0) + positions.max(axis=0))
        radius = np.linalg.norm(positions - centre, axis=1).max()
        positions = (positions - centre) / max(radius, 1e-12)
    indices = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    normals = smooth_normals(positions, indices) if normals is None else _unit(normals)
    if tangents is None:
        tangents = compute_tangents(positions, normals, uvs, indices)
    return MeshData(
        positions=positions.astype(np.float32),
        normals=np.asarray(normals, dtype=np.float32),
        tangents=np.asarray(tangents, dtype=np.float32),
        uvs=np.asarray(uvs, dtype=np.float32),
        indices=indices.astype(np.uint32),
        name=name,
    )


def from_obj(path: str | os.PathLike[str], *, normalize: bool = True) -> MeshData:
    """An OBJ (via :func:`matshop.render.mesh.load_obj`), split into GPU vertices."""
    from ...render.mesh import load_obj

    mesh = load_obj(path)
    nrm = mesh.tri_nrm if mesh.tri_nrm is not None else np.full_like(mesh.tri_pos, -1)
    keys = np.stack([mesh.tri_pos, mesh.tri_uv, nrm], axis=-1).reshape(-1, 3)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    indices = inverse.reshape(-1, 3)
    positions = mesh.positions[unique[:, 0]]
    uvs = mesh.uvs[unique[:, 1]]
    normals = None
    if mesh.normals is not None:
        normals = mesh.normals[unique[:, 2]]
    else:
        # smooth over shared positions, not over the split GPU vertices
        per_position = smooth_normals(mesh.positions, mesh.tri_pos)
        normals = per_position[unique[:, 0]]
    return build(
        positions, uvs, indices, normals=normals, name=Path(path).stem, normalize=normalize
    )


def from_gltf(path: str | os.PathLike[str], *, normalize: bool = True) -> MeshData:
    """Every triangle primitive of a .gltf/.glb (node transforms ignored), merged."""
    import pygltflib

    gltf = pygltflib.GLTF2().load(str(path))
    if gltf is None or not gltf.meshes:
        raise MatshopError("no meshes in the glTF file", path)

    def read(accessor_index: int) -> np.ndarray:
        accessor = gltf.accessors[accessor_index]
        view = gltf.bufferViews[accessor.bufferView]
        buffer = gltf.buffers[view.buffer]
        data = gltf.get_data_from_buffer_uri(buffer.uri) if buffer.uri else gltf.binary_blob()
        dtype = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}[
            accessor.componentType
        ]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[accessor.type]
        start = (view.byteOffset or 0) + (accessor.byteOffset or 0)
        item = np.dtype(dtype).itemsize * width
        stride = view.byteStride or item
        raw = np.frombuffer(
            data, dtype=np.uint8, count=stride * (accessor.count - 1) + item, offset=start
        )
        rows = np.lib.stride_tricks.as_strided(raw, (accessor.count, item), (stride, 1))
        return np.ascontiguousarray(rows).view(dtype).reshape(accessor.count, width)

    parts: list[tuple[np.ndarray, ...]] = []
    base = 0
    for mesh in gltf.meshes:
        for prim in mesh.primitives:
            if prim.mode not in (None, 4):  # 4 = TRIANGLES
                continue
            attrs = prim.attributes
            if attrs.TEXCOORD_0 is None:
                raise MatshopError("a glTF primitive has no TEXCOORD_0: no texture can map", path)
            pos = read(attrs.POSITION)
            uv = read(attrs.TEXCOORD_0).astype(np.float64)
            uv[:, 1] = 1.0 - uv[:, 1]  # glTF's v points down the image; ours up
            nrm = read(attrs.NORMAL) if attrs.NORMAL is not None else None
            tan = read(attrs.TANGENT) if attrs.TANGENT is not None else None
            idx = (
                read(prim.indices).reshape(-1) if prim.indices is not None else np.arange(len(pos))
            )
            parts.append((pos, uv, nrm, tan, idx.astype(np.int64) + base))
            base += len(pos)
    if not parts:
        raise MatshopError("no triangle primitives in the glTF file", path)
    positions = np.concatenate([p[0] for p in parts])
    uvs = np.concatenate([p[1] for p in parts])
    normals = (
        np.concatenate([p[2] for p in parts]) if all(p[2] is not None for p in parts) else None
    )
    tangents = None
    if all(p[3] is not None for p in parts):
        # flipping v mirrors the tangent frame: the handedness flips with it
        tangents = np.concatenate([p[3] for p in parts]).astype(np.float32)
        tangents[:, 3] *= -1.0
    indices = np.concatenate([p[4] for p in parts])
    return build(
        positions,
        uvs,
        indices,
        normals=normals,
        tangents=tangents,
        name=Path(path).stem,
        normalize=normalize,
    )


def load_mesh(path: str | os.PathLike[str], *, normalize: bool = True) -> MeshData:
    """An .obj, .gltf or .glb file."""
    suffix = Path(path).suffix.lower()
    if suffix == ".obj":
        return from_obj(path, normalize=normalize)
    if suffix in (".gltf", ".glb"):
        return from_gltf(path, normalize=normalize)
    raise MatshopError("unknown mesh format (use .obj, .gltf or .glb)", path)


def uv_sphere(segments: int = 256, rings: int = 128) -> MeshData:
    """The reference renderer's sphere as triangles: unit radius, ``u`` = longitude from
    ``+z`` towards ``+x`` plus 1/2, ``v`` = latitude / pi + 1/2 (:func:`scenes.sphere`)."""
    u = np.arange(segments + 1) / segments  # the seam column is duplicated
    v = np.arange(rings + 1) / rings
    phi = 2.0 * np.pi * (u[None, :] - 0.5)
    lat = np.pi * (v[:, None] - 0.5)
    n = np.stack(
        np.broadcast_arrays(np.sin(phi) * np.cos(lat), np.sin(lat), np.cos(phi) * np.cos(lat)),
        axis=-1,
    ).reshape(-1, 3)
    tangent = np.stack(
        np.broadcast_arrays(np.cos(phi), 0.0 * lat, -np.sin(phi), 1.0 + 0.0 * lat), axis=-1
    ).reshape(-1, 4)
    uvs = np.stack(np.broadcast_arrays(u[None, :], v[:, None]), axis=-1).reshape(-1, 2)
    row = segments + 1
    i, j = np.mgrid[0:rings, 0:segments]
    a = (i * row + j).ravel()
    b, c, d = a + 1, a + row + 1, a + row
    indices = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return build(n, uvs, indices, normals=n, tangents=tangent, name="uv-sphere")
