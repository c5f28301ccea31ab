"""The history panel: every undo step by label; click one to go back (or forward) to it.

Row 0 is the document as opened; row ``k`` is the state after ``k`` steps.
Steps that were undone stay listed, dimmed, until a new edit drops them.
The rows follow the history's events (:class:`matshop.layers.HistoryEvents`)
one by one: a push adds or relabels one row, an undo dims one, dropped steps
take their rows with them.
"""

from __future__ import annotations

from PySide6.QtCore import QSignalBlocker
from PySide6.QtGui import QBrush, QColor
from PySide6.QtWidgets import QListWidget, QListWidgetItem, QVBoxLayout, QWidget

from ..layers import Edit, History
from .session import DocumentSession

UNDONE = QColor("#6b6f77")
OPENED = "Open"
TRUNCATED = "(older steps dropped)"


class HistoryPanel(QWidget):
    def __init__(self, session: DocumentSession, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.session = session
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 8, 8, 8)
        self.list = QListWidget()
        layout.addWidget(self.list)
        self._history: History | None = None
        self._applied = 0  # steps applied, as the rows show them
        self.list.currentRowChanged.connect(self._jump)
        session.documentReplaced.connect(self._follow)
        self._follow()

    # -- following the history ---------------------------------------------------

    def _follow(self) -> None:
        """Mirror the session's (new) history: rows from its report, then its events."""
        if self._history is not None:
            self._connect(self._history, False)
        self._history = self.session.history
        with QSignalBlocker(self.list):
            self.list.clear()
        self._applied = 0
        if self._history is None:
            return
        report = self._history.report()
        with QSignalBlocker(self.list):
            self.list.addItem(TRUNCATED if report.dropped_steps else OPENED)
            self.list.addItems(list(report.undo_labels))
            for label in report.redo_labels:
                self.list.addItem(_dimmed(QListWidgetItem(label), True))
        self._show_current(report.undo_steps)
        self._connect(self._history, True)

    def _connect(self, history: History, on: bool) -> None:
        events = history.events
        for signal, slot in (
            (events.pushed, self._pushed),
            (events.undone, self._undone),
            (events.redone, self._redone),
            (events.dropped, self._dropped),
        ):
            (signal.connect if on else signal.disconnect)(slot)

    def _pushed(self, step: Edit, merged: bool) -> None:
        if merged:
            self.list.item(self._applied).setText(step.label)
        else:
            self.list.insertItem(self._applied + 1, step.label)
            self._show_current(self._applied + 1)

    def _undone(self, _step: Edit) -> None:
        _dimmed(self.list.item(self._applied), True)
        self._show_current(self._applied - 1)

    def _redone(self, _step: Edit) -> None:
        _dimmed(self.list.item(self._applied + 1), False)
        self._show_current(self._applied + 1)

    def _dropped(self, steps: tuple[Edit, ...], reason: str) -> None:
        if reason == "limit":  # the oldest: the rows just after the first
            for _ in steps:
                self.list.takeItem(1)
            self.list.item(0).setText(TRUNCATED)
            self._show_current(self._applied - len(steps))
        elif reason == "redo":  # the whole redo stack: the last rows
            for _ in steps:
                self.list.takeItem(self.list.count() - 1)
        else:
            self._follow()

    def _show_current(self, applied: int) -> None:
        """Row ``applied`` is the current state (showing where history is is no jump)."""
        self._applied = applied
        with QSignalBlocker(self.list):
            self.list.setCurrentRow(applied)
        self.list.scrollToItem(self.list.currentItem())

    # -- reading and clicking --------------------------------------------------------

    def labels(self) -> list[str]:
        return [self.list.item(row).text() for row in range(self.list.count())]

    def dimmed(self) -> list[bool]:
        """Per row: shown as undone."""
        return [
            self.list.item(row).foreground().color() == UNDONE for row in range(self.list.count())
        ]

    def _jump(self, row: int) -> None:
        if row >= 0:
            self.session.jump_to(row)


def _dimmed(item: QListWidgetItem, undone: bool) -> QListWidgetItem:
    item.setForeground(UNDONE if undone else QBrush())
    return item
