"""Flatten the layer stack per tile, with caches that an edit invalidates locally.

The composite after the first ``k`` layers over a rectangle is computed
bottom-up in edit space. Three kinds of cache keep this cheap:

- the *top* cache: the flattened document in edit space, per tile;
- the *physical* cache: the same tiles after ``from_edit``;
- a *checkpoint* per visible neighbourhood filter layer (blur), holding the
  composite just after it, per tile, so work above a filter never re-runs it.

A filter with reach ``m`` computes a tile from the composite below over the
tile grown by ``m`` texels (wrapped or clamped at the image edge exactly as
the op would on the whole image), so tiles equal the whole-image result bit
for bit. A filter whose reach is unknown or global computes the whole image
once into its checkpoint.

Invalidation is the mirror image: a change over some tiles of the input of a
layer changes the same tiles of its output, or those tiles dilated by the
reach of a filter (all tiles for a global one); walking up the stack gives
exactly the tiles of every cache to drop, and the dirty tiles to report.

A layer whose mask is *generated* (:class:`~matshop.ops.generators.MaskGenerator`)
reads the normals of the whole composite below it: the compositor keeps its
mask (one ``(H, W)`` array per layer) until a change below reaches the
normals, then drops it and dirties everything the layer covers, since the
generator's reach is the whole image. Which parameters a change can touch is
carried up the stack (a layer changes only its own parameters, a filter may
change its parameters from any), so painting the color under a cavity mask
leaves the mask alone.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from ..material import Schema
from .blend import blend, get_blend_mode, mean_of, weighted_mean
from .cache import TileCache
from .geometry import Rect, TileLayout, TileSet, periodic_runs
from .layer import FillLayer, FilterLayer, GroupLayer, Layer, PaintLayer


class LayerStack(Protocol):
    """What compositing reads of a document: its layers, tiling, schema and background.

    The compositor is typed against this, not the document that owns it, so the two
    modules do not import each other.
    """

    layers: list[Layer]
    layout: TileLayout
    schema: Schema
    background: np.ndarray

    def shows(self, layer: Layer) -> bool: ...

    def group_starts(self) -> dict[int, int]: ...

    def extent(self, layer: Layer) -> TileSet: ...


#: parameter names a change may have touched; None: any of them
Touched = frozenset[str] | None


def touched_by(layer: Layer, schema: Schema, touched: Touched = frozenset()) -> Touched:
    """``touched`` plus the parameters ``layer`` writes (None: all)."""
    written = layer.written_parameters(schema)
    if touched is None or written is None:
        return None
    return touched | frozenset(written)


def generated_mask(layer: Layer, schema: Schema, below: np.ndarray) -> np.ndarray:
    """The mask ``layer``'s generator makes of ``below``, the whole edit-space composite
    under it: its normal parameter converted back to unit normals, then the generator."""
    assert layer.mask_generator is not None
    param = schema["normal"]
    normals = param.space.from_edit(below[..., schema.edit_slices["normal"]])
    return layer.mask_generator.run(np.asarray(normals)[..., :3])


#: Texels per rectangle computed in one go (bounds temporaries to ~100s of MB
#: for wide schemas while keeping the per-call overhead negligible).
BAND_TEXELS = 1 << 20


def channel_selector(layer: Layer, schema) -> slice | np.ndarray | None:
    """Which edit channels a layer writes: None (all), a slice, or an index array."""
    written = layer.written_parameters(schema)
    if written is None:
        return None
    index = schema.channel_indices(written)
    if index.size and index[-1] - index[0] + 1 == index.size:
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


def blend_into(
    layer: Layer,
    schema,
    below: np.ndarray,
    values: np.ndarray,
    alpha: np.ndarray,
    mean: np.ndarray | None,
) -> None:
    """Blend ``values`` onto ``below`` in place, only in the layer's channels."""
    mode = get_blend_mode(layer.blend)
    select = channel_selector(layer, schema)
    if select is None:
        blend(mode, below, values, alpha, mean=mean, out=below)
    elif isinstance(select, slice):
        view = below[..., select]
        sub_mean = None if mean is None else mean[select]
        blend(mode, view, values[..., select], alpha, mean=sub_mean, out=view)
    else:
        block = below[..., select]
        sub_mean = None if mean is None else mean[select]
        below[..., select] = blend(mode, block, values[..., select], alpha, mean=sub_mean)


