"""The editor's filter settings go through the op's bind: a setting that could never run
(levels' white point below its black point) is refused with a message and changes
nothing, the same rule ``matshop layer add`` and the Python API follow."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from matshop.app.testing import shown_window  # noqa: E402

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def test_a_filter_setting_that_could_never_run_is_refused_with_a_message(window) -> None:
    assert window.open_path(SAMPLE)
    commands, session = window.layer_commands, window.session
    layer_id = commands.add_filter_layer("levels", {"in_black": 0.2, "remap": "space"})
    steps, kept = session.steps, dict(session.doc.layer(layer_id).op_params)
    said: list[str] = []
    commands.message.connect(said.append)
    commands.set_property(layer_id, "op_params", {**kept, "in_black": 0.9, "in_white": 0.1})
    assert said and "in_white (0.1) must exceed in_black (0.9)" in said[-1]
    assert session.doc.layer(layer_id).op_params == kept and session.steps == steps
