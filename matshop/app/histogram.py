"""Histogram of a parameter's edit values, on the [0, 1] axis a tone curve works on.

Qt-free. The curves op maps each parameter to [0, 1] by its ``remap``
(:mod:`matshop.ops.tone_range`: the values' own range in the image by default,
or the space's fixed range): per channel for colors and scalars, by the
weighted magnitude for vectors (frames and sampled lobes). The histogram uses
the op's own ranges (:func:`~matshop.ops.curves.curve_ranges`), so what the
user sees under a curve point is exactly what that point moves.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..material import Schema
from ..ops.selection import Selection
from ..ops.tone_range import CLIP_PERCENT, Remap, group_values, tone_ranges

#: Texels read at most; bigger images are strided (a histogram needs no more).
MAX_TEXELS = 1 << 20


def edit_histogram(
    edit: np.ndarray,
    schema: Schema,
    parameters: Sequence[str] | None,
    bins: int = 128,
    *,
    remap: Remap = "data",
    clip_percent: float = CLIP_PERCENT,
) -> np.ndarray:
    """Counts per bin over [0, 1] of the selected parameters (None: all), scaled to max 1."""
    height, width = edit.shape[:2]
    step = max(1, int(np.ceil(np.sqrt(height * width / MAX_TEXELS))))
    sample = np.ascontiguousarray(edit[::step, ::step])
    selection = Selection(sample, schema=schema, params=parameters, mask=None, op="curves")
    block = selection.take(sample)
    ranges = tone_ranges(block, selection.groups, remap=remap, clip_percent=clip_percent)
    counts = np.zeros(bins, dtype=np.float64)
    for group, tone in zip(selection.groups, ranges, strict=True):
        t = (group_values(block, group) - tone.lo) / tone.span
        index = np.clip((t.reshape(-1) * bins).astype(np.int64), 0, bins - 1)
        counts += np.bincount(index, minlength=bins)
    peak = counts.max()
    return counts / peak if peak > 0 else counts
