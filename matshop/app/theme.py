"""The dark theme: a Fusion palette plus a style sheet, in the manner of modern DCC tools.

Colors are defined once here; widgets never hard-code their own. Fusion is
used because it honours palettes identically on every platform (native
styles ignore parts of a dark palette).
"""

from __future__ import annotations

from PySide6.QtGui import QColor, QPalette
from PySide6.QtWidgets import QApplication

from .icons import ICON_DIR

WINDOW = "#2b2d31"
PANEL = "#232428"
BASE = "#1e1f22"
RAISED = "#35373c"
BORDER = "#3c3f45"
TEXT = "#dcdde0"
DIM = "#8f939b"
ACCENT = "#4c8dff"
ACCENT_DIM = "#2f5aa8"
ARROW = (ICON_DIR / "down.svg").as_posix()
CLOSE = (ICON_DIR / "close.svg").as_posix()
FLOAT = (ICON_DIR / "float.svg").as_posix()

STYLE_SHEET = f"""
QMainWindow, QDialog {{ background: {WINDOW}; }}
QWidget {{ color: {TEXT}; font-size: 9pt; }}
QMainWindow::separator {{ background: {BASE}; width: 3px; height: 3px; }}
QMainWindow::separator:hover {{ background: {ACCENT_DIM}; }}

QDockWidget {{ titlebar-close-icon: url({CLOSE}); titlebar-normal-icon: url({FLOAT});
    font-weight: 600; }}
QDockWidget::close-button, QDockWidget::float-button {{ border: none; background: transparent;
    icon-size: 12px; padding: 1px; }}
QDockWidget::close-button:hover, QDockWidget::float-button:hover {{ background: {RAISED}; }}
QDockWidget::title {{
    background: {PANEL}; padding: 6px 8px; border-bottom: 1px solid {BORDER};
    text-transform: uppercase;
}}
QDockWidget > QWidget {{ background: {WINDOW}; }}

QMenuBar {{ background: {PANEL}; border-bottom: 1px solid {BORDER}; }}
QMenuBar::item {{ padding: 5px 10px; background: transparent; }}
QMenuBar::item:selected {{ background: {RAISED}; border-radius: 4px; }}
QMenu {{ background: {PANEL}; border: 1px solid {BORDER}; padding: 4px; }}
QMenu::item {{ padding: 5px 28px 5px 22px; border-radius: 4px; }}
QMenu::item:selected {{ background: {ACCENT_DIM}; }}
QMenu::item:disabled {{ color: #5d6068; }}
QMenu::separator {{ height: 1px; background: {BORDER}; margin: 4px 6px; }}

QToolBar {{ background: {PANEL}; border: none; spacing: 2px; padding: 4px; }}
QToolBar#tools {{ border-right: 1px solid {BORDER}; }}
QToolButton {{ background: transparent; border: 1px solid transparent; border-radius: 5px;
    padding: 4px; }}
QToolButton:hover {{ background: {RAISED}; }}
QToolButton:checked {{ background: {ACCENT_DIM}; border-color: {ACCENT}; }}
QToolButton:disabled {{ color: #5d6068; }}

QStatusBar {{ background: {PANEL}; border-top: 1px solid {BORDER}; color: {DIM}; }}
QStatusBar QLabel {{ color: {DIM}; padding: 0 6px; }}

QListWidget, QTreeView, QTextEdit, QPlainTextEdit {{
    background: {BASE}; border: 1px solid {BORDER}; border-radius: 4px; outline: none;
}}
QListWidget::item {{ padding: 5px 4px; border-radius: 3px; }}
QListWidget::item:selected {{ background: {ACCENT_DIM}; color: white; }}
QListWidget::item:hover:!selected {{ background: {RAISED}; }}

QPushButton {{ background: {RAISED}; border: 1px solid {BORDER}; border-radius: 4px;
    padding: 5px 12px; }}
QPushButton:hover {{ border-color: {ACCENT}; }}
QPushButton:pressed {{ background: {ACCENT_DIM}; }}
QPushButton:disabled {{ color: #5d6068; }}

QComboBox, QSpinBox, QDoubleSpinBox, QLineEdit {{
    background: {BASE}; border: 1px solid {BORDER}; border-radius: 4px; padding: 3px 6px;
    selection-background-color: {ACCENT_DIM};
}}
QComboBox:hover, QSpinBox:hover, QDoubleSpinBox:hover, QLineEdit:hover {{ border-color: #555962; }}
QComboBox::drop-down {{ border: none; width: 18px; }}
QComboBox::down-arrow {{ image: url({ARROW}); width: 12px; height: 12px; }}
QComboBox QAbstractItemView {{ background: {PANEL}; border: 1px solid {BORDER};
    selection-background-color: {ACCENT_DIM}; }}
QSpinBox::up-button, QSpinBox::down-button,
QDoubleSpinBox::up-button, QDoubleSpinBox::down-button {{ width: 0; border: none; }}

QSlider::groove:horizontal {{ height: 4px; background: {BASE}; border-radius: 2px; }}
QSlider::sub-page:horizontal {{ background: {ACCENT_DIM}; border-radius: 2px; }}
QSlider::handle:horizontal {{ background: {TEXT}; width: 12px; height: 12px;
    margin: -5px 0; border-radius: 6px; }}
QSlider::handle:horizontal:hover {{ background: white; }}

QCheckBox::indicator {{ width: 14px; height: 14px; border: 1px solid #555962;
    border-radius: 3px; background: {BASE}; }}
QCheckBox::indicator:checked {{ background: {ACCENT}; border-color: {ACCENT}; }}

QGroupBox {{ border: 1px solid {BORDER}; border-radius: 5px; margin-top: 14px;
    padding: 8px 6px 6px 6px; }}
QGroupBox::title {{ subcontrol-origin: margin; left: 8px; padding: 0 4px; color: {DIM}; }}
QLabel#hint {{ color: {DIM}; }}
QLabel#heading {{ font-weight: 600; color: {TEXT}; }}
QScrollArea {{ border: none; background: transparent; }}
QScrollBar:vertical {{ background: transparent; width: 10px; margin: 0; }}
QScrollBar::handle:vertical {{ background: #4a4d54; border-radius: 4px; min-height: 24px; }}
QScrollBar::add-line, QScrollBar::sub-line {{ height: 0; }}
QToolTip {{ background: {PANEL}; color: {TEXT}; border: 1px solid {BORDER}; padding: 4px; }}
"""


def palette() -> QPalette:
    pal = QPalette()
    roles = QPalette.ColorRole
    for role, color in (
        (roles.Window, WINDOW),
        (roles.WindowText, TEXT),
        (roles.Base, BASE),
        (roles.AlternateBase, PANEL),
        (roles.Text, TEXT),
        (roles.Button, RAISED),
        (roles.ButtonText, TEXT),
        (roles.Highlight, ACCENT_DIM),
        (roles.HighlightedText, "#ffffff"),
        (roles.ToolTipBase, PANEL),
        (roles.ToolTipText, TEXT),
        (roles.PlaceholderText, DIM),
        (roles.Link, ACCENT),
    ):
        pal.setColor(role, QColor(color))
    for role in (roles.Text, roles.WindowText, roles.ButtonText):
        pal.setColor(QPalette.ColorGroup.Disabled, role, QColor("#5d6068"))
    return pal


def apply_theme(app: QApplication) -> None:
    """Fusion + the dark palette + the style sheet, application-wide."""
    app.setStyle("Fusion")
    app.setPalette(palette())
    app.setStyleSheet(STYLE_SHEET)