def filter_by_tile(
    layer: FilterLayer,
    schema,
    layout,
    rect: Rect,
    below: np.ndarray,
    reach: int,
) -> np.ndarray:
    """A neighbourhood filter's values over ``rect`` (whole tiles), one tile at a time.

    ``below`` is the composite over ``rect`` grown by ``reach`` (continued past
    the image edge as the op's border says). Each tile is filtered from its
    own window, the tile grown by ``reach``: OpenCV's rounding depends on an
    image's size and on where a texel sits in it (SIMD tails, IPP paths for
    one channel), so a fixed window per tile is what makes the result the
    same whichever tiles happen to be recomputed together. It differs from
    running the op on the whole image by float32 rounding only.
    """
    grown = rect.expand(reach)
    out = np.empty((rect.height, rect.width, below.shape[2]), dtype=np.float32)
    for key in layout.keys_in(rect):
        tile = layout.tile_rect(key)
        result = layer.run(below[tile.expand(reach).relative_to(grown)], schema, window=True)
        out[tile.relative_to(rect)] = result[
            reach : reach + tile.height, reach : reach + tile.width
        ]
    return out


def close_group(
    doc: LayerStack,
    group: GroupLayer,
    below: np.ndarray,
    block: np.ndarray,
    rect: Rect,
    generated: np.ndarray | None = None,
) -> None:
    """End a pass-through group in place: ``block = lerp(below, block, opacity x mask)``.

    ``below`` is the composite under the group's lowest member, ``block`` the
    composite after its members; outside the group's parameters the members'
    work is dropped (``below`` shows), like any layer limited to parameters.
    """
    if not doc.shows(group):
        block[...] = below  # a hidden group hides its members
        return
    mixed = below.copy()
    blend_into(group, doc.schema, mixed, block, group.alpha(rect, generated=generated), None)
    block[...] = mixed


def is_barrier(layer: Layer, doc: LayerStack) -> bool:
    """A visible filter reading a neighbourhood: it gets a checkpoint cache."""
    return (
        isinstance(layer, FilterLayer)
        and doc.shows(layer)
        and layer.reach(doc.layout, doc.schema) != 0
    )


