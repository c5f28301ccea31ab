"""The status bar's "computing" indicator: what is computing, for how long, and Cancel."""

from __future__ import annotations

from PySide6.QtWidgets import QHBoxLayout, QLabel, QProgressBar, QPushButton, QWidget


class BusyIndicator(QWidget):
    """Hidden until :meth:`show_progress`; the Cancel button is :attr:`cancel`."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 6, 0)
        layout.setSpacing(6)
        self.label = QLabel("")
        self.bar = QProgressBar()
        self.bar.setRange(0, 0)  # the ops report no progress of their own: a busy bar
        self.bar.setFixedSize(120, 10)
        self.bar.setTextVisible(False)
        self.cancel = QPushButton("Cancel")
        self.cancel.setToolTip("Stop: undo the filter just added, or hide the slow filter(s)")
        layout.addWidget(self.label)
        layout.addWidget(self.bar)
        layout.addWidget(self.cancel)
        self.hide()

    def show_progress(self, what: str, seconds: float) -> None:
        self.label.setText(f"Computing {what}… {seconds:.1f} s")
        self.show()
