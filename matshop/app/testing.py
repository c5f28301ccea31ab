"""Helpers for driving the editor from tests and scripts (the napari ``_testsupport`` idea).

:class:`ScriptedPrompts` answers every dialog from attributes and records
what was asked; :func:`make_window` builds a window with private settings;
:func:`drag` sends a real press-move-release sequence (QTest's mouseMove
carries no buttons, which sliders need).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from PySide6.QtCore import QEvent, QEventLoop, QPoint, QPointF, QSettings, Qt, QTimer
from PySide6.QtGui import QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication, QWidget

from ..io.textureset import TextureSet
from .export_dialog import ExportChoices, smaller_sizes
from .main_window import MainWindow
from .prompts import Prompts, SaveAnswer


class ScriptedPrompts(Prompts):
    """Dialogs answered by attributes; every question is appended to ``asked``."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)  # type: ignore[arg-type]
        self.asked: list[tuple[str, str]] = []
        self.save_answer: SaveAnswer = "discard"
        self.restore_answer = False
        self.save_path: Path | None = None
        self.open_path: Path | None = None
        self.mesh_path: Path | None = None
        self.image_path: Path | None = None
        #: the answer to "use this image as": picks from the labels offered (None: cancel)
        self.image_use: Callable[[list[str]], str | None] = lambda labels: None
        #: the answer to a height image's displacement in texels (given the default)
        self.height_px: Callable[[float], float | None] = lambda default: default
        self.recipe_path: Path | None = None
        #: the answer to View > Lighting > Open HDR/EXR… (None: cancel)
        self.environment_path: Path | None = None
        self.folder: Path | None = None
        self.preset: str | None = None
        #: the review of a texture set: returns the set to open (corrected) or None (cancel)
        self.texture_set_fix: Callable[[TextureSet], TextureSet | None] = lambda ts: ts
        #: which material of a folder holding several to open (None: cancel)
        self.material_answer: Callable[[list[str]], str | None] = lambda names: names[0]
        #: the answer to the list of files an export will write
        self.export_answer = True
        #: extras of the export dialog to check (e.g. {"usd"})
        self.export_extras: set[str] = set()
        #: the lines of the last export confirmation
        self.export_lines: list[str] = []
        #: the smaller size chosen in the export dialog (None: as it is)
        self.export_size: int | None = None
        #: the keep-variance box (None: left as the preset sets it)
        self.export_keep_variance: bool | None = None

    def error(self, title: str, text: str) -> None:
        self.asked.append(("error", text))

    def info(self, title: str, text: str) -> None:
        self.asked.append(("info", text))

    def ask_save_changes(self, name: str) -> SaveAnswer:
        self.asked.append(("save_changes", name))
        return self.save_answer

    def ask_restore(self, recovery: Path) -> bool:
        self.asked.append(("restore", str(recovery)))
        return self.restore_answer

    def review_texture_set(self, ts: TextureSet) -> TextureSet | None:
        self.asked.append(("texture_set", ts.name))
        return self.texture_set_fix(ts)

    def choose_material(self, folder: str, choices: list[str]) -> str | None:
        self.asked.append(("material", ", ".join(choices)))
        return self.material_answer(choices)

    def open_file(self, start: str = "") -> Path | None:
        self.asked.append(("open_file", start))
        return self.open_path

    def open_image(self, start: str = "") -> Path | None:
        self.asked.append(("open_image", start))
        return self.image_path

    def choose_image_use(self, name: str, choices: list[str]) -> str | None:
        self.asked.append(("image_use", f"{name}: " + " | ".join(choices)))
        return self.image_use(choices)

    def ask_height_px(self, name: str, default: float) -> float | None:
        self.asked.append(("height_px", f"{name}: {default:g}"))
        return self.height_px(default)

    def open_mesh(self, start: str = "") -> Path | None:
        self.asked.append(("open_mesh", start))
        return self.mesh_path

    def open_environment(self, start: str = "") -> Path | None:
        self.asked.append(("open_environment", start))
        return self.environment_path

    def open_recipe(self, start: str = "") -> Path | None:
        self.asked.append(("open_recipe", start))
        return self.recipe_path

    def open_folder(self, start: str = "") -> Path | None:
        self.asked.append(("open_folder", start))
        return self.folder

    def save_file(self, suggested: str) -> Path | None:
        self.asked.append(("save_file", suggested))
        return self.save_path

    def choose_preset(self, names: list[str]) -> str | None:
        self.asked.append(("preset", ",".join(names)))
        return self.preset if self.preset in names else (names[0] if names else None)

    def export_folder(self, start: str = "") -> Path | None:
        self.asked.append(("export_folder", start))
        return self.folder

    def confirm_export(
        self,
        lines: list[str],
        extras: dict[str, tuple[str, list[str]]] | None = None,
        *,
        size_hw: tuple[int, int] | None = None,
        keep_variance: bool = False,
    ) -> ExportChoices | None:
        extras = extras or {}
        chosen = {name: name in self.export_extras for name in extras}
        shown = [line for name, (_, more) in extras.items() if chosen[name] for line in more]
        self.asked.append(("export", "\n".join([*lines, *shown])))
        self.export_lines = [*lines, *shown]
        if not self.export_answer:
            return None
        size = self.export_size
        if size is not None and (size_hw is None or size not in smaller_sizes(size_hw)):
            raise AssertionError(f"the dialog offers no size {size} for {size_hw}")
        keep = keep_variance if self.export_keep_variance is None else self.export_keep_variance
        # as the dialog: the option applies only to a smaller size
        return ExportChoices(chosen, size, size is not None and keep)

    def kinds(self) -> list[str]:
        return [kind for kind, _ in self.asked]


