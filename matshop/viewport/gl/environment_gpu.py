"""An :class:`~matshop.render.environment.Environment` as two textures.

- the radiance mip chain: the reference's own ``Environment.levels`` (INTER_AREA
  halvings down to 4 rows) uploaded level by level, so ``textureLod`` reads
  what ``Environment.lookup`` reads: bilinear, wrapping in ``u``, clamped in
  ``v``, linear between levels, the level clamped to ``[0, max_level]``;
- the irradiance map (64 x 32), bilinear, the same wrap and clamp.

Float32 storage: the sun of the ``sky`` environment is 400 times the sky.
"""

from __future__ import annotations

import numpy as np
from OpenGL import GL

from ...render.environment import Environment

#: bytes an incremental upload sends a step (about 15 ms on llvmpipe; a 4K
#: environment's 133 MB took 238 ms in one go on the GUI thread)
STEP_BYTES = 8 << 20


def _texture(levels: list[np.ndarray], mipmapped: bool, *, unit: int, fill: bool = True) -> int:
    """A float RGB texture of ``levels`` on texture ``unit``; ``fill=False`` leaves
    the levels for :meth:`EnvironmentTextures.upload` to allocate and fill."""
    tex = GL.glGenTextures(1)
    GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
    GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
    GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
    for level, image in enumerate(levels if fill else []):
        _allocate(level, image, np.ascontiguousarray(image, dtype=np.float32))
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_BASE_LEVEL, 0)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAX_LEVEL, len(levels) - 1)
    minify = GL.GL_LINEAR_MIPMAP_LINEAR if mipmapped else GL.GL_LINEAR
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MIN_FILTER, minify)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAG_FILTER, GL.GL_LINEAR)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_S, GL.GL_REPEAT)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_T, GL.GL_CLAMP_TO_EDGE)
    return tex


def _allocate(level: int, image: np.ndarray, data: np.ndarray | None) -> None:
    """Level ``level`` of the bound texture, the shape of ``image``, filled with ``data``."""
    h, w = image.shape[:2]
    GL.glTexImage2D(GL.GL_TEXTURE_2D, level, GL.GL_RGB32F, w, h, 0, GL.GL_RGB, GL.GL_FLOAT, data)


class EnvironmentTextures:
    """Radiance mip chain and irradiance map of one environment (needs a current context).

    ``incremental=True``: the textures are only named; :meth:`upload` allocates
    each level and sends its texels a band of rows at a time (:data:`STEP_BYTES`),
    so a large environment reaches the GPU over several frames instead of
    stalling the thread that draws (the view keeps the previous environment
    meanwhile). One level's allocation is one call: a 4K level's 76 ms on
    llvmpipe is the longest step.
    """

    RADIANCE_UNIT = 5
    IRRADIANCE_UNIT = 6

    def __init__(self, env: Environment, *, incremental: bool = False) -> None:
        self.env = env
        fill = not incremental
        self.radiance = _texture(env.levels, True, unit=self.RADIANCE_UNIT, fill=fill)
        self.irradiance = _texture(
            [env.irradiance_map], False, unit=self.IRRADIANCE_UNIT, fill=fill
        )
        #: (texture, unit, level, image) still to send, and the next row of the first
        self._todo = (
            [(self.irradiance, self.IRRADIANCE_UNIT, 0, env.irradiance_map)]
            + [(self.radiance, self.RADIANCE_UNIT, i, lv) for i, lv in enumerate(env.levels)]
            if incremental
            else []
        )
        self._row = 0

    @property
    def complete(self) -> bool:
        """Every texel is on the GPU."""
        return not self._todo

    def upload(self, budget_bytes: int = STEP_BYTES) -> int:
        """The next step of an incremental upload, about ``budget_bytes`` (at least one
        row): a level's storage is allocated when its first rows go (llvmpipe zeroes
        it, 76 ms for a 4K level), then bands of rows. Returns the bytes counted
        (0 when complete)."""
        sent = 0
        while self._todo and sent < budget_bytes:
            tex, unit, level, image = self._todo[0]
            h, w = image.shape[:2]
            row_bytes = w * 3 * 4
            GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
            GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
            GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
            if self._row == 0:
                _allocate(level, image, None)
                sent += h * row_bytes
            rows = min(h - self._row, max(1, (budget_bytes - sent) // row_bytes))
            band = np.ascontiguousarray(image[self._row : self._row + rows], dtype=np.float32)
            GL.glTexSubImage2D(
                GL.GL_TEXTURE_2D, level, 0, self._row, w, rows, GL.GL_RGB, GL.GL_FLOAT, band
            )
            sent += rows * row_bytes
            self._row += rows
            if self._row == h:
                self._todo.pop(0)
                self._row = 0
        return sent

    def bind(self, program) -> None:
        GL.glActiveTexture(GL.GL_TEXTURE0 + self.RADIANCE_UNIT)
        GL.glBindTexture(GL.GL_TEXTURE_2D, self.radiance)
        GL.glActiveTexture(GL.GL_TEXTURE0 + self.IRRADIANCE_UNIT)
        GL.glBindTexture(GL.GL_TEXTURE_2D, self.irradiance)
        program.set("u_env", self.RADIANCE_UNIT)
        program.set("u_irradiance", self.IRRADIANCE_UNIT)
        program.set("u_env_texel_solid_angle", float(self.env.texel_solid_angle()))

    def delete(self) -> None:
        GL.glDeleteTextures([self.radiance, self.irradiance])
