"""A grayscale image laid on the texture by a similarity transform, sampled at texel centres.

Brush tips and stencils are both such images: a tip is scaled to the dab's
size and turned to its angle, a stencil is placed, scaled and turned by the
artist. Both are sampled bilinearly at texel centres from a box-filtered
level of a :class:`Pyramid`, so a large image drawn small does not alias;
outside the image a tip is zero, a stencil continues its edge.

Conventions: an image of ``(h, w)`` pixels spans ``[0, w) x [0, h)`` in its
own pixel units (pixel (i, j) centred at (j + 0.5, i + 0.5)); it is placed
with its centre at texel point ``(cx, cy)``, ``scale`` texels per pixel,
turned ``angle_deg`` counter-clockwise as seen on screen (texel y points down,
so 90 degrees takes the image's right edge to its top, as ``np.rot90`` does).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import MatshopError
from ._sample_kernel import sample_block


class Pyramid:
    """An image and its 2x2 box-averaged halvings.

    Odd sizes are padded by one row or column before halving: with zeros for
    ``outside="zero"`` (a tip is zero around), with the edge for ``"clamp"``.
    """

    def __init__(self, image: np.ndarray, outside: str = "zero") -> None:
        image = np.ascontiguousarray(image, dtype=np.float32)
        self.outside = outside
        levels = [image]
        while max(levels[-1].shape) > 1:
            level = levels[-1]
            h, w = level.shape
            if h % 2 or w % 2:
                mode = "constant" if outside == "zero" else "edge"
                level = np.pad(level, ((0, h % 2), (0, w % 2)), mode=mode)
            h, w = level.shape
            levels.append(level.reshape(h // 2, 2, w // 2, 2).mean(axis=(1, 3), dtype=np.float32))
        self.levels = levels
        #: each level with a one-pixel border (zeros, or its edge), what sampling reads
        mode = "constant" if outside == "zero" else "edge"
        self.padded = [np.pad(level, 1, mode=mode) for level in levels]

    @property
    def shape(self) -> tuple[int, int]:
        return self.levels[0].shape  # type: ignore[return-value]

    def level_for(self, scale: float) -> int:
        """The coarsest level whose pixels are at most one texel (``scale`` texels a pixel)."""
        if scale >= 1.0:
            return 0
        return min(int(math.floor(math.log2(1.0 / scale))), len(self.levels) - 1)


def _cos_sin(theta: float) -> tuple[float, float]:
    """cos and sin, exact at multiples of 90 degrees (a quarter turn moves texels, nothing else)."""
    quarter = theta / (math.pi / 2)
    if abs(quarter - round(quarter)) < 1e-12:
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[round(quarter) % 4]
    return math.cos(theta), math.sin(theta)


def sample_placed(
    pyramid: Pyramid,
    x0: int,
    y0: int,
    height: int,
    width: int,
    centre: tuple[float, float],
    scale: float,
    angle_deg: float,
    *,
    with_inside: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """The placed image at the centres of texels ``[x0, x0 + width) x [y0, y0 + height)``.

    Returns ``(values, inside)``, both ``(height, width)``: bilinear samples of
    the pyramid level matching ``scale`` (texels per image pixel), and whether
    each texel centre falls on the image (None unless ``with_inside``: a tip
    needs only its values, which then skip the texels past a zero border).
    """
    level = pyramid.level_for(scale)
    cos, sin = _cos_sin(math.radians(angle_deg))
    # a texel offset d shows the image at R^-1 d / scale: R turns counter-clockwise on
    # screen, where y points down (so R = [[cos, sin], [-sin, cos]] in x, y)
    h, w = pyramid.shape
    values = np.empty((height, width), np.float32)
    inside = np.empty((height, width) if with_inside else (0, 0), np.bool_)
    sample_block(
        pyramid.padded[level],
        x0,
        y0,
        float(centre[0]),
        float(centre[1]),
        cos / scale,
        -sin / scale,
        sin / scale,
        cos / scale,
        w / 2.0,
        h / 2.0,
        float(1 << level),
        pyramid.outside == "clamp",
        values,
        inside,
    )
    return values, inside if with_inside else None


def read_gray(path: str | os.PathLike[str], what: str) -> np.ndarray:
    """A tip's or stencil's gray from any image OpenImageIO reads: its gray (Rec. 709
    luminance of a color image) times its alpha, if it has one. Errors name ``what``."""
    from ..io.images import luminance, read_image  # OpenImageIO only when a file is read

    path = Path(path)
    try:
        pixels, info = read_image(path)
    except MatshopError as exc:
        raise MatshopError(f"{what} {path}: {exc.problem}") from None
    gray = luminance(pixels)
    if info.channels in (2, 4):  # gray+alpha or RGBA: transparent parts let nothing through
        gray = gray * pixels[..., -1]
    return gray


def warm_up() -> None:
    """Load the compiled sampling kernel now (half a second from numba's cache, seconds
    the first time), so the first tip or stencil dab of a session does not wait for it."""
    pyramid = Pyramid(np.ones((2, 2), np.float32))
    sample_placed(pyramid, 0, 0, 1, 1, (0.5, 0.5), 1.0, 0.0)
