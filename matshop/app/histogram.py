"""Histogram of a parameter's edit values, on the [0, 1] axis a tone curve works on.

Qt-free. The curves op maps each parameter's edit range to [0, 1]: per
channel for colors and scalars (``(v - lo) / span``), by the weighted
magnitude for vectors (``|v| / span``, frames and sampled lobes). The
histogram uses the same mapping (the op's own channel groups), so what the
user sees under a curve point is exactly what that point moves.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..material import Schema
from ..ops.selection import Selection

#: Texels read at most; bigger images are strided (a histogram needs no more).
MAX_TEXELS = 1 << 20


def edit_histogram(
    edit: np.ndarray, schema: Schema, parameters: Sequence[str] | None, bins: int = 128
) -> np.ndarray:
    """Counts per bin over [0, 1] of the selected parameters (None: all), scaled to max 1."""
    height, width = edit.shape[:2]
    step = max(1, int(np.ceil(np.sqrt(height * width / MAX_TEXELS))))
    sample = np.ascontiguousarray(edit[::step, ::step])
    selection = Selection(sample, schema=schema, params=parameters, mask=None, op="curves")
    block = selection.take(sample)
    counts = np.zeros(bins, dtype=np.float64)
    for group in selection.groups:
        values = block[..., group.channels].astype(np.float64)
        span = group.edit_range.span if np.isfinite(group.edit_range.span) else 1.0
        if group.curve_mode == "vector":
            t = np.sqrt((values**2 * group.quadrature).sum(axis=-1)) / span
        else:
            t = (values - group.edit_range.lo) / span
        index = np.clip((t.reshape(-1) * bins).astype(np.int64), 0, bins - 1)
        counts += np.bincount(index, minlength=bins)
    peak = counts.max()
    return counts / peak if peak > 0 else counts
