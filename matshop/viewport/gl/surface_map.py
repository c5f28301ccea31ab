"""Every texel's point on the surface: the UV-space bake behind 3D dabs.

The mesh is drawn with its texture coordinates as screen positions into a
float framebuffer the size of the document, so every texel centre receives
the world position and normal of the surface point that shows it, and the
world length of one texel there (``sqrt(world area / texel area)`` of its
triangle). A dab is then a ball in world space: it paints the texels whose
surface point lies inside it (:mod:`.painting`), whichever UV island or side
of a seam they belong to.

- **Repeats.** Texture coordinates past 1 repeat the texture (the sphere's
  ``uv_scale`` of 2 around, the shared cube's faces in cells up to u = 3), so
  one texel can show at several surface points. Triangles are grouped by the
  integer uv cell of their centroid and each cell is baked into its own
  layer; a texel is painted when any of its points is inside the ball.
- **Edge padding.** Texels no triangle covers (gutters between islands, the
  rim of an island) take the point of the nearest covered texel, up to
  ``pad`` texels away, so paint reaching an island's edge also fills the
  gutter beside it and bilinear/mip filtering at the seam never mixes in
  unpainted texels.
- **Finding texels fast.** Each layer keeps per-tile bounding boxes of its
  points; a dab only looks inside tiles whose box meets the ball.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np
from OpenGL import GL
from scipy import ndimage

from ...layers.geometry import TileKey, TileLayout
from . import shaders
from .fbo import Framebuffer
from .mesh_data import MeshData

DEFAULT_PAD = 4


@dataclass
class SurfaceLayer:
    """One uv cell's bake: ``(H, W)`` arrays in document texel order (row 0 = v = 1)."""

    cell: tuple[int, int]
    position: np.ndarray  # (H, W, 3) float32
    normal: np.ndarray  # (H, W, 3) float32
    texel_world: np.ndarray  # (H, W) float32, 0 where invalid
    valid: np.ndarray  # (H, W) bool: covered or padded
    box_min: np.ndarray  # (TY, TX, 3) per-tile bounds of valid points (+inf when none)
    box_max: np.ndarray  # (TY, TX, 3)


def _cells(uvs: np.ndarray, indices: np.ndarray) -> np.ndarray:
    centroid = uvs[indices].mean(axis=1)
    return np.floor(centroid).astype(np.int64)


def _texel_world(mesh: MeshData, uvs: np.ndarray, width: int, height: int) -> np.ndarray:
    """World length of a texel per triangle ``(T,)``."""
    p = mesh.positions[mesh.indices].astype(np.float64)
    t = uvs[mesh.indices].astype(np.float64)
    world = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    texels = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]) * width * height
    return np.sqrt(world / np.maximum(texels, 1e-20))


