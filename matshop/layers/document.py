"""The document: a schema, a size, a layer stack, and its flattened output.

The document is the single place where layer state changes. Each mutation
method invalidates exactly the cached tiles it can affect (see
:mod:`matshop.layers.compositor`) and emits notifications; views subscribe to
``doc.events`` and redraw the dirty tiles. The mutation methods record
nothing: undo lives in :mod:`matshop.layers.edits` (edit objects that call
them) and :mod:`matshop.layers.history`. Widgets and the CLI build edits;
they never touch layers or arrays directly.

Flattening is lazy and per tile: :meth:`Document.flatten_edit`,
:meth:`Document.flatten_physical` and :meth:`Document.update` recompute only
invalid tiles and convert through ``from_edit`` once per tile.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator
from typing import Any, Literal

import numpy as np

from ..errors import InvalidValue
from ..material import EditMaterial, Material, Schema
from ..memory import require_memory
from ..ops import get_op
from ..ops.spec import OpTarget
from .compositor import Compositor, touched_by
from .events import DirtyRegion, DocumentEvents
from .filters import bind_filter
from .geometry import Rect, TileKey, TileLayout, TileSet
from .layer import FillLayer, FilterLayer, GroupLayer, Layer, PaintLayer
from .tiles import TileGrid, freeze

#: What each layer kind is made of besides its properties (Document.new_layer)
_CONTENT: dict[str, tuple[str, ...]] = {
    "paint": ("pixels",),
    "fill": ("value", "source"),
    "filter": ("op", "op_params"),
    "group": (),
}

#: Which tiles of a layer an edit addresses: its painted values or its mask.
Target = Literal["pixels", "mask"]


class Document:
    """A layered material in edit space.

    Parameters
    ----------
    schema : Schema
        The material's parameters and editing spaces.
    height, width : int
        Size in texels.
    tile_size : int
        Edge of the square storage and cache tiles (64 measured best; see
        ``benchmarks/document.py``).
    background : (C,) array_like, optional
        Edit values under the bottom layer (zeros by default).
    name : str
        Material name used for flattened outputs.
    """

    def __init__(
        self,
        schema: Schema,
        height: int,
        width: int,
        *,
        tile_size: int = 64,
        background: np.ndarray | None = None,
        name: str = "untitled",
        sources: dict[str, dict] | None = None,
    ) -> None:
        self.schema = schema
        self.name = name
        #: where each parameter came from (file, slot, bit depth, normal convention):
        #: kept in projects, and flattening writes normals in the source's convention
        self.sources: dict[str, dict] = dict(sources or {})
        self.layout = TileLayout(height, width, tile_size)
        fill = np.zeros(schema.edit_width) if background is None else background
        self.background = freeze(
            np.array(np.broadcast_to(np.asarray(fill, np.float32), (schema.edit_width,)))
        )
        self.layers: list[Layer] = []
        #: the layers by id (kept by insert/remove: finding a group is O(1), so
        #: flattening thousands of grouped layers stays linear)
        self._by_id: dict[int, Layer] = {}
        self.events = DocumentEvents()
        self._next_id = 1
        self._compositor = Compositor(self)

    @classmethod
    def from_material(
        cls,
        material: Material | EditMaterial,
        *,
        tile_size: int = 64,
        layer_name: str = "Base",
    ) -> Document:
        """A document whose bottom layer is a fill layer holding ``material``."""
        edit = material.to_edit() if isinstance(material, Material) else material
        height, width = edit.size
        doc = cls(
            edit.schema, height, width, tile_size=tile_size, name=edit.name, sources=edit.sources
        )
        doc.insert_layer(doc.new_fill_layer(layer_name, source=edit.data))
        return doc

    @property
    def normal_convention(self) -> str:
        """How the material's normal file encodes green ("opengl" or "directx").

        The canvas shows normals as that file does, and flattening writes them
        so; the stored normals are OpenGL whatever the file's convention.
        """
        return self.sources.get("normal", {}).get("convention", "opengl")

    # -- shape -------------------------------------------------------------

    @property
    def height(self) -> int:
        return self.layout.height

    @property
    def width(self) -> int:
        return self.layout.width

    @property
    def size(self) -> tuple[int, int]:
        """(height, width) in texels, like :attr:`Material.size`."""
        return self.layout.height, self.layout.width

    @property
    def channels(self) -> int:
        """Edit channels per texel."""
        return self.schema.edit_width

    # -- making layers (not yet in the stack: add them with an AddLayer edit) --

    def _props(self, layer: Layer, props: dict[str, Any]) -> Layer:
        for key, value in props.items():
            layer.put(key, layer.validate(key, value, self.schema, self.size))
        return layer

    def _new_id(self) -> int:
        layer_id = self._next_id
        self._next_id += 1
        return layer_id

    def new_layer(self, kind: str, name: str | None = None, **state: Any) -> Layer:
        """A new layer of ``kind``, not yet in the stack (add it with an AddLayer edit).

        ``state`` is its content -- paint: ``pixels`` (a grid of this document,
        default empty); fill: ``value`` (an edit vector) or ``source`` (an
        edit-space texture or EditMaterial); filter: ``op`` and ``op_params``
        (bound against this document and the layer's parameters); group: none --
        and any layer property (``visible=False``, ``parameters=[...]``), each
        validated; ``mask`` a one-channel grid of this document. Nothing changes in
        the document when a value is refused.
        """
        mask = state.pop("mask", None)
        if mask is not None:
            self._check_mask(mask)
        content = {key: state.pop(key) for key in _CONTENT.get(kind, ()) if key in state}
        layer: Layer
        if kind == "paint":
            pixels = content.get("pixels")
            if pixels is None:
                pixels = TileGrid(self.layout, self.channels + 1, 0.0)
            layer = PaintLayer(0, "", pixels=pixels)
        elif kind == "fill":
            value, source = content.get("value"), content.get("source")
            if (value is None) == (source is None):
                raise InvalidValue("a fill layer needs exactly one of value= or source=")
            layer = FillLayer(0, "")
            if value is not None:
                layer.put("value", layer.validate("value", value, self.schema))
            else:
                data = source.data if isinstance(source, EditMaterial) else source
                if np.shape(data)[:2] != self.size:
                    raise InvalidValue(
                        f"fill source is {np.shape(data)[:2]}, the document {self.size}"
                    )
                layer.put("source", layer.validate("source", data, self.schema))
        elif kind == "filter":
            if "op" not in content:
                raise InvalidValue("a filter layer needs op=")
            spec, bound = bind_filter(content["op"], content.get("op_params"))
            layer = FilterLayer(0, "", op=spec.name, op_params=bound)
        elif kind == "group":
            layer = GroupLayer(0, "")
        else:
            raise InvalidValue(f"unknown layer kind {kind!r} (known: {', '.join(_CONTENT)})")
        self._props(layer, state)
        layer.mask = mask
        if isinstance(layer, FilterLayer):
            get_op(layer.op).check(
                layer.op_params, OpTarget(self.schema, layer.parameters, self.size)
            )
        layer.id = self._new_id()
        if isinstance(layer, FilterLayer):
            default = get_op(layer.op).label
        else:
            default = f"{kind.title()} {layer.id}"
        layer.put("name", default if name is None else name)
        return layer

    # typed shorthands of :meth:`new_layer`

    def new_paint_layer(self, name: str | None = None, **props: Any) -> PaintLayer:
        """An empty paint layer (costs a dict and a fill vector until painted)."""
        return self.new_layer("paint", name, **props)  # type: ignore[return-value]

    def new_fill_layer(self, name: str | None = None, **state: Any) -> FillLayer:
        """A fill layer with a constant edit ``value`` or an edit-space ``source`` texture."""
        return self.new_layer("fill", name, **state)  # type: ignore[return-value]

    def new_filter_layer(self, op: str, name: str | None = None, **state: Any) -> FilterLayer:
        """A filter layer running registry op ``op`` with ``op_params``."""
        return self.new_layer("filter", name, op=op, **state)  # type: ignore[return-value]

    def new_group_layer(self, name: str | None = None, **props: Any) -> GroupLayer:
        """An empty group; layers join it by ``parent`` (and sit just below it)."""
        return self.new_layer("group", name, **props)  # type: ignore[return-value]

    def _check_mask(self, mask: TileGrid) -> None:
        if mask.channels != 1 or mask.layout != self.layout:
            raise ValueError("a mask is a one-channel tile grid of this document's layout")

    def new_mask(self, fill: float = 1.0, array: np.ndarray | None = None) -> TileGrid:
        """A mask grid: uniform ``fill`` (1 reveals all, 0 hides all), or from a grayscale array."""
        if array is None:
            return TileGrid(self.layout, 1, fill)
        mask = np.clip(np.asarray(array, dtype=np.float32), 0.0, 1.0)
        return TileGrid.from_array(mask, self.layout, fill)

    # -- looking layers up -------------------------------------------------

    def __len__(self) -> int:
        return len(self.layers)

    def __iter__(self) -> Iterator[Layer]:
        return iter(self.layers)

    def index_of(self, layer_id: int) -> int:
        for index, layer in enumerate(self.layers):
            if layer.id == layer_id:
                return index
        raise KeyError(f"no layer with id {layer_id} in the document")

    def layer(self, layer_id: int) -> Layer:
        return self.layers[self.index_of(layer_id)]

    def _parent_of(self, layer: Layer) -> GroupLayer | None:
        if layer.parent is None:
            return None
        other = self._by_id.get(layer.parent)  # None: its group was removed
        return other if isinstance(other, GroupLayer) else None

    def shows(self, layer: Layer) -> bool:
        """Visible, and so is every group it belongs to."""
        seen = set()
        current: Layer | None = layer
        while current is not None and current.id not in seen:
            if not current.visible:
                return False
            seen.add(current.id)
            current = self._parent_of(current)
        return True

    def in_group(self, layer: Layer, group_id: int) -> bool:
        """Whether ``layer`` belongs to group ``group_id``, directly or through nested groups."""
        seen = set()
        current = self._parent_of(layer)
        while current is not None and current.id not in seen:
            if current.id == group_id:
                return True
            seen.add(current.id)
            current = self._parent_of(current)
        return False

    def group_start(self, index: int) -> int:
        """Index of the lowest member of the group at ``index`` (``index`` when it has none).

        The group mixes everything from there up to itself with its input.
        """
        return self.group_starts()[index]

    def group_starts(self) -> dict[int, int]:
        """:meth:`group_start` of every group, by index, in one pass over the stack."""
        index_of = {layer.id: i for i, layer in enumerate(self.layers)}
        starts = {i: i for i, layer in enumerate(self.layers) if isinstance(layer, GroupLayer)}
        for below, layer in enumerate(self.layers):
            seen = set()
            group = self._parent_of(layer)
            while group is not None and group.id not in seen:
                seen.add(group.id)
                index = index_of[group.id]
                if below < index:
                    starts[index] = min(starts[index], below)
                group = self._parent_of(group)
        return starts

    def grid(self, layer_id: int, target: Target) -> TileGrid:
        """The tile grid an edit on ``target`` of a layer addresses."""
        layer = self.layer(layer_id)
        if target == "mask":
            if layer.mask is None:
                raise InvalidValue(f"layer {layer.name!r} has no mask")
            return layer.mask
        if not isinstance(layer, PaintLayer) or layer.pixels is None:
            raise InvalidValue(f"layer {layer.name!r} is a {layer.kind} layer: it has no pixels")
        return layer.pixels

    # -- mutations (no undo here: edits call these) -------------------------

    def extent(self, layer: Layer) -> TileSet:
        """Tiles where a layer can change the composite at all."""
        if isinstance(layer, PaintLayer) and layer.pixels is not None:
            return layer.pixels.present()
        return self.layout.all_tiles()

    def _regroups(self, layer: Layer) -> bool:
        """Whether adding, removing or moving ``layer`` can change group membership."""
        return isinstance(layer, GroupLayer) or layer.parent is not None

    def _restructured(self) -> TileSet:
        """Drop every cache (group structure changed; rare, never per dab); all tiles dirty."""
        self._compositor.invalidate_all()
        return self.layout.all_tiles()

    def _check_parent(self, layer: Layer, parent: int | None) -> None:
        if parent is None:
            return
        group = next((other for other in self.layers if other.id == parent), None)
        if group is None:
            # an id no layer has any more: a group removed after the layer joined
            # it. Members keep that id (so undoing the removal regroups them) and
            # undo must be able to put it back; it reads as "no group".
            return
        if not isinstance(group, GroupLayer):
            raise InvalidValue(f"parent {parent} is not a group layer of this document")
        if parent == layer.id or self.in_group(group, layer.id):
            raise InvalidValue(f"layer {layer.name!r} cannot belong to itself")

    def _emit_dirty(self, tiles: TileSet) -> None:
        if tiles.any():
            self.events.dirty.emit(DirtyRegion(self.layout, tiles.copy()))

    def insert_layer(self, layer: Layer, index: int | None = None) -> int:
        """Put ``layer`` at ``index`` (default: on top); returns the index."""
        if any(other.id == layer.id for other in self.layers):
            raise ValueError(f"layer id {layer.id} is already in the document")
        for grid in (getattr(layer, "pixels", None), layer.mask):
            if grid is not None and grid.layout != self.layout:
                raise ValueError("the layer was made for a document of another size or tiling")
        index = len(self.layers) if index is None else index
        if not 0 <= index <= len(self.layers):
            raise IndexError(f"layer index {index} outside 0..{len(self.layers)}")
        self.layers.insert(index, layer)
        self._by_id[layer.id] = layer
        # a layer made elsewhere (a loaded project) keeps its id; new ones follow it,
        # and its group's id too, so a removed group's id is never given out again
        self._next_id = max(self._next_id, layer.id + 1, (layer.parent or 0) + 1)
        self._compositor.drop_checkpoint(layer.id)
        if self._regroups(layer):
            dirty = self._restructured()
        else:
            tiles = self.extent(layer) if self.shows(layer) else self.layout.no_tiles()
            dirty = self._compositor.output_changed(index, tiles, touched_by(layer, self.schema))
        self.events.layers.emit("insert", layer.id, index)
        self._emit_dirty(dirty)
        return index

    def remove_layer(self, layer_id: int) -> tuple[Layer, int]:
        """Take a layer out of the stack; returns it and where it was."""
        index = self.index_of(layer_id)
        layer = self.layers[index]
        shown = self.shows(layer)
        self.layers.pop(index)
        del self._by_id[layer_id]
        self._compositor.drop_checkpoint(layer_id)
        if self._regroups(layer):
            dirty = self._restructured()
        else:
            tiles = self.extent(layer) if shown else self.layout.no_tiles()
            dirty = self._compositor.input_changed(index, tiles, touched_by(layer, self.schema))
        self.events.layers.emit("remove", layer_id, index)
        self._emit_dirty(dirty)
        return layer, index

    def move_layer(self, layer_id: int, index: int) -> int:
        """Move a layer to ``index`` in the stack; returns its old index."""
        old = self.index_of(layer_id)
        if not 0 <= index < len(self.layers):
            raise IndexError(f"layer index {index} outside 0..{len(self.layers) - 1}")
        if old == index:
            return old
        layer = self.layers.pop(old)
        self.layers.insert(index, layer)
        self._compositor.generated.pop(layer_id, None)  # other layers are below it now
        if self._regroups(layer):
            dirty = self._restructured()
        else:
            # every composite from the lower position up differs where the layer acts
            tiles = self.extent(layer) if self.shows(layer) else self.layout.no_tiles()
            touched = touched_by(layer, self.schema)
            dirty = self._compositor.input_changed(min(old, index), tiles, touched)
        self.events.layers.emit("move", layer_id, index)
        self._emit_dirty(dirty)
        return old

    def set_property(self, layer_id: int, name: str, value: Any) -> Any:
        """Change a layer property (validated); returns the old value."""
        index = self.index_of(layer_id)
        layer = self.layers[index]
        value = layer.validate(name, value, self.schema, self.size)
        if name == "parent":
            self._check_parent(layer, value)
        old = layer.get(name)
        was_shown = self.shows(layer)
        layer.put(name, value)
        if name == "parent" or (name == "visible" and isinstance(layer, GroupLayer)):
            # membership and a group's visibility change what its members show
            self._emit_dirty(self._restructured())
        elif name != "name":
            if isinstance(layer, FilterLayer) or name == "mask_generator":
                self._compositor.drop_checkpoint(layer_id)
            if was_shown or self.shows(layer):
                self._emit_dirty(self._compositor.output_changed(index, self.extent(layer)))
        self.events.layer.emit(layer_id, name)
        return old

    def set_mask(self, layer_id: int, mask: TileGrid | None) -> TileGrid | None:
        """Give a layer a mask (a one-channel grid of this document) or remove it."""
        index = self.index_of(layer_id)
        layer = self.layers[index]
        if mask is not None:
            self._check_mask(mask)
        old = layer.mask
        layer.mask = mask
        if self.shows(layer):
            touched = touched_by(layer, self.schema)
            self._emit_dirty(self._compositor.output_changed(index, self.extent(layer), touched))
        self.events.layer.emit(layer_id, "mask")
        return old

    def replace_tiles(
        self, layer_id: int, target: Target, changes: dict[TileKey, np.ndarray | None]
    ) -> dict[TileKey, np.ndarray | None]:
        """Swap tile objects of a layer's pixels or mask; returns the replaced ones."""
        old = self.grid(layer_id, target).replace(changes)
        self.tiles_changed(layer_id, target, self.layout.tiles_from_keys(changes))
        return old

    def tiles_changed(self, layer_id: int, target: Target, tiles: TileSet) -> None:
        """Tiles of a layer's pixels or mask were changed: invalidate and notify.

        Paint transactions call this after changing their working tiles in place.
        """
        index = self.index_of(layer_id)
        layer = self.layers[index]
        if target == "pixels" and isinstance(layer, PaintLayer):
            layer.version += 1  # the cached mean is stale
        self.events.content.emit(layer_id, target, tiles)
        if not self.shows(layer):
            return
        if target == "pixels":
            from .blend import get_blend_mode

            if get_blend_mode(layer.blend).uses_mean:
                # the layer's mean moved: everything it covers moves with it
                tiles = tiles | self.extent(layer)
        elif isinstance(layer, PaintLayer):
            tiles = tiles & self.extent(layer)  # no coverage, nothing to mask
        touched = touched_by(layer, self.schema)
        self._emit_dirty(self._compositor.output_changed(index, tiles, touched))

    # -- outputs -----------------------------------------------------------

    def flatten_edit(self, rect: Rect | None = None, *, copy: bool = True) -> np.ndarray:
        """The flattened edit values over ``rect`` (whole image by default).

        ``copy=False`` returns a read-only view of the cache: no copy, but
        later edits change what it shows.
        """
        rect = self.layout.bounds if rect is None else rect
        if not self.layout.bounds.contains(rect):
            raise InvalidValue(f"{rect} reaches outside the {self.width}x{self.height} document")
        view = self._compositor.edit(rect)
        return _out(view, copy)

    def composite_through(self, layer_id: int, rect: Rect) -> np.ndarray:
        """Edit values of the layers from the bottom up to and including ``layer_id``.

        What a clone stamp samples ("current and below"): the layers above,
        filters among them, are not in it, so cloning into a layer under a
        filter does not feed the filter's output back into its input. ``rect``
        may reach past the image edges: the document wraps (tiling textures).
        A new array.
        """
        return self._compositor.read(self.index_of(layer_id) + 1, rect, "wrap")

    def generated_mask(self, layer_id: int, *, compute: bool = True) -> np.ndarray | None:
        """The mask ``(H, W)`` a layer's mask generator makes of the material below it, as
        the flatten uses it (recomputed only after a change below); None: not generated,
        or ``compute=False`` and not computed yet (what a thumbnail on the GUI thread asks)."""
        return self._compositor.mask_of(self.index_of(layer_id), compute)

    def flatten(self, *, copy: bool = True) -> EditMaterial:
        """The flattened document as an :class:`EditMaterial`."""
        self._require_flatten_memory()
        return EditMaterial(self.name, self.schema, self.flatten_edit(copy=copy))

    def _require_flatten_memory(self) -> None:
        """Refuse a whole-document flatten that cannot fit (a tiny file may declare 16K)."""
        phys = sum(p.phys_channels for p in self.schema.parameters)
        # edit cache, one working block and the copy; physical cache and its copy
        need = 4 * self.height * self.width * (3 * self.channels + 2 * phys)
        require_memory(need, f"flattening this {self.width}x{self.height} document")

    def physical(self, rect: Rect | None = None, *, copy: bool = True) -> dict[str, np.ndarray]:
        """Physical maps (after ``from_edit``) per parameter over ``rect``."""
        rect = self.layout.bounds if rect is None else rect
        block = self._compositor.physical_view(rect)
        maps, start = {}, 0
        for param in self.schema.parameters:
            maps[param.name] = _out(block[..., start : start + param.phys_channels], copy)
            start += param.phys_channels
        return maps

    def flatten_physical(self, *, copy: bool = True) -> Material:
        """The flattened document as a physical :class:`Material` (ready to export)."""
        self._require_flatten_memory()
        return Material(self.name, self.schema, self.physical(copy=copy), dict(self.sources))

    def update(self) -> TileSet:
        """Bring every cache up to date (edit and physical); returns the tiles recomputed."""
        stale = ~self._compositor.physical.valid
        if stale.any():
            self._compositor.physical_view(self.layout.bounds)
        return stale

    # -- working off the GUI thread ----------------------------------------------

    def snapshot(self) -> Document:
        """An independent document in the same state, without caches, for a worker thread.

        Layers are copied (the owner may change a live layer's properties
        while a worker reads the copy); what the copies share is immutable:
        tiles (copy-on-write: edits swap tile objects, never write into one),
        fill textures, background, op parameter dicts. Must not be called
        while a paint transaction is open: its working tiles change in place.
        """
        twin = Document(
            self.schema,
            self.height,
            self.width,
            tile_size=self.layout.tile_size,
            background=self.background,
            name=self.name,
            sources=self.sources,
        )
        for layer in self.layers:
            copied = copy.copy(layer)
            if isinstance(copied, PaintLayer) and copied.pixels is not None:
                copied.pixels = copied.pixels.copy()
            if copied.mask is not None:
                copied.mask = copied.mask.copy()
            twin.insert_layer(copied)
        return twin

    def adopt_caches(self, snapshot: Document) -> None:
        """Take over the flattened caches a worker computed on ``snapshot``.

        Only valid while this document is in exactly the state the snapshot
        was taken in; ``snapshot`` must not be used afterwards.
        """
        if snapshot.size != self.size or len(snapshot.layers) != len(self.layers):
            raise ValueError("the snapshot is of another document state")
        compositor = snapshot._compositor
        compositor.doc = self
        known = set(self._compositor.generated)
        self._compositor = compositor
        for layer_id in compositor.generated.keys() - known:
            self.events.layer.emit(layer_id, "generated_mask")  # thumbnails may show it now

    def stale_global_layers(self) -> list[Layer]:
        """Visible layers reading the whole image that the next flatten must recompute.

        A filter reading the whole image (bilateral, detail, or one blended in
        "detail" mode) recomputes all of it when anything below it changes, and
        so does a generated mask (cavity, edge, AO) when the normals below
        change: the slow part of a flatten, worth moving off an interactive thread.
        """
        compositor = self._compositor
        if compositor.top.valid.all():
            return []
        stale: list[Layer] = compositor.stale_masks()
        for layer in self.layers:
            if isinstance(layer, FilterLayer) and self.shows(layer):
                if layer.reach(self.layout, self.schema) is None:
                    cached = compositor.checkpoints.get(layer.id)
                    if cached is None or not cached.valid.all():
                        stale.append(layer)
        return stale

    def invalidate_all(self) -> None:
        """Forget every cached tile (the next flatten recomputes from scratch)."""
        self._compositor.invalidate_all()
        self._emit_dirty(self.layout.all_tiles())

    def memory(self) -> dict[str, int]:
        """Bytes held: layer payloads (pixels, masks, sources) and caches."""
        layers = 0
        seen: set[int] = set()
        for layer in self.layers:
            for array in layer.arrays():
                if id(array) not in seen:
                    seen.add(id(array))
                    layers += array.nbytes
        caches = self._compositor.nbytes()
        return {"layers": layers, "caches": caches, "total": layers + caches}

    def __repr__(self) -> str:
        return (
            f"Document({self.name!r}, {self.width}x{self.height}, {len(self.layers)} layers, "
            f"{self.schema!r})"
        )


def _out(view: np.ndarray, copy: bool) -> np.ndarray:
    if copy:
        return view.copy()
    view = view.view()
    view.flags.writeable = False
    return view
