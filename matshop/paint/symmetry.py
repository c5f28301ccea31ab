"""Mirror painting in texture space: one dab, and its mirror images about the mirror lines.

``x`` mirrors left <-> right about a vertical line ``x = cx``, ``y`` top <->
bottom about a horizontal one ``y = cy``; both give four dabs. The centre
``(cx, cy)`` is the texture's middle unless moved (texels from the top-left
corner, as stroke points are). A mirrored footprint is the dab's own
footprint flipped, so what a symmetric stroke paints on one side is, texel
for texel, the mirror image of the other side (no resampling, no half-texel
drift); for that the centre is kept on the half-texel grid (a texel edge or
a texel centre), where column ``i`` mirrors to column ``2 cx - 1 - i`` exactly.

At the texture's border a mirror image is an ordinary dab at ``2c - x``: it
follows the stroke's edge rule like the dab it mirrors. A tiling texture's
stroke (``wrap=True``, the default) wraps it to the opposite side, which is
the mirror on the torus the tiling texture is (the reflection about ``cx``
is also one about ``cx + W/2`` there), and exactly the dab the artist would
have painted by hand at that point; ``wrap=False`` clips it at the border.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidValue

_NAMES = {"none": (False, False), "x": (True, False), "y": (False, True), "xy": (True, True)}


def snap_half(value: float) -> float:
    """``value`` on the half-texel grid (texel edges and centres), where flips are exact."""
    return math.floor(2.0 * value + 0.5) / 2.0


@dataclass(frozen=True)
class Symmetry:
    """Which axes a stroke mirrors across: ``x`` (left/right), ``y`` (top/bottom).

    ``centre``: where the mirror lines cross, in texels from the top-left
    corner (snapped to half texels when used); None is the texture's middle.
    """

    x: bool = False
    y: bool = False
    centre: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.centre is not None:
            cx, cy = self.centre
            if not all(isinstance(v, int | float) and math.isfinite(v) for v in (cx, cy)):
                raise InvalidValue(f"symmetry centre must be two finite numbers, got {self.centre}")
            object.__setattr__(self, "centre", (snap_half(cx), snap_half(cy)))

    @classmethod
    def parse(cls, text: str, centre: tuple[float, float] | None = None) -> Symmetry:
        """``"none"``, ``"x"``, ``"y"`` or ``"xy"`` (also ``"yx"``), about ``centre``."""
        key = "xy" if text == "yx" else text
        if key not in _NAMES:
            raise InvalidValue(f"symmetry must be none, x, y or xy, got {text!r}")
        return cls(*_NAMES[key], centre=centre)

    @property
    def name(self) -> str:
        return next(name for name, axes in _NAMES.items() if axes == (self.x, self.y))

    def centre_in(self, width: int, height: int) -> tuple[float, float]:
        """The mirror centre in a ``width x height`` texture, kept inside it."""
        if self.centre is None:
            return width / 2.0, height / 2.0
        cx, cy = self.centre
        return min(max(cx, 0.0), float(width)), min(max(cy, 0.0), float(height))

    def mirror_point(
        self, x: float, y: float, width: int, height: int
    ) -> list[tuple[float, float]]:
        """Texel point ``(x, y)`` and its mirror images (``2c - x``), in stamping order."""
        cx, cy = self.centre_in(width, height)
        points = [(x, y)]
        if self.x:
            points.append((2.0 * cx - x, y))
        if self.y:
            points += [(px, 2.0 * cy - y) for px, _ in points]
        return points

    def __bool__(self) -> bool:
        return self.x or self.y


NONE = Symmetry()


def mirrored_footprints(
    x0: int, y0: int, alpha: np.ndarray, width: int, height: int, symmetry: Symmetry
) -> list[tuple[int, int, np.ndarray]]:
    """``(x0, y0, alpha)`` of a footprint and its mirror images in a ``width x height`` texture.

    Texel column ``i`` mirrors to ``2 cx - 1 - i`` (rows likewise), so the
    block ``[x0, x0 + w)`` lands on ``[2 cx - x0 - w, 2 cx - x0)`` flipped.
    Positions are unclipped, like :func:`~matshop.paint.brush.dab_footprint`'s:
    the caller wraps or clips them (see the module docstring).
    """
    cx, cy = symmetry.centre_in(width, height)
    kx, ky = round(2.0 * cx), round(2.0 * cy)  # integers: the centre is on the half grid
    h, w = alpha.shape
    images = [(x0, y0, alpha)]
    if symmetry.x:
        images.append((kx - x0 - w, y0, alpha[:, ::-1]))
    if symmetry.y:
        images += [(x, ky - y0 - h, a[::-1, :]) for x, _, a in images]
    return images
