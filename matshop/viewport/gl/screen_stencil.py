"""A stencil fixed on the 3D view's screen: what it lets through where a surface point shows.

The stencil is placed in widget pixels (centre, pixels per image pixel, angle),
as the 2D canvas keeps it on its screen. A 3D dab's texels are masked by the
stencil at the widget point their surface point projects to through the
stroke's camera (taken when the stroke starts): the stencil's own sampling at
pixel centres (:meth:`matshop.paint.stencil.Stencil.mask`), read bilinearly
between them. Occlusion is not considered: a dab only reaches texels near the
cursor's surface point, on the side facing the dab.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import ndimage

from ...paint.stencil import Stencil


class ScreenStencil:
    """``stencil`` (in widget pixels) seen through ``project``: world points -> widget pixels."""

    def __init__(self, stencil: Stencil, project: Callable[[np.ndarray], np.ndarray]) -> None:
        self.stencil = stencil
        self.project = project

    def at(self, points: np.ndarray) -> np.ndarray:
        """What the stencil lets through at world ``points (..., 3)``: ``(...)`` in [0, 1]."""
        screen = self.project(points)
        x0 = int(np.floor(screen[..., 0].min() - 1.0))
        y0 = int(np.floor(screen[..., 1].min() - 1.0))
        x1 = int(np.ceil(screen[..., 0].max() + 1.0))
        y1 = int(np.ceil(screen[..., 1].max() + 1.0))
        grid = self.stencil.mask(x0, y0, y1 - y0, x1 - x0)  # at pixel centres (x0 + j + 1/2, ...)
        return ndimage.map_coordinates(
            grid,
            [screen[..., 1] - y0 - 0.5, screen[..., 0] - x0 - 0.5],
            order=1,
            mode="nearest",
            prefilter=False,
        ).astype(np.float32)
