"""``Material.to_edit`` after numba ran first, as a ratio to matshop imported first.

    python benchmarks/import_order.py [--pairs N]

OpenMP reads its wait policy once, when numba first runs a parallel loop; a
script that does so before importing matshop used to get spinning workers
(to_edit 40-484 ms instead of 30 ms). Each pair runs two fresh processes on
the chessboard set, one per import order, alternately; each reports its
median of 7 to_edit calls (wall, and the process's CPU time: all threads, spinning
included). Goal (issue 16): the same speed, <= 1.25x, in wall time.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
from pathlib import Path

from _common import goal

CHILD = """
import sys, time, statistics
if sys.argv[1] == "numba-first":
    import numpy as np
    from numba import njit, prange

    @njit(parallel=True)
    def total(a):
        s = 0.0
        for i in prange(a.shape[0]):
            s += a[i]
        return s

    total(np.ones(1000))
import warnings
warnings.simplefilter("ignore")
import matshop  # noqa: F401
sys.path.insert(0, "benchmarks")
from _common import chessboard_material
material = chessboard_material()
material.to_edit()
times, cpu = [], []
for _ in range(7):
    start, start_cpu = time.perf_counter(), time.process_time()
    material.to_edit()
    times.append(time.perf_counter() - start)
    cpu.append(time.process_time() - start_cpu)
print(statistics.median(times), statistics.median(cpu))
"""


def child(order: str) -> tuple[float, float]:
    """(wall, CPU) seconds: medians of ``to_edit`` in a fresh process."""
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run(
        [sys.executable, "-c", CHILD, order], capture_output=True, text=True, cwd=root, check=True
    )
    wall, cpu = done.stdout.split()[-2:]
    return float(wall), float(cpu)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=5)
    args = parser.parse_args()
    ratios, cpu_ratios = [], []
    for _ in range(args.pairs):
        first = child("matshop-first")
        other = child("numba-first")
        ratios.append(other[0] / first[0])
        cpu_ratios.append(other[1] / first[1])
        print(
            f"to_edit median: matshop first {first[0] * 1e3:.0f} ms (CPU {first[1] * 1e3:.0f}),"
            f" numba first {other[0] * 1e3:.0f} ms (CPU {other[1] * 1e3:.0f})"
        )
    print(f"CPU time ratio: median {statistics.median(cpu_ratios):.2f}")
    goal("to_edit, numba started first / matshop first", ratios, 1.25)


if __name__ == "__main__":
    main()
