"""A :class:`~.mesh_data.MeshData` in a vertex array object.

Attribute locations match the shaders: 0 position, 1 normal, 2 tangent (xyz,
handedness), 3 uv; one interleaved float32 buffer and a uint32 index buffer.
"""

from __future__ import annotations

import ctypes

import numpy as np
from OpenGL import GL

from .mesh_data import MeshData

#: (location, components) in the interleaved vertex, in order
_LAYOUT = ((0, 3), (1, 3), (2, 4), (3, 2))


class GpuMesh:
    """Vertex and index buffers of one mesh, drawn as indexed triangles."""

    def __init__(self, mesh: MeshData) -> None:
        self.mesh = mesh
        vertices = np.ascontiguousarray(
            np.concatenate([mesh.positions, mesh.normals, mesh.tangents, mesh.uvs], axis=1),
            dtype=np.float32,
        )
        indices = np.ascontiguousarray(mesh.indices, dtype=np.uint32)
        self.count = indices.size
        self.vao = GL.glGenVertexArrays(1)
        GL.glBindVertexArray(self.vao)
        self.vbo, self.ebo = GL.glGenBuffers(2)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, vertices.nbytes, vertices, GL.GL_STATIC_DRAW)
        GL.glBindBuffer(GL.GL_ELEMENT_ARRAY_BUFFER, self.ebo)
        GL.glBufferData(GL.GL_ELEMENT_ARRAY_BUFFER, indices.nbytes, indices, GL.GL_STATIC_DRAW)
        stride = vertices.shape[1] * 4
        offset = 0
        for location, size in _LAYOUT:
            GL.glEnableVertexAttribArray(location)
            GL.glVertexAttribPointer(
                location, size, GL.GL_FLOAT, GL.GL_FALSE, stride, ctypes.c_void_p(offset)
            )
            offset += size * 4
        GL.glBindVertexArray(0)

    def draw(self) -> None:
        GL.glBindVertexArray(self.vao)
        GL.glDrawElements(GL.GL_TRIANGLES, self.count, GL.GL_UNSIGNED_INT, None)
        GL.glBindVertexArray(0)

    def delete(self) -> None:
        GL.glDeleteBuffers(2, [self.vbo, self.ebo])
        GL.glDeleteVertexArrays(1, [self.vao])
