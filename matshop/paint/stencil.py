"""Stencils: a grayscale image laid over the canvas that lets paint through where it is white.

The editor keeps a stencil fixed on the screen (the texture pans and zooms
under it, as in Substance Painter); when a stroke starts, the stencil's
place is converted to texel space (:class:`Stencil`), which is what strokes
and stroke files use, so a replay needs no screen. Each dab's alpha is
multiplied by the stencil at the texel centres it covers; outside the
stencil's image nothing is masked (a sheet laid on the canvas). A dab is
masked where it is painted, before it wraps across the texture's edge or is
mirrored: mirror images stay exact flips of the masked dab.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from ..errors import InvalidValue
from .sampling import Pyramid, read_gray, sample_placed

#: texels per stencil pixel: beyond these a stencil is a speck or a single blur
MIN_SCALE, MAX_SCALE = 1e-3, 1e3


@dataclass(frozen=True, eq=False)
class Stencil:
    """A gray image (``(h, w)`` in [0, 1], white lets paint through) placed in texel space.

    ``centre``: the texel point under the image's centre; ``scale``: texels
    per image pixel; ``angle_deg``: counter-clockwise on screen. ``source``
    is the file it came from (what a stroke file names).
    """

    image: np.ndarray
    centre: tuple[float, float] = (0.0, 0.0)
    scale: float = 1.0
    angle_deg: float = 0.0
    source: str = ""
    _pyramid: Pyramid | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self._pyramid is None:  # a new image (:meth:`placed` shares a checked one)
            image = np.ascontiguousarray(self.image, dtype=np.float32)
            if image.ndim != 2 or min(image.shape) < 1 or not np.isfinite(image).all():
                raise InvalidValue("a stencil is a finite 2D gray image")
            object.__setattr__(self, "image", np.clip(image, 0.0, 1.0))
            object.__setattr__(self, "_pyramid", Pyramid(self.image, "clamp"))
        numbers = (*self.centre, self.scale, self.angle_deg)
        if len(self.centre) != 2 or not all(math.isfinite(v) for v in numbers):
            raise InvalidValue("stencil centre, scale and angle must be finite numbers")
        if not MIN_SCALE <= self.scale <= MAX_SCALE:
            raise InvalidValue(
                f"stencil scale must lie in [{MIN_SCALE:g}, {MAX_SCALE:g}] texels a pixel, "
                f"got {self.scale:g}"
            )

    def placed(self, centre: tuple[float, float], scale: float, angle_deg: float) -> Stencil:
        """The same image somewhere else (its pyramid is shared, not rebuilt)."""
        return Stencil(
            self.image,
            (float(centre[0]), float(centre[1])),
            float(scale),
            float(angle_deg),
            self.source,
            self._pyramid,
        )

    def mask(self, x0: int, y0: int, height: int, width: int) -> np.ndarray:
        """What the stencil lets through at the centres of texels ``[x0, x0+width) x ...``."""
        assert self._pyramid is not None
        values, inside = sample_placed(
            self._pyramid, x0, y0, height, width, self.centre, self.scale, self.angle_deg
        )
        return np.where(inside, values, np.float32(1.0))


def load_stencil(path: str | os.PathLike[str]) -> Stencil:
    """A stencil from any image OpenImageIO reads, not yet placed (centre at texel 0, 0)."""
    return Stencil(read_gray(path, "stencil image"), source=str(path))
