"""Mirror painting in texture space: one dab, and its mirror images about the centre lines.

``x`` mirrors left <-> right about the texture's vertical centre line
(``x = width / 2``), ``y`` top <-> bottom about its horizontal one; both
give four dabs. A mirrored footprint is the dab's own footprint flipped, so
what a symmetric stroke paints on one side is, texel for texel, the mirror
image of the other side (no resampling, no half-texel drift).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InvalidValue

_NAMES = {"none": (False, False), "x": (True, False), "y": (False, True), "xy": (True, True)}


@dataclass(frozen=True)
class Symmetry:
    """Which axes a stroke mirrors across: ``x`` (left/right), ``y`` (top/bottom)."""

    x: bool = False
    y: bool = False

    @classmethod
    def parse(cls, text: str) -> Symmetry:
        """``"none"``, ``"x"``, ``"y"`` or ``"xy"`` (also ``"yx"``)."""
        key = "xy" if text == "yx" else text
        if key not in _NAMES:
            raise InvalidValue(f"symmetry must be none, x, y or xy, got {text!r}")
        return cls(*_NAMES[key])

    @property
    def name(self) -> str:
        return next(name for name, axes in _NAMES.items() if axes == (self.x, self.y))

    def __bool__(self) -> bool:
        return self.x or self.y


NONE = Symmetry()


def mirrored_footprints(
    x0: int, y0: int, alpha: np.ndarray, width: int, height: int, symmetry: Symmetry
) -> list[tuple[int, int, np.ndarray]]:
    """``(x0, y0, alpha)`` of a footprint and its mirror images in a ``width x height`` texture.

    Texel column ``i`` mirrors to ``width - 1 - i`` (rows likewise), so the
    block ``[x0, x0 + w)`` lands on ``[width - x0 - w, width - x0)`` flipped.
    Positions are unclipped, like :func:`~matshop.paint.brush.dab_footprint`'s.
    """
    h, w = alpha.shape
    images = [(x0, y0, alpha)]
    if symmetry.x:
        images.append((width - x0 - w, y0, alpha[:, ::-1]))
    if symmetry.y:
        images += [(x, height - y0 - h, a[::-1, :]) for x, _, a in images]
    return images
