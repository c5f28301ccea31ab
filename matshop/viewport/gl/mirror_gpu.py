"""Showing the mirror plane in the 3D view: where it cuts the mesh, and the plane itself.

Two overlays drawn after the shaded mesh:

- the **cut**: the mesh drawn again where it meets the plane, a line about
  two pixels wide (the plane's signed distance over its screen-space rate,
  ``fwidth``), light over a dark rim so it reads on any material; the depth
  test keeps only the visible side. Seen edge-on (an X plane from the front)
  the plane is this line;
- the **plane**: a translucent quad over the mesh's bounding box (15% larger),
  with an outline, behind the mesh where the mesh is nearer.

Colours are the 2D canvas's mirror line's (:data:`MIRROR_RGB`), written
straight to the framebuffer (no tone mapping: an overlay, not a material).
"""

from __future__ import annotations

import ctypes

import numpy as np
from OpenGL import GL

from . import shaders
from .mesh_gpu import GpuMesh
from .mirror import AXES, MirrorPlane

#: the canvas's MIRROR_LINE (90, 200, 255), as GL colours
MIRROR_RGB = (90 / 255, 200 / 255, 255 / 255)
#: how much of the colour the plane's fill lays over what is behind it
PLANE_ALPHA = 0.22
#: the quad reaches this much past the mesh's bounding box
PLANE_MARGIN = 1.15
#: half-width of the cut's light core, in pixels (the dark rim doubles it)
CUT_HALF_WIDTH_PX = 1.2

CUT_FRAGMENT = (
    shaders.VERSION
    + """
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
uniform vec3 u_plane_point;
uniform vec3 u_plane_normal;
uniform vec3 u_color;
uniform float u_half_width;
out vec4 frag_color;
void main() {
    float d = dot(v_position - u_plane_point, u_plane_normal);
    float pixels = abs(d) / max(fwidth(d), 1e-8);
    if (pixels > 2.0 * u_half_width) discard;
    frag_color = vec4(pixels <= u_half_width ? u_color : vec3(0.0), 1.0);
}
"""
)

PLANE_VERTEX = (
    shaders.VERSION
    + """
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_proj;
void main() {
    gl_Position = u_view_proj * vec4(a_position, 1.0);
}
"""
)

PLANE_FRAGMENT = (
    shaders.VERSION
    + """
uniform vec4 u_color;
out vec4 frag_color;
void main() {
    frag_color = u_color;
}
"""
)


def plane_quad(plane: MirrorPlane, positions: np.ndarray) -> np.ndarray:
    """The four corners ``(4, 3)`` of the plane's quad over a mesh's bounding box."""
    lo, hi = positions.min(axis=0).astype(np.float64), positions.max(axis=0).astype(np.float64)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo) * PLANE_MARGIN
    k = AXES.index(plane.axis)
    i, j = (a for a in range(3) if a != k)
    half = np.maximum(half, 0.05 * half.max())  # a flat mesh still shows its plane
    corners = np.tile(centre, (4, 1))
    corners[:, k] = centre[k] + plane.offset
    for row, (si, sj) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
        corners[row, i] += si * half[i]
        corners[row, j] += sj * half[j]
    return corners


class MirrorOverlay:
    """GL objects of the overlays (needs a current context)."""

    def __init__(self) -> None:
        self.cut = shaders.Program(shaders.MESH_VERTEX, CUT_FRAGMENT)
        self.fill = shaders.Program(PLANE_VERTEX, PLANE_FRAGMENT)
        self.vao = GL.glGenVertexArrays(1)
        self.vbo = GL.glGenBuffers(1)
        GL.glBindVertexArray(self.vao)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, 4 * 3 * 4, None, GL.GL_DYNAMIC_DRAW)
        GL.glEnableVertexAttribArray(0)
        GL.glVertexAttribPointer(0, 3, GL.GL_FLOAT, GL.GL_FALSE, 12, ctypes.c_void_p(0))
        GL.glBindVertexArray(0)

    def draw(self, plane: MirrorPlane, mesh: GpuMesh, view_proj: np.ndarray, uv_scale) -> None:
        """Draw the cut and the plane over the frame just drawn (depth buffer intact)."""
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glDepthMask(GL.GL_FALSE)  # overlays never hide one another or the mesh
        # the cut: the mesh again, only near the plane, on top of its own depth
        GL.glDepthFunc(GL.GL_LEQUAL)
        GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
        GL.glPolygonOffset(-1.0, -1.0)
        c = self.cut
        c.use()
        c.set("u_view_proj", view_proj)
        c.set("u_uv_scale", np.asarray(uv_scale, dtype=np.float32))
        c.set("u_plane_point", plane.point(mesh.mesh).astype(np.float32))
        c.set("u_plane_normal", plane.normal.astype(np.float32))
        c.set("u_color", np.asarray(MIRROR_RGB, np.float32))
        c.set("u_half_width", float(CUT_HALF_WIDTH_PX))
        mesh.draw()
        GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)
        # the plane: a translucent quad and its outline, behind nearer surfaces
        GL.glDepthFunc(GL.GL_LESS)
        corners = plane_quad(plane, mesh.mesh.positions)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo)
        GL.glBufferSubData(GL.GL_ARRAY_BUFFER, 0, corners.astype(np.float32).tobytes())
        f = self.fill
        f.use()
        f.set("u_view_proj", view_proj)
        GL.glEnable(GL.GL_BLEND)
        # colour over what is there; the frame's alpha stays opaque (Qt composes the widget
        # by it: a translucent alpha would tint the window behind into the picture)
        GL.glBlendFuncSeparate(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA, GL.GL_ZERO, GL.GL_ONE)
        GL.glBindVertexArray(self.vao)
        f.set("u_color", np.asarray((*MIRROR_RGB, PLANE_ALPHA), np.float32))
        GL.glDrawArrays(GL.GL_TRIANGLE_FAN, 0, 4)
        f.set("u_color", np.asarray((*MIRROR_RGB, 0.9), np.float32))
        GL.glDrawArrays(GL.GL_LINE_LOOP, 0, 4)
        GL.glBindVertexArray(0)
        GL.glDisable(GL.GL_BLEND)
        GL.glDepthMask(GL.GL_TRUE)

    def delete(self) -> None:
        self.cut.delete()
        self.fill.delete()
        GL.glDeleteBuffers(1, [self.vbo])
        GL.glDeleteVertexArrays(1, [self.vao])
