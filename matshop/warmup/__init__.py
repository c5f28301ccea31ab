"""Compile numba's kernels ahead of first use (``matshop warm-up``; the editor at launch).

numba compiles a kernel the first time it meets a new signature and keeps the
machine code in its on-disk cache (``cache=True``). On a fresh install that cache
is empty, so the editor's first open, first stroke and first HDR compiled on the
thread that called: the GUI thread (measured from an empty cache: 28 kernels while the
sample opened, 2 more and 2.2 s of GUI-thread CPU in the first tip stroke), or a
worker, which holds the GIL while numba compiles and so froze the event loop as well.
Running the same kernels once in *another process* fills the cache; the editor then
only loads machine code.

How numba keys its cache decides how this is done. Each kernel has an index file
(next to its source, or under ``NUMBA_CACHE_DIR``) stamped with the source file's
modification time and size; its entries are keyed by the argument types and the
target CPU (name and features). So the warm-up

- runs the engine's public paths (read, convert, paint, filter, flatten, render,
  write) on small data instead of calling kernels directly: each kernel then meets
  the argument types (dtype, dimensions, layout) the editor gives it;
- runs in a child of the same interpreter, on the same source files, with the same
  environment (``NUMBA_CACHE_DIR``), on the same machine: the entries it writes are
  the ones the editor looks up.

:func:`write_stamp` records numba's version, the CPU and every kernel module's
(mtime, size) next to the cache; :func:`is_warm` compares, so the editor can tell a
warm cache from a cold or stale one without compiling anything.
"""

from __future__ import annotations

import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from .. import huge_pages
from .bytecode import compile_package
from .jobs import jobs
from .stamp import STAMP_NAME, compile_counts, is_warm, kernels, stamp_path, write_stamp

__all__ = [
    "STAMP_NAME",
    "choose_huge_pages",
    "compile_counts",
    "compile_package",
    "is_warm",
    "jobs",
    "kernels",
    "stamp_path",
    "warm_up",
    "write_stamp",
]


def warm_up(report: Callable[[str], None] = print) -> tuple[int, int]:
    """Compile the package's bytecode, measure the memory policy, run every job, then
    stamp the cache; returns (compiled, loaded) signature counts."""
    compile_package()
    choose_huge_pages(report)
    with tempfile.TemporaryDirectory(prefix="matshop-warm-up-") as scratch:
        for label, run in jobs(Path(scratch)):
            began = time.perf_counter()
            run()
            report(f"  {label}: {time.perf_counter() - began:.1f} s")
    write_stamp()
    return compile_counts()


def choose_huge_pages(report: Callable[[str], None] = print) -> None:
    """Measure whether numpy's huge pages make fresh memory slower here, and record it for
    every later matshop process (:mod:`matshop.huge_pages`)."""
    if not huge_pages.huge_pages_possible():
        report("  memory: this kernel gives no transparent huge pages; nothing to choose")
        return
    try:
        found = huge_pages.measure()
    except (OSError, subprocess.SubprocessError, ValueError) as exc:  # e.g. a memory cap
        report(f"  memory: could not measure first touches ({exc}); numpy's default kept")
        return
    huge_pages.record(found)
    verdict = "kept" if found["use_huge_pages"] else "turned off for matshop"
    report(
        f"  memory: first touch of {found['megabytes']} MB, median of"
        f" {len(found['huge_pages_s'])}: huge pages {found['huge_pages_median_s']:.2f} s,"
        f" 4 KB pages {found['small_pages_median_s']:.2f} s: numpy's huge pages {verdict}"
        f" ({huge_pages.record_path()})"
    )
