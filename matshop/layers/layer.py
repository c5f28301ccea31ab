"""The layer kinds: paint, fill and filter.

Every layer has a name, visibility, opacity, blend mode, the parameters it
affects (schema names; None means all) and an optional tiled mask (one
channel, 1 = show; ``mask_inverted`` flips it). What differs is where its
edit values ``L`` and coverage come from:

- :class:`PaintLayer`: tiled edit values plus a coverage channel, stored
  together (``channels + 1`` per texel) in one :class:`TileGrid`; unpainted
  texels have coverage 0 and cost nothing.
- :class:`FillLayer`: one constant edit vector, or a whole edit-space
  texture set (e.g. "rust" over "steel"); coverage 1 everywhere.
- :class:`FilterLayer`: an op from the registry applied to the composite
  below (non-destructive blur, curves, levels, scale...); ``L`` is the op's
  result, coverage 1.
- :class:`GroupLayer`: a pass-through group. Its members (layers whose
  ``parent`` is the group) sit just below it in the stack; they composite as
  usual, then the group mixes the result with the composite below its lowest
  member by its opacity and mask, only in its parameters. Hiding the group
  hides its members.

Layers are plain state. They are changed only through the document (which
invalidates caches and notifies) and, for undo, through edits; nothing here
knows about caches, history or Qt.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ..errors import InvalidValue
from ..material import Schema
from ..ops import get_op
from ..ops.generators import MaskGenerator
from ..ops.spec import OpTarget, Reach, run_op
from .blend import get_blend_mode, mean_of, weighted_mean
from .filters import bind_filter
from .geometry import Rect, TileLayout
from .properties import check_property, properties_of
from .tiles import TileGrid, freeze


@dataclass(eq=False)
class Layer:
    """State every layer kind shares."""

    id: int
    name: str
    visible: bool = True
    opacity: float = 1.0
    blend: str = "normal"
    #: schema parameter names the layer writes (None: all), in schema order
    parameters: tuple[str, ...] | None = None
    #: one-channel tiled mask in [0, 1] (1 shows the layer), or None
    mask: TileGrid | None = None
    mask_inverted: bool = False
    #: the mask is generated from the material below (recomputed when it changes;
    #: the compositor keeps the result), times ``mask`` when the layer has both
    mask_generator: MaskGenerator | None = None
    #: id of the group layer this layer belongs to, or None
    parent: int | None = None

    kind: ClassVar[str] = "layer"
    #: properties :meth:`Document.set_property` may change (:mod:`.properties`)
    PROPERTIES: ClassVar[tuple[str, ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.PROPERTIES = properties_of(cls.kind)

    def validate(
        self, name: str, value: Any, schema: Schema, size: tuple[int, int] | None = None
    ) -> Any:
        """Check a new property value; return it normalised (raises InvalidValue).

        ``size`` (height, width) is the document's, for checks that need it.
        """
        return check_property(self.kind, name, value, schema)

    def written_parameters(self, schema: Schema) -> tuple[str, ...] | None:
        """The parameters the compositor takes from this layer (None: all)."""
        return self.parameters

    def state(self) -> dict[str, Any]:
        """What :meth:`Document.new_layer` needs for a twin of this layer (a new id,
        any name): its properties and its content (tiles are shared copy-on-write)."""
        return {name: self.get(name) for name in self.PROPERTIES if name not in ("name", "filter")}

    def get(self, name: str) -> Any:
        """A property's current value (what an edit stores to undo)."""
        return getattr(self, name)

    def put(self, name: str, value: Any) -> None:
        """Set a validated property value (the document calls this, then invalidates)."""
        setattr(self, name, value)

    # -- contribution ------------------------------------------------------

    def coverage(self, rect: Rect) -> np.ndarray | None:
        """Per-texel coverage over ``rect`` (None: 1 everywhere)."""
        return None

    def alpha(
        self,
        rect: Rect,
        coverage: np.ndarray | None = None,
        generated: np.ndarray | None = None,
    ) -> np.ndarray:
        """Weight of the layer per texel: coverage x generated x mask x opacity, float32.

        One function for the tiled and the whole-image flatten, so both round
        alike. ``coverage`` saves re-reading it when the caller has it;
        ``generated`` is the whole generated mask ``(H, W)`` when the layer has
        a :attr:`mask_generator` (the compositor computes it from the layers below).
        """
        weight = self.coverage(rect) if coverage is None else coverage
        if generated is not None:
            shown = generated[rect.slices]
            weight = shown if weight is None else weight * shown
        if self.mask is not None:
            shown = self.mask.read(rect)[..., 0]
            if self.mask_inverted:
                shown = np.float32(1.0) - shown
            weight = shown if weight is None else weight * shown
        if weight is None:
            return np.full((rect.height, rect.width), self.opacity, dtype=np.float32)
        return weight * np.float32(self.opacity)

    def mean(self) -> np.ndarray | None:
        """The layer's coverage-weighted mean edit vector (for "detail"); None if it has none."""
        return None

    def arrays(self) -> Iterator[np.ndarray]:
        """Arrays this layer keeps alive (for history's memory accounting)."""
        if self.mask is not None:
            yield from self.mask._tiles.values()

    def describe(self) -> dict[str, Any]:
        """Properties as plain values (for panels, tests and project files)."""
        generator = self.mask_generator
        return {
            "kind": self.kind,
            "name": self.name,
            "visible": self.visible,
            "opacity": self.opacity,
            "blend": self.blend,
            "parameters": self.parameters,
            "mask": self.mask is not None,
            "mask_inverted": self.mask_inverted,
            "mask_generator": None if generator is None else generator.to_json(),
            "parent": self.parent,
        }