class SurfaceMap:
    """The bake of ``mesh`` (with ``uv_scale``) over a document's texels (needs a context)."""

    def __init__(
        self,
        mesh: MeshData,
        layout: TileLayout,
        *,
        uv_scale: tuple[float, float] = (1.0, 1.0),
        pad: int = DEFAULT_PAD,
    ) -> None:
        self.layout = layout
        self.width, self.height = layout.width, layout.height
        uvs = mesh.uvs.astype(np.float64) * np.asarray(uv_scale, dtype=np.float64)
        cells = _cells(uvs, mesh.indices.astype(np.int64))
        texel_world = _texel_world(mesh, uvs, self.width, self.height)
        program = shaders.Program(shaders.BAKE_VERTEX, shaders.BAKE_FRAGMENT)
        self.layers: list[SurfaceLayer] = []
        try:
            for cell in np.unique(cells, axis=0):
                chosen = np.all(cells == cell, axis=1)
                raw = self._bake(program, mesh, uvs, texel_world, chosen, cell)
                self.layers.append(self._finish(tuple(int(c) for c in cell), *raw, pad))
        finally:
            program.delete()

    # -- baking ------------------------------------------------------------

    def _bake(self, program, mesh, uvs, texel_world, chosen, cell):
        tris = mesh.indices[chosen].astype(np.int64)
        vertices = np.concatenate(
            [
                mesh.positions[tris].reshape(-1, 3),
                mesh.normals[tris].reshape(-1, 3),
                np.repeat(texel_world[chosen], 3)[:, None],
                uvs[tris].reshape(-1, 2),
            ],
            axis=1,
        ).astype(np.float32)
        vao = GL.glGenVertexArrays(1)
        vbo = GL.glGenBuffers(1)
        previous = GL.glGetIntegerv(GL.GL_FRAMEBUFFER_BINDING)
        fbo = Framebuffer(self.width, self.height, (GL.GL_RGBA32F, GL.GL_RGBA32F))
        try:
            GL.glBindVertexArray(vao)
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, vbo)
            GL.glBufferData(GL.GL_ARRAY_BUFFER, vertices.nbytes, vertices, GL.GL_STATIC_DRAW)
            offset = 0
            for location, size in ((0, 3), (1, 3), (2, 1), (3, 2)):
                GL.glEnableVertexAttribArray(location)
                GL.glVertexAttribPointer(
                    location,
                    size,
                    GL.GL_FLOAT,
                    GL.GL_FALSE,
                    vertices.shape[1] * 4,
                    ctypes.c_void_p(offset),
                )
                offset += size * 4
            fbo.bind()
            GL.glDisable(GL.GL_DEPTH_TEST)  # overlapping UVs: any one point will do
            GL.glDisable(GL.GL_CULL_FACE)
            GL.glClearColor(0.0, 0.0, 0.0, 0.0)
            GL.glClear(GL.GL_COLOR_BUFFER_BIT)
            program.use()
            program.set("u_offset", -np.asarray(cell, dtype=np.float32))
            GL.glDrawArrays(GL.GL_TRIANGLES, 0, vertices.shape[0])
            # the bake put texel row 0 at the bottom: GL's order is document order
            return fbo.read(0, flip=False), fbo.read(1, flip=False)
        finally:
            fbo.delete()
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, previous)
            GL.glBindVertexArray(0)
            GL.glDeleteBuffers(1, [vbo])
            GL.glDeleteVertexArrays(1, [vao])

    def _finish(self, cell, position_w, normal_w, pad: int) -> SurfaceLayer:
        covered = normal_w[..., 3] > 0.0
        position = position_w[..., :3]
        normal = normal_w[..., :3]
        texel_world = position_w[..., 3]
        valid = covered.copy()
        if pad > 0 and covered.any() and not covered.all():
            distance, (rows, cols) = ndimage.distance_transform_edt(~covered, return_indices=True)
            near = (~covered) & (distance <= pad)
            position = position.copy()
            normal = normal.copy()
            texel_world = texel_world.copy()
            position[near] = position[rows[near], cols[near]]
            normal[near] = normal[rows[near], cols[near]]
            texel_world[near] = texel_world[rows[near], cols[near]]
            valid |= near
        box_min, box_max = self._boxes(position, valid)
        return SurfaceLayer(cell, position, normal, texel_world, valid, box_min, box_max)

    def _boxes(self, position: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        t = self.layout.tile_size
        ty, tx = -(-self.height // t), -(-self.width // t)
        lo = np.full((ty, tx, 3), np.inf, dtype=np.float32)
        hi = np.full((ty, tx, 3), -np.inf, dtype=np.float32)
        for j in range(ty):
            for i in range(tx):
                block = valid[j * t : (j + 1) * t, i * t : (i + 1) * t]
                if block.any():
                    pts = position[j * t : (j + 1) * t, i * t : (i + 1) * t][block]
                    lo[j, i] = pts.min(axis=0)
                    hi[j, i] = pts.max(axis=0)
        return lo, hi

    # -- queries -----------------------------------------------------------

    def _texel_at(self, uv: np.ndarray) -> tuple[list, int, int]:
        """The baked layers to search at ``uv`` (its UV tile's first, else all) and the texel."""
        cell = tuple(int(c) for c in np.floor(uv))
        u, v = np.mod(uv, 1.0)
        col = min(int(u * self.width), self.width - 1)
        row = min(int((1.0 - v) * self.height), self.height - 1)
        return [lay for lay in self.layers if lay.cell == cell] or self.layers, row, col

    def texel_world_at(self, uv: np.ndarray) -> float:
        """World length of a texel at texture coordinate ``uv`` (after the uv scale)."""
        layers, row, col = self._texel_at(uv)
        for layer in layers:
            if layer.valid[row, col]:
                return float(layer.texel_world[row, col])
        values = [lay.texel_world[lay.valid] for lay in self.layers if lay.valid.any()]
        return float(np.median(np.concatenate(values))) if values else 1.0

    def texel_axes_at(self, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """World steps of one texel along texel x and y (y down) at ``uv``, or None.

        Central differences of the baked points (one-sided at an island's edge);
        None where the neighbours are not baked (the texel is alone in its island).
        """
        layers, row, col = self._texel_at(uv)
        for layer in layers:
            if not layer.valid[row, col]:
                continue
            steps = []
            for dr, dc in ((0, 1), (1, 0)):
                ahead = (min(row + dr, self.height - 1), min(col + dc, self.width - 1))
                behind = (max(row - dr, 0), max(col - dc, 0))
                ahead = ahead if layer.valid[ahead] else (row, col)
                behind = behind if layer.valid[behind] else (row, col)
                span = (ahead[0] - behind[0]) + (ahead[1] - behind[1])
                if span == 0:
                    return None
                steps.append((layer.position[ahead] - layer.position[behind]) / span)
            return steps[0].astype(np.float64), steps[1].astype(np.float64)
        return None

    def ball(
        self, centre: np.ndarray, radius: float, normal: np.ndarray | None = None
    ) -> dict[TileKey, tuple[np.ndarray, np.ndarray]]:
        """Texels within ``radius`` (world) of ``centre``, by tile: key -> (distance, inside).

        ``distance`` is the world distance ``(th, tw)`` from the centre to each
        texel's nearest point over all layers; ``inside`` says which texels have a
        point in the ball (facing the same side as ``normal`` when given: a thin
        shell's far side is not painted through).
        """
        c = np.asarray(centre, dtype=np.float32)
        out = {}
        for key, (points, inside) in self.ball_points(centre, radius, normal).items():
            out[key] = (np.where(inside, np.linalg.norm(points - c, axis=-1), np.inf), inside)
        return out

    def ball_points(
        self, centre: np.ndarray, radius: float, normal: np.ndarray | None = None
    ) -> dict[TileKey, tuple[np.ndarray, np.ndarray]]:
        """As :meth:`ball`, with each texel's nearest surface point ``(th, tw, 3)``
        instead of its distance (undefined where not inside)."""
        out: dict[TileKey, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        c = np.asarray(centre, dtype=np.float32)
        for layer in self.layers:
            gap = np.maximum(np.maximum(layer.box_min - c, c - layer.box_max), 0.0)
            near = np.sum(gap * gap, axis=-1) <= radius * radius
            for j, i in zip(*np.nonzero(near), strict=True):
                key = (int(j), int(i))
                rect = self.layout.tile_rect(key)
                pos = layer.position[rect.slices]
                dist = np.linalg.norm(pos - c, axis=-1)
                inside = layer.valid[rect.slices] & (dist <= radius)
                if normal is not None:
                    facing = layer.normal[rect.slices] @ np.asarray(normal, np.float32) > 0.0
                    inside &= facing
                dist = np.where(inside, dist, np.inf)
                if key in out:
                    old_dist, old_inside, old_pos = out[key]
                    nearer = dist < old_dist
                    pos = np.where(nearer[..., None], pos, old_pos)
                    dist = np.minimum(dist, old_dist)
                    inside = inside | old_inside
                out[key] = (dist, inside, pos)
        return {k: (pos, inside) for k, (_, inside, pos) in out.items() if inside.any()}
