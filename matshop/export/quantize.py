"""Quantising to 8-bit codes with dithering.

Rounding a smooth ramp to 256 codes makes flat bands tens of texels wide, and
packed data (roughness) shows them as visible steps in highlights. Dithering
adds a threshold ``t`` in ``[0, 1)`` code before taking the floor:
``q = floor(v * 255 + t)``. Over texels whose thresholds cover ``[0, 1)``
evenly, the mean of ``q`` is ``v * 255``, so every region keeps the
unquantised value (no bands), and one texel's error stays below one code.

The thresholds are interleaved gradient noise (Jimenez 2014, the dither of
real-time renderers): ``frac(52.9829189 * frac(0.06711056 x + 0.00583715 y))``.
Any few neighbouring texels get well-spread thresholds, so region means are
far closer to the truth than with white noise and runs of one code stay
short; it is deterministic (a seed only shifts the pattern), so exporting
twice gives identical files.

Constant channels are rounded, not dithered. Values already on the code grid
(anything read from an 8-bit file and not edited) are kept exactly: a
dithered export of untouched 8-bit data gives back the same codes, which
keeps data in alpha and ORM channels bit-exact.
"""

from __future__ import annotations

import numpy as np

#: a value this close to a code (in code units) is that code: float32 maths on
#: ``k / 255`` (e.g. ``1 - k / 255`` for smoothness) lands a few ulps off it
_ON_GRID = 1e-3


def code_max(bit_depth: str) -> int | None:
    """The largest code of an integer depth (255, 65535); None for float depths."""
    return {"uint8": 255, "uint16": 65535}.get(bit_depth)


def quantize(array: np.ndarray, bit_depth: str, *, dither: bool, seed: int = 0) -> np.ndarray:
    """``array`` (float, ``[0, 1]``) snapped onto the code grid of ``bit_depth``.

    Returns float32 values ``code / max`` that the image writer stores
    exactly; float depths are returned unchanged. Dithering is applied to
    8-bit depths only (16 bits have no visible bands).

    Parameters
    ----------
    array : (H, W, C) float array in ``[0, 1]`` (clipped).
    bit_depth : ``uint8``, ``uint16``, ``half`` or ``float``.
    dither : add a threshold in ``[0, 1)`` code before flooring (8-bit only).
    seed : shifts the threshold pattern; the same seed gives the same codes.
    """
    top = code_max(bit_depth)
    if top is None:
        return np.asarray(array, dtype=np.float32)
    scaled = np.clip(np.asarray(array, dtype=np.float64), 0.0, 1.0) * top
    nearest = np.rint(scaled)
    if not dither or top != 255:
        codes = nearest
    else:
        noise = dither_thresholds(scaled.shape[:2], seed=seed)
        if scaled.ndim == 3:
            noise = noise[..., None]
        dithered = np.clip(np.floor(scaled + noise), 0, top)
        keep = np.abs(scaled - nearest) < _ON_GRID
        # a constant channel (a default fill, the HDRP detail mask) has no
        # gradient to band: noise would only make it grainy
        flat = (scaled.min(axis=(0, 1)) == scaled.max(axis=(0, 1))) if scaled.ndim == 3 else False
        codes = np.where(keep | flat, nearest, dithered)
    return (codes / top).astype(np.float32)


def dither_thresholds(shape: tuple[int, int], *, seed: int = 0) -> np.ndarray:
    """Interleaved gradient noise in ``[0, 1)``, shape ``(H, W)``, shifted by ``seed``."""
    offset_x, offset_y = seed % 4099, (seed // 4099) % 4093
    y, x = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float64)
    inner = np.mod(0.06711056 * (x + offset_x) + 0.00583715 * (y + offset_y), 1.0)
    return np.mod(52.9829189 * inner, 1.0)
