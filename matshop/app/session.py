"""The open document, its history and the active layer, as Qt signals.

Every change the GUI makes goes through :meth:`DocumentSession.push` as an
edit (never a mutation of arrays), so history, the modified flag and the
panels stay in step. The session mirrors the history stack with one token
per step so "modified" is exact after undoing back to the saved state.
"""

from __future__ import annotations

import itertools
from pathlib import Path

from PySide6.QtCore import QObject, Signal

from ..layers import Document, Edit, History, Layer

_tokens = itertools.count(1)


class DocumentSession(QObject):
    """One open document: ``doc``, ``history``, where it came from and where it saves."""

    #: a different document was opened (or closed)
    documentReplaced = Signal()
    #: the undo/redo stacks changed (push, undo, redo, merge)
    historyChanged = Signal()
    #: layers were added, removed, moved or changed a property
    layersChanged = Signal()
    activeLayerChanged = Signal()
    modifiedChanged = Signal(bool)
    #: strokes switched between the active layer's pixels and its mask
    targetChanged = Signal(bool)

    def __init__(self) -> None:
        super().__init__()
        self.doc: Document | None = None
        self.history: History | None = None
        #: the .matshop file Save writes (None: never saved as a project)
        self.project_path: Path | None = None
        #: what was opened (a texture set or the project); names the recovery file
        self.source_path: Path | None = None
        self.active_layer_id: int | None = None
        #: strokes paint the active layer's mask (its thumbnail is selected), not its pixels
        self.mask_target = False
        self._undo_tokens: list[int] = []
        self._redo_tokens: list[int] = []
        # the edits beside their tokens (the history keeps them privately)
        self._undo_edits: list[Edit] = []
        self._redo_edits: list[Edit] = []
        self._saved_token = 0
        self._autosaved_token = 0
        self._forced_modified = False

    # -- the document --------------------------------------------------------

    def set_document(
        self,
        doc: Document | None,
        *,
        project_path: Path | None = None,
        source_path: Path | None = None,
        modified: bool = False,
    ) -> None:
        if self.doc is not None:
            self.doc.events.layers.disconnect(self._on_layers)
            self.doc.events.layer.disconnect(self._on_layer)
        was_modified = self.modified
        self.doc = doc
        self.history = None if doc is None else History(doc)
        self.project_path = project_path
        self.source_path = source_path
        self._undo_tokens, self._redo_tokens = [], []
        self._undo_edits, self._redo_edits = [], []
        self._saved_token = self._autosaved_token = 0
        self._forced_modified = modified
        self.active_layer_id = None
        self.mask_target = False
        if doc is not None:
            doc.events.layers.connect(self._on_layers)
            doc.events.layer.connect(self._on_layer)
            self.active_layer_id = doc.layers[-1].id if doc.layers else None
        self.documentReplaced.emit()
        self.historyChanged.emit()
        self.layersChanged.emit()
        self.activeLayerChanged.emit()
        if self.modified != was_modified:
            self.modifiedChanged.emit(self.modified)

    def _on_layers(self, kind: str, layer_id: int, index: int) -> None:
        if kind == "insert":
            self.active_layer_id = layer_id
        elif kind == "remove" and layer_id == self.active_layer_id:
            assert self.doc is not None
            below = min(max(index - 1, 0), len(self.doc.layers) - 1)
            self.active_layer_id = self.doc.layers[below].id if self.doc.layers else None
        if kind != "move":
            self.set_mask_target(False)
        self.layersChanged.emit()
        self.activeLayerChanged.emit()

    def _on_layer(self, layer_id: int, name: str) -> None:
        if name == "mask" and layer_id == self.active_layer_id:
            self.set_mask_target(self.mask_target)  # the mask went: so does the target
        self.layersChanged.emit()

    @property
    def active_layer(self) -> Layer | None:
        if self.doc is None or self.active_layer_id is None:
            return None
        try:
            return self.doc.layer(self.active_layer_id)
        except KeyError:
            return None

    def set_active_layer(self, layer_id: int | None) -> None:
        if layer_id != self.active_layer_id:
            self.active_layer_id = layer_id
            self.set_mask_target(False)
            self.activeLayerChanged.emit()

    def set_mask_target(self, on: bool) -> None:
        """Paint into the active layer's mask (only when it has one)."""
        layer = self.active_layer
        on = bool(on) and layer is not None and layer.mask is not None
        if on != self.mask_target:
            self.mask_target = on
            self.targetChanged.emit(on)

    # -- history -------------------------------------------------------------

    def push(self, edit: Edit, *, applied: bool = False, merge: bool = False) -> bool:
        """Apply (unless ``applied``) and record ``edit``; True if it merged into the last step.

        ``merge=True`` only for the ticks of one slider drag (see :meth:`seal`).
        """
        assert self.history is not None, "no document"
        before = self.modified
        merged = self.history.push(edit, applied=applied, merge=merge)
        if merged and self._undo_tokens:
            self._undo_tokens[-1] = next(_tokens)  # the step changed: no longer the saved one
        else:
            self._undo_tokens.append(next(_tokens))
            self._undo_edits.append(edit)
        self._redo_tokens.clear()
        self._redo_edits.clear()
        self._changed(before)
        return merged

    def seal(self) -> None:
        """The next push starts a new undo step (a drag ended or began)."""
        if self.history is not None:
            self.history.seal()

    def undo(self) -> Edit | None:
        if self.history is None or not self.history.can_undo:
            return None
        before = self.modified
        edit = self.history.undo()
        self._redo_tokens.append(self._undo_tokens.pop())
        self._redo_edits.append(self._undo_edits.pop())
        self._changed(before)
        return edit

    def redo(self) -> Edit | None:
        if self.history is None or not self.history.can_redo:
            return None
        before = self.modified
        edit = self.history.redo()
        self._undo_tokens.append(self._redo_tokens.pop())
        self._undo_edits.append(self._redo_edits.pop())
        self._changed(before)
        return edit

    def jump_to(self, steps: int) -> None:
        """Undo or redo until ``steps`` steps are applied (the history panel's click)."""
        while self.history is not None and len(self._undo_tokens) > steps and self.undo():
            pass
        while self.history is not None and len(self._undo_tokens) < steps and self.redo():
            pass

    @property
    def last_edit(self) -> Edit | None:
        """The step the next undo reverts (None: nothing to undo)."""
        return self._undo_edits[-1] if self._undo_edits else None

    @property
    def steps(self) -> int:
        """Undo steps currently applied."""
        return len(self._undo_tokens)

    def _changed(self, was_modified: bool) -> None:
        # the history may have dropped its oldest steps to stay in budget
        if self.history is not None:
            dropped = max(0, len(self._undo_tokens) - self.history.report().undo_steps)
            del self._undo_tokens[:dropped]
            del self._undo_edits[:dropped]
        self.historyChanged.emit()
        if self.modified != was_modified:
            self.modifiedChanged.emit(self.modified)

    # -- saved state ---------------------------------------------------------

    def _top(self) -> int:
        return self._undo_tokens[-1] if self._undo_tokens else 0

    @property
    def modified(self) -> bool:
        """Changed since opened or saved (undoing back to the saved state clears it)."""
        return self.doc is not None and (self._forced_modified or self._top() != self._saved_token)

    @property
    def needs_autosave(self) -> bool:
        return self.modified and self._top() != self._autosaved_token

    def mark_saved(self, project_path: Path) -> None:
        before = self.modified
        self.project_path = project_path
        self._saved_token = self._autosaved_token = self._top()
        self._forced_modified = False
        if self.modified != before:
            self.modifiedChanged.emit(self.modified)

    def mark_autosaved(self) -> None:
        self._autosaved_token = self._top()

    @property
    def title(self) -> str:
        if self.doc is None:
            return ""
        if self.project_path is not None:
            return self.project_path.name
        return self.doc.name
