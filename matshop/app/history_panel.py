"""The history panel: every undo step by label; click one to go back (or forward) to it.

Row 0 is the document as opened; row ``k`` is the state after ``k`` steps.
Steps that were undone stay listed, dimmed, until a new edit drops them.
"""

from __future__ import annotations

from PySide6.QtGui import QColor
from PySide6.QtWidgets import QListWidget, QListWidgetItem, QVBoxLayout, QWidget

from .session import DocumentSession


class HistoryPanel(QWidget):
    def __init__(self, session: DocumentSession, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.session = session
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 8, 8, 8)
        self.list = QListWidget()
        layout.addWidget(self.list)
        self._refreshing = False
        self.list.currentRowChanged.connect(self._jump)
        session.historyChanged.connect(self.refresh)
        self.refresh()

    def refresh(self) -> None:
        if self._refreshing:
            return
        self._refreshing = True
        self.list.clear()
        history = self.session.history
        if history is not None:
            report = history.report()
            first = "Open" if not report.dropped_steps else "(older steps dropped)"
            self.list.addItem(QListWidgetItem(first))
            for label in report.undo_labels:
                self.list.addItem(QListWidgetItem(label))
            for label in report.redo_labels:
                item = QListWidgetItem(label)
                item.setForeground(QColor("#6b6f77"))
                self.list.addItem(item)
            self.list.setCurrentRow(report.undo_steps)
            self.list.scrollToItem(self.list.currentItem())
        self._refreshing = False

    def labels(self) -> list[str]:
        return [self.list.item(row).text() for row in range(self.list.count())]

    def _jump(self, row: int) -> None:
        if self._refreshing or row < 0:
            return
        # one rebuild after the whole jump, not one per undone step
        self._refreshing = True
        try:
            self.session.jump_to(row)
        finally:
            self._refreshing = False
        self.refresh()