@dataclass(eq=False)
class PaintLayer(Layer):
    """Painted edit values with per-texel coverage, in sparse tiles.

    ``pixels`` has ``edit_width + 1`` channels: the edit vector, then coverage
    (straight, not premultiplied: ``L`` is the painted value itself).
    """

    pixels: TileGrid | None = None
    #: bumped on every pixel change (keys the cached mean)
    version: int = 0
    _mean: tuple[int, np.ndarray] | None = field(default=None, repr=False)

    kind: ClassVar[str] = "paint"

    @property
    def channels(self) -> int:
        assert self.pixels is not None
        return self.pixels.channels - 1

    def values(self, rect: Rect) -> tuple[np.ndarray, np.ndarray]:
        """``(values (h, w, C), coverage (h, w))`` over ``rect``, as views of one new block."""
        assert self.pixels is not None
        block = self.pixels.read(rect)
        return block[..., :-1], block[..., -1]

    def coverage(self, rect: Rect) -> np.ndarray | None:
        assert self.pixels is not None
        return self.pixels.read(rect)[..., -1]

    def mean(self) -> np.ndarray:
        assert self.pixels is not None
        if self._mean is not None and self._mean[0] == self.version:
            return self._mean[1]
        total = np.zeros(self.channels, dtype=np.float64)
        weight = 0.0
        # sorted keys: the float64 sum does not depend on painting order
        for key in sorted(self.pixels.keys()):
            tile = self.pixels.get(key)
            assert tile is not None
            part, w = weighted_mean(tile[..., :-1], tile[..., -1])
            total += part
            weight += w
        mean = freeze(mean_of(total, weight))
        self._mean = (self.version, mean)
        return mean

    def state(self) -> dict[str, Any]:
        assert self.pixels is not None
        return {**super().state(), "pixels": self.pixels.copy()}

    def arrays(self) -> Iterator[np.ndarray]:
        yield from super().arrays()
        assert self.pixels is not None
        yield from self.pixels._tiles.values()

    def describe(self) -> dict[str, Any]:
        info = super().describe()
        assert self.pixels is not None
        info["tiles"] = len(self.pixels)
        return info


@dataclass(eq=False)
class FillLayer(Layer):
    """A constant edit vector, or a whole edit-space texture set, over the document."""

    #: (C,) constant edit vector, or None when ``source`` is set
    value: np.ndarray | None = None
    #: (H, W, C) read-only edit-space texture, or None
    source: np.ndarray | None = None
    _source_mean: np.ndarray | None = field(default=None, repr=False)

    kind: ClassVar[str] = "fill"

    def validate(
        self, name: str, value: Any, schema: Schema, size: tuple[int, int] | None = None
    ) -> Any:
        if name == "value":
            vector = np.array(value, dtype=np.float32).reshape(-1)
            if vector.shape != (schema.edit_width,):
                raise InvalidValue(
                    f"a fill value needs {schema.edit_width} edit channels, got {vector.shape}"
                )
            return freeze(vector)
        if name == "source":
            if value is None:
                if self.value is None:
                    raise InvalidValue("a fill layer without a value needs its source")
                return None
            array = np.asarray(value)
            if array.ndim != 3 or array.shape[2] != schema.edit_width:
                raise InvalidValue(
                    f"a fill source must be (H, W, {schema.edit_width}), got {array.shape}"
                )
            if array.dtype != np.float32:
                raise InvalidValue(f"a fill source must be float32 edit values, got {array.dtype}")
            # the layer must own an immutable copy: undo keeps it by reference
            return freeze(array.copy()) if array.flags.writeable else array
        return super().validate(name, value, schema, size)

    def put(self, name: str, value: Any) -> None:
        super().put(name, value)
        if name == "source":
            self._source_mean = None

    def content(self, rect: Rect) -> np.ndarray:
        """Edit values over ``rect`` (a read-only view or broadcast; do not write)."""
        if self.source is not None:
            return self.source[rect.slices]
        assert self.value is not None
        return np.broadcast_to(self.value, (rect.height, rect.width, self.value.shape[0]))

    def mean(self) -> np.ndarray:
        if self.source is None:
            assert self.value is not None
            return self.value
        if self._source_mean is None:
            self._source_mean = freeze(mean_of(*weighted_mean(self.source)))
        return self._source_mean

    def arrays(self) -> Iterator[np.ndarray]:
        yield from super().arrays()
        if self.source is not None:
            yield self.source

    def describe(self) -> dict[str, Any]:
        info = super().describe()
        info["value"] = None if self.value is None else self.value.tolist()
        info["source"] = None if self.source is None else tuple(self.source.shape)
        return info


