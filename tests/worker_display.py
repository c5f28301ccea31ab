"""An X server of its own for each pytest-xdist worker.

Qt windows of two processes on one X display take the keyboard focus from each other, and
the editor tests activate their window and send it shortcuts (``shown_window``; the 3D
view's tests wait for ``isActiveWindow``): two workers on ``make test``'s one Xvfb would
race for it. So a worker of a run on several workers that was given a display starts an
Xvfb of its own (the screen ``make test`` asks for) and uses that; the server ends with
the worker.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import signal
import subprocess
import sys

SCREEN = "1280x1024x24"
_PR_SET_PDEATHSIG = 1


def _end_with_parent() -> None:
    # the server gets SIGTERM when the worker dies, however it dies (Linux only; elsewhere
    # the worker's own end, in conftest, stops it)
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


def start_own_display() -> subprocess.Popen | None:
    """Start this worker's Xvfb and point DISPLAY at it; None (nothing changed) outside a
    run on several workers, without a display, or without Xvfb."""
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    xvfb = shutil.which("Xvfb")
    if workers < 2 or not os.environ.get("DISPLAY") or xvfb is None:
        return None
    read, write = os.pipe()
    # -displayfd: the server picks a free display number and writes it to the pipe
    server = subprocess.Popen(
        [xvfb, "-displayfd", str(write), "-screen", "0", SCREEN, "-nolisten", "tcp"],
        pass_fds=(write,),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        preexec_fn=_end_with_parent,
    )
    os.close(write)
    with os.fdopen(read) as pipe:
        number = pipe.readline().strip()
    if not number.isdigit():
        server.kill()
        raise RuntimeError(f"Xvfb did not start (exit status {server.wait()})")
    os.environ["DISPLAY"] = f":{number}"
    return server
