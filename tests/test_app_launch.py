"""The editor runs its event loop inside matshop.kernel_cache's shortcut (a cached kernel's
first load on a worker no longer holds the GIL for numba's compiler set-up, which the
event loop would wait for) and gives numba its own loader back when the loop ends. A
fresh process runs the real launch with the event loop's start replaced by a probe."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("PySide6")

_PROBE = """
from PySide6.QtWidgets import QApplication
from numba.core import caching
from matshop.app import launch
from matshop.app.kernel_warm_up import KernelWarmUp

KernelWarmUp.start_if_cold = lambda self: False  # no warm-up child from a test
seen = []

def exec_(self):
    seen.append(getattr(caching.Cache.load_overload, "lean", False))
    return 0

QApplication.exec = exec_
status = launch.start(argv=["matshop"])
print(status, seen, getattr(caching.Cache.load_overload, "lean", False))
"""


def test_the_editor_loads_cached_kernels_without_the_compiler_while_it_runs(
    tmp_path: Path,
) -> None:
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "HOME": str(tmp_path)}
    env["XDG_CONFIG_HOME"] = str(tmp_path / "config")
    done = subprocess.run(
        [sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=300, env=env
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split("\n")[-2] == "0 [True] False"
