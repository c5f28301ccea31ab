"""Brush tips on the mesh: a tip dab laid in the surface's tangent plane.

The 2D canvas samples a tip at texel centres around the dab (texel x right,
y down). On the mesh a texel's place in the tip is its surface point's
offset from the dab centre, measured along the texel x and y directions
there (:func:`tip_frame`: the baked points' steps, made orthonormal in the
tangent plane) in texel units (the texel's world size at the dab). On a
flat, uniformly mapped surface those offsets are the 2D canvas's exactly,
so the dab is the 2D tip dab; on a curved surface the tip wraps on it like
a decal, across seams as the round 3D dab does.

The values come from :meth:`matshop.paint.brush.Brush.footprint` (the 2D
tip dab, on the lattice of the texels' offsets) read bilinearly at each
offset: exact where the offsets are that lattice, the tip's own sampling and
pyramid level everywhere.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from ...paint.brush import Brush
from .picking import SurfaceHit
from .surface_map import SurfaceMap


def tip_frame(surface: SurfaceMap, hit: SurfaceHit) -> tuple[np.ndarray, np.ndarray]:
    """Unit world directions of texel x and texel y (y down) in the tangent plane at ``hit``.

    Where the bake has no neighbours to measure, any orthonormal pair in the plane.
    """
    n = np.asarray(hit.normal, np.float64)
    n = n / max(np.linalg.norm(n), 1e-12)
    axes = surface.texel_axes_at(hit.uv)
    along = axes[0] if axes is not None else np.array([1.0, 0.0, 0.0])
    t = along - (along @ n) * n
    if np.linalg.norm(t) < 1e-9:  # degenerate: pick a direction across the normal
        t = np.cross(n, [0.0, 1.0, 0.0] if abs(n[1]) < 0.9 else [1.0, 0.0, 0.0])
    t /= np.linalg.norm(t)
    b = np.cross(n, t)
    if axes is not None and b @ axes[1] < 0.0:  # texel y runs the other way (mirrored uv)
        b = -b
    return t, b


def heading(step_world: np.ndarray, frame: tuple[np.ndarray, np.ndarray]) -> float | None:
    """A world step's direction in texel space (``atan2(dy, dx)``, y down), None if it is 0."""
    dx, dy = float(step_world @ frame[0]), float(step_world @ frame[1])
    return None if dx == 0.0 and dy == 0.0 else math.atan2(dy, dx)


def tip_alpha(
    brush: Brush, offsets: np.ndarray, inside: np.ndarray, radius_px: float, angle_deg: float
) -> np.ndarray:
    """The tip dab's alpha at texel ``offsets`` ``(..., 2)`` (x, y) from its centre, 0 where
    not ``inside``.

    The 2D dab is sampled on the lattice through an inside texel's offset, so
    where the frame runs along the texel grid (flat, uniformly mapped; turned by
    quarter turns or mirrored) every texel reads one of the 2D dab's own samples.
    """
    if not inside.any():
        return np.zeros(inside.shape, np.float32)
    first = offsets[inside][0]
    fx, fy = (0.5 - float(first[0])) % 1.0, (0.5 - float(first[1])) % 1.0
    x0, y0, footprint = brush.footprint(fx, fy, radius_px, angle_deg)
    # footprint[i, j] is the dab at texel centre (x0 + j + 1/2, y0 + i + 1/2)
    cols = offsets[..., 0] + fx - x0 - 0.5
    rows = offsets[..., 1] + fy - y0 - 0.5
    alpha = ndimage.map_coordinates(
        footprint, [rows, cols], order=1, mode="constant", cval=0.0, prefilter=False
    )
    return np.where(inside, alpha, 0.0).astype(np.float32)


def tip_reach(brush: Brush, radius_px: float) -> float:
    """Texels from a tip dab's centre to its farthest painted texel (any angle)."""
    h, w = brush.tip.image.shape
    scale = 2.0 * radius_px / max(h, w)
    return 0.5 * scale * float(np.hypot(h, w)) + scale + 1.0
