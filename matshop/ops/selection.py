"""Which edit channels an op touches, how they group, and how a mask blends.

Ops see an edit array ``(H, W, C)`` and, optionally, the :class:`Schema` that
names its channels. A :class:`Selection` resolves a parameter list to
channel indices, splits them into groups (a color's channels are
independent; a frame's or a distribution's form one vector), and writes an
op's result back: unselected channels are copied untouched and a mask in
[0, 1] blends the result with the input (``input + mask * (result - input)``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..material import Schema
from ..spaces.base import CurveMode, EditRange
from .spec import OpError

#: Names users type for parameters, mapped to schema names.
PARAMETER_ALIASES: dict[str, tuple[str, ...]] = {
    "kd": ("diffuse", "base_color"),
    "ks": ("specular",),
    "albedo": ("base_color", "diffuse"),
    "color": ("base_color", "diffuse"),
    "basecolor": ("base_color",),
    "frame": ("normal",),
    "normals": ("normal",),
    "rough": ("roughness",),
    "d": ("distribution",),
}


@dataclass(frozen=True)
class ChannelGroup:
    """Channels that belong together, with what curves and distances need to know."""

    name: str
    #: positions within the *selected* block (not the full edit vector)
    channels: np.ndarray
    curve_mode: CurveMode
    edit_range: EditRange
    #: quadrature weight per channel: a vector's magnitude is sqrt(sum(w v^2)),
    #: all ones except for sampled functions (inverse CDFs at fixed y)
    quadrature: np.ndarray

    def distance_weights(self) -> np.ndarray:
        """Per-channel scale making distances comparable across parameters (range -> 1)."""
        span = self.edit_range.span if np.isfinite(self.edit_range.span) else 1.0
        return (np.sqrt(self.quadrature) / max(span, 1e-12)).astype(np.float32)


def _space_groups(space, offset: int, name: str) -> list[ChannelGroup]:
    width = space.edit_channels
    custom = getattr(space, "edit_groups", None)
    if custom is not None:
        groups = []
        for label, local, mode, edit_range, quadrature in custom():
            idx = np.arange(width)[local] + offset
            groups.append(
                ChannelGroup(f"{name}.{label}", idx, mode, edit_range, np.asarray(quadrature))
            )
        return groups
    # sampled functions (inverse CDFs at fixed y) carry their quadrature weights
    dy = getattr(space, "dy", None)
    quadrature = np.ones(width) if dy is None else np.asarray(dy, dtype=np.float64)
    idx = np.arange(offset, offset + width)
    return [ChannelGroup(name, idx, space.curve_mode, space.edit_range, quadrature)]


def resolve_params(schema: Schema, params: Sequence[str] | str | None, op: str) -> list[str]:
    """Schema parameter names for a user's selection (aliases allowed, ``None`` = all)."""
    if params is None:
        return list(schema.names)
    if isinstance(params, str):
        params = [p for p in params.split(",") if p.strip()]
    names: list[str] = []
    for raw in params:
        key = raw.strip().lower()
        if key in schema:
            candidates: tuple[str, ...] = (key,)
        else:
            candidates = tuple(n for n in PARAMETER_ALIASES.get(key, ()) if n in schema)
        if not candidates:
            raise OpError(
                f"{op}: no parameter {raw!r} in this material (has: {', '.join(schema.names)})"
            )
        if candidates[0] not in names:
            names.append(candidates[0])
    if not names:
        raise OpError(f"{op}: the parameter selection is empty")
    return names


def selected_width(schema: Schema, params: Sequence[str] | str | None, op: str) -> int:
    """Edit channels a selection covers (before any array exists: checks at bind time)."""
    return sum(schema[name].edit_channels for name in resolve_params(schema, params, op))


