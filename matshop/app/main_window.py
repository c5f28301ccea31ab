"""The main window: canvas in the middle, tools on the left, layers and history on the right.

It wires the parts together and owns no document logic: the session holds
the document and history, the file controller opens and saves, the layer
commands and tools build edits. ``MainWindow(settings=..., prompts=...)``
takes replaceable settings and dialogs so tests run it headless.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from PySide6.QtCore import QSettings, QSize, Qt
from PySide6.QtGui import QCloseEvent, QDragEnterEvent, QDropEvent, QFont
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QLabel,
    QMainWindow,
    QScrollArea,
    QToolBar,
    QWidget,
)

from .. import __version__
from ..layers import Rect
from ..render.environment_choice import EnvironmentChoice
from ..tools.base import Tool
from ..tools.painting import TOOL_CLASSES
from ..tools.settings import BrushSettings, SwatchModel
from ..tools.swatch_library import SwatchLibrary
from ..tools.tool_panel import ToolPanel
from ..viewport.canvas import TextureCanvas
from ..viewport.display import display_mode, format_values
from .action_rules import ENABLED_WHEN
from .background import BackgroundFlatten
from .brush_images import choose_stencil, choose_tip
from .busy_indicator import BusyIndicator
from .curves_dialog import CurvesDialog
from .files import FileController
from .gui_gc import collect_on_gui_thread_while
from .history_panel import HistoryPanel
from .image_import import import_image, is_image
from .kernel_warm_up import KernelWarmUp
from .layer_commands import LayerCommands
from .layers_panel import LayersPanel
from .lighting import LightingController
from .lighting_bar import LightingBar
from .lit_preview import LitPreview
from .menus import build_actions, build_menus
from .prompts import Prompts
from .properties_panel import PropertiesPanel
from .session import DocumentSession
from .settings import AppSettings
from .tool_host import EditorToolHost
from .view3d import View3DDock


class MainWindow(QMainWindow):
    """The matshop editor window."""

    def __init__(self, settings: QSettings | None = None, prompts: Prompts | None = None) -> None:
        super().__init__()
        collect_on_gui_thread_while(self)
        self.setWindowTitle("matshop")
        self.setAcceptDrops(True)
        self.setDockOptions(
            QMainWindow.DockOption.AnimatedDocks | QMainWindow.DockOption.AllowTabbedDocks
        )
        self.app_settings = AppSettings(settings)
        self.prompts = prompts or Prompts(self)
        self.session = DocumentSession()
        # before anything that reads the flatten connects to the session
        self.background = BackgroundFlatten(self.session, tool_busy=self._tool_busy)
        self.brush_settings = BrushSettings()
        self.swatch_model = SwatchModel()
        self.layer_commands = LayerCommands(self.session, self.swatch_model.swatch)
        self.files = FileController(
            self.session, self.prompts, self.app_settings, self.editor_state, self._tool_busy
        )
        self.host = EditorToolHost(
            self.session,
            self.layer_commands,
            self.brush_settings,
            self.swatch_model,
            self.show_message,
            lambda: self.background.ready,
            stencil=lambda: self.canvas.texel_stencil(),
        )
        self.tools: dict[str, Tool] = {cls.name: cls(self.host) for cls in TOOL_CLASSES}
        self.curves_dialog: CurvesDialog | None = None
        self.canvas = TextureCanvas()
        # one lighting for the 3D view and the lit display (before the menus: View > Lighting)
        self.lighting = LightingController(self.app_settings)
        self.lighting_bar = LightingBar(self.lighting, self.prompts, self)
        self.actions_by_name = build_actions(self)
        build_menus(self, self.actions_by_name)
        self._build_central()
        self._build_docks()
        self.view3d = View3DDock(self, self.actions_by_name["view3d"])
        self.lit_preview = LitPreview(
            self.session,
            self.canvas,
            self.actions_by_name["lit"],
            lambda: self.background.ready,
            self._tool_busy,
        )
        self.lit_preview.message.connect(self.show_message)
        self.addToolBar(self.lighting_bar)
        self.lighting.message.connect(self.show_message)
        # the 3D view first: its upload on this thread is done before the lit display's
        # thread starts drawing with the new lighting on the same llvmpipe threads
        self.lighting.changed.connect(self.view3d.show_lighting)
        self.lighting.changed.connect(self.lit_preview.set_lighting)
        saved = self.app_settings.lighting()
        if saved is None or not self.lighting.restore(saved):
            self.lighting.choose(EnvironmentChoice())
        self._build_status()

        self.session.documentReplaced.connect(self._document_replaced)
        for signal in (
            self.session.historyChanged,
            self.session.activeLayerChanged,
            self.session.layersChanged,
        ):
            signal.connect(self.update_actions)
        self.session.modifiedChanged.connect(self._update_title)
        self.files.opened.connect(self.apply_editor_state)
        self.files.message.connect(self.show_message)
        self.files.recentChanged.connect(self._rebuild_recent)
        self.layer_commands.message.connect(self.show_message)
        self.brush_settings.changed.connect(self._brush_changed)
        self.session.targetChanged.connect(self._target_changed)
        self.canvas.cursorMoved.connect(self._cursor_moved)
        self.canvas.mirrorCentreDragged.connect(
            lambda x, y: self.brush_settings.set_mirror_centre((x, y))
        )
        self._cursor = (math.nan, math.nan)
        # values under a still cursor change when a stroke or an undo lands
        self.session.historyChanged.connect(lambda: self._cursor_moved(*self._cursor))
        self.canvas.viewChanged.connect(self._view_changed)
        self.background.busyChanged.connect(self._background_busy)
        self.background.progress.connect(self._background_progress)
        self.background.message.connect(self.show_message)
        self.busy_indicator.cancel.clicked.connect(self.background.cancel)
        for signal in (
            self.session.activeLayerChanged,
            self.session.layersChanged,
            self.session.targetChanged,
            self.session.historyChanged,
            self.swatch_model.changed,
            self.brush_settings.changed,  # the mirror toggles
            self.brush_settings.stencil.changed,  # "through the stencil"
        ):
            signal.connect(self.update_tool_action)

        self.set_tool("brush")
        self._rebuild_recent()
        self._document_replaced()
        self.resize(1560, 940)
        geometry, state = self.app_settings.geometry()
        if geometry is not None:
            self.restoreGeometry(geometry)
        if state is not None:
            self.restoreState(state)

    # -- layout ----------------------------------------------------------------

    def _build_central(self) -> None:
        tools = QToolBar("Tools")
        tools.setObjectName("tools")
        tools.setOrientation(Qt.Orientation.Vertical)
        tools.setMovable(False)
        tools.setIconSize(QSize(22, 22))
        for name in self.tools:
            tools.addAction(self.actions_by_name[f"tool_{name}"])
        self.addToolBar(Qt.ToolBarArea.LeftToolBarArea, tools)

        options = QToolBar("View")
        options.setObjectName("view")
        options.setMovable(False)
        options.setIconSize(QSize(18, 18))
        for name in ("open", "save", "undo", "redo"):
            options.addAction(self.actions_by_name[name])
        options.addSeparator()
        label = QLabel("  Parameter ")
        label.setObjectName("hint")
        options.addWidget(label)
        self.parameter_combo = QComboBox()
        self.parameter_combo.setMinimumWidth(170)
        self.parameter_combo.activated.connect(
            lambda index: self.show_parameter(self.parameter_combo.itemData(index))
        )
        options.addWidget(self.parameter_combo)
        options.addSeparator()
        for name in ("fit", "actual"):
            options.addAction(self.actions_by_name[name])
        self.zoom_label = QLabel("")
        self.zoom_label.setObjectName("hint")
        self.zoom_label.setMinimumWidth(56)
        options.addWidget(self.zoom_label)
        self.addToolBar(Qt.ToolBarArea.TopToolBarArea, options)
        self.setCentralWidget(self.canvas)

    def _dock(
        self, title: str, name: str, widget: QWidget, area: Qt.DockWidgetArea, scroll: bool = False
    ) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(name)
        dock.setFeatures(
            QDockWidget.DockWidgetFeature.DockWidgetMovable
            | QDockWidget.DockWidgetFeature.DockWidgetFloatable
            | QDockWidget.DockWidgetFeature.DockWidgetClosable
        )
        if scroll:
            area_widget = QScrollArea()
            area_widget.setWidgetResizable(True)
            area_widget.setWidget(widget)
            widget = area_widget
        dock.setWidget(widget)
        self.addDockWidget(area, dock)
        self.panels_menu.addAction(dock.toggleViewAction())
        return dock

    def _build_docks(self) -> None:
        right, left = Qt.DockWidgetArea.RightDockWidgetArea, Qt.DockWidgetArea.LeftDockWidgetArea
        self.swatch_library = SwatchLibrary(self.app_settings.swatch_library_path())
        self.tool_panel = ToolPanel(
            self.brush_settings, self.swatch_model, library=self.swatch_library
        )
        self.tool_panel.tip_panel.loadRequested.connect(lambda: choose_tip(self))
        self.tool_panel.stencil_panel.loadRequested.connect(lambda: choose_stencil(self))
        self.canvas.set_stencil(self.brush_settings.stencil)
        # compiled kernels loaded off the GUI thread, so the first dab does not wait for numba
        self.kernel_warm_up = KernelWarmUp()
        self.kernel_warm_up.message.connect(self.show_message)
        self.kernel_warm_up.preload()
        self.layers_panel = LayersPanel(self.session, self.layer_commands, self.actions_by_name)
        self.properties_panel = PropertiesPanel(self.session, self.layer_commands)
        self.history_panel = HistoryPanel(self.session)
        self.tool_dock = self._dock("Tool", "tool_dock", self.tool_panel, left, scroll=True)
        self.layers_dock = self._dock("Layers", "layers_dock", self.layers_panel, right)
        self.properties_dock = self._dock(
            "Properties", "properties_dock", self.properties_panel, right, scroll=True
        )
        self.history_dock = self._dock("History", "history_dock", self.history_panel, right)
        self.tabifyDockWidget(self.properties_dock, self.history_dock)
        self.properties_dock.raise_()
        self.resizeDocks([self.tool_dock], [self._tool_dock_width()], Qt.Orientation.Horizontal)
        self.resizeDocks([self.layers_dock], [310], Qt.Orientation.Horizontal)
        self.resizeDocks(
            [self.layers_dock, self.properties_dock], [520, 360], Qt.Orientation.Vertical
        )

    def _tool_dock_width(self) -> int:
        """Wide enough for the tool panel's widest row beside a vertical scroll bar: the
        panel scrolls up and down, never sideways (a cut-off row hides its right end)."""
        area = self.tool_dock.widget()
        assert isinstance(area, QScrollArea)
        scroll_bar = area.verticalScrollBar().sizeHint().width()
        panel = self.tool_panel.minimumSizeHint().width()
        return max(290, panel + scroll_bar + 2 * area.frameWidth())

    def _build_status(self) -> None:
        status = self.statusBar()
        mono = QFont("DejaVu Sans Mono")
        mono.setStyleHint(QFont.StyleHint.Monospace)
        self.texel_label = QLabel("")
        self.texel_label.setFont(mono)
        self.values_label = QLabel("")
        self.values_label.setFont(mono)
        self.busy_indicator = BusyIndicator()
        #: what pressing on the canvas will do with the current tool, layer and swatch
        self.tool_label = QLabel("")
        self.tool_label.setObjectName("hint")
        status.addPermanentWidget(self.tool_label)
        status.addPermanentWidget(self.values_label, 1)
        status.addPermanentWidget(self.busy_indicator)
        status.addPermanentWidget(self.kernel_warm_up)
        status.addPermanentWidget(self.texel_label)

    # -- state -------------------------------------------------------------------

    def open_path(self, path: str | Path) -> bool:
        """Open a texture set (folder or map) or a ``.matshop`` project."""
        return self.files.open_path(path)

    @property
    def tool(self) -> Tool:
        return self.canvas.tool  # type: ignore[return-value]

    def set_tool(self, name: str) -> None:
        if self.canvas.tool is not None:
            self.canvas.tool.cancel()
        tool = self.tools[name]
        self.canvas.tool = tool
        self.actions_by_name[f"tool_{name}"].setChecked(True)
        self.tool_panel.show_tool(
            tool.label, tool.tip, uses_brush=tool.uses_brush, uses_swatch=name == "brush"
        )
        self.canvas.update()
        self.update_tool_action()

    def update_tool_action(self, *_args) -> None:
        """The status bar says what the active tool will do (layer, mask, parameters)."""
        tool = self.canvas.tool
        self.tool_label.setText("" if tool is None else tool.action())

    def show_parameter(self, name: str) -> None:
        self.canvas.set_parameter(name)
        index = self.parameter_combo.findData(name)
        self.parameter_combo.setCurrentIndex(index)
        doc = self.session.doc
        if doc is not None:
            self.parameter_combo.setToolTip(display_mode(doc.schema[name]).note)
        for action in self.parameter_menu.actions():
            action.setChecked(action.data() == name)

    def undo(self) -> None:
        # never under a stroke in progress: its transaction owns the tiles it touches
        if not self._tool_busy():
            self.session.undo()

    def redo(self) -> None:
        if not self._tool_busy():
            self.session.redo()

    def open_curves(self) -> CurvesDialog | None:
        """The curves dialog on the active curves layer, or on a new one (window-modal)."""
        dialog = CurvesDialog(
            self.session, self.layer_commands, lambda: self.background.ready, parent=self
        )
        if not dialog.begin():
            dialog.deleteLater()
            return None
        dialog.resize(460, 520)
        dialog.open()
        self.curves_dialog = dialog
        return dialog

    def editor_state(self) -> dict[str, Any]:
        """What a project stores about the editor beside the document."""
        return {
            "active_layer": self.session.active_layer_id,
            "parameter": self.canvas.parameter,
            "brush": self.brush_settings.to_json(),
            "swatch": self.swatch_model.to_json(),
            "view3d_mirror": self.view3d.mirror_state(),
            "lighting": self.lighting.target().to_json(),
        }

    def apply_editor_state(self, state: dict[str, Any]) -> None:
        if "lighting" in state:  # a project of an older version has none: keep the current
            self.lighting.restore(state["lighting"])
        doc = self.session.doc
        if doc is None:
            return
        layer_id = state.get("active_layer")
        if isinstance(layer_id, int) and any(layer.id == layer_id for layer in doc.layers):
            self.session.set_active_layer(layer_id)
        if state.get("parameter") in doc.schema:
            self.show_parameter(state["parameter"])
        self.brush_settings.load_json(state.get("brush"))
        self.swatch_model.load_json(state.get("swatch"))
        self.view3d.load_mirror_state(state.get("view3d_mirror"))

    def _document_replaced(self) -> None:
        doc = self.session.doc
        self.canvas.set_document(doc)
        self.parameter_combo.clear()
        self.parameter_menu.clear()
        if doc is not None:
            self.swatch_model.reset(doc)  # before the editor shows its values
        self.tool_panel.swatch_editor.set_schema(None if doc is None else doc.schema)
        extent = (0, 0) if doc is None else (doc.width, doc.height)
        self.tool_panel.brush_panel.set_extent(*extent)
        if doc is not None:
            for number, param in enumerate(doc.schema.parameters, start=1):
                self.parameter_combo.addItem(param.label, param.name)
                action = self.parameter_menu.addAction(param.label)
                action.setData(param.name)
                action.setCheckable(True)
                if number <= 9:
                    action.setShortcut(f"Alt+{number}")
                action.triggered.connect(lambda _=False, n=param.name: self.show_parameter(n))
            self.show_parameter(doc.schema.names[0])
        self._update_title()
        self.update_actions()

    def _brush_changed(self) -> None:
        """The mirror toggles and lines follow the symmetry; the cursor ring, the size."""
        symmetry = self.brush_settings.symmetry
        self.actions_by_name["mirror_x"].setChecked(symmetry.x)
        self.actions_by_name["mirror_y"].setChecked(symmetry.y)
        self.canvas.set_symmetry(symmetry)
        self.canvas.update()

    def update_actions(self) -> None:
        """Enable what makes sense now (:data:`ENABLED_WHEN`); name the undo/redo steps."""
        a, doc, layer = self.actions_by_name, self.session.doc, self.session.active_layer
        for name, enabled in ENABLED_WHEN.items():
            a[name].setEnabled(enabled(doc, layer))
        self.parameter_combo.setEnabled(doc is not None)
        history = self.session.history
        undo = None if history is None else history.undo_label
        redo = None if history is None else history.redo_label
        a["undo"].setEnabled(undo is not None)
        a["redo"].setEnabled(redo is not None)
        a["undo"].setText("&Undo" if undo is None else f"&Undo {undo}")
        a["redo"].setText("&Redo" if redo is None else f"&Redo {redo}")

    def _update_title(self, *_args) -> None:
        title = self.session.title
        # Qt draws "[*]" as "*" while the window is modified
        self.setWindowTitle(f"{title}[*] — matshop" if title else "matshop")
        self.setWindowModified(self.session.modified)

    def _rebuild_recent(self) -> None:
        self.recent_menu.clear()
        recent = self.app_settings.recent_files()
        for path in recent:
            action = self.recent_menu.addAction(str(path))
            action.triggered.connect(lambda _=False, p=path: self.open_path(p))
        if recent:
            self.recent_menu.addSeparator()
            self.recent_menu.addAction("Clear Recent", self._clear_recent)
        self.recent_menu.setEnabled(bool(recent))

    def _clear_recent(self) -> None:
        self.app_settings.clear_recent()
        self._rebuild_recent()

    # -- status ------------------------------------------------------------------

    def show_message(self, text: str) -> None:
        self.statusBar().showMessage(text, 6000)

    def _cursor_moved(self, x: float, y: float) -> None:
        self._cursor = (x, y)
        doc = self.session.doc
        if doc is None or math.isnan(x):
            self.texel_label.setText("")
            self.values_label.setText("")
            return
        ix, iy = math.floor(x), math.floor(y)
        if not (0 <= ix < doc.width and 0 <= iy < doc.height):
            self.texel_label.setText("")
            self.values_label.setText("")
            return
        if not self.background.ready:  # reading now would compute the slow filter here
            self.texel_label.setText(f"x {ix:>5}  y {iy:>5}")
            self.values_label.setText("computing…")
            return
        rect = Rect(ix, iy, ix + 1, iy + 1)
        self.texel_label.setText(f"x {ix:>5}  y {iy:>5}")
        self.values_label.setText(format_values(doc.schema, doc.physical(rect, copy=False)))
        edit = doc.flatten_edit(rect, copy=False).reshape(-1)
        self.values_label.setToolTip("edit values: " + " ".join(f"{v:.3f}" for v in edit[:24]))

    def _target_changed(self, mask: bool) -> None:
        if mask:
            self.show_message("Painting the mask: the brush hides the layer, the eraser reveals it")
        else:
            self.show_message("Painting layer pixels")

    def _tool_busy(self) -> bool:
        view3d = getattr(self, "view3d", None)  # built after the background flatten
        return (self.canvas.tool is not None and self.canvas.tool.busy) or (
            view3d is not None and view3d.busy
        )

    def _background_busy(self, busy: bool) -> None:
        self.canvas.set_held("Computing…" if busy else None)
        if busy:
            self.busy_indicator.show_progress(self.background.label, 0.0)
        else:
            self.busy_indicator.hide()
            self._cursor_moved(*self._cursor)

    def _background_progress(self, what: str, seconds: float) -> None:
        self.busy_indicator.show_progress(what, seconds)
        self.canvas.set_held(f"Computing {what}… {seconds:.1f} s")

    def _view_changed(self) -> None:
        self.zoom_label.setText(f"{self.canvas.view.zoom * 100:.0f}%")

    def show_about(self) -> None:
        self.prompts.info(
            "About matshop",
            f"matshop {__version__}: a layer-based editor for spatially-varying materials, "
            "editing every parameter in its own editing space.",
        )

    # -- window events -----------------------------------------------------------

    def dragEnterEvent(self, event: QDragEnterEvent) -> None:  # noqa: N802 - Qt override
        if any(url.isLocalFile() for url in event.mimeData().urls()):
            event.acceptProposedAction()

    def dropEvent(self, event: QDropEvent) -> None:  # noqa: N802 - Qt override
        paths = [Path(url.toLocalFile()) for url in event.mimeData().urls() if url.isLocalFile()]
        if paths:
            event.acceptProposedAction()
            if self.session.doc is not None and is_image(paths[0]):
                import_image(self, paths[0], dropped=True)  # asks what to make of it
            else:
                self.open_path(paths[0])

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt override
        if not self.files.close_document():
            event.ignore()
            return
        self.app_settings.save_geometry(self.saveGeometry(), self.saveState())
        self.lit_preview.close()
        event.accept()
