"""When each window action makes sense: one predicate per action, read in one place.

A rule takes the open document (None: nothing open) and the active layer
(None: no layer chosen) and says whether the action can run now. The main
window enables its actions from this table whenever the document, its layers
or the active layer change; undo and redo follow the history instead.
"""

from __future__ import annotations

from collections.abc import Callable

from ..layers import Document, Layer

Rule = Callable[[Document | None, Layer | None], bool]


def document_open(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None


def layer_chosen(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None and layer is not None


def _deletable(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None and layer is not None and len(doc) > 1  # never the last layer


def _copyable(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None and layer is not None and layer.kind != "group"


def _grouped(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None and layer is not None and layer.parent is not None


def _unmasked(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None and layer is not None and layer.mask is None


def _masked(doc: Document | None, layer: Layer | None) -> bool:
    return doc is not None and layer is not None and layer.mask is not None


def _movable(delta: int) -> Rule:
    def rule(doc: Document | None, layer: Layer | None) -> bool:
        if doc is None or layer is None:
            return False
        return 0 <= doc.index_of(layer.id) + delta < len(doc)

    return rule


ENABLED_WHEN: dict[str, Rule] = {
    "save": document_open,
    "save_as": document_open,
    "export": document_open,
    "close": document_open,
    "add_paint": document_open,
    "add_fill": document_open,
    "add_filter": document_open,
    "add_recipe": document_open,
    "import_image": document_open,
    "curves": document_open,
    "fit": document_open,
    "actual": document_open,
    "zoom_in": document_open,
    "zoom_out": document_open,
    "delete": _deletable,
    "duplicate": _copyable,
    "group": layer_chosen,
    "ungroup": _grouped,
    "add_mask": _unmasked,
    "remove_mask": _masked,
    "invert_mask": _masked,
    "move_up": _movable(1),
    "move_down": _movable(-1),
}