class Selection:
    """The selected channels of an edit array, their groups, and the mask."""

    def __init__(
        self,
        edit: np.ndarray,
        *,
        schema: Schema | None,
        params: Sequence[str] | str | None,
        mask: np.ndarray | None,
        op: str,
    ) -> None:
        edit = np.asarray(edit)
        if edit.ndim != 3 or edit.dtype != np.float32:
            raise OpError(
                f"{op}: expected a (H, W, C) float32 edit array, got {edit.shape} {edit.dtype}"
            )
        self.op = op
        self.shape = edit.shape
        width = edit.shape[2]
        groups: list[ChannelGroup] = []
        if schema is None:
            if params is not None:
                raise OpError(f"{op}: selecting parameters by name needs the material's schema")
            one = np.ones(1)
            groups = [
                ChannelGroup(f"c{i}", np.array([i]), "channels", EditRange(0.0, 1.0), one)
                for i in range(width)
            ]
        else:
            if schema.edit_width != width:
                raise OpError(
                    f"{op}: the edit array has {width} channels, the schema {schema.edit_width}"
                )
            for name in resolve_params(schema, params, op):
                start = schema.edit_slices[name].start
                groups.extend(_space_groups(schema[name].space, start, name))
        full_index = np.concatenate([g.channels for g in groups])
        order = np.argsort(full_index, kind="stable")
        self.channels = full_index[order]
        # groups address the selected block: renumber their channels
        position = {int(c): i for i, c in enumerate(self.channels)}
        self.groups = [
            ChannelGroup(
                g.name,
                np.array([position[int(c)] for c in g.channels]),
                g.curve_mode,
                g.edit_range,
                g.quadrature,
            )
            for g in groups
        ]
        lo, hi = int(self.channels[0]), int(self.channels[-1]) + 1
        contiguous = hi - lo == len(self.channels)
        self._slice: slice | np.ndarray = slice(lo, hi) if contiguous else self.channels
        self.everything = contiguous and lo == 0 and hi == width
        self.mask = check_mask(mask, edit.shape[:2], op)

    @property
    def width(self) -> int:
        return len(self.channels)

    def take(self, edit: np.ndarray) -> np.ndarray:
        """The selected channels (a view when they are contiguous)."""
        return edit[..., self._slice]

    def distance_weights(self) -> np.ndarray:
        """Per selected channel: scale for range distances (bilateral)."""
        weights = np.empty(self.width, dtype=np.float32)
        for group in self.groups:
            weights[group.channels] = group.distance_weights()
        return weights

    def put_with(
        self, edit: np.ndarray, kernel: Callable[[np.ndarray, np.ndarray], None]
    ) -> np.ndarray:
        """A new full array whose selected channels ``kernel(src, dst)`` writes.

        For pointwise ops that fuse the mask blend into their own pass, so no
        intermediate full-size result is made; the other channels are copied.
        """
        if self.everything:
            out = np.empty_like(edit)
            kernel(edit, out)
            return out
        out = edit.copy()
        if isinstance(self._slice, slice):
            kernel(edit[..., self._slice], out[..., self._slice])
        else:
            block = np.empty((*edit.shape[:2], self.width), dtype=np.float32)
            kernel(self.take(edit), block)
            out[..., self._slice] = block
        return out

    def put(self, edit: np.ndarray, result: np.ndarray) -> np.ndarray:
        """A new full array: ``result`` in the selected channels, blended by the mask."""
        from ._kernels import lerp

        result = np.asarray(result, dtype=np.float32)
        if self.everything:
            if self.mask is None:
                return result if result is not edit else result.copy()
            out = np.empty_like(edit)
            lerp(edit, result, self.mask, out)
            return out
        out = edit.copy()
        if self.mask is None:
            out[..., self._slice] = result
        elif isinstance(self._slice, slice):
            lerp(edit[..., self._slice], result, self.mask, out[..., self._slice])
        else:
            block = np.empty_like(result)
            lerp(edit[..., self._slice], result, self.mask, block)
            out[..., self._slice] = block
        return out


def check_mask(mask: np.ndarray | None, size: tuple[int, int], op: str) -> np.ndarray | None:
    """A mask as (H, W) float32 in [0, 1], or a clear error."""
    if mask is None:
        return None
    mask = np.asarray(mask)
    if mask.ndim == 3 and mask.shape[2] == 1:
        mask = mask[..., 0]
    if mask.shape != tuple(size):
        raise OpError(
            f"{op}: mask is {mask.shape[1] if mask.ndim > 1 else '?'}x{mask.shape[0]}, "
            f"the material is {size[1]}x{size[0]}"
        )
    mask = mask.astype(np.float32, copy=False)
    if not np.isfinite(mask).all():
        raise OpError(f"{op}: mask contains NaN or Inf")
    return np.clip(mask, 0.0, 1.0)