@dataclass(eq=False)
class FilterLayer(Layer):
    """A registry op applied non-destructively to the composite below."""

    op: str = "scale"
    op_params: dict[str, Any] = field(default_factory=dict)

    kind: ClassVar[str] = "filter"

    def validate(
        self, name: str, value: Any, schema: Schema, size: tuple[int, int] | None = None
    ) -> Any:
        """The op binds its settings against the document (schema, selected
        parameters, size), so a layer that validates can always run; a new
        selection is checked against the settings it keeps."""
        target = OpTarget(schema, self.parameters, size)
        if name == "op_params":
            return bind_filter(self.op, value, target)[1]
        if name == "filter":  # (op, params) together: switching ops rebinds
            op, params = value
            return (op, bind_filter(op, params, target)[1])
        value = super().validate(name, value, schema, size)
        if name == "parameters":
            get_op(self.op).check(self.op_params, OpTarget(schema, value, size))
        return value

    def written_parameters(self, schema: Schema) -> tuple[str, ...] | None:
        """Its parameters, plus the lobes an op with ``keep_variance`` (blur, bilateral,
        detail) widens when it smooths the normals (the widening is the point of the option)."""
        params = self.parameters
        if params is None or "normal" not in params or not self.op_params.get("keep_variance"):
            return params
        from ..ops.variance import lobe_parameters

        extra = set(lobe_parameters(schema)) - set(params)
        return tuple(n for n in schema.names if n in params or n in extra)

    def state(self) -> dict[str, Any]:
        return {**super().state(), "op": self.op}

    def get(self, name: str) -> Any:
        if name == "filter":
            return (self.op, self.op_params)
        return super().get(name)

    def put(self, name: str, value: Any) -> None:
        if name == "filter":
            self.op, self.op_params = value
        else:
            super().put(name, value)

    @property
    def border(self) -> str:
        """How the op treats the image edge (``wrap`` unless it says otherwise)."""
        return str(self.op_params.get("border", "wrap"))

    def reach(self, layout: TileLayout, schema: Schema) -> Reach:
        """Texels of the composite below one output texel depends on; None: all of them.

        The op declares its reach (:attr:`OpSpec.reach`). "detail" needs the mean
        of the filtered image, and a reach that wraps around the whole image is
        no cheaper than the image, so both are global.
        """
        if get_blend_mode(self.blend).uses_mean:
            return None
        target = OpTarget(schema, self.parameters, (layout.height, layout.width))
        reach = get_op(self.op).reach_of(self.op_params, target)
        if reach is not None and 2 * reach >= min(layout.height, layout.width):
            return None
        return reach

    def run(self, below: np.ndarray, schema: Schema, *, window: bool = False) -> np.ndarray:
        """The op on an ``(h, w, C)`` block of the composite below (a new array).

        ``window=True``: the block carries its own margin of context and only
        its interior is kept, so the op's edge handling is irrelevant and the
        cheapest one is used (a wrapped blur re-blurs its seams otherwise).
        """
        values = self.op_params
        if window and "border" in values:
            values = {**values, "border": "clamp"}
        function = get_op(self.op).function
        what = f"filter layer {self.name[:40]!r} ({self.op})"
        return run_op(what, function, below, schema=schema, params=self.parameters, **values)

    def describe(self) -> dict[str, Any]:
        info = super().describe()
        info["op"] = self.op
        info["op_params"] = dict(self.op_params)
        return info


@dataclass(eq=False)
class GroupLayer(Layer):
    """A pass-through group of the layers whose ``parent`` is this layer's id.

    It has no content of its own: ``out = lerp(input, members, opacity x mask)``
    in its parameters, where ``input`` is the composite below its lowest
    member and ``members`` the composite just below the group.
    """

    kind: ClassVar[str] = "group"

    def validate(
        self, name: str, value: Any, schema: Schema, size: tuple[int, int] | None = None
    ) -> Any:
        if name == "blend" and get_blend_mode(value).name != "normal":
            raise InvalidValue("a group passes its layers through: its blend mode is normal")
        return super().validate(name, value, schema, size)
