"""Layer operations as edits, shared by the Layer menu and the layers panel.

Each method builds the edit the engine defines (AddLayer, RemoveLayer,
MoveLayer, SetProperty, SetMask, or several as one CompoundEdit) and pushes
it through the session; an engine refusal (a MatshopError) becomes a status
message and changes nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any, TypeVar

from PySide6.QtCore import QObject, Signal

from ..errors import InvalidValue, MatshopError
from ..layers import (
    AddLayer,
    CompoundEdit,
    Edit,
    GroupLayer,
    Layer,
    MoveLayer,
    RemoveLayer,
    SetMask,
    SetProperty,
)
from ..layers.filters import bind_filter
from ..ops import all_ops
from ..paint import Swatch
from .session import DocumentSession

T = TypeVar("T")

#: :meth:`LayerCommands.import_image` uses besides a parameter's name
HEIGHT_USE = "height->normal"
MASK_USE = "mask"


@cache
def filter_ops() -> tuple[tuple[str, str], ...]:
    """(name, label) of every op that can run as a filter layer with its defaults."""
    usable = []
    for name, spec in all_ops().items():
        try:
            bind_filter(name)
        except MatshopError:
            continue  # needs a second input or a region: not a filter layer
        usable.append((name, spec.label))
    return tuple(usable)


class LayerCommands(QObject):
    """Add, remove, reorder and change layers of the session's document."""

    #: a short message for the status bar
    message = Signal(str)

    def __init__(self, session: DocumentSession, swatch: Callable[[], Swatch]) -> None:
        super().__init__()
        self.session = session
        self.swatch = swatch

    def _attempt(self, action: Callable[..., T], *args: Any, **kwargs: Any) -> T | None:
        """``action(...)``; None, with the engine's one-line refusal as the message,
        when it refuses (the one place these commands catch errors)."""
        try:
            return action(*args, **kwargs)
        except MatshopError as exc:
            self.message.emit(str(exc))
            return None

    def _push(self, edit: Edit, *, merge: bool = False) -> bool:
        def push() -> bool:
            self.session.push(edit, merge=merge)
            return True

        return self._attempt(push) is not None

    def _above_active(self) -> int | None:
        doc, active = self.session.doc, self.session.active_layer_id
        if doc is None or active is None:
            return None
        return doc.index_of(active) + 1

    # -- adding --------------------------------------------------------------

    def add_paint_layer(self, parameters: tuple[str, ...] | None = None) -> int | None:
        """A new empty paint layer above the active one; returns its id."""
        doc = self.session.doc
        if doc is None:
            return None
        layer = doc.new_paint_layer(parameters=parameters)
        return layer.id if self._push(AddLayer(layer, self._above_active())) else None

    def add_fill_layer(self) -> int | None:
        """A fill layer of the current swatch, affecting the parameters it sets."""
        doc = self.session.doc
        if doc is None:
            return None

        def fill() -> Layer:
            swatch = self.swatch()
            vector, _ = swatch.edit_values(doc.schema)
            return doc.new_fill_layer(
                f"Fill {swatch.name}", value=vector, parameters=swatch.parameters
            )

        layer = self._attempt(fill)
        if layer is None:
            return None
        return layer.id if self._push(AddLayer(layer, self._above_active())) else None

    def add_filter_layer(self, op: str, params: dict[str, Any] | None = None) -> int | None:
        """A filter layer running ``op`` on everything below it."""
        doc = self.session.doc
        if doc is None:
            return None
        layer = self._attempt(doc.new_filter_layer, op, op_params=params)
        if layer is None:
            return None
        return layer.id if self._push(AddLayer(layer, self._above_active())) else None

    def add_recipe_layers(self, path: Path | None) -> list[int]:
        """The op chain of a batch recipe as filter layers above the active one (one step).

        The layers are :func:`matshop.opchain.filter_layers`' own, so the document
        flattens to the bytes ``matshop apply`` and ``matshop batch`` write for it.
        """
        doc = self.session.doc
        if doc is None or path is None:
            return []
        from ..batch.recipe import load_recipe
        from ..opchain import filter_layers

        def read() -> tuple[Any, list[Layer]]:
            recipe = load_recipe(path)
            if recipe.look is not None:
                raise MatshopError("a .matshop look: open it as a project instead", path)
            return recipe, filter_layers(doc, recipe.steps)

        made = self._attempt(read)
        if made is None:
            return []
        recipe, layers = made
        index = self._above_active()
        adds = [
            AddLayer(layer, None if index is None else index + n) for n, layer in enumerate(layers)
        ]
        if not self._push(CompoundEdit(adds, f"Add Recipe {path.name}")):
            return []
        note = "; its [export] table is for matshop batch" if recipe.export is not None else ""
        self.message.emit(f"Added {len(layers)} filter layer(s) from {path.name}{note}")
        return [layer.id for layer in layers]

    def image_uses(self) -> list[tuple[str, str]]:
        """``(use, label)`` of what an image can become in the open document: a parameter's
        values (normals also from a height image), or the active layer's mask."""
        from ..tools.settings import short_label

        doc, layer = self.session.doc, self.session.active_layer
        if doc is None:
            return []
        uses = []
        for param in doc.schema.parameters:
            if param.name == "normal" and param.phys_channels == 3:
                uses.append(("normal", "Normal (a normal map)"))
                uses.append((HEIGHT_USE, "Normal from a height image"))
            elif param.phys_channels in (1, 3) and param.name != "normal":
                uses.append((param.name, f"{short_label(param.name)} values"))
        if layer is not None:
            uses.append((MASK_USE, f"Mask of layer {layer.name!r}"))
        return uses

    def import_image(self, path: Path, use: str, *, height_px: float | None = None) -> int | None:
        """The image as ``use`` (see :meth:`image_uses`), one undo step; the new paint
        layer's id, or the masked layer's. ``height_px``: a height image's displacement
        (default :data:`~matshop.image_content.HEIGHT_PX`)."""
        from ..image_content import HEIGHT_PX, image_layer, image_mask

        doc, active = self.session.doc, self.session.active_layer
        if doc is None:
            return None
        if use == MASK_USE:
            if active is None:
                return None
            made = self._attempt(image_mask, doc, path)
            if made is None or not self._push(SetMask(active.id, made[0])):
                return None
            self._tell(made[1], f"{path.name} masks layer {active.name!r}")
            return active.id
        parameters = ("normal",) if use == HEIGHT_USE else (use,)
        made = self._attempt(
            image_layer,
            doc,
            path,
            parameters,
            as_height=use == HEIGHT_USE,
            height_px=HEIGHT_PX if height_px is None else height_px,
        )
        if made is None:
            return None
        layer, notes = made
        if not self._push(AddLayer(layer, self._above_active())):
            return None
        self._tell(notes, f"Added paint layer {layer.name!r} from {path.name}")
        return layer.id

    def _tell(self, notes: list[str], done: str) -> None:
        self.message.emit("; ".join([done, *notes]))

    def duplicate_active(self) -> int | None:
        """A copy of the active layer just above it (its tiles shared, copy-on-write)."""
        doc, layer = self.session.doc, self.session.active_layer
        if doc is None or layer is None:
            return None
        twin = self._attempt(_duplicate, doc, layer)
        if twin is None:
            return None
        return twin.id if self._push(AddLayer(twin, doc.index_of(layer.id) + 1)) else None

    # -- groups ----------------------------------------------------------------

    def group(self, layer_ids: list[int]) -> int | None:
        """Put the layers in a new group: gathered (in stack order) just below it, one step."""
        doc = self.session.doc
        if doc is None or not layer_ids:
            return None
        order = sorted(layer_ids, key=doc.index_of)
        top = doc.layer(order[-1])
        if any(doc.layer(i).parent != top.parent for i in order):
            self.message.emit("Group layers of the same group (or of none) together")
            return None
        stack = [layer.id for layer in doc.layers]
        edits: list[Edit] = []
        # gather: each lower layer moves to just below the one above it in the selection
        for below, above in zip(reversed(order[:-1]), reversed(order[1:]), strict=True):
            b, a = stack.index(below), stack.index(above)
            target = a - 1 if b < a else a  # MoveLayer pops first, then inserts
            if b != target:
                edits.append(MoveLayer(below, target))
                stack.insert(target, stack.pop(b))
        group = doc.new_group_layer(parent=top.parent)
        edits.append(AddLayer(group, stack.index(top.id) + 1))
        edits += [SetProperty(layer_id, "parent", group.id) for layer_id in order]
        return group.id if self._push(CompoundEdit(edits, label="Group layers")) else None

    def ungroup_active(self) -> None:
        """Take the active layer out of its group: just above the group, in the group's parent."""
        doc, layer = self.session.doc, self.session.active_layer
        if doc is None or layer is None or layer.parent is None:
            return
        group = doc.layer(layer.parent)
        edits: list[Edit] = [SetProperty(layer.id, "parent", group.parent)]
        index = doc.index_of(group.id)  # moving up from below it: lands just above it
        edits.append(MoveLayer(layer.id, index))
        self._push(CompoundEdit(edits, label="Move out of group"))

    def depth(self, layer: Layer) -> int:
        """How many groups ``layer`` is nested in (the panel indents by it)."""
        doc = self.session.doc
        depth, seen, current = 0, set(), layer
        while doc is not None and current.parent is not None and current.id not in seen:
            seen.add(current.id)
            try:
                current = doc.layer(current.parent)
            except KeyError:
                break
            depth += 1
        return depth

    # -- masks ------------------------------------------------------------------

    def add_mask(self) -> None:
        """A mask showing everything (paint it to hide parts of the layer)."""
        doc, layer = self.session.doc, self.session.active_layer
        if doc is not None and layer is not None and layer.mask is None:
            self._push(SetMask(layer.id, doc.new_mask(1.0)))

    def remove_mask(self) -> None:
        layer = self.session.active_layer
        if layer is not None and layer.mask is not None:
            self._push(SetMask(layer.id, None))

    def invert_mask(self) -> None:
        layer = self.session.active_layer
        if layer is not None and layer.mask is not None:
            self._push(SetProperty(layer.id, "mask_inverted", not layer.mask_inverted))

    # -- changing ------------------------------------------------------------

    def remove_active(self) -> None:
        layer = self.session.active_layer
        if layer is not None and self.session.doc is not None and len(self.session.doc) > 1:
            self._push(RemoveLayer(layer.id))

    def move_active(self, delta: int) -> None:
        """Move the active layer ``delta`` places up (+) or down (-) the stack."""
        doc, layer = self.session.doc, self.session.active_layer
        if doc is None or layer is None:
            return
        self.move(layer.id, doc.index_of(layer.id) + delta)

    def move(self, layer_id: int, index: int) -> None:
        doc = self.session.doc
        if doc is None or not 0 <= index < len(doc) or doc.index_of(layer_id) == index:
            return
        self._push(MoveLayer(layer_id, index))

    def set_property(self, layer_id: int, name: str, value: Any, *, merge: bool = False) -> None:
        """One property change; ``merge`` for the ticks of a slider drag."""
        doc = self.session.doc
        if doc is None:
            return
        current = doc.layer(layer_id).get(name)
        if _same(current, value):
            return
        self._push(SetProperty(layer_id, name, value), merge=merge)


def _same(a: Any, b: Any) -> bool:
    try:
        return bool(a == b)
    except ValueError:  # arrays compare elementwise: treat as changed
        return False


def _duplicate(doc, layer: Layer) -> Layer:
    """A new layer (new id) with ``layer``'s properties and content; not in the stack yet."""
    if isinstance(layer, GroupLayer):
        raise InvalidValue("duplicate a group's layers one by one (groups copy no members)")
    twin = doc.new_layer(layer.kind, f"{layer.name} copy", **layer.state())
    if layer.mask is not None:
        twin.mask = layer.mask.copy()  # the new layer is not in the document yet
    return twin
