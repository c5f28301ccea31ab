"""Alpha compositing in edit space: ``p~' = (1 - a) p~_under + a p~_over``.

The operation layers and brush dabs are built on. ``a`` is the opacity times
the mask; parameters outside the selection keep the layer below.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..material import Schema
from ._kernels import lerp
from .selection import Selection, check_mask
from .spec import OpError, OpSpec, ParamSpec


def composite(
    under: np.ndarray,
    over: np.ndarray,
    *,
    opacity: float = 1.0,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Composite ``over`` onto ``under`` (both (H, W, C) float32 edit arrays).

    ``mask`` (H, W) in [0, 1] is the coverage of ``over``; ``opacity`` scales it.
    """
    over = np.asarray(over)
    if over.shape != np.shape(under):
        raise OpError(f"composite: layer is {over.shape}, the material below is {np.shape(under)}")
    if over.dtype != np.float32:
        raise OpError(f"composite: layer must be float32 edit values, got {over.dtype}")
    selection = Selection(under, schema=schema, params=params, mask=None, op="composite")
    coverage = check_mask(mask, under.shape[:2], "composite")
    if coverage is None:
        coverage = np.full(under.shape[:2], opacity, dtype=np.float32)
    elif opacity != 1.0:
        coverage = coverage * np.float32(opacity)
    sl = selection.channels
    if selection.everything:
        out = np.empty_like(under)
        lerp(under, over, coverage, out)
    else:
        out = under.copy()
        block = np.empty((*under.shape[:2], selection.width), dtype=np.float32)
        lerp(selection.take(under), selection.take(over), coverage, block)
        out[..., sl] = block
    return out


SPECS = (
    OpSpec(
        name="composite",
        label="Composite",
        summary="alpha-over another material (or layer) in edit space",
        function=composite,
        params=(
            ParamSpec(
                "opacity",
                "float",
                1.0,
                "opacity of the layer",
                hard_range=(0.0, 1.0),
                ui_range=(0.0, 1.0),
            ),
        ),
        linear=True,
        inputs=("over",),
    ),
)
