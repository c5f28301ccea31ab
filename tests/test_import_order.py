"""Thread settings do not depend on whether numba ran before matshop was imported.

OpenMP fixes its wait policy when numba first runs a parallel loop; matshop
sets it passive only if it gets there first. A script that ran numba first keeps
every thread (libgomp's default policy spins a few ms after each loop and then
sleeps, which the last test checks) and gets a warning; only workers told to spin
forever (OMP_WAIT_POLICY=ACTIVE) make matshop run its kernels on one thread.
Fresh interpreters, real imports.
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


def test_numba_first_with_the_default_policy_keeps_every_thread_and_says_so() -> None:
    threads, default, warned = run("numba-first")
    assert threads == default and warned == 1


@pytest.mark.skipif(os.cpu_count() == 1, reason="one CPU: numba has one thread anyway")
def test_numba_first_with_an_active_policy_runs_on_one_thread_and_says_so() -> None:
    threads, default, warned = run("numba-first", OMP_WAIT_POLICY="active")
    assert default > 1 and threads == 1 and warned == 1


def test_numba_first_with_a_passive_policy_keeps_every_thread() -> None:
    threads, default, warned = run("numba-first", OMP_WAIT_POLICY="passive")
    assert threads == default and warned == 0


IDLE = """
import time
import numba
import numpy as np
from numba import njit, prange

@njit(parallel=True)
def fill(a):
    for i in prange(a.shape[0]):
        a[i] = 1.0

for _ in range(4):
    fill(np.zeros(100_000))
start = time.process_time()
time.sleep(1.0)
print(numba.threading_layer(), time.process_time() - start)
"""


def idle_cpu_s(**env: str) -> float:
    """CPU seconds numba's process spends in the second after its last parallel loop
    (OpenMP's workers only: the test is skipped under another threading layer)."""
    environ = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"} | env
    done = subprocess.run(
        [sys.executable, "-c", IDLE], capture_output=True, text=True, env=environ, check=True
    )
    layer, cpu_s = done.stdout.split()[-2:]
    if layer != "omp":
        pytest.skip(f"numba's threading layer is {layer}, not OpenMP")
    return float(cpu_s)


@pytest.mark.skipif(os.cpu_count() == 1, reason="one CPU: numba starts no workers")
def test_default_policy_workers_sleep_soon_and_active_ones_spin() -> None:
    """Why numba-first keeps every thread: libgomp's default spins ~3 ms (measured 4 ms)
    after a loop, then sleeps; ACTIVE spins on (measured 286 ms of one idle second at
    load 10, a whole core on a quiet machine)."""
    assert idle_cpu_s() < 0.05
    assert idle_cpu_s(OMP_WAIT_POLICY="active") > 0.05
