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

A whole upload (a new document, keep variance toggled) can run in the background
(:meth:`MaterialTextures.reload`, :mod:`.band_loader`): blocks are built on a
worker thread and uploaded a block a frame, so the GL thread never spends seconds
on a large set's conversion (a 2K sampled lobe: tens of seconds of CPU).

:attr:`MaterialTextures.bytes_uploaded` counts every byte passed to
``glTexImage2D``/``glTexSubImage2D``; ``tests/test_viewport_gl.py`` checks a dab
against ``tiles x texels x 4 channels x 2 bytes x (1 + 1/4 + 1/16 + ...)``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np
from OpenGL import GL

from ...layers.geometry import Rect, TileKey
from . import sampled_lobe, shading_maps
from .band_loader import BandLoader
from .shaders import FAMILY_CODES

BYTES_PER_TEXEL = 4 * 2  # RGBA16F, per layer
#: texels of an upload block (before a sampled lobe's share): in the background, a
#: block's read and upload on the GL thread stay a few tens of ms
BLOCK_TEXELS = 1 << 18
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


def gl_layout(block: np.ndarray, layered: bool) -> np.ndarray:
    """``block`` ``(h, w, 4 layers)`` as the half floats ``glTexSubImage`` takes:
    ``(h, w, 4)``, or ``(layers, h, w, 4)`` for an array texture (no GL call: a
    worker thread prepares it)."""
    data = np.ascontiguousarray(block, dtype=np.float16)
    if not layered:
        return data
    h, w, c = data.shape
    return np.ascontiguousarray(data.reshape(h, w, c // 4, 4).transpose(2, 0, 1, 3))


def _sub_image(target: int, level: int, x: int, y: int, data: np.ndarray) -> None:
    """Write ``data`` (:func:`gl_layout`) at ``(x, y)`` of ``level``."""
    if target == GL.GL_TEXTURE_2D:
        h, w = data.shape[:2]
        GL.glTexSubImage2D(target, level, x, y, w, h, GL.GL_RGBA, GL.GL_HALF_FLOAT, data)
        return
    layers, h, w = data.shape[:3]
    GL.glTexSubImage3D(target, level, x, y, 0, w, h, layers, GL.GL_RGBA, GL.GL_HALF_FLOAT, data)


class MaterialTextures:
    """Shading textures of a document (anything with ``schema``, ``layout``, ``physical(rect)``).

    Needs a current OpenGL context for every method.
    """

    def __init__(
        self,
        doc,
        *,
        lobe: str | None = None,
        keep_variance: bool = False,
        background: bool = False,
    ) -> None:
        self.doc = doc
        self.lobe = lobe
        self.family = shading_maps.lobe_family(doc.schema, lobe)
        self.widen: str | None = None
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
            _sub_image(_target(layers), 0, 0, 0, gl_layout(np.zeros((1, 1, 4)), bool(layers)))
        self.bytes_uploaded = 0
        self.tiles_uploaded = 0
        self._loader: BandLoader | None = None
        self.reload(keep_variance=keep_variance, background=background)

    # -- uploads -----------------------------------------------------------

    def build(self, maps: Mapping[str, np.ndarray], widen: str | None) -> dict[str, list]:
        """One block's physical ``maps`` -> every texture's levels in :func:`gl_layout`.

        Pure numpy, no GL, nothing of the document but its (fixed) schema: safe on a
        worker thread.
        """
        packed = shading_maps.pack(self.doc.schema, maps, self.lobe)
        levels = self.max_level if self.tile_mips else 0
        chain = shading_maps.mip_chain(packed, levels, self.bins, widen=widen)
        return {
            name: [gl_layout(block, self.layers[name] > 0) for block in chain[name]]
            for name in self.names
        }

    def _send(self, rect: Rect, built: dict[str, list]) -> int:
        GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
        sent = 0
        for name in self.names:
            target = _target(self.layers[name])
            GL.glBindTexture(target, self.textures[name])
            for level, data in enumerate(built[name]):
                _sub_image(target, level, rect.x0 >> level, rect.y0 >> level, data)
                sent += data.nbytes
            if not self.tile_mips:
                GL.glGenerateMipmap(target)
        return sent

    def _upload(self, rect: Rect) -> int:
        maps = self.doc.physical(rect, copy=False)
        return self._send(rect, self.build(maps, self.widen))

    def _blocks(self) -> list[Rect]:
        """Tile-aligned blocks of about :data:`BLOCK_TEXELS` covering the document, row-major."""
        tile = self.doc.layout.tile_size
        # a sampled lobe has 128 channels (its inverse CDF takes ~10 float64 temporaries)
        texels = BLOCK_TEXELS // (1 + self.bins // 4)
        if texels >= tile * self.width:  # bands of whole rows
            rows, cols = texels // self.width // tile * tile, self.width
        else:
            rows, cols = tile, max(tile, texels // tile // tile * tile)
        return [
            Rect(x0, y0, min(x0 + cols, self.width), min(y0 + rows, self.height))
            for y0 in range(0, self.height, rows)
            for x0 in range(0, self.width, cols)
        ]

    def reload(self, *, keep_variance: bool, background: bool = False) -> None:
        """Upload the whole document again, into the same textures; ``keep_variance``:
        mips widen the lobe (analytic or sampled) by the tilt variance they average away.

        ``background``: the blocks are built on a worker thread and uploaded as
        :meth:`poll` finds them ready (the textures show the old contents until then);
        otherwise everything is uploaded before this returns.
        """
        self.cancel_loading()
        self.widen = self.family if keep_variance else None
        if not background:
            self.upload_all()
            return
        widen = self.widen
        self._loader = BandLoader(
            self._blocks(),
            lambda rect: self.doc.physical(rect, copy=True),
            lambda maps: self.build(maps, widen),
        )

    @property
    def loading(self) -> bool:
        """A background :meth:`reload` has blocks not yet uploaded."""
        return self._loader is not None

    def poll(self, *, wait: bool = False, paused: bool = False) -> int:
        """Upload the background blocks that are ready (one a call; ``wait``: all of
        them, built now if need be); returns bytes. ``paused``: read no new blocks
        (the document is being recomputed elsewhere)."""
        if self._loader is None:
            return 0
        self._loader.paused = paused
        sent = 0
        for rect, built in self._loader.take(None if wait else 1, wait=wait):
            sent += self._send(rect, built)
        if self._loader.done:
            self._loader = None
        self.bytes_uploaded += sent
        return sent

    def cancel_loading(self) -> None:
        if self._loader is not None:
            self._loader.cancel()
            self._loader = None

    def upload_all(self) -> int:
        """Upload the whole document (blocks of bounded memory); returns bytes."""
        sent = sum(self._upload(rect) for rect in self._blocks())
        self.bytes_uploaded += sent
        return sent

    def update_tiles(self, keys: Iterable[TileKey]) -> int:
        """Re-upload only the tiles ``keys`` (and their mip pyramids); returns bytes sent."""
        sent = 0
        count = 0
        for key in keys:
            sent += self._upload(self.doc.layout.tile_rect(key))
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
        self.cancel_loading()
        GL.glDeleteTextures([*self.textures.values(), *self._dummy.values()])
        self.textures = {}
