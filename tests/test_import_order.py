"""Thread settings do not depend on whether numba ran before matshop was imported.

OpenMP fixes its wait policy when numba first runs a parallel loop; matshop
sets it passive only if it gets there first. A script that ran numba first
gets a warning and single-threaded kernels in that thread instead of spinning
workers; the normal order keeps every thread. Fresh interpreters, real imports.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = """
import sys, warnings
warnings.simplefilter("always")
if sys.argv[1] == "numba-first":
    import numpy as np
    from numba import njit, prange

    @njit(parallel=True)
    def fill(a):
        for i in prange(a.shape[0]):
            a[i] = 1.0

    fill(np.zeros(100))
with warnings.catch_warnings(record=True) as caught:
    import matshop  # noqa: F401
import numba
print(numba.get_num_threads(), numba.config.NUMBA_NUM_THREADS, len(caught))
"""


def run(order: str, **env: str) -> tuple[int, int, int]:
    environ = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"} | env
    environ["PYTHONPATH"] = str(ROOT)
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT, order],
        capture_output=True,
        text=True,
        env=environ,
        cwd=ROOT,
        check=True,
    )
    threads, default, warned = map(int, done.stdout.split())
    return threads, default, warned


def test_matshop_first_keeps_every_thread() -> None:
    threads, default, warned = run("matshop-first")
    assert threads == default and warned == 0


@pytest.mark.skipif(os.cpu_count() == 1, reason="one CPU: numba has one thread anyway")
def test_numba_first_without_a_passive_policy_runs_on_one_thread_and_says_so() -> None:
    threads, default, warned = run("numba-first")
    assert default > 1 and threads == 1 and warned == 1


def test_numba_first_with_a_passive_policy_keeps_every_thread() -> None:
    threads, default, warned = run("numba-first", OMP_WAIT_POLICY="passive")
    assert threads == default and warned == 0
