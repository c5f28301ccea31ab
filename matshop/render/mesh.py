"""A user's OBJ mesh as a geometry buffer: load, normalise, rasterise from the fixed camera.

Loading keeps positions, texture coordinates and normals (``v``, ``vt``, ``vn``;
polygons are fanned into triangles; a mesh without ``vt`` cannot carry a
texture and is refused). The mesh is centred and scaled into the unit
sphere, so the sphere scene's camera frames it the same way.

Rasterising is a z-buffer over triangles in a numba kernel (one triangle at
a time; Python would spend seconds on a few thousand). Each pixel gets the
nearest triangle and perspective-correct barycentrics; normals and ``uv`` are
interpolated, the tangent is the triangle's ``dP/du`` made orthogonal to the
interpolated normal (flat per triangle, enough for a reference view).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import MatshopError
from .scenes import CAMERA_DISTANCE, HALF_FOV, GBuffer, camera_rays


@dataclass
class Mesh:
    """Triangles with per-corner attributes: ``(T, 3)`` indices into each array."""

    positions: np.ndarray  # (V, 3)
    uvs: np.ndarray  # (U, 2)
    normals: np.ndarray | None  # (N, 3)
    tri_pos: np.ndarray  # (T, 3) int
    tri_uv: np.ndarray  # (T, 3) int
    tri_nrm: np.ndarray | None  # (T, 3) int


def load_obj(path: str | os.PathLike[str]) -> Mesh:
    """Read the geometry of a Wavefront OBJ (materials and groups are ignored)."""
    pos: list[list[float]] = []
    uv: list[list[float]] = []
    nrm: list[list[float]] = []
    faces: list[list[tuple[int, int, int]]] = []
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            for number, line in enumerate(fh, 1):
                parts = line.split()
                if not parts:
                    continue
                tag = parts[0]
                try:
                    if tag == "v":
                        pos.append([float(x) for x in parts[1:4]])
                    elif tag == "vt":
                        uv.append([float(x) for x in parts[1:3]])
                    elif tag == "vn":
                        nrm.append([float(x) for x in parts[1:4]])
                    elif tag == "f":
                        faces.append([_corner(c, len(pos), len(uv), len(nrm)) for c in parts[1:]])
                except (ValueError, IndexError):
                    raise MatshopError(
                        f"line {number}: cannot read {line.strip()!r}", path
                    ) from None
    except OSError as exc:
        raise MatshopError(exc.strerror or "cannot read", path) from None
    if not faces or not pos:
        raise MatshopError("no faces in the mesh", path)
    if not uv:
        raise MatshopError(
            "the mesh has no texture coordinates (vt): a texture cannot map onto it", path
        )
    tris = [(f[0], f[k], f[k + 1]) for f in faces for k in range(1, len(f) - 1)]
    corners = np.array(tris, dtype=np.int64)  # (T, 3, 3): position, uv, normal index
    if corners.size == 0 or np.any(corners[..., 1] < 0):
        raise MatshopError("every face corner needs a texture coordinate (v/vt)", path)
    has_normals = bool(nrm) and np.all(corners[..., 2] >= 0)
    return Mesh(
        positions=np.array(pos, dtype=np.float64),
        uvs=np.array(uv, dtype=np.float64),
        normals=np.array(nrm, dtype=np.float64) if has_normals else None,
        tri_pos=corners[..., 0],
        tri_uv=corners[..., 1],
        tri_nrm=corners[..., 2] if has_normals else None,
    )


def _corner(text: str, n_pos: int, n_uv: int, n_nrm: int) -> tuple[int, int, int]:
    fields = (text.split("/") + ["", ""])[:3]

    def index(value: str, count: int) -> int:
        if not value:
            return -1
        i = int(value)
        i = i - 1 if i > 0 else count + i  # OBJ is 1-based; negatives count back
        if not 0 <= i < count:
            raise IndexError(value)
        return i

    return index(fields[0], n_pos), index(fields[1], n_uv), index(fields[2], n_nrm)


@njit(cache=True, nogil=True)  # arrays only: other threads (the GUI) run meanwhile
def _rasterize(sx, sy, depth, tris, height, width, zbuf, tri_id, bary):
    for t in range(tris.shape[0]):
        a, b, c = tris[t, 0], tris[t, 1], tris[t, 2]
        ax, ay, bx, by, cx, cy = sx[a], sy[a], sx[b], sy[b], sx[c], sy[c]
        area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if abs(area) < 1e-12:
            continue
        x0 = max(int(np.floor(min(ax, bx, cx))), 0)
        x1 = min(int(np.ceil(max(ax, bx, cx))), width - 1)
        y0 = max(int(np.floor(min(ay, by, cy))), 0)
        y1 = min(int(np.ceil(max(ay, by, cy))), height - 1)
        for y in range(y0, y1 + 1):
            py = y + 0.5
            for x in range(x0, x1 + 1):
                px = x + 0.5
                w0 = ((bx - px) * (cy - py) - (by - py) * (cx - px)) / area
                w1 = ((cx - px) * (ay - py) - (cy - py) * (ax - px)) / area
                w2 = 1.0 - w0 - w1
                if w0 < 0.0 or w1 < 0.0 or w2 < 0.0:
                    continue
                # perspective-correct: interpolate 1/z linearly in screen space
                inv = w0 / depth[a] + w1 / depth[b] + w2 / depth[c]
                z = 1.0 / inv
                if z < zbuf[y, x]:
                    zbuf[y, x] = z
                    tri_id[y, x] = t
                    bary[y, x, 0] = w0 / depth[a] * z
                    bary[y, x, 1] = w1 / depth[b] * z
                    bary[y, x, 2] = w2 / depth[c] * z


def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _view_rotation(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    y, x = np.radians(yaw_deg), np.radians(pitch_deg)
    yaw = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    pitch = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    return pitch @ yaw


def mesh_gbuffer(mesh: Mesh, size: int, *, tiles: float | tuple[float, float] = 1.0) -> GBuffer:
    """Rasterise ``mesh`` (normalised into the unit sphere, turned to a three-quarter view)."""
    p = mesh.positions
    centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
    radius = np.linalg.norm(p - centre, axis=1).max()
    # a three-quarter view (yaw 30, pitch 20 degrees): a cube shows three faces
    rot = _view_rotation(30.0, 20.0)
    p = ((p - centre) / max(radius, 1e-12)) @ rot.T
    depth = CAMERA_DISTANCE - p[:, 2]
    if np.any(depth <= 1e-6):
        raise MatshopError("mesh crosses the camera plane after normalisation")
    tan_f = np.tan(HALF_FOV)
    sx = (p[:, 0] / (depth * tan_f) + 1.0) * 0.5 * size
    sy = (1.0 - p[:, 1] / (depth * tan_f)) * 0.5 * size
    zbuf = np.full((size, size), np.inf)
    tri_id = np.full((size, size), -1, dtype=np.int64)
    bary = np.zeros((size, size, 3))
    _rasterize(sx, sy, depth, mesh.tri_pos, size, size, zbuf, tri_id, bary)
    mask = tri_id >= 0
    t = tri_id[mask]
    w = bary[mask]

    def interp(values: np.ndarray, index: np.ndarray) -> np.ndarray:
        corners = values[index[t]]  # (P, 3, C)
        return np.einsum("pk,pkc->pc", w, corners)

    tu, tv = (tiles, tiles) if np.isscalar(tiles) else tiles
    uv = interp(mesh.uvs, mesh.tri_uv) * np.array([tu, tv])
    # triangle geometry: face normal and dP/du
    tri = p[mesh.tri_pos]  # (T, 3, 3)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    face_n = _normalize(np.cross(e1, e2))
    tuv = mesh.uvs[mesh.tri_uv]
    d1, d2 = tuv[:, 1] - tuv[:, 0], tuv[:, 2] - tuv[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    safe = np.where(np.abs(det) > 1e-12, det, 1.0)
    face_t = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) / safe[:, None]
    face_b = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) / safe[:, None]
    normal = (
        _normalize(interp(mesh.normals @ rot.T, mesh.tri_nrm))
        if mesh.normals is not None
        else face_n[t]
    )
    origin, rays = camera_rays(size)
    d = rays[mask]
    view = -d
    # two-sided: a triangle seen from behind shades its back side
    flip = np.sum(normal * view, axis=1) < 0.0
    normal[flip] *= -1.0
    tangent = face_t[t]
    tangent = _normalize(tangent - normal * np.sum(tangent * normal, axis=1, keepdims=True))
    bitangent = np.cross(normal, tangent)
    # mirrored UVs: keep the bitangent along +v
    mirrored = np.sum(bitangent * face_b[t], axis=1) < 0.0
    bitangent[mirrored] *= -1.0
    pixel_world = 2.0 * tan_f * (CAMERA_DISTANCE - 1.0) / size
    uv_extent = max(float(np.ptp(mesh.uvs[:, 0])), float(np.ptp(mesh.uvs[:, 1])), 1e-6)
    return GBuffer(
        mask=mask,
        uv=uv,
        normal=normal,
        tangent=tangent,
        bitangent=bitangent,
        view=view,
        uv_per_pixel=pixel_world * uv_extent * max(tu, tv) / 2.0,
        rays=rays,
    )
