"""The history panel follows History's events: rows per step, dimmed undone steps,
dropped steps gone (by a step limit or by a new edit after undo), and the window's
modified flag from History's saved marker."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from matshop.app.testing import shown_window  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def shown(window) -> list[tuple[str, bool]]:
    panel = window.history_panel
    return list(zip(panel.labels(), panel.dimmed(), strict=True))


def in_step_with_history(window) -> None:
    """The panel's rows are the history's report, and its current row the applied steps."""
    report = window.session.history.report()
    first = "(older steps dropped)" if report.dropped_steps else "Open"
    assert window.history_panel.labels() == [first, *report.undo_labels, *report.redo_labels]
    assert window.history_panel.list.currentRow() == report.undo_steps


def test_history_panel_after_a_step_limit_drops_steps(window) -> None:
    assert window.open_path(SAMPLE)
    session, commands = window.session, window.layer_commands
    base = session.active_layer_id
    session.history.max_steps = 3
    commands.set_property(base, "opacity", 0.5)
    commands.set_property(base, "blend", "add")
    commands.set_property(base, "visible", False)
    assert shown(window) == [
        ("Open", False),
        ("Layer opacity", False),
        ("Blend mode", False),
        ("Layer visibility", False),
    ]
    commands.set_property(base, "name", "Ground")  # a fourth step: the oldest goes
    assert shown(window) == [
        ("(older steps dropped)", False),
        ("Blend mode", False),
        ("Layer visibility", False),
        ("Rename layer", False),
    ]
    in_step_with_history(window)

    session.undo()
    session.undo()
    assert shown(window) == [
        ("(older steps dropped)", False),
        ("Blend mode", False),
        ("Layer visibility", True),
        ("Rename layer", True),
    ]
    assert window.history_panel.list.currentRow() == 1
    in_step_with_history(window)

    name = session.doc.layer(base).name
    commands.set_property(base, "blend", "multiply")  # drops the two undone steps
    commands.set_property(base, "opacity", 0.25)
    commands.set_property(base, "visible", False)  # the limit drops "Blend mode" (add)
    assert shown(window) == [
        ("(older steps dropped)", False),
        ("Blend mode", False),
        ("Layer opacity", False),
        ("Layer visibility", False),
    ]
    in_step_with_history(window)
    layer = session.doc.layer(base)
    assert (layer.blend, layer.opacity, layer.visible, layer.name) == (
        "multiply",
        0.25,
        False,
        name,
    )

    # every step undone: the opened state is gone with the dropped steps, so still modified
    window.history_panel.list.setCurrentRow(0)
    assert session.steps == 0 and (layer.blend, layer.opacity, layer.visible) == ("add", 0.5, True)
    assert window.isWindowModified()
    in_step_with_history(window)


def test_merged_slider_steps_relabel_one_row_and_a_click_jumps(window) -> None:
    assert window.open_path(SAMPLE)
    session, commands = window.session, window.layer_commands
    base = session.active_layer_id
    session.seal()
    for value in (0.9, 0.8, 0.7):  # one drag: one row
        commands.set_property(base, "opacity", value, merge=True)
    session.seal()
    commands.set_property(base, "blend", "add")
    assert shown(window) == [("Open", False), ("Layer opacity", False), ("Blend mode", False)]
    window.history_panel.list.setCurrentRow(1)  # the user clicks the opacity row
    assert session.steps == 1 and session.doc.layer(base).blend == "normal"
    assert shown(window) == [("Open", False), ("Layer opacity", False), ("Blend mode", True)]
    window.history_panel.list.setCurrentRow(0)
    assert session.doc.layer(base).opacity == 1.0 and not window.isWindowModified()
    window.history_panel.list.setCurrentRow(2)
    assert session.doc.layer(base).blend == "add" and window.isWindowModified()
    in_step_with_history(window)
