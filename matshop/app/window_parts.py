"""What the window's parts (its actions and menus, the 3D dock) use of the main window.

They are given the window and reach its controllers through this protocol, so
they never import :mod:`.main_window`, which builds them (no import cycle).
:class:`~.main_window.MainWindow` satisfies it structurally.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from pathlib import Path

    from PySide6.QtCore import Qt
    from PySide6.QtGui import QAction
    from PySide6.QtWidgets import QDockWidget, QMenu, QMenuBar

    from ..tools.base import Tool
    from ..tools.settings import BrushSettings
    from ..viewport.canvas import TextureCanvas
    from .background import BackgroundFlatten
    from .files import FileController
    from .layer_commands import LayerCommands
    from .layers_panel import LayersPanel
    from .lighting import LightingController
    from .lighting_bar import LightingBar
    from .prompts import Prompts
    from .session import DocumentSession
    from .tool_host import EditorToolHost


class EditorWindow(Protocol):
    """The main window as its actions, menus and docks see it."""

    session: DocumentSession
    background: BackgroundFlatten
    files: FileController
    layer_commands: LayerCommands
    layers_panel: LayersPanel
    canvas: TextureCanvas
    host: EditorToolHost
    prompts: Prompts
    tools: dict[str, Tool]
    brush_settings: BrushSettings
    tool_dock: QDockWidget
    filter_menu: QMenu
    panels_menu: QMenu
    parameter_menu: QMenu
    recent_menu: QMenu
    lighting: LightingController
    lighting_bar: LightingBar

    # the window's commands
    def undo(self) -> None: ...
    def redo(self) -> None: ...
    def open_curves(self) -> object: ...
    def set_tool(self, name: str) -> None: ...
    def show_about(self) -> None: ...
    def show_message(self, text: str) -> None: ...
    def open_path(self, path: str | Path) -> bool: ...

    # QMainWindow's own, used to place actions and docks
    def addAction(self, action: QAction) -> None: ...  # noqa: N802 (Qt's names)
    def menuBar(self) -> QMenuBar: ...  # noqa: N802
    def close(self) -> bool: ...
    def addDockWidget(self, area: Qt.DockWidgetArea, dock: QDockWidget) -> None: ...  # noqa: N802
    def splitDockWidget(self, first: QDockWidget, second: QDockWidget, o: Any) -> None: ...  # noqa: N802
    def resizeDocks(self, docks: list[QDockWidget], sizes: list[int], o: Any) -> None: ...  # noqa: N802
