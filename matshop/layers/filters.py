"""What a filter layer may run, bound against the document it runs in.

Filter layers run ops from the registry (:mod:`matshop.ops`) on the composite
below them. Everything about the op -- its parameters, the checks across them
and against the material, and its *reach* (texels of context one output texel
reads, which the tiled compositor uses as margin) -- is the op's
:class:`~matshop.ops.OpSpec`; this module only says which ops can be layers.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..ops import OpError, OpSpec, get_op
from ..ops.spec import OpTarget


def bind_filter(
    op: str, values: Mapping[str, Any] | None = None, target: OpTarget | None = None
) -> tuple[OpSpec, dict[str, Any]]:
    """Validate an op and its parameters for use as a filter layer on ``target``.

    Returns the op's spec and its bound parameters (defaults filled in).
    Ops that need more inputs than the composite below (compositing,
    cloning a region) cannot be filter layers.
    """
    spec = get_op(op)
    if spec.inputs:
        raise OpError(f"{op} needs {', '.join(spec.inputs)} besides the image: not a filter layer")
    if not isinstance(values, Mapping | None):
        raise OpError(f"{op}: filter settings must be a mapping of name to value, got {values!r}")
    return spec, spec.bind(dict(values or {}), target)
