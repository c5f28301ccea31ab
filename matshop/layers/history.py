"""Undo/redo with a memory budget.

History holds edits (:mod:`matshop.layers.edits`) in an undo and a redo
stack. It counts the bytes of the arrays they keep alive (each tile or
texture once, however many steps share it: the "after" tiles of one stroke
are the "before" tiles of the next) and drops the oldest steps when the total
passes the budget (2 GiB by default), so undo alone can never exhaust memory
(the ArmorPaint complaint: 16 steps of a 16K project, 24 GB). The count is
conservative: tiles the live document also uses are counted too.

History says what it did through :class:`HistoryEvents` (plain callbacks, as
the document's :mod:`.events`), so a view mirrors it without polling, and it
owns the saved marker: each state has an id, equal ids are equal states, so
"modified" stays exact across undo, merges and dropped steps.
"""

from __future__ import annotations

import itertools
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from .edits import Edit
from .events import Signal

if TYPE_CHECKING:
    from .document import Document

GiB = 1 << 30

#: why steps left the history: "limit" (the oldest, past the memory or step
#: budget), "redo" (undone steps a new push discarded), "clear" (all of them)
DropReason = Literal["limit", "redo", "clear"]


class HistoryEvents:
    """History's signals, emitted once the stacks are in their new state.

    - ``pushed(step, merged)``: ``step`` is now the top undo step; ``merged``:
      the pushed edit went into it (a slider drag) instead of adding a step.
    - ``undone(step)`` / ``redone(step)``: one step moved between the stacks.
    - ``dropped(steps, reason)``: steps are gone for good (:data:`DropReason`);
      ``"limit"`` steps were the oldest undo steps, ``"redo"`` steps the whole
      redo stack, next-to-redo first. A push emits ``dropped(..., "redo")``
      before ``pushed`` and ``dropped(..., "limit")`` after it.
    - ``saved()``: the saved marker moved to the current state.
    """

    def __init__(self) -> None:
        self.pushed = Signal("pushed")
        self.undone = Signal("undone")
        self.redone = Signal("redone")
        self.dropped = Signal("dropped")
        self.saved = Signal("saved")


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
    max_steps : int, optional
        Most undo steps kept (None: only the byte budget limits them).
    """

    def __init__(
        self, doc: Document, budget_bytes: int = 2 * GiB, max_steps: int | None = None
    ) -> None:
        self.doc = doc
        self.budget_bytes = int(budget_bytes)
        self.max_steps = max_steps
        self.events = HistoryEvents()
        self._undo: deque[Edit] = deque()
        self._redo: list[Edit] = []
        self._sealed = True  # the next push never merges into an older step
        self._refs: dict[int, tuple[np.ndarray, int]] = {}  # id -> (array, steps using it)
        self._held: dict[int, list[np.ndarray]] = {}  # id(edit) -> arrays counted for it
        self._bytes = 0
        self._dropped = 0
        # state ids: the state after each step (a merge makes a new state), and
        # the state under the oldest undo step (the document as opened, or the
        # state the dropped steps left)
        self._state_ids = itertools.count(1)
        self._after: dict[int, int] = {}  # id(edit) -> state id after it
        self._base_state = 0
        self._saved_state = 0

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

    def _forget(self, edit: Edit) -> None:
        self._release(edit)
        self._after.pop(id(edit))

    def _over_limit(self) -> bool:
        too_many = self.max_steps is not None and len(self._undo) > self.max_steps
        return bool(self._undo) and (self._bytes > self.budget_bytes or too_many)

    def _enforce_limits(self) -> list[Edit]:
        dropped = []
        while self._over_limit():
            edit = self._undo.popleft()
            self._base_state = self._after[id(edit)]
            self._forget(edit)
            dropped.append(edit)
        self._dropped += len(dropped)
        return dropped

    # -- the stacks ----------------------------------------------------------

    def push(self, edit: Edit, *, applied: bool = False, merge: bool = True) -> bool:
        """Record ``edit`` (applying it first unless ``applied``); returns True if it
        merged into the previous step (consecutive slider moves)."""
        if not applied:
            edit.apply(self.doc)
        discarded = self._redo[::-1]  # next-to-redo first
        for undone in discarded:
            self._forget(undone)
        self._redo.clear()
        merged = False
        if merge and not self._sealed and self._undo:
            top = self._undo[-1]
            self._release(top)
            merged = top.merge_with(edit)
            self._hold(top)
            if merged:
                self._after[id(top)] = next(self._state_ids)  # a new state: not the saved one
        if not merged:
            self._undo.append(edit)
            self._hold(edit)
            self._after[id(edit)] = next(self._state_ids)
            self._sealed = False
        step = self._undo[-1]
        limited = self._enforce_limits()
        if discarded:
            self.events.dropped.emit(tuple(discarded), "redo")
        self.events.pushed.emit(step, merged)
        if limited:
            self.events.dropped.emit(tuple(limited), "limit")
        return merged

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
        self.events.undone.emit(edit)
        return edit

    def redo(self) -> Edit | None:
        """Re-apply the last undone step; returns it (None when there is nothing to redo)."""
        if not self._redo:
            return None
        edit = self._redo.pop()
        edit.apply(self.doc)
        self._undo.append(edit)
        self._sealed = True
        self.events.redone.emit(edit)
        return edit

    def clear(self) -> None:
        """Forget every step (the current state stays what it is, saved or not)."""
        self._base_state = self.state_id
        gone = (*self._undo, *reversed(self._redo))
        for edit in gone:
            self._forget(edit)
        self._undo.clear()
        self._redo.clear()
        self._sealed = True
        if gone:
            self.events.dropped.emit(gone, "clear")

    # -- the saved marker ----------------------------------------------------

    @property
    def state_id(self) -> int:
        """Names the document's current state: equal ids, equal documents."""
        return self._after[id(self._undo[-1])] if self._undo else self._base_state

    def mark_saved(self) -> None:
        """The current state is what is on disk."""
        self._saved_state = self.state_id
        self.events.saved.emit()

    @property
    def at_saved(self) -> bool:
        """The document is in the state last marked saved (as opened, before any mark)."""
        return self.state_id == self._saved_state

    # -- reading -------------------------------------------------------------

    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        return bool(self._redo)

    @property
    def undo_steps(self) -> int:
        return len(self._undo)

    @property
    def redo_steps(self) -> int:
        return len(self._redo)

    @property
    def last_edit(self) -> Edit | None:
        """The step the next undo reverts."""
        return self._undo[-1] if self._undo else None

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
