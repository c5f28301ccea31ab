"""Brush tips: a grayscale image stamped as a dab, scaled to its size and turned to its angle.

White paints, black does not (Substance Painter's alphas): a tip read from a
file is its gray (Rec. 709 luminance of a color image) times its alpha, if it
has one. The tip's longer side spans the dab's diameter (``2 * radius``),
its centre at the dab's centre; see :mod:`.sampling` for the placement and
the angle's sense (counter-clockwise on screen). Hardness does not apply:
the image is the falloff.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InvalidValue, MatshopError
from .sampling import Pyramid, read_gray, sample_placed
from .tip_shapes import SHAPES

#: a tip larger than this (per side) is refused: no brush needs it, and it costs memory
MAX_TIP_PX = 8192


@dataclass(frozen=True, eq=False)
class Tip:
    """A tip image (``(h, w)`` float32 in [0, 1]) and where it came from.

    ``source`` is what a stroke file writes for it: ``{"image": path}`` or
    ``{"procedural": name, "seed": n}``. Tips compare by identity.
    """

    image: np.ndarray
    source: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        image = np.ascontiguousarray(self.image, dtype=np.float32)
        if image.ndim != 2 or min(image.shape) < 1:
            raise InvalidValue(f"a tip is a 2D gray image, got shape {image.shape}")
        if not np.isfinite(image).all():
            raise InvalidValue("a tip image must be finite")
        object.__setattr__(self, "image", np.clip(image, 0.0, 1.0))
        object.__setattr__(self, "_pyramid", Pyramid(self.image, "zero"))

    @property
    def name(self) -> str:
        if "image" in self.source:
            return Path(self.source["image"]).name
        return f"{self.source.get('procedural', 'tip')} {self.source.get('seed', 0)}"

    @property
    def pyramid(self) -> Pyramid:
        return self._pyramid  # type: ignore[attr-defined]


def procedural_tip(name: str, seed: int = 0) -> Tip:
    """A built-in tip (``noise``, ``scratches``, ``spots``), the same for the same seed."""
    if not isinstance(name, str) or name not in SHAPES:
        raise InvalidValue(f"unknown tip {name!r}: one of {', '.join(SHAPES)} or an image file")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise InvalidValue(f"tip seed must be an integer in [0, 2^63), got {seed!r}")
    return Tip(SHAPES[name](seed), {"procedural": name, "seed": seed})


def load_tip(path: str | os.PathLike[str]) -> Tip:
    """A tip from any image OpenImageIO reads (see :func:`.sampling.read_gray`)."""
    from ..io.images import probe_image

    path = Path(path)
    try:
        info = probe_image(path)
    except MatshopError as exc:
        raise MatshopError(f"tip image {path}: {exc.problem}") from None
    if max(info.width, info.height) > MAX_TIP_PX:  # refused before reading its pixels
        raise InvalidValue(
            f"tip image {path} is {info.width}x{info.height}: at most {MAX_TIP_PX} px a side"
        )
    gray = read_gray(path, "tip image")
    if not (gray > 0).any():
        raise InvalidValue(f"tip image {path} is black everywhere: it would paint nothing")
    return Tip(gray, {"image": str(path)})


def tip_footprint(
    x: float, y: float, radius_px: float, angle_deg: float, tip: Tip
) -> tuple[int, int, np.ndarray]:
    """The alpha of one tip dab centred at (x, y): ``(x0, y0, alpha (h, w))``, unclipped.

    The block is a square about the centre, wide enough for the tip at any
    angle (its half-diagonal plus one tip pixel and one texel), so turning a
    dab centred on a texel by 90 degrees moves its texels and nothing else.
    """
    h, w = tip.image.shape
    scale = 2.0 * radius_px / max(h, w)  # texels per tip pixel
    reach = 0.5 * scale * float(np.hypot(h, w)) + scale + 1.0
    x0 = int(np.floor(x - reach))
    y0 = int(np.floor(y - reach))
    size_x = int(np.ceil(x + reach)) - x0
    size_y = int(np.ceil(y + reach)) - y0
    alpha, _ = sample_placed(
        tip.pyramid, x0, y0, size_y, size_x, (x, y), scale, angle_deg, with_inside=False
    )
    return x0, y0, alpha
