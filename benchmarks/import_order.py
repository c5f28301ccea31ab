"""``Material.to_edit`` after numba ran first, as a ratio to matshop imported first.

    python benchmarks/import_order.py [--pairs N]

OpenMP reads its wait policy once, when numba first runs a parallel loop; a
script that does so before importing matshop used to get spinning workers
(to_edit 40-484 ms instead of 30 ms). Each pair runs two fresh processes on
the chessboard set, one per import order, alternately; each reports its
median of 7 to_edit calls. Goal (issue 16): the same speed, <= 1.25x.
"""

from __future__ import annotations

import argparse
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
times = []
for _ in range(7):
    start = time.perf_counter()
    material.to_edit()
    times.append(time.perf_counter() - start)
print(statistics.median(times))
"""


def child(order: str) -> float:
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run(
        [sys.executable, "-c", CHILD, order], capture_output=True, text=True, cwd=root, check=True
    )
    return float(done.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=5)
    args = parser.parse_args()
    ratios = []
    for _ in range(args.pairs):
        first = child("matshop-first")
        other = child("numba-first")
        ratios.append(other / first)
        print(
            f"to_edit median: matshop first {first * 1e3:.0f} ms, numba first {other * 1e3:.0f} ms"
        )
    goal("to_edit, numba started first / matshop first", ratios, 1.25)


if __name__ == "__main__":
    main()
