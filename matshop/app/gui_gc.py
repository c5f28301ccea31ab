"""Python's cyclic garbage collector runs on the GUI thread while an editor window is open.

Python collects reference cycles in whichever thread happens to allocate when
a generation's count passes its threshold; with the editor's workers loading
files and rendering, that is often a worker, and a cycle holding a Qt object
(a closed dialog, a widget and the lambda connected to it) is then destroyed
off the GUI thread, where Qt may crash the whole process (seen: a segfault in
the suite, "Garbage-collecting" on a file-loading worker). While a window is
open, automatic collection is off and pyqtgraph's ``GarbageCollector`` runs
the same generational collections from a timer on the GUI thread; when the
last window is gone, automatic collection is back. What lived before the
first window (modules, caches: most of the heap) is collected once and then
frozen out of the collector's scans, so the GUI thread's full collections
walk only what the editor made since (a long test session's heap made them
take a third of a second).
"""

from __future__ import annotations

import gc

from pyqtgraph.util.garbage_collector import GarbageCollector
from PySide6.QtCore import QObject

#: how often the GUI thread looks at the collector's counts
INTERVAL_S = 0.5

#: while windows are open: how many, the timer, and whether collection was automatic before
_state: dict = {"windows": 0, "collector": None, "was_enabled": True}


def collect_on_gui_thread_while(window: QObject) -> None:
    """Until ``window`` is destroyed, cycles are collected on the GUI thread only.

    Call on the GUI thread. Windows nest: automatic collection returns (if it
    was on) when the last one is destroyed.
    """
    if _state["windows"] == 0:
        _state["was_enabled"] = gc.isenabled()
        gc.collect()
        gc.freeze()
        _state["collector"] = GarbageCollector(interval=INTERVAL_S)  # disables automatic
    _state["windows"] += 1
    window.destroyed.connect(_release)


def _release() -> None:
    _state["windows"] -= 1
    if _state["windows"] == 0:
        _state["collector"].timer.stop()
        _state["collector"] = None
        gc.unfreeze()
        if _state["was_enabled"]:
            gc.enable()
