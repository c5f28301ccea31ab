"""Which window actions are enabled, state by state, against a written table."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from matshop.app.testing import shown_window  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"

DOCUMENT = {
    "save",
    "save_as",
    "export",
    "close",
    "add_paint",
    "add_fill",
    "add_filter",
    "curves",
    "fit",
    "actual",
    "zoom_in",
    "zoom_out",
}
LAYER = {
    "delete",
    "duplicate",
    "group",
    "ungroup",
    "add_mask",
    "remove_mask",
    "invert_mask",
    "move_up",
    "move_down",
}
HISTORY = {"undo", "redo"}

#: state -> the enabled actions among DOCUMENT | LAYER | HISTORY (written by hand)
EXPECTED = {
    "nothing open": set(),
    "opened: the one base layer": DOCUMENT | {"duplicate", "group", "add_mask"},
    "a paint layer on top": DOCUMENT
    | {"delete", "duplicate", "group", "add_mask", "move_down", "undo"},
    "the base layer under it": DOCUMENT
    | {"delete", "duplicate", "group", "add_mask", "move_up", "undo"},
    "the paint layer with a mask": DOCUMENT
    | {"delete", "duplicate", "group", "remove_mask", "invert_mask", "move_down", "undo"},
    "the mask undone": DOCUMENT
    | {"delete", "duplicate", "group", "add_mask", "move_down", "undo", "redo"},
    "a group on top": DOCUMENT | {"delete", "group", "add_mask", "move_down", "undo"},
    "a member of the group": DOCUMENT
    | {"delete", "duplicate", "group", "ungroup", "add_mask", "move_up", "move_down", "undo"},
}


def enabled(window) -> set[str]:
    actions = window.actions_by_name
    return {name for name in DOCUMENT | LAYER | HISTORY if actions[name].isEnabled()}


def test_actions_enabled_state_by_state(qtbot, tmp_path) -> None:
    window = shown_window(qtbot, tmp_path)
    window.prompts.save_answer = "discard"
    session, commands = window.session, window.layer_commands
    seen = {"nothing open": enabled(window)}

    assert window.open_path(SAMPLE)
    base = session.active_layer_id
    seen["opened: the one base layer"] = enabled(window)

    paint = commands.add_paint_layer()
    seen["a paint layer on top"] = enabled(window)
    session.set_active_layer(base)
    seen["the base layer under it"] = enabled(window)

    session.set_active_layer(paint)
    commands.add_mask()
    seen["the paint layer with a mask"] = enabled(window)
    session.undo()
    seen["the mask undone"] = enabled(window)

    group = commands.group([paint])
    assert session.active_layer_id == group
    seen["a group on top"] = enabled(window)
    session.set_active_layer(paint)
    seen["a member of the group"] = enabled(window)

    assert seen == EXPECTED
    assert window.actions_by_name["undo"].text() == "&Undo Group layers"
