"""Undo/redo with a memory budget.

History holds edits (:mod:`matshop.layers.edits`) in an undo and a redo
stack. It counts the bytes of the arrays they keep alive (each tile or
texture once, however many steps share it: the "after" tiles of one stroke
are the "before" tiles of the next) and drops the oldest steps when the total
passes the budget (2 GiB by default), so undo alone can never exhaust memory
(the ArmorPaint complaint: 16 steps of a 16K project, 24 GB). The count is
conservative: tiles the live document also uses are counted too.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .edits import Edit

if TYPE_CHECKING:
    from .document import Document

GiB = 1 << 30


@dataclass(frozen=True)
class HistoryReport:
    """What history holds, for a status bar or ``matshop`` verbs."""

    undo_steps: int
    redo_steps: int
    bytes: int
    budget_bytes: int
    dropped_steps: int
    undo_labels: tuple[str, ...]
    redo_labels: tuple[str, ...]

    def __str__(self) -> str:
        return (
            f"{self.undo_steps} undo / {self.redo_steps} redo steps, "
            f"{self.bytes / 2**20:.1f} MiB of {self.budget_bytes / 2**20:.0f} MiB"
            + (f", {self.dropped_steps} oldest dropped" if self.dropped_steps else "")
        )


class History:
    """Undo and redo stacks of edits on one document.

    Parameters
    ----------
    doc : Document
    budget_bytes : int
        Most bytes of arrays kept alive by history; oldest steps go first.
    """

    def __init__(self, doc: Document, budget_bytes: int = 2 * GiB) -> None:
        self.doc = doc
        self.budget_bytes = int(budget_bytes)
        self._undo: deque[Edit] = deque()
        self._redo: list[Edit] = []
        self._sealed = True  # the next push never merges into an older step
        self._refs: dict[int, tuple[np.ndarray, int]] = {}  # id -> (array, steps using it)
        self._held: dict[int, list[np.ndarray]] = {}  # id(edit) -> arrays counted for it
        self._bytes = 0
        self._dropped = 0

    # -- accounting ----------------------------------------------------------

    def _hold(self, edit: Edit) -> None:
        # what the edit holds *now*: an AddLayer's layer gains tiles later, but
        # those belong to the paint edits that made them
        arrays = list({id(a): a for a in edit.arrays()}.values())
        self._held[id(edit)] = arrays
        for array in arrays:
            held = self._refs.get(id(array))
            if held is None:
                self._refs[id(array)] = (array, 1)
                self._bytes += array.nbytes
            else:
                self._refs[id(array)] = (array, held[1] + 1)

    def _release(self, edit: Edit) -> None:
        for array in self._held.pop(id(edit)):
            _, count = self._refs[id(array)]
            if count == 1:
                del self._refs[id(array)]
                self._bytes -= array.nbytes
            else:
                self._refs[id(array)] = (array, count - 1)

    def _enforce_budget(self) -> None:
        while self._bytes > self.budget_bytes and self._undo:
            self._release(self._undo.popleft())
            self._dropped += 1

    # -- the stacks ----------------------------------------------------------

    def push(self, edit: Edit, *, applied: bool = False, merge: bool = True) -> bool:
        """Record ``edit`` (applying it first unless ``applied``); returns True if it
        merged into the previous step (consecutive slider moves)."""
        if not applied:
            edit.apply(self.doc)
        for undone in self._redo:
            self._release(undone)
        self._redo.clear()
        if merge and not self._sealed and self._undo:
            top = self._undo[-1]
            self._release(top)
            merged = top.merge_with(edit)
            self._hold(top)
            if merged:
                self._enforce_budget()
                return True
        self._undo.append(edit)
        self._hold(edit)
        self._sealed = False
        self._enforce_budget()
        return False

    def seal(self) -> None:
        """End merging: the next push starts a new step (a slider drag was released)."""
        self._sealed = True

    def undo(self) -> Edit | None:
        """Revert the last step; returns it (None when there is nothing to undo)."""
        if not self._undo:
            return None
        edit = self._undo.pop()
        edit.revert(self.doc)
        self._redo.append(edit)
        self._sealed = True
        return edit

    def redo(self) -> Edit | None:
        """Re-apply the last undone step; returns it (None when there is nothing to redo)."""
        if not self._redo:
            return None
        edit = self._redo.pop()
        edit.apply(self.doc)
        self._undo.append(edit)
        self._sealed = True
        return edit

    def clear(self) -> None:
        for edit in (*self._undo, *self._redo):
            self._release(edit)
        self._undo.clear()
        self._redo.clear()
        self._sealed = True

    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        return bool(self._redo)

    @property
    def undo_label(self) -> str | None:
        return self._undo[-1].label if self._undo else None

    @property
    def redo_label(self) -> str | None:
        return self._redo[-1].label if self._redo else None

    @property
    def nbytes(self) -> int:
        return self._bytes

    def report(self) -> HistoryReport:
        return HistoryReport(
            undo_steps=len(self._undo),
            redo_steps=len(self._redo),
            bytes=self._bytes,
            budget_bytes=self.budget_bytes,
            dropped_steps=self._dropped,
            undo_labels=tuple(edit.label for edit in self._undo),
            redo_labels=tuple(edit.label for edit in reversed(self._redo)),
        )
