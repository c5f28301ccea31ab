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


def _texture(levels: list[np.ndarray], mipmapped: bool) -> int:
    tex = GL.glGenTextures(1)
    GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
    GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
    for level, image in enumerate(levels):
        data = np.ascontiguousarray(image, dtype=np.float32)
        h, w = data.shape[:2]
        GL.glTexImage2D(
            GL.GL_TEXTURE_2D, level, GL.GL_RGB32F, w, h, 0, GL.GL_RGB, GL.GL_FLOAT, data
        )
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_BASE_LEVEL, 0)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAX_LEVEL, len(levels) - 1)
    minify = GL.GL_LINEAR_MIPMAP_LINEAR if mipmapped else GL.GL_LINEAR
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MIN_FILTER, minify)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAG_FILTER, GL.GL_LINEAR)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_S, GL.GL_REPEAT)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_T, GL.GL_CLAMP_TO_EDGE)
    return tex


class EnvironmentTextures:
    """Radiance mip chain and irradiance map of one environment (needs a current context)."""

    RADIANCE_UNIT = 5
    IRRADIANCE_UNIT = 6

    def __init__(self, env: Environment) -> None:
        self.env = env
        self.radiance = _texture(env.levels, mipmapped=True)
        self.irradiance = _texture([env.irradiance_map], mipmapped=False)

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
