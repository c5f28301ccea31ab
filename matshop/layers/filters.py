"""What a filter layer may run, and how far around a texel it reads.

Filter layers run ops from the registry (:mod:`matshop.ops`) on the composite
below them. The document caches per tile, so it must know each op's *reach*:
how many texels of context one output texel depends on. Pointwise ops reach
0 (a tile is computed from the same tile below); a Gaussian blur reaches its
kernel radius; an op whose reach is not declared here is treated as global
(any change below recomputes the whole layer), which is slow but never wrong.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from ..ops import OpError, OpSpec, get_op

#: Reach in texels for ops whose footprint is known exactly (None: global).
#: Pointwise ops (``neighbourhood=False``) need no entry unless a parameter makes
#: them global (curves and levels over the image's own value range).
_REACH: dict[str, Callable[[Mapping[str, Any]], int | None]] = {}


def _blur_reach(values: Mapping[str, Any]) -> int:
    from ..ops.blur import kernel_radius_px

    sigma = float(values["sigma_px"])
    return 0 if sigma == 0 else kernel_radius_px(sigma)


_REACH["blur"] = _blur_reach


def _tone_reach(values: Mapping[str, Any]) -> int | None:
    # remap="data" reads the value range of the whole image below: global
    return 0 if values.get("remap") == "space" else None


_REACH["curves"] = _REACH["levels"] = _tone_reach


def bind_filter(op: str, values: Mapping[str, Any] | None = None) -> tuple[OpSpec, dict[str, Any]]:
    """Validate an op and its parameters for use as a filter layer.

    Returns the op's spec and its bound parameters (defaults filled in).
    Ops that need more inputs than the composite below (compositing,
    cloning a region) cannot be filter layers.
    """
    spec = get_op(op)
    if spec.inputs:
        raise OpError(f"{op} needs {', '.join(spec.inputs)} besides the image: not a filter layer")
    return spec, spec.bind(dict(values or {}))


def filter_reach(op: str, values: Mapping[str, Any]) -> int | None:
    """Texels of context the op reads around each output texel; None for the whole image."""
    spec = get_op(op)
    reach = _REACH.get(op)
    if reach is not None:
        return reach(values)
    return 0 if not spec.neighbourhood else None
