"""Framebuffer objects with one or more color attachments, read back as numpy arrays.

Rows come back top row first (image order), although OpenGL stores the
bottom row first, unless ``flip=False`` (the UV bake wants GL's order).
"""

from __future__ import annotations

import numpy as np
from OpenGL import GL

#: internal format -> (format, type, numpy dtype, channels) for reading back
_FORMATS = {
    GL.GL_RGBA8: (GL.GL_RGBA, GL.GL_UNSIGNED_BYTE, np.uint8, 4),
    GL.GL_RGBA32F: (GL.GL_RGBA, GL.GL_FLOAT, np.float32, 4),
}


class Framebuffer:
    """``width x height`` color attachments of ``formats`` plus a depth buffer."""

    def __init__(self, width: int, height: int, formats: tuple[int, ...] = (GL.GL_RGBA8,)) -> None:
        self.width = width
        self.height = height
        self.formats = formats
        self.id = GL.glGenFramebuffers(1)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.id)
        self.textures: list[int] = []
        for index, internal in enumerate(formats):
            fmt, kind, _, _ = _FORMATS[internal]
            tex = GL.glGenTextures(1)
            GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
            GL.glTexImage2D(GL.GL_TEXTURE_2D, 0, internal, width, height, 0, fmt, kind, None)
            GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MIN_FILTER, GL.GL_NEAREST)
            GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAG_FILTER, GL.GL_NEAREST)
            GL.glFramebufferTexture2D(
                GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0 + index, GL.GL_TEXTURE_2D, tex, 0
            )
            self.textures.append(tex)
        self.depth = GL.glGenRenderbuffers(1)
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, self.depth)
        GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_DEPTH_COMPONENT24, width, height)
        GL.glFramebufferRenderbuffer(
            GL.GL_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, GL.GL_RENDERBUFFER, self.depth
        )
        GL.glDrawBuffers(len(formats), [GL.GL_COLOR_ATTACHMENT0 + k for k in range(len(formats))])
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError(f"framebuffer incomplete (status 0x{status:x})")

    def bind(self) -> None:
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.id)
        GL.glViewport(0, 0, self.width, self.height)

    def read(self, attachment: int = 0, *, flip: bool = True) -> np.ndarray:
        """The attachment as ``(height, width, 4)`` (uint8 or float32)."""
        fmt, kind, dtype, channels = _FORMATS[self.formats[attachment]]
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self.id)
        GL.glReadBuffer(GL.GL_COLOR_ATTACHMENT0 + attachment)
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        data = GL.glReadPixels(0, 0, self.width, self.height, fmt, kind)
        array = np.frombuffer(data, dtype=dtype).reshape(self.height, self.width, channels)
        return np.ascontiguousarray(array[::-1] if flip else array)

    def delete(self) -> None:
        GL.glDeleteTextures(self.textures)
        GL.glDeleteRenderbuffers(1, [self.depth])
        GL.glDeleteFramebuffers(1, [self.id])
