"""The document's shading textures on the GPU, re-uploaded tile by tile.

Storage is RGBA16F (half floats keep linear colors, GGX alpha down to 1e-3 and
Phong exponents up to 6e4; half the bytes of float32). Mip levels are
computed on the CPU *per tile* (:func:`.shading_maps.box_mips`) and uploaded
with the tile, so a dab re-uploads its tiles' pyramids and nothing else: no
``glGenerateMipmap`` over the whole 2K/4K texture per dab. That needs tiles
aligned with the mip grid, so the chain stops where a tile is one texel
(``GL_TEXTURE_MAX_LEVEL = log2(tile)``; a 64-texel tile on a 2K map: 32x32 at
the coarsest level, fine for any view the viewport offers). A document whose
size is not a multiple of a power-of-two tile falls back to regenerating the
mips on the GPU after an update (counted as the base level only).

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
from . import shading_maps
from .shaders import FAMILY_CODES

BYTES_PER_TEXEL = 4 * 2  # RGBA16F
#: texture units: the material's (0-4, and 7-10 for a sampled lobe's quantiles);
#: the environment's are 5 and 6 (EnvironmentTextures)
UNITS = {name: unit if unit < 5 else unit + 2 for unit, name in enumerate(shading_maps.TEXTURES)}


def _new_texture(width: int, height: int, max_level: int) -> int:
    tex = GL.glGenTextures(1)
    GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
    for level in range(max_level + 1):
        w, h = max(1, width >> level), max(1, height >> level)
        GL.glTexImage2D(
            GL.GL_TEXTURE_2D, level, GL.GL_RGBA16F, w, h, 0, GL.GL_RGBA, GL.GL_HALF_FLOAT, None
        )
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_BASE_LEVEL, 0)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAX_LEVEL, max_level)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MIN_FILTER, GL.GL_LINEAR_MIPMAP_LINEAR)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAG_FILTER, GL.GL_LINEAR)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_S, GL.GL_REPEAT)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_T, GL.GL_REPEAT)
    return tex


class MaterialTextures:
    """Shading textures of a document (anything with ``schema``, ``layout``, ``physical(rect)``).

    Needs a current OpenGL context for every method.
    """

    def __init__(self, doc, *, lobe: str | None = None) -> None:
        self.doc = doc
        self.lobe = lobe
        self.family = shading_maps.lobe_family(doc.schema, lobe)
        layout = doc.layout
        self.width, self.height = layout.width, layout.height
        tile = layout.tile_size
        aligned = tile & (tile - 1) == 0 and self.width % tile == 0 and self.height % tile == 0
        #: mips travel with the tiles (True) or are regenerated on the GPU (False)
        self.tile_mips = aligned
        full = int(math.log2(max(self.width, self.height)))
        self.max_level = int(math.log2(tile)) if aligned else full
        self.names = shading_maps.present(doc.schema, self.family)
        self.textures = {
            name: _new_texture(self.width, self.height, self.max_level) for name in self.names
        }
        # 1x1 stand-ins so every sampler is bound to something valid
        self._dummy = _new_texture(1, 1, 0)
        GL.glTexSubImage2D(
            GL.GL_TEXTURE_2D,
            0,
            0,
            0,
            1,
            1,
            GL.GL_RGBA,
            GL.GL_FLOAT,
            np.zeros(4, dtype=np.float32),
        )
        self.bytes_uploaded = 0
        self.tiles_uploaded = 0
        self.upload_all()

    # -- uploads -----------------------------------------------------------

    def _upload_block(self, rect: Rect, packed: dict[str, np.ndarray]) -> int:
        GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
        sent = 0
        levels = self.max_level if self.tile_mips else 0
        for name in self.names:
            GL.glBindTexture(GL.GL_TEXTURE_2D, self.textures[name])
            for level, block in enumerate(shading_maps.box_mips(packed[name], levels)):
                data = np.ascontiguousarray(block, dtype=np.float16)
                h, w = data.shape[:2]
                GL.glTexSubImage2D(
                    GL.GL_TEXTURE_2D,
                    level,
                    rect.x0 >> level,
                    rect.y0 >> level,
                    w,
                    h,
                    GL.GL_RGBA,
                    GL.GL_HALF_FLOAT,
                    data,
                )
                sent += data.nbytes
            if not self.tile_mips:
                GL.glGenerateMipmap(GL.GL_TEXTURE_2D)
        return sent

    def _pack(self, rect: Rect) -> dict[str, np.ndarray]:
        return shading_maps.pack(self.doc.schema, self.doc.physical(rect, copy=False), self.lobe)

    def upload_all(self) -> int:
        """Upload the whole document (bands of tile rows, bounded memory); returns bytes."""
        layout = self.doc.layout
        tile = layout.tile_size
        band = max(tile, (1 << 20) // max(self.width, 1) // tile * tile)
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
        return texels * BYTES_PER_TEXEL * len(self.names)

    # -- drawing -----------------------------------------------------------

    def bind(self, program) -> None:
        """Bind every material sampler of ``program`` (:data:`UNITS`) and the presence flags."""
        for name in shading_maps.TEXTURES:
            unit = UNITS[name]
            GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
            GL.glBindTexture(GL.GL_TEXTURE_2D, self.textures.get(name, self._dummy))
            program.set(f"u_{name}", unit)
        program.set("u_has_tangent", "tangent" in self.textures)
        program.set("u_has_emissive", "emissive" in self.textures)
        program.set("u_family", FAMILY_CODES[self.family])

    def delete(self) -> None:
        GL.glDeleteTextures([*self.textures.values(), self._dummy])
        self.textures = {}