class Compositor:
    """Caches and computes the flattened document; knows what an edit invalidates."""

    def __init__(self, doc: LayerStack) -> None:
        self.doc = doc
        self.top = TileCache(doc.layout, doc.schema.edit_width)
        phys_width = sum(p.phys_channels for p in doc.schema.parameters)
        self.physical = TileCache(doc.layout, phys_width)
        self.checkpoints: dict[int, TileCache] = {}
        #: the generated masks of layers with a mask generator, by layer id
        self.generated: dict[int, np.ndarray] = {}

    # -- invalidation ------------------------------------------------------

    def through(self, layer: Layer, tiles: TileSet) -> TileSet:
        """Tiles of a layer's output that change when ``tiles`` of its input change."""
        if not (isinstance(layer, FilterLayer) and self.doc.shows(layer)):
            return tiles
        reach = layer.reach(self.doc.layout, self.doc.schema)
        if reach is None:
            return self.doc.layout.all_tiles() if tiles.any() else tiles
        return self.doc.layout.dilate(tiles, reach, layer.border)

    def output_changed(self, index: int, tiles: TileSet, touched: Touched = None) -> TileSet:
        """The output of ``layers[index]`` itself changed over ``tiles`` (in the parameters
        ``touched``, default: any); returns dirty tiles."""
        layer = self.doc.layers[index]
        if layer.id in self.checkpoints:
            self.checkpoints[layer.id].invalidate(tiles)
        return self.input_changed(index + 1, tiles, touched)

    def input_changed(self, start: int, tiles: TileSet, touched: Touched = None) -> TileSet:
        """The composite below ``layers[start]`` changed over ``tiles`` (in the parameters
        ``touched``, default: any); returns dirty tiles."""
        doc = self.doc
        for layer in doc.layers[start:]:
            if not tiles.any():
                break
            if layer.mask_generator is not None and (touched is None or "normal" in touched):
                # the generator reads the whole image: its mask changes everywhere
                self.generated.pop(layer.id, None)
                if doc.shows(layer):
                    tiles = tiles | doc.extent(layer)
                    touched = touched_by(layer, doc.schema, touched)
            if isinstance(layer, FilterLayer) and doc.shows(layer):
                touched = touched_by(layer, doc.schema, touched)  # it may read any parameter
            tiles = self.through(layer, tiles)
            if layer.id in self.checkpoints:
                self.checkpoints[layer.id].invalidate(tiles)
        self.top.invalidate(tiles)
        self.physical.invalidate(tiles)
        return tiles

    def drop_checkpoint(self, layer_id: int) -> None:
        """Forget what was cached of a layer (inserted, removed, moved or its filter changed)."""
        self.checkpoints.pop(layer_id, None)
        self.generated.pop(layer_id, None)

    def invalidate_all(self) -> None:
        for cache in (self.top, self.physical, *self.checkpoints.values()):
            cache.invalidate(self.doc.layout.all_tiles())
        self.generated.clear()

    # -- generated masks ---------------------------------------------------

    def mask_of(self, index: int, compute: bool = True) -> np.ndarray | None:
        """The generated mask ``(H, W)`` of ``layers[index]`` (computed once per change
        below; ``compute=False``: only if it is at hand), or None when its mask is not
        generated. Read-only."""
        layer = self.doc.layers[index]
        if layer.mask_generator is None:
            return None
        mask = self.generated.get(layer.id)
        if mask is None and compute:
            below = self.composite(index, self.doc.layout.bounds)
            mask = generated_mask(layer, self.doc.schema, below)
            mask.flags.writeable = False
            self.generated[layer.id] = mask
        return mask

    def stale_masks(self) -> list[Layer]:
        """Shown layers whose generated mask the next flatten must compute."""
        return [
            layer
            for layer in self.doc.layers
            if layer.mask_generator is not None
            and layer.id not in self.generated
            and self.doc.shows(layer)
        ]

    # -- computing ---------------------------------------------------------

    def _cache_at(self, count: int) -> TileCache | None:
        """The cache holding the composite of the first ``count`` layers, if any."""
        layers = self.doc.layers
        if count == 0:
            return None
        if count == len(layers):
            return self.top
        layer = layers[count - 1]
        if is_barrier(layer, self.doc):
            return self.checkpoints.setdefault(
                layer.id, TileCache(self.doc.layout, self.top.channels)
            )
        return None

    def composite(self, count: int, rect: Rect) -> np.ndarray:
        """A new array: the composite of the first ``count`` layers over ``rect`` (in the image)."""
        cache = self._cache_at(count)
        if cache is None:
            return self._compute(count, rect)
        self._fill(cache, count, rect)
        return cache.view(rect).copy()

    def _fill(self, cache: TileCache, count: int, rect: Rect) -> None:
        missing = cache.missing(rect)
        if not missing.any():
            return
        layout = self.doc.layout
        layer = self.doc.layers[count - 1]
        if (
            isinstance(layer, FilterLayer)
            and self.doc.shows(layer)
            and layer.reach(layout, self.doc.schema) is None
        ):
            # a global filter costs the whole image whatever is asked: do it once
            cache.store(layout.bounds, self._compute(count, layout.bounds))
            return
        for part in layout.rects_of(missing, BAND_TEXELS):
            cache.store(part, self._compute(count, part))

    def _compute(self, count: int, rect: Rect) -> np.ndarray:
        layers = self.doc.layers
        if count == 0:
            return self.background(rect)
        if is_barrier(layers[count - 1], self.doc):
            return self._filter(count - 1, rect)
        start = count - 1
        while start > 0 and self._cache_at(start) is None:
            start -= 1
        first = start
        if start == 0 and self._opaque_base():
            # alpha-over at full weight gives the layer exactly: skip the background
            block = np.array(layers[0].content(rect), dtype=np.float32)
            first = 1
        else:
            block = self.background(rect) if start == 0 else self.composite(start, rect)
        # the input of each group that opens in this run, saved as the run passes it
        opening = {}
        starts = self.doc.group_starts()
        for index in range(start, count):
            if isinstance(layers[index], GroupLayer):
                opening.setdefault(starts[index], []).append(index)
        inputs: dict[int, np.ndarray] = {}
        for index in range(first, count):
            layer = layers[index]
            if index in opening:
                inputs[index] = block.copy()
            if isinstance(layer, GroupLayer):
                first = starts[index]
                below = inputs.get(first)
                if below is None:  # the group opened under this run's start: read the cache
                    below = self.composite(first, rect)
                close_group(self.doc, layer, below, block, rect, self.mask_of(index))
            else:
                self._apply(index, block, rect)
        return block

    def _opaque_base(self) -> bool:
        """Whether the bottom layer hides the background everywhere, in every parameter."""
        layer = self.doc.layers[0]
        return (
            isinstance(layer, FillLayer)
            and layer.parent is None
            and self.doc.shows(layer)
            and layer.blend == "normal"
            and layer.opacity == 1.0
            and layer.mask is None
            and layer.mask_generator is None
            and layer.parameters is None
        )

    def background(self, rect: Rect) -> np.ndarray:
        # a broadcast assignment releases the GIL (np.tile does not): a worker
        # flattening a snapshot must not stall the GUI thread
        out = np.empty((rect.height, rect.width, self.top.channels), dtype=np.float32)
        out[...] = self.doc.background
        return out

    def _apply(self, index: int, block: np.ndarray, rect: Rect) -> None:
        """Blend ``layers[index]``, without neighbourhood, onto ``block`` (covering ``rect``)
        in place."""
        layer = self.doc.layers[index]
        if not self.doc.shows(layer):
            return
        generated = self.mask_of(index)
        schema = self.doc.schema
        uses_mean = get_blend_mode(layer.blend).uses_mean
        mean = layer.mean() if uses_mean and not isinstance(layer, FilterLayer) else None
        if isinstance(layer, PaintLayer):
            assert layer.pixels is not None
            keys = layer.pixels.keys_in(rect)
            if not keys:
                return  # coverage 0: every mode leaves the composite as it is
            for part in self.doc.layout.rects_of_keys(keys):
                part = part.intersect(rect)
                values, coverage = layer.values(part)
                target = block[part.relative_to(rect)]
                alpha = layer.alpha(part, coverage, generated)
                blend_into(layer, schema, target, values, alpha, mean)
        elif isinstance(layer, FillLayer):
            alpha = layer.alpha(rect, generated=generated)
            blend_into(layer, schema, block, layer.content(rect), alpha, mean)
        elif isinstance(layer, FilterLayer):  # pointwise: the block is all it reads
            filtered = layer.run(block, schema)
            blend_into(layer, schema, block, filtered, layer.alpha(rect, generated=generated), mean)
        else:  # pragma: no cover - new kinds must be taught here
            raise TypeError(f"cannot composite a {type(layer).__name__}")

    def _filter(self, index: int, rect: Rect) -> np.ndarray:
        """Composite after the neighbourhood filter ``layers[index]`` over ``rect``."""
        layer = self.doc.layers[index]
        assert isinstance(layer, FilterLayer)
        layout, schema = self.doc.layout, self.doc.schema
        reach = layer.reach(layout, schema)
        if reach is None:
            below = self.composite(index, layout.bounds)
            filtered = layer.run(below, schema)
            mean = None
            if get_blend_mode(layer.blend).uses_mean:
                mean = mean_of(*weighted_mean(filtered))
            alpha = layer.alpha(layout.bounds, generated=self.mask_of(index))
            blend_into(layer, schema, below, filtered, alpha, mean)
            return below if rect == layout.bounds else below[rect.slices].copy()
        grown = rect.expand(reach)
        below = self.read(index, grown, layer.border)
        filtered = filter_by_tile(layer, schema, layout, rect, below, reach)
        block = np.ascontiguousarray(below[rect.relative_to(grown)])
        alpha = layer.alpha(rect, generated=self.mask_of(index))
        blend_into(layer, schema, block, filtered, alpha, None)
        return block

    def read(self, count: int, rect: Rect, border: str) -> np.ndarray:
        """Composite of the first ``count`` layers over any rectangle, continued past the
        image edge periodically (``"wrap"``) or by repeating the edge texels (``"clamp"``)."""
        bounds = self.doc.layout.bounds
        if bounds.contains(rect):
            return self.composite(count, rect)
        if border == "clamp":
            inner = rect.intersect(bounds)
            block = self.composite(count, inner)
            pad = (
                (inner.y0 - rect.y0, rect.y1 - inner.y1),
                (inner.x0 - rect.x0, rect.x1 - inner.x1),
                (0, 0),
            )
            return np.pad(block, pad, mode="edge")
        out = np.empty((rect.height, rect.width, self.top.channels), dtype=np.float32)
        for dy, sy, height in periodic_runs(rect.y0, rect.y1, bounds.y1):
            for dx, sx, width in periodic_runs(rect.x0, rect.x1, bounds.x1):
                part = Rect(sx, sy, sx + width, sy + height)
                out[dy : dy + height, dx : dx + width] = self.composite(count, part)
        return out

    # -- the outputs -------------------------------------------------------

    def edit(self, rect: Rect) -> np.ndarray:
        """The flattened edit values over ``rect`` (a view of the top cache, up to date)."""
        if not self.doc.layers:
            return self.background(rect)
        self._fill(self.top, len(self.doc.layers), self.doc.layout.aligned(rect))
        return self.top.view(rect)

    def physical_view(self, rect: Rect) -> np.ndarray:
        """Physical values (parameters side by side) over ``rect``, up to date."""
        layout = self.doc.layout
        missing = self.physical.missing(rect)
        for part in layout.rects_of(missing, BAND_TEXELS):
            edit = self.edit(part)
            block = np.empty((part.height, part.width, self.physical.channels), np.float32)
            start = 0
            for param in self.doc.schema.parameters:
                width = param.phys_channels
                edit_part = edit[..., self.doc.schema.edit_slices[param.name]]
                into = getattr(param.space, "from_edit_into", None)
                if into is not None:  # fused kernels write straight into the block
                    into(edit_part, block[..., start : start + width])
                else:
                    block[..., start : start + width] = param.space.from_edit(edit_part)
                start += width
            self.physical.store(part, block)
        return self.physical.view(rect)

    def nbytes(self) -> int:
        caches = (self.top, self.physical, *self.checkpoints.values())
        masks = sum(mask.nbytes for mask in self.generated.values())
        return sum(cache.nbytes for cache in caches) + masks
