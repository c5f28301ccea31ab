"""Reading a mask image: one reader for layer masks, op masks and clone regions.

A mask is the *brightness* of an image, white showing and black hiding:
one- and two-channel images (gray, gray + alpha) give their gray channel,
color images the Rec. 709 luminance ``0.2126 R + 0.7152 G + 0.0722 B`` of
the values in the file. Why luminance and not the first channel: a mask is made
by painting light over dark in an image editor, and it is judged by eye; a
green or blue stroke on black is as much a selection as a white one (the
first channel would read it as empty), and a red one reads as dark, as it
looks. GIMP's and Krita's image-to-mask conversions take the luminance too.
Alpha is ignored: a mask's coverage is its brightness, and the files
editors save have opaque alpha. A region (a clone's) is where the mask
reads more than one half.
"""

from __future__ import annotations

import os

import numpy as np

from ..errors import MatshopError
from .images import luminance, read_image, resample_image

#: a region is where a mask reads more than this
REGION_THRESHOLD = 0.5

PathLike = str | os.PathLike[str]


def load_mask(
    path: PathLike, size: tuple[int, int] | None = None, *, resample: bool = False
) -> np.ndarray:
    """A mask image as ``(H, W)`` float32 in [0, 1], checked against ``size`` (H, W).

    ``resample``: a mask of another size is resampled to ``size`` (area-averaged
    down, bilinear up) instead of refused; a batch recipe's mask meets sets of
    every size. ``size=None`` takes the image as it is.
    """
    pixels, info = read_image(path)
    if size is None:
        return luminance(pixels)
    if pixels.shape[:2] != tuple(size) and not resample:
        raise MatshopError(
            f"mask is {info.width}x{info.height}, the material is {size[1]}x{size[0]}", path
        )
    return resample_image(luminance(pixels), size)


def load_region(path: PathLike) -> np.ndarray:
    """A mask image as a boolean region: where it reads more than one half."""
    return load_mask(path) > REGION_THRESHOLD
