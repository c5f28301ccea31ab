"""The window's actions (one QAction per command, shared by menus, toolbars and panels).

:func:`build_actions` makes them with their shortcuts; :func:`build_menus`
arranges them. Which are enabled is decided by one predicate per action in
:mod:`.action_rules`, applied by :meth:`MainWindow.update_actions`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QMenu

from .icons import icon
from .image_import import import_image
from .layer_commands import filter_ops

if TYPE_CHECKING:
    from .window_parts import EditorWindow


def _action(
    window: EditorWindow,
    text: str,
    slot: Callable[[], object],
    shortcut: str | QKeySequence.StandardKey | list[str] | None = None,
    *,
    icon_name: str | None = None,
    tip: str = "",
    checkable: bool = False,
) -> QAction:
    action = QAction(text, window)
    if isinstance(shortcut, list):
        action.setShortcuts([QKeySequence(s) for s in shortcut])
    elif shortcut is not None:
        action.setShortcut(QKeySequence(shortcut))
    if icon_name:
        action.setIcon(icon(icon_name))
    if tip or action.shortcut().toString():
        keys = action.shortcut().toString(QKeySequence.SequenceFormat.NativeText)
        action.setToolTip(
            f"{tip or text.replace('&', '').rstrip('.')}" + (f"  ({keys})" if keys else "")
        )
    action.setCheckable(checkable)
    action.triggered.connect(lambda _checked=False: slot())
    window.addAction(action)  # shortcuts work even while the menu bar is hidden
    return action


def build_actions(w: EditorWindow) -> dict[str, QAction]:
    files, layers, canvas = w.files, w.layer_commands, w.canvas
    a = {
        "open": _action(w, "&Open...", files.open_dialog, "Ctrl+O", icon_name="open"),
        "open_folder": _action(
            w, "Open Texture &Folder...", files.open_folder_dialog, "Ctrl+Shift+O"
        ),
        "save": _action(w, "&Save", files.save, "Ctrl+S", icon_name="save"),
        "save_as": _action(w, "Save &As...", files.save_as, "Ctrl+Shift+S"),
        "export": _action(w, "&Export...", files.export, "Ctrl+E", icon_name="export"),
        "close": _action(w, "&Close", files.close_document, "Ctrl+W"),
        "quit": _action(w, "&Quit", w.close, "Ctrl+Q"),
        "undo": _action(w, "&Undo", w.undo, "Ctrl+Z", icon_name="undo"),
        "redo": _action(w, "&Redo", w.redo, ["Ctrl+Shift+Z", "Ctrl+Y"], icon_name="redo"),
        "add_paint": _action(
            w, "New &Paint Layer", layers.add_paint_layer, "Ctrl+Shift+N", icon_name="paint_layer"
        ),
        "add_fill": _action(
            w,
            "New &Fill Layer (Swatch)",
            layers.add_fill_layer,
            icon_name="fill_layer",
            tip="New fill layer of the swatch, in the parameters it paints",
        ),
        "add_filter": _action(
            w,
            "New Filter &Layer",
            lambda: None,
            icon_name="filter_layer",
            tip="New filter layer (blur, curves, bilateral...)",
        ),
        "add_recipe": _action(
            w,
            "Add Layers from &Recipe...",
            lambda: layers.add_recipe_layers(w.prompts.open_recipe()),
            tip="The op chain of a matshop batch recipe (.toml) as filter layers",
        ),
        "import_image": _action(
            w,
            "Import &Image...",
            lambda: import_image(w),
            "Ctrl+Shift+I",
            tip="An image as a new paint layer's values (color, roughness, normals from a "
            "height...) or as the active layer's mask",
        ),
        "curves": _action(
            w,
            "&Curves...",
            w.open_curves,
            "Ctrl+M",
            tip="Add a curves filter layer (or edit the selected one) with a curve editor",
        ),
        "delete": _action(w, "&Delete Layer", layers.remove_active, icon_name="trash"),
        "duplicate": _action(
            w, "D&uplicate Layer", layers.duplicate_active, "Ctrl+J", icon_name="duplicate"
        ),
        "group": _action(
            w,
            "&Group Layers",
            lambda: layers.group(w.layers_panel.selected_ids() or [w.session.active_layer_id]),
            "Ctrl+G",
            icon_name="group_layer",
            tip="Put the selected layers in a new group",
        ),
        "ungroup": _action(w, "Move &Out of Group", layers.ungroup_active, "Ctrl+Shift+G"),
        "add_mask": _action(
            w,
            "Add &Mask",
            layers.add_mask,
            icon_name="mask",
            tip="Add a mask showing everything; click its thumbnail to paint it",
        ),
        "remove_mask": _action(w, "&Remove Mask", layers.remove_mask),
        "invert_mask": _action(w, "&Invert Mask", layers.invert_mask),
        "move_up": _action(
            w, "Move Layer &Up", lambda: layers.move_active(1), "Ctrl+]", icon_name="up"
        ),
        "move_down": _action(
            w, "Move Layer Dow&n", lambda: layers.move_active(-1), "Ctrl+[", icon_name="down"
        ),
        "fit": _action(w, "&Fit to Window", canvas.fit, "F", icon_name="fit"),
        "actual": _action(w, "&Actual Size (1:1)", canvas.actual_size, "1", icon_name="actual"),
        "zoom_in": _action(w, "Zoom &In", lambda: canvas.zoom_by(1.25), ["Ctrl++", "Ctrl+="]),
        "zoom_out": _action(w, "Zoom &Out", lambda: canvas.zoom_by(0.8), "Ctrl+-"),
        "size_down": _action(
            w, "Smaller Brush", lambda: w.brush_settings.scale_radius(1 / 1.25), "["
        ),
        "size_up": _action(w, "Bigger Brush", lambda: w.brush_settings.scale_radius(1.25), "]"),
        # checked state follows the brush settings (MainWindow._brush_changed)
        "mirror_x": _action(
            w,
            "Mirror &X (Left/Right)",
            lambda: w.brush_settings.set_mirror("x", not w.brush_settings.symmetry.x),
            "Shift+X",
            checkable=True,
            tip="Brush and eraser strokes also paint their mirror image across the vertical "
            "centre line",
        ),
        "mirror_y": _action(
            w,
            "Mirror &Y (Top/Bottom)",
            lambda: w.brush_settings.set_mirror("y", not w.brush_settings.symmetry.y),
            "Shift+Y",
            checkable=True,
            tip="Brush and eraser strokes also paint their mirror image across the horizontal "
            "centre line",
        ),
        "about": _action(w, "&About matshop", w.show_about),
        # toggled through the action's own signal (LitPreview listens to it)
        "lit": _action(
            w,
            "&Lit Preview",
            lambda: None,
            "L",
            tip="Show the material lit from a light (right-drag on the canvas moves it)",
            checkable=True,
        ),
        # the 3D view dock shows and hides with this action's checked state
        "view3d": _action(
            w,
            "&3D View",
            lambda: None,
            "F3",
            checkable=True,
            tip="Show the material on a mesh beside the canvas, and paint on it",
        ),
    }
    filters = QMenu("New Filter Layer", w)
    for name, label in filter_ops():
        item = filters.addAction(label)
        item.triggered.connect(lambda _=False, op=name: layers.add_filter_layer(op))
    a["add_filter"].setMenu(filters)
    w.filter_menu = filters

    group = QActionGroup(w)
    group.setExclusive(True)
    for tool in w.tools.values():
        action = _action(
            w,
            tool.label,
            lambda name=tool.name: w.set_tool(name),
            tool.shortcut,
            icon_name=tool.name,
            tip=tool.tip,
            checkable=True,
        )
        group.addAction(action)
        a[f"tool_{tool.name}"] = action
    return a


def build_menus(w: EditorWindow, a: dict[str, QAction]) -> None:
    bar = w.menuBar()
    file_menu = bar.addMenu("&File")
    file_menu.addActions([a["open"], a["open_folder"]])
    w.recent_menu = file_menu.addMenu("Open &Recent")
    file_menu.addSeparator()
    file_menu.addActions([a["save"], a["save_as"], a["export"]])
    file_menu.addSeparator()
    file_menu.addActions([a["close"], a["quit"]])

    edit_menu = bar.addMenu("&Edit")
    edit_menu.addActions([a["undo"], a["redo"]])

    layer_menu = bar.addMenu("&Layer")
    layer_menu.addActions([a["add_paint"], a["add_fill"]])
    layer_menu.addMenu(w.filter_menu)
    layer_menu.addActions([a["curves"], a["add_recipe"], a["import_image"]])
    layer_menu.addSeparator()
    layer_menu.addActions([a["duplicate"], a["group"], a["ungroup"]])
    layer_menu.addSeparator()
    layer_menu.addActions([a["add_mask"], a["invert_mask"], a["remove_mask"]])
    layer_menu.addSeparator()
    layer_menu.addActions([a["move_up"], a["move_down"], a["delete"]])

    view_menu = bar.addMenu("&View")
    view_menu.addActions([a["fit"], a["actual"], a["zoom_in"], a["zoom_out"]])
    view_menu.addSeparator()
    view_menu.addAction(a["view3d"])
    view_menu.addAction(a["lit"])
    view_menu.addMenu(w.lighting_bar.menu)
    w.parameter_menu = view_menu.addMenu("&Parameter")
    w.panels_menu = view_menu.addMenu("P&anels")

    tools_menu = bar.addMenu("&Tools")
    tools_menu.addActions([a[f"tool_{name}"] for name in w.tools])
    tools_menu.addSeparator()
    tools_menu.addActions([a["size_down"], a["size_up"]])
    tools_menu.addSeparator()
    tools_menu.addActions([a["mirror_x"], a["mirror_y"]])

    help_menu = bar.addMenu("&Help")
    help_menu.addAction(a["about"])
