"""An op chain: ops with their settings, checked up front, then run on one material.

``matshop apply`` (words on the command line), ``matshop batch`` (a TOML
recipe) and scripts build the same :class:`Step` list and run it through
:func:`run_steps`, so one set edited either way gives byte-identical files.
The editor takes the same list as filter layers (:func:`filter_layers`), which
flatten to the same bytes. Validation is the op registry's own
(``OpSpec.parse_args`` / ``bind``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .api import EditableMaterial, load_mask
from .errors import MatshopError
from .ops import get_op
from .ops.selection import resolve_params

if TYPE_CHECKING:  # the document model is for the editor's filter layers, not `matshop apply`
    from .layers import Document
    from .layers.layer import FilterLayer


@dataclass(frozen=True)
class Step:
    """One op of a chain: its name, raw settings, parameter selection and mask file."""

    op: str
    #: typed settings as ``EditableMaterial.apply`` takes them (inputs as paths)
    values: dict[str, Any]
    #: parameter names or aliases (None: all of the material's)
    params: tuple[str, ...] | None = None
    #: a grayscale mask image blending the op's result (None: everywhere)
    mask: Path | None = None


def checked(op: str, values: dict[str, Any]) -> dict[str, Any]:
    """``values`` after the registry validated every setting of ``op`` (raises OpError)."""
    spec = get_op(op)
    spec.bind({k: v for k, v in values.items() if k not in spec.all_inputs})
    return values


def step_from_words(
    words: Sequence[str], *, params: Sequence[str] | None = None, mask: Path | None = None
) -> Step:
    """A step from the command line's words: ``["blur", "sigma_px=4"]``."""
    name, *pairs = words
    values = checked(name, get_op(name).parse_args(pairs))
    return Step(name, values, None if params is None else tuple(params), mask)


def run_steps(
    material: EditableMaterial,
    steps: Sequence[Step],
    *,
    mask_loader: Callable[[Path, tuple[int, int]], Any] = load_mask,
    progress: Callable[[int, int], None] | None = None,
) -> EditableMaterial:
    """Apply ``steps`` in order to ``material`` (in place); each mask file is read once."""
    masks: dict[Path, Any] = {}
    for done, step in enumerate(steps, 1):
        mask = None
        if step.mask is not None:
            if step.mask not in masks:
                masks[step.mask] = mask_loader(step.mask, material.size)
            mask = masks[step.mask]
        params = None if step.params is None else list(step.params)
        material.apply(step.op, params=params, mask=mask, **step.values)
        if progress is not None:
            progress(done, len(steps))
    return material


def filter_layers(
    doc: Document,
    steps: Sequence[Step],
    *,
    mask_loader: Callable[[Path, tuple[int, int]], Any] = load_mask,
) -> list[FilterLayer]:
    """``steps`` as filter layers of ``doc``, bottom first, to insert on top of it.

    Each layer runs its step's op with the same settings on the same parameters,
    masked by the same image, so the document flattens to what :func:`run_steps`
    gives the flattened material (the same bytes: both run the op on the whole
    composite below and blend by the mask). Ops that need another texture set
    (composite, clone) are refused: a filter layer has only the composite below it.
    """
    masks: dict[Path, Any] = {}
    layers = []
    for number, step in enumerate(steps, 1):
        if get_op(step.op).inputs:
            raise MatshopError(
                f"step {number} ({step.op}) needs another texture set: not a filter layer"
            )
        params = None if step.params is None else list(step.params)
        names = tuple(resolve_params(doc.schema, params, step.op))
        if step.mask is not None and step.mask not in masks:
            masks[step.mask] = doc.new_mask(array=mask_loader(step.mask, doc.size))
        mask = None if step.mask is None else masks[step.mask]
        layers.append(
            doc.new_filter_layer(step.op, op_params=step.values, parameters=names, mask=mask)
        )
    return layers
