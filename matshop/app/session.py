"""The open document, its history and the active layer, as Qt signals.

Every change the GUI makes goes through :meth:`DocumentSession.push` as an
edit (never a mutation of arrays). The session listens to the history's
events (:class:`matshop.layers.HistoryEvents`) and turns them into Qt
signals; the history owns the saved marker, so "modified" is exact after
undoing back to the saved state, after merges and after dropped steps.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QObject, Signal

from ..layers import Document, Edit, History, Layer


class DocumentSession(QObject):
    """One open document: ``doc``, ``history``, where it came from and where it saves."""

    #: a different document was opened (or closed)
    documentReplaced = Signal()
    #: the undo/redo stacks changed (push, undo, redo, merge, clear); a view that
    #: mirrors the steps subscribes to ``history.events`` instead
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
        self._autosaved_state = 0  # the history state last written to the recovery file
        self._forced_modified = False
        self._was_modified = False

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
        if self.history is not None:
            self._subscribe(self.history, False)
        self.doc = doc
        self.history = None if doc is None else History(doc)
        self.project_path = project_path
        self.source_path = source_path
        self._autosaved_state = 0 if self.history is None else self.history.state_id
        self._forced_modified = modified
        self.active_layer_id = None
        self.mask_target = False
        if doc is not None:
            doc.events.layers.connect(self._on_layers)
            doc.events.layer.connect(self._on_layer)
            self.active_layer_id = doc.layers[-1].id if doc.layers else None
        if self.history is not None:
            self._subscribe(self.history, True)
        self.documentReplaced.emit()
        self.historyChanged.emit()
        self.layersChanged.emit()
        self.activeLayerChanged.emit()
        self._check_modified()

    def _subscribe(self, history: History, on: bool) -> None:
        events = history.events
        pairs = [
            (events.pushed, self._stacks_changed),
            (events.undone, self._stacks_changed),
            (events.redone, self._stacks_changed),
            (events.dropped, self._steps_dropped),
            (events.saved, self._check_modified),
        ]
        for signal, slot in pairs:
            (signal.connect if on else signal.disconnect)(slot)

    def _stacks_changed(self, *_args) -> None:
        self.historyChanged.emit()
        self._check_modified()

    def _steps_dropped(self, _steps: tuple[Edit, ...], reason: str) -> None:
        # the drops of a push come with its ``pushed``: one historyChanged for both
        if reason == "clear":
            self._stacks_changed()

    def _check_modified(self) -> None:
        if self.modified != self._was_modified:
            self._was_modified = self.modified
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
        return self.history.push(edit, applied=applied, merge=merge)

    def seal(self) -> None:
        """The next push starts a new undo step (a drag ended or began)."""
        if self.history is not None:
            self.history.seal()

    def undo(self) -> Edit | None:
        return None if self.history is None else self.history.undo()

    def redo(self) -> Edit | None:
        return None if self.history is None else self.history.redo()

    def jump_to(self, steps: int) -> None:
        """Undo or redo until ``steps`` steps are applied (the history panel's click)."""
        while self.history is not None and self.history.undo_steps > steps and self.undo():
            pass
        while self.history is not None and self.history.undo_steps < steps and self.redo():
            pass

    @property
    def last_edit(self) -> Edit | None:
        """The step the next undo reverts (None: nothing to undo)."""
        return None if self.history is None else self.history.last_edit

    @property
    def steps(self) -> int:
        """Undo steps currently applied."""
        return 0 if self.history is None else self.history.undo_steps

    # -- saved state ---------------------------------------------------------

    @property
    def modified(self) -> bool:
        """Changed since opened or saved (undoing back to the saved state clears it)."""
        if self.doc is None or self.history is None:
            return False
        return self._forced_modified or not self.history.at_saved

    @property
    def needs_autosave(self) -> bool:
        return (
            self.modified
            and self.history is not None
            and self.history.state_id != self._autosaved_state
        )

    def mark_saved(self, project_path: Path) -> None:
        self.project_path = project_path
        self._forced_modified = False
        if self.history is not None:
            self._autosaved_state = self.history.state_id
            self.history.mark_saved()  # its ``saved`` event updates the modified flag
        self._check_modified()

    def mark_autosaved(self) -> None:
        if self.history is not None:
            self._autosaved_state = self.history.state_id

    @property
    def title(self) -> str:
        if self.doc is None:
            return ""
        if self.project_path is not None:
            return self.project_path.name
        return self.doc.name
