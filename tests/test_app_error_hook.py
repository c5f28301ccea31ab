"""The editor's one catch of escaped engine errors: a real window, a real action whose
slot raises, the status bar read back (truth: the error's own one-line text)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtGui import QAction  # noqa: E402

from matshop.app import error_hook  # noqa: E402
from matshop.app.testing import shown_window  # noqa: E402
from matshop.errors import InvalidValue  # noqa: E402


@pytest.fixture
def window_with_hook(qtbot, tmp_path):
    window = shown_window(qtbot, tmp_path)
    printed: list[BaseException] = []
    saved = sys.excepthook
    error_hook.install(window.show_message, previous=lambda kind, error, tb: printed.append(error))
    yield window, printed
    sys.excepthook = saved


def _trigger_raising(window, error: BaseException) -> None:
    def slot() -> None:
        raise error

    action = QAction("Raises", window)
    action.triggered.connect(slot)
    action.trigger()


@pytest.mark.qt_no_exception_capture
def test_an_escaped_engine_error_is_its_one_line_in_the_status_bar(window_with_hook) -> None:
    window, printed = window_with_hook
    error = InvalidValue("sigma_px=-3 is below 0", Path("look.toml"))
    _trigger_raising(window, error)
    assert window.statusBar().currentMessage() == "look.toml: sigma_px=-3 is below 0"
    assert printed == []  # no traceback for a user's bad value


@pytest.mark.qt_no_exception_capture
def test_any_other_exception_is_printed_and_said_to_be_internal(window_with_hook) -> None:
    window, printed = window_with_hook
    error = ZeroDivisionError("division by zero")
    _trigger_raising(window, error)
    assert printed == [error]
    message = window.statusBar().currentMessage()
    assert message.startswith("Internal error: ZeroDivisionError: division by zero")
