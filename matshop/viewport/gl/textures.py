"""The document's shading textures on the GPU, re-uploaded tile by tile.

Storage is RGBA16F (half floats keep linear colors, GGX alpha down to 1e-3 and
Phong exponents up to 6e4; half the bytes of float32). A sampled lobe (128
bins) is a 2D array texture of 40 such layers (:mod:`.sampled_lobe`): 320 bytes
a texel, 5/8 of what the material's own float32 table holds. Mip levels are
computed on the CPU *per tile* (:func:`.shading_maps.mip_chain`) and uploaded
with the tile, so a dab re-uploads its tiles' pyramids and nothing else: no
``glGenerateMipmap`` over the whole 2K/4K texture per dab. That needs tiles
aligned with the mip grid, so the chain stops where a tile is one texel
(``GL_TEXTURE_MAX_LEVEL = log2(tile)``; a 64-texel tile on a 2K map: 32x32 at
the coarsest level, fine for any view the viewport offers). A document whose
size is not a multiple of a power-of-two tile falls back to regenerating the
mips on the GPU after an update (counted as the base level only; a sampled
lobe's nodes are then averaged nodes, not its averaged table's). With
``keep_variance`` each level's lobe is widened by the tilt variance the level
averages out of the normals (:func:`.shading_maps.mip_chain`: analytic lobes by
their slope variance, a sampled lobe's averaged table by a Gaussian slope
convolution before its nodes are taken; not on the fallback path).

:attr:`MaterialTextures.bytes_uploaded` counts every byte passed to
``glTexImage2D``/``glTexSubImage2D``; ``tests/test_viewport_gl.py`` checks a dab
against ``tiles x texels x 4 channels x 2 bytes x (1 + 1/4 + 1/16 + ...)``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
from OpenGL import GL

from ...layers.geometry import Rect, TileKey
from . import sampled_lobe, shading_maps
from .shaders import FAMILY_CODES

BYTES_PER_TEXEL = 4 * 2  # RGBA16F, per layer
#: texture units: the material's (0-4, and 7 for a sampled lobe); the environment's
#: are 5 and 6 (EnvironmentTextures)
UNITS = {name: unit if unit < 5 else unit + 2 for unit, name in enumerate(shading_maps.TEXTURES)}


def _target(layers: int) -> int:
    return GL.GL_TEXTURE_2D_ARRAY if layers else GL.GL_TEXTURE_2D


def _new_texture(width: int, height: int, max_level: int, layers: int = 0) -> int:
    """An RGBA16F texture with ``max_level`` mip levels; ``layers > 0``: a 2D array of them."""
    target = _target(layers)
    tex = GL.glGenTextures(1)
    GL.glBindTexture(target, tex)
    for level in range(max_level + 1):
        w, h = max(1, width >> level), max(1, height >> level)
        if layers:
            GL.glTexImage3D(
                target, level, GL.GL_RGBA16F, w, h, layers, 0, GL.GL_RGBA, GL.GL_HALF_FLOAT, None
            )
        else:
            GL.glTexImage2D(
                target, level, GL.GL_RGBA16F, w, h, 0, GL.GL_RGBA, GL.GL_HALF_FLOAT, None
            )
    GL.glTexParameteri(target, GL.GL_TEXTURE_BASE_LEVEL, 0)
    GL.glTexParameteri(target, GL.GL_TEXTURE_MAX_LEVEL, max_level)
    GL.glTexParameteri(target, GL.GL_TEXTURE_MIN_FILTER, GL.GL_LINEAR_MIPMAP_LINEAR)
    GL.glTexParameteri(target, GL.GL_TEXTURE_MAG_FILTER, GL.GL_LINEAR)
    GL.glTexParameteri(target, GL.GL_TEXTURE_WRAP_S, GL.GL_REPEAT)
    GL.glTexParameteri(target, GL.GL_TEXTURE_WRAP_T, GL.GL_REPEAT)
    return tex


def _sub_image(target: int, level: int, x: int, y: int, data: np.ndarray) -> None:
    """Write ``data`` ``(h, w, 4 layers)`` half floats at ``(x, y)`` of ``level``."""
    h, w, c = data.shape
    if target == GL.GL_TEXTURE_2D:
        GL.glTexSubImage2D(target, level, x, y, w, h, GL.GL_RGBA, GL.GL_HALF_FLOAT, data)
        return
    layered = np.ascontiguousarray(data.reshape(h, w, c // 4, 4).transpose(2, 0, 1, 3))
    GL.glTexSubImage3D(target, level, x, y, 0, w, h, c // 4, GL.GL_RGBA, GL.GL_HALF_FLOAT, layered)


class MaterialTextures:
    """Shading textures of a document (anything with ``schema``, ``layout``, ``physical(rect)``).

    Needs a current OpenGL context for every method.
    """

    def __init__(self, doc, *, lobe: str | None = None, keep_variance: bool = False) -> None:
        self.doc = doc
        self.lobe = lobe
        self.family = shading_maps.lobe_family(doc.schema, lobe)
        #: mips widen the lobe (analytic or sampled) by the tilt variance they average away
        self.widen = self.family if keep_variance else None
        layout = doc.layout
        self.width, self.height = layout.width, layout.height
        tile = layout.tile_size
        aligned = tile & (tile - 1) == 0 and self.width % tile == 0 and self.height % tile == 0
        #: mips travel with the tiles (True) or are regenerated on the GPU (False)
        self.tile_mips = aligned
        full = int(math.log2(max(self.width, self.height)))
        self.max_level = int(math.log2(tile)) if aligned else full
        self.names = shading_maps.present(doc.schema, self.family)
        #: bins of a sampled lobe's table (0: none shown), and each texture's layers
        self.bins = doc.schema["distribution"].phys_channels if "distribution" in self.names else 0
        self.layers = {
            name: sampled_lobe.layers(self.bins) if name in shading_maps.ARRAY_TEXTURES else 0
            for name in self.names
        }
        self.textures = {
            name: _new_texture(self.width, self.height, self.max_level, self.layers[name])
            for name in self.names
        }
        # 1x1 stand-ins so every sampler is bound to something valid
        self._dummy = {layers: _new_texture(1, 1, 0, layers) for layers in (0, 1)}
        for layers, tex in self._dummy.items():
            GL.glBindTexture(_target(layers), tex)
            _sub_image(_target(layers), 0, 0, 0, np.zeros((1, 1, 4), np.float16))
        self.bytes_uploaded = 0
        self.tiles_uploaded = 0
        self.upload_all()

    # -- uploads -----------------------------------------------------------

    def _upload_block(self, rect: Rect, packed: dict[str, np.ndarray]) -> int:
        GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
        sent = 0
        levels = self.max_level if self.tile_mips else 0
        chain = shading_maps.mip_chain(packed, levels, self.bins, widen=self.widen)
        for name in self.names:
            target = _target(self.layers[name])
            GL.glBindTexture(target, self.textures[name])
            for level, block in enumerate(chain[name]):
                data = np.ascontiguousarray(block, dtype=np.float16)
                _sub_image(target, level, rect.x0 >> level, rect.y0 >> level, data)
                sent += data.nbytes
            if not self.tile_mips:
                GL.glGenerateMipmap(target)
        return sent

    def _pack(self, rect: Rect) -> dict[str, np.ndarray]:
        return shading_maps.pack(self.doc.schema, self.doc.physical(rect, copy=False), self.lobe)

    def upload_all(self) -> int:
        """Upload the whole document (bands of tile rows, bounded memory); returns bytes."""
        layout = self.doc.layout
        tile = layout.tile_size
        # about 2^20 texels a band, fewer for a sampled lobe's 128 channels (its inverse
        # CDF takes ~10 float64 temporaries of them)
        texels = (1 << 20) // (1 + self.bins // 4)
        band = max(tile, texels // max(self.width, 1) // tile * tile)
        sent = 0
        for y0 in range(0, self.height, band):
            rect = Rect(0, y0, self.width, min(y0 + band, self.height))
            sent += self._upload_block(rect, self._pack(rect))
        self.bytes_uploaded += sent
        return sent

    def update_tiles(self, keys: Iterable[TileKey]) -> int:
        """Re-upload only the tiles ``keys`` (and their mip pyramids); returns bytes sent."""
        sent = 0
        count = 0
        for key in keys:
            rect = self.doc.layout.tile_rect(key)
            sent += self._upload_block(rect, self._pack(rect))
            count += 1
        self.bytes_uploaded += sent
        self.tiles_uploaded += count
        return sent

    def tile_bytes(self, key: TileKey) -> int:
        """What :meth:`update_tiles` sends for one tile: every texture, every uploaded level."""
        rect = self.doc.layout.tile_rect(key)
        levels = self.max_level if self.tile_mips else 0
        texels = sum(
            max(1, rect.width >> lv) * max(1, rect.height >> lv) for lv in range(levels + 1)
        )
        layers = sum(max(1, self.layers[name]) for name in self.names)
        return texels * BYTES_PER_TEXEL * layers

    # -- drawing -----------------------------------------------------------

    def bind(self, program) -> None:
        """Bind every material sampler of ``program`` (:data:`UNITS`) and the presence flags."""
        for name in shading_maps.TEXTURES:
            unit = UNITS[name]
            array = int(name in shading_maps.ARRAY_TEXTURES)
            GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
            GL.glBindTexture(_target(array), self.textures.get(name, self._dummy[array]))
            program.set(f"u_{name}", unit)
        program.set("u_bins", self.bins)
        if self.bins:
            program.set_floats("u_node_y", sampled_lobe.node_levels(self.bins))
        program.set("u_has_tangent", "tangent" in self.textures)
        program.set("u_has_emissive", "emissive" in self.textures)
        program.set("u_family", FAMILY_CODES[self.family])

    def delete(self) -> None:
        GL.glDeleteTextures([*self.textures.values(), *self._dummy.values()])
        self.textures = {}
