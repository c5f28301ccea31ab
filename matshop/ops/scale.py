"""Scale: ``p~' = s * p~``.

In edit space this has a meaning per parameter: halves the reflected energy
of a color, scales every frame perturbation angle by ``s`` (0 flattens),
narrows (s < 1) or widens (s > 1) a microfacet lobe.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..material import Schema
from ._kernels import scale_lerp
from .selection import Selection, selected_width
from .spec import OpError, OpSpec, OpTarget, ParamSpec


def scale(
    edit: np.ndarray,
    *,
    factor: float = 1.0,
    channel_factors: Sequence[float] | None = None,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Multiply the selected edit channels by ``factor``.

    Parameters
    ----------
    edit : (H, W, C) float32 ndarray
        Edit-space values; never modified.
    factor : float
        The scale ``s``.
    channel_factors : sequence of float, optional
        One more factor per selected edit channel, in schema order (e.g.
        ``(1, 2.5)`` on an Ashikhmin-Shirley lobe widens it along one axis
        only; per-axis factors on a frame rotate and stretch perturbations).
    schema, params : which parameters to touch (all when ``params`` is None).
    mask : (H, W) ndarray in [0, 1], optional
        Blends the result with the input.

    Returns
    -------
    (H, W, C) float32 ndarray

    Examples
    --------
    >>> import numpy as np
    >>> scale(np.ones((1, 1, 2), np.float32), factor=0.5)[0, 0].tolist()
    [0.5, 0.5]
    """
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="scale")
    if channel_factors is not None:
        _check_factor_count(channel_factors, selection.width)
        block = selection.take(edit)
        gains = np.float32(factor) * np.asarray(channel_factors, dtype=np.float32)
        return selection.put(edit, np.multiply(block, gains, dtype=np.float32))
    if selection.mask is not None:
        # scale and blend in one pass: no full-size intermediate
        weights = selection.mask
        return selection.put_with(
            edit, lambda src, dst: scale_lerp(src, np.float32(factor), weights, dst)
        )
    block = selection.take(edit)
    return selection.put(edit, np.multiply(block, np.float32(factor), dtype=np.float32))


def _check_factor_count(channel_factors: Sequence[float], width: int) -> None:
    if len(channel_factors) != width:
        raise OpError(
            f"scale: channel_factors has {len(channel_factors)} values, the selection "
            f"has {width} edit channels"
        )


def check_scale(values: Mapping[str, Any], target: OpTarget) -> None:
    """One channel factor per selected edit channel (when the selection is known)."""
    if values["channel_factors"] is not None and target.schema is not None:
        width = selected_width(target.schema, target.params, "scale")
        _check_factor_count(values["channel_factors"], width)


SPECS = (
    OpSpec(
        name="scale",
        label="Scale",
        summary="multiply edit values: energy of colors, angle of frames, width of lobes",
        function=scale,
        params=(
            ParamSpec(
                "factor", "float", 1.0, "the scale s", hard_range=(-100.0, 100.0), ui_range=(0, 2)
            ),
            ParamSpec(
                "channel_factors",
                "floats",
                None,
                "one more factor per selected edit channel, e.g. 1,2.5 (per-axis scaling)",
                hard_range=(-100.0, 100.0),
            ),
        ),
        linear=True,
        checks=(check_scale,),
    ),
)
