"""Whether numpy asks the kernel for huge pages: measured once per machine, then followed.

On Linux numpy marks every large array ``madvise(MADV_HUGEPAGE)``, so that where
transparent huge pages are on "madvise" the kernel backs it with 2 MB pages: 512
times fewer page faults, usually a faster first touch. Some virtual machines turn
that around: a guest whose balloon reports free memory to its host (Firecracker's
and QEMU's ``virtio_balloon`` free page reporting) gives back free 2 MB blocks, the
size of a huge page, and the host has to fault each one in again when the guest
hands it out. Measured on such a VM (2 vCPUs), filling 500 MB of new numpy memory
4 s after the last process ended took 3.7-5.0 s with huge pages and 0.25-0.39 s
with 4 KB pages (3 tries each); right after a process freed memory, which the guest
still holds, huge pages took 0.05-0.2 s, so back-to-back runs land anywhere
between. ``matshop apply`` on the 2K chessboard spent 0.50-0.60 s of system time
with 4 KB pages and 0.63-1.84 s with huge pages.

The other side of the choice: memory a process frees and takes again at once is
still backed, and there huge pages stay faster (filling 64 MB 20 times in a row in
one process: 10-13 ms each with huge pages, 48-50 ms with 4 KB pages), which shows
where a loop allocates large temporaries back to back (``benchmarks/clone.py``'s
first clone into a new array: 1.09x OpenCV with huge pages, 1.74x without; its goal
row, into the caller's buffer, 0.78x and 0.80x). A command starts cold, and memory
an editor frees between two actions has gone back to the host after the 2 s
reporting delay, so the cold first touch is what decides.

So :func:`measure` times both in fresh child processes after such a pause
(``matshop warm-up`` runs it and :func:`record` keeps the result in the user's cache
folder), and :func:`follow_recorded_choice`, which ``import matshop`` calls, turns
numpy's huge pages off in this process and the ones it starts where the record
says they were clearly slower. ``NUMPY_MADVISE_HUGEPAGE`` set by the user always
wins, and nothing is changed where no measurement was recorded.
"""

from __future__ import annotations

# the standard library only, and lazily: ``import matshop`` runs this module
import json
import os
import sys
from pathlib import Path
from typing import Any

#: numpy's own switch (read when numpy is imported); a user's setting is left alone
NUMPY_SWITCH = "NUMPY_MADVISE_HUGEPAGE"
#: the record's name in :func:`cache_folder`
RECORD_NAME = "huge-pages.json"
#: huge pages are turned off only when their median first touch is this much slower
SLOWER_BY = 1.5
#: how much fresh memory each try fills, and how many tries of each kind
MEGABYTES, TRIES = 256, 3
#: the pause before each try: longer than Linux's free page reporting delay (2 s), so
#: that what the previous try freed has gone back to the host as it would when idle
SETTLE_S = 2.5
#: whether this process set the switch (:func:`environment_without_choice`)
_set_here = False
_THP_SETTING = Path("/sys/kernel/mm/transparent_hugepage/enabled")

# a fresh process fills new numpy memory once and prints the seconds it took
_TOUCH = """
import sys, time
import numpy as np
size = int(sys.argv[1])
began = time.perf_counter()
np.empty(size, np.uint8).fill(1)
print(time.perf_counter() - began)
"""


def cache_folder() -> Path:
    """matshop's folder in the user's cache (``$XDG_CACHE_HOME/matshop``, else ``~/.cache``)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "matshop"


def record_path() -> Path:
    return cache_folder() / RECORD_NAME


def huge_pages_possible() -> bool:
    """Whether this kernel gives numpy huge pages when asked (transparent huge pages on
    "always" or "madvise")."""
    try:
        setting = _THP_SETTING.read_text(encoding="ascii")
    except OSError:
        return False
    return "[never]" not in setting


def _first_touch_seconds(size_bytes: int, huge: bool) -> float:
    import subprocess

    env = {**os.environ, NUMPY_SWITCH: "1" if huge else "0"}
    done = subprocess.run(
        [sys.executable, "-c", _TOUCH, str(size_bytes)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    return float(done.stdout.split()[-1])


def measure(
    megabytes: int | None = None, tries: int | None = None, settle_s: float | None = None
) -> dict[str, Any]:
    """First touch of ``megabytes`` of fresh memory with huge pages and with 4 KB pages.

    Each try is a fresh process (a process reuses the memory it freed, which is no
    longer fresh) started ``settle_s`` after the previous one ended; the two kinds
    alternate, so a slow moment of the machine falls on both. Returns the seconds of
    every try, their medians and the decision. Unset arguments take the module's
    :data:`MEGABYTES`, :data:`TRIES` and :data:`SETTLE_S`.
    """
    import statistics
    import time

    megabytes = MEGABYTES if megabytes is None else megabytes
    tries = TRIES if tries is None else tries
    settle_s = SETTLE_S if settle_s is None else settle_s
    huge, small = [], []
    for _ in range(tries):
        for kind in (huge, small):
            time.sleep(settle_s)
            kind.append(_first_touch_seconds(megabytes << 20, huge=kind is huge))
    huge_median, small_median = statistics.median(huge), statistics.median(small)
    return {
        "megabytes": megabytes,
        "huge_pages_s": huge,
        "small_pages_s": small,
        "huge_pages_median_s": huge_median,
        "small_pages_median_s": small_median,
        "use_huge_pages": huge_median <= SLOWER_BY * small_median,
    }


def record(measurement: dict[str, Any], path: Path | None = None) -> Path:
    """Keep ``measurement`` where :func:`follow_recorded_choice` finds it (written whole
    or not at all)."""
    path = record_path() if path is None else path
    path.parent.mkdir(parents=True, exist_ok=True)
    staging = path.with_name(f".{path.name}.{os.getpid()}")
    staging.write_text(json.dumps(measurement, indent=1), encoding="utf-8")
    os.replace(staging, path)
    return path


def recorded_choice(path: Path | None = None) -> bool | None:
    """The recorded decision (use huge pages or not); None when none was recorded or the
    record cannot be read."""
    try:
        with open(record_path() if path is None else path, encoding="utf-8") as file:
            choice = json.load(file).get("use_huge_pages")
    except (OSError, ValueError, AttributeError):
        return None
    return choice if isinstance(choice, bool) else None


def follow_recorded_choice() -> None:
    """Turn numpy's huge pages off where the recorded measurement found them clearly
    slower and the user did not set ``NUMPY_MADVISE_HUGEPAGE``.

    The switch is set in the environment, where numpy reads it when it is imported
    (``matshop --help`` imports no numpy) and the processes matshop starts inherit it
    (warm-up jobs, batch workers), as ``OMP_WAIT_POLICY`` is; a numpy imported
    already is switched with numpy's own setter, the one its import calls.
    """
    global _set_here
    if NUMPY_SWITCH in os.environ or recorded_choice() is not False:
        return
    os.environ[NUMPY_SWITCH] = "0"
    _set_here = True
    numpy = sys.modules.get("numpy")
    if numpy is None:
        return
    core = getattr(numpy, "_core", None) or numpy.core  # numpy 2 renamed numpy.core
    switch = getattr(core.multiarray, "_set_madvise_hugepage", None)
    if switch is not None:
        switch(False)


def environment_without_choice() -> dict[str, str]:
    """This process's environment as it was before :func:`follow_recorded_choice` set
    the switch: how a process outside matshop (a benchmark's baseline script) starts."""
    env = dict(os.environ)
    if _set_here:
        env.pop(NUMPY_SWITCH, None)
    return env
