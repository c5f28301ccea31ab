"""A fresh editor's first launch, open and tip stroke, run as its own process.

numba reads NUMBA_CACHE_DIR when it is imported, so a test that wants an empty cache
(a fresh install) runs this script in a child with that variable set. It starts the
real editor window, lets its launch step warm the kernels (``--launch``: the window's
warm-up child, as ``matshop open`` starts it), opens the bundled sample, picks the
Noise tip with random rotation at radius 200 in the panel and paints one stroke on the
canvas with a 10 ms heartbeat running. The last line of stdout is JSON: the longest
event-loop gap (wall, GUI-thread CPU), the kernels this process compiled during the
open and during the stroke, and the status lines the window showed.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

if not os.environ.get("DISPLAY"):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop import warmup  # noqa: E402
from matshop.app.testing import Heartbeat, drag, make_window, spin  # noqa: E402


def _compiled() -> set[str]:
    """The signatures numba compiled in this process so far, as ``kernel(types)``."""
    return {
        f"{name}{signature}"
        for name, kernel in warmup.kernels().items()
        for signature in kernel.stats.cache_misses
    }


def _new(before: set[str]) -> list[str]:
    return sorted(_compiled() - before)


def _pick(combo, data: str) -> None:
    """What choosing an entry with the keyboard does: set it, then the activated signal."""
    index = combo.findData(data)
    assert index >= 0, data
    combo.setCurrentIndex(index)
    combo.activated.emit(index)


def main(folder: Path, launch: bool) -> dict:
    app = QApplication.instance() or QApplication([])
    window = make_window(folder)
    window.resize(1560, 940)
    window.show()
    spin(200)
    messages: list[str] = []
    window.statusBar().messageChanged.connect(lambda text: text and messages.append(text))
    result: dict = {"launch_started": False, "note_shown": False}
    if launch:
        result["launch_started"] = window.kernel_warm_up.start_if_cold()
        spin(50)
        result["note_shown"] = window.kernel_warm_up.isVisible()
        end = time.perf_counter() + 900.0
        while window.kernel_warm_up.running and time.perf_counter() < end:
            spin(100)
    result["warm"] = warmup.is_warm()
    before = _compiled()
    assert window.open_path(ROOT / "resources" / "sample")
    window.canvas.actual_size()
    window.canvas.flush()
    spin(300)
    result["compiled_opening"] = _new(before)
    window.brush_settings.set("radius_px", 200.0)
    tip_panel = window.tool_panel.tip_panel
    _pick(tip_panel.kind, "noise")
    _pick(tip_panel.rotation, "random")
    points = [
        window.canvas.to_widget(60 + 400 * i / 11, 200 + 18 * math.sin(i / 2.0)) for i in range(12)
    ]
    before = _compiled()
    beat = Heartbeat()
    _, wall, cpu = beat.measure(lambda: drag(window.canvas, points, pause_ms=20), lambda: True)
    result.update(
        stroke_wall_s=wall,
        stroke_cpu_s=cpu,
        stroke_own_s=beat.own_stall,
        compiled_stroke=_new(before),
        painted=window.session.history.can_undo,
        messages=messages,
        load=os.getloadavg()[0],
    )
    window.prompts.save_answer = "discard"
    window.close()
    app.processEvents()
    return result


if __name__ == "__main__":
    print(json.dumps(main(Path(sys.argv[1]), "--launch" in sys.argv)))
