"""The layer document: sparse tiles, layers, masks, blend modes, cached flatten, undo.

Qt-free. Modules, one idea each:

- :mod:`.geometry` — :class:`Rect`, :class:`TileLayout`, tile sets
- :mod:`.tiles` — :class:`TileGrid`, sparse copy-on-write tile storage
- :mod:`.blend` — blend modes in edit space (:data:`BLEND_MODES`)
- :mod:`.filters` — which ops filter layers run (their reach is the op's own)
- :mod:`.properties` — the layer properties: type, range, text form, edit label
- :mod:`.layer` — :class:`PaintLayer`, :class:`FillLayer`, :class:`FilterLayer`,
  :class:`GroupLayer`
- :mod:`.cache`, :mod:`.compositor` — per-tile flatten and invalidation
- :mod:`.reference` — the uncached whole-image flatten (the oracle)
- :mod:`.events` — change notifications (:class:`DirtyRegion`)
- :mod:`.document` — :class:`Document`
- :mod:`.edits`, :mod:`.transaction`, :mod:`.history` — reversible edits, paint
  transactions, undo/redo with a memory budget
"""

from .blend import BLEND_MODES, BlendMode, blend, get_blend_mode
from .document import Document
from .edits import (
    AddLayer,
    CompoundEdit,
    Edit,
    MoveLayer,
    PaintEdit,
    RemoveLayer,
    SetMask,
    SetProperty,
)
from .events import DirtyRegion
from .geometry import Rect, TileLayout
from .history import History, HistoryEvents, HistoryReport
from .layer import FillLayer, FilterLayer, GroupLayer, Layer, PaintLayer
from .reference import flatten_reference
from .tiles import TileGrid
from .transaction import PaintTransaction

__all__ = [
    "BLEND_MODES",
    "AddLayer",
    "BlendMode",
    "CompoundEdit",
    "DirtyRegion",
    "Document",
    "Edit",
    "FillLayer",
    "FilterLayer",
    "GroupLayer",
    "History",
    "HistoryEvents",
    "HistoryReport",
    "Layer",
    "MoveLayer",
    "PaintEdit",
    "PaintLayer",
    "PaintTransaction",
    "Rect",
    "RemoveLayer",
    "SetMask",
    "SetProperty",
    "TileGrid",
    "TileLayout",
    "blend",
    "flatten_reference",
    "get_blend_mode",
]
