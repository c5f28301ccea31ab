"""The editor's first launch after an install: compile the kernels in a child process.

With numba's on-disk cache cold, the first stroke, open or HDR would compile its
kernels on the thread that needs them, and compiling holds the GIL, so the event loop
would stop for seconds whichever thread it is. ``matshop warm-up`` (:mod:`matshop.warmup`)
compiles them in another process instead, where the GIL is its own; the editor only
loads the machine code it leaves in the cache. The child runs this interpreter on this
package's sources with this environment (``NUMBA_CACHE_DIR`` included), since numba
keys its cache by source file, argument types and CPU. While it runs, a note in the
status bar says so; its end is one status line.

Loading machine code from the cache still takes half a second for the tip and stencil
sampling kernel, so a window loads it on a worker when it opens (:meth:`preload`), or
once the child is done; never while the cache is cold (that would compile it here,
holding the GIL for seconds).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from PySide6.QtCore import QProcess, QProcessEnvironment, QThreadPool, Signal
from PySide6.QtWidgets import QLabel

from .work import start_worker

#: the package's parent folder: the child imports these sources, not an installed copy
_SOURCES = str(Path(__file__).resolve().parents[2])


class KernelWarmUp(QLabel):
    """A status-bar note, hidden unless the warm-up child is running."""

    #: a one-line result for the status bar
    message = Signal(str)

    def __init__(self) -> None:
        super().__init__("Compiling image kernels for first use…")
        self.setObjectName("hint")
        self.setToolTip(
            "matshop compiles its image kernels once after an install, in the background; "
            "until it ends, a tool's first use may pause while it compiles"
        )
        self.process: QProcess | None = None
        self._began = 0.0
        self.hide()

    @property
    def running(self) -> bool:
        return self.process is not None

    def preload(self) -> bool:
        """Load the sampling kernel on a worker, if the cache holds it (see the module doc)."""
        from ..paint.sampling import warm_up
        from ..warmup import is_warm

        if self.running or not is_warm():
            return False
        start_worker(QThreadPool.globalInstance(), warm_up)
        return True

    def start_if_cold(self) -> bool:
        """Start ``matshop warm-up`` unless the cache is warm (or it already runs)."""
        from ..warmup import is_warm

        if self.running or is_warm():
            return False
        process = QProcess(self)
        env = QProcessEnvironment.systemEnvironment()
        path = env.value("PYTHONPATH")
        env.insert("PYTHONPATH", _SOURCES + (os.pathsep + path if path else ""))
        process.setProcessEnvironment(env)
        process.setProcessChannelMode(QProcess.ProcessChannelMode.MergedChannels)
        process.finished.connect(self._finished)
        process.errorOccurred.connect(self._failed_to_start)
        self.process, self._began = process, time.perf_counter()
        process.start(sys.executable, ["-m", "matshop", "warm-up", "--if-cold"])
        self.show()
        return True

    def _failed_to_start(self, error: QProcess.ProcessError) -> None:
        if error == QProcess.ProcessError.FailedToStart:
            self._end(False, f"could not start {sys.executable}")

    def _finished(self, code: int, status: QProcess.ExitStatus) -> None:
        assert self.process is not None
        output = bytes(self.process.readAll().data()).decode(errors="replace").strip()
        ok = code == 0 and status == QProcess.ExitStatus.NormalExit
        self._end(ok, output.splitlines()[-1] if output else f"exit status {code}")

    def _end(self, ok: bool, detail: str) -> None:
        if self.process is None:
            return
        self.process = None
        self.hide()
        seconds = time.perf_counter() - self._began
        if ok:
            self.preload()
            self.message.emit(f"Image kernels compiled ({seconds:.0f} s): tools start at once now")
        else:
            self.message.emit(
                f"Compiling the image kernels failed ({' '.join(detail.split())}); "
                "each tool compiles on its first use instead"
            )