def make_window(folder: Path, prompts: Prompts | None = None) -> MainWindow:
    """A window whose settings (autosave folder, swatch library) live in ``folder``."""
    settings = QSettings(str(folder / "settings.ini"), QSettings.Format.IniFormat)
    settings.setValue("recovery_dir", str(folder / "recovery"))
    settings.setValue("swatch_library", str(folder / "swatches.json"))
    window = MainWindow(settings=settings, prompts=prompts or ScriptedPrompts())
    if isinstance(window.prompts, ScriptedPrompts):
        window.prompts.parent = window
    return window


def shown_window(qtbot: Any, folder: Path, *, size: tuple[int, int] = (1560, 940)) -> MainWindow:
    """A themed window (settings in ``folder``) shown, exposed and active, closed after the test.

    Window shortcuts need the active window, under Xvfb too.
    """
    from PySide6.QtWidgets import QApplication

    from .theme import apply_theme

    apply_theme(QApplication.instance())
    window = make_window(folder)
    qtbot.addWidget(window)
    window.resize(*size)
    window.show()
    qtbot.waitExposed(window)
    window.activateWindow()
    return window


def spin(ms: int) -> None:
    """Run the event loop for ``ms`` milliseconds.

    A QEventLoop, not ``processEvents()``: in PySide6 6.12 every ``processEvents()``
    call drops a reference to None it does not own (see ``tests/conftest.py``).
    """
    loop = QEventLoop()
    QTimer.singleShot(ms, loop.quit)
    loop.exec()


def run_queue_wait_s() -> float:
    """Seconds the calling thread has spent runnable but waiting for a CPU (Linux
    ``/proc/thread-self/schedstat``; 0.0 where the kernel does not say)."""
    try:
        with open("/proc/thread-self/schedstat") as stats:
            return int(stats.read().split()[1]) * 1e-9
    except (OSError, ValueError, IndexError):
        return 0.0


class Heartbeat:
    """A 10 ms timer measuring event-loop stalls: wall and GUI-thread CPU time between ticks.

    The GUI thread's CPU time between two ticks is the work that blocked the loop;
    the wall gap adds whatever time the OS gave to other threads and processes.
    :attr:`own_gaps` is each wall gap less the time the GUI thread sat runnable waiting
    for a CPU: what this process itself kept the loop from (its work, and waits on the
    GIL or a lock), whatever the load of the machine.
    """

    def __init__(self) -> None:
        self.timer = QTimer()
        self.timer.setInterval(10)
        self.timer.timeout.connect(self._tick)
        self.wall_gaps: list[float] = []
        self.cpu_gaps: list[float] = []
        self.own_gaps: list[float] = []

    def _tick(self) -> None:
        wall, cpu, queued = time.perf_counter(), time.thread_time(), run_queue_wait_s()
        self.wall_gaps.append(wall - self._wall)
        self.cpu_gaps.append(cpu - self._cpu)
        self.own_gaps.append(wall - self._wall - (queued - self._queued))
        self._wall, self._cpu, self._queued = wall, cpu, queued

    def measure(
        self, action: Callable[[], object], settle: Callable[[], bool], timeout_s: float = 60.0
    ) -> tuple[object, float, float]:
        """Run ``action``, then the event loop until ``settle()``.

        Returns ``(action's result, longest wall gap, longest GUI-thread CPU gap)`` in
        seconds; :attr:`own_stall` is the longest of :attr:`own_gaps`.
        """
        self.wall_gaps, self.cpu_gaps, self.own_gaps = [], [], []
        self._wall, self._cpu = time.perf_counter(), time.thread_time()
        self._queued = run_queue_wait_s()
        self.timer.start()
        result = action()
        end = time.perf_counter() + timeout_s
        while not settle() and time.perf_counter() < end:
            spin(5)
        self.timer.stop()
        self._tick()
        return result, max(self.wall_gaps), max(self.cpu_gaps)

    @property
    def own_stall(self) -> float:
        """The longest gap this process caused (see the class doc), seconds."""
        return max(self.own_gaps, default=0.0)

    def idle(self, seconds: float) -> float:
        """The longest wall gap with nothing to do for ``seconds`` (the machine's own noise)."""
        end = time.perf_counter() + seconds
        _, wall, _ = self.measure(lambda: None, lambda: time.perf_counter() > end)
        return wall


def _mouse(
    widget: QWidget,
    kind: QEvent.Type,
    pos: QPointF,
    button: Qt.MouseButton,
    buttons: Qt.MouseButton,
    modifiers: Qt.KeyboardModifier,
) -> None:
    global_pos = QPointF(widget.mapToGlobal(pos.toPoint()))
    event = QMouseEvent(kind, pos, global_pos, button, buttons, modifiers)
    QApplication.sendEvent(widget, event)


def drag(
    widget: QWidget,
    points: Sequence[QPointF | QPoint | tuple[float, float]],
    *,
    button: Qt.MouseButton = Qt.MouseButton.LeftButton,
    modifiers: Qt.KeyboardModifier = Qt.KeyboardModifier.NoModifier,
    pause_ms: int = 0,
) -> None:
    """Press at the first point, move through the others with the button held, release.

    ``pause_ms`` waits between events (pyqtgraph drops moves closer than 10 ms apart).
    """
    pts = [QPointF(*p) if isinstance(p, tuple) else QPointF(p) for p in points]
    none = Qt.MouseButton.NoButton
    _mouse(widget, QEvent.Type.MouseButtonPress, pts[0], button, button, modifiers)
    for point in pts[1:]:
        if pause_ms:
            QTest.qWait(pause_ms)
        _mouse(widget, QEvent.Type.MouseMove, point, none, button, modifiers)
    _mouse(widget, QEvent.Type.MouseButtonRelease, pts[-1], button, none, modifiers)


def click(
    widget: QWidget,
    point: QPointF | tuple[float, float],
    *,
    modifiers: Qt.KeyboardModifier = Qt.KeyboardModifier.NoModifier,
) -> None:
    drag(widget, [point], modifiers=modifiers)
