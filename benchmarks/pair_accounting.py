"""Why a paired ratio was high: levels against the copy, pair by pair, with the
threads' own accounting.

    python benchmarks/pair_accounting.py [--pairs N] [--size 2048] [--show K]

The same pairs as ``curves.py``'s levels goals (a copy of the edit data, then
levels on it; 10 channels with the frame, and the base colour alone), each
pair timed alone. Around each pair it reads what the kernel says each thread
of this process did (``/proc/self/task/*/schedstat``: nanoseconds on a CPU,
nanoseconds waiting to get one; a running thread's count is brought up to date at
scheduling events, so it can lag by a tick) and the CPUs' stolen ticks
(``/proc/stat``).
It prints the ratios' median, 90th percentile and maximum, then the ``--show``
highest pairs and some typical ones. A high pair whose threads ran the whole
call with no wait and no steal was not short of a core: the cores ran slower
(session 15 found the levels call 1.45x slower in stretches while the copy was
not). No goal: a diagnosis for the tables' outliers (Linux only).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np
from _common import real_set
from curves import LEVELS, cases

from matshop.material import Schema
from matshop.ops.curves import levels


def stolen_ticks() -> list[int]:
    """Per CPU, the ticks the hypervisor gave to others (``/proc/stat``'s 8th field)."""
    with open("/proc/stat") as stat:
        return [int(line.split()[8]) for line in stat if line[:3] == "cpu" and line[3] != " "]


def thread_times() -> dict[str, tuple[int, int]]:
    """Per thread of this process: (ns on a CPU, ns waiting in a run queue)."""
    times = {}
    for tid in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{tid}/schedstat") as stat:
                ran, waited, _ = stat.read().split()
        except OSError:  # the thread ended
            continue
        times[tid] = (int(ran), int(waited))
    return times


def pairs(data: np.ndarray, schema: Schema, count: int) -> list[dict]:
    copy = np.empty_like(data)

    def run_levels() -> None:
        levels(data, schema=schema, **LEVELS)

    run_levels()
    rows = []
    for _ in range(count):
        steal, threads = stolen_ticks(), thread_times()
        start = time.perf_counter()
        np.copyto(copy, data)
        copied = time.perf_counter()
        run_levels()
        done = time.perf_counter()
        after = thread_times()
        ran = sorted((after[t][0] - threads[t][0] for t in after if t in threads), reverse=True)
        waited = max(after[t][1] - threads[t][1] for t in after if t in threads)
        rows.append(
            {
                "ratio": (done - copied) / (copied - start),
                "copy_ms": (copied - start) * 1e3,
                "levels_ms": (done - copied) * 1e3,
                "ran_ms": [t / 1e6 for t in ran[:2]],
                "wait_ms": waited / 1e6,
                "stolen": [b - a for a, b in zip(steal, stolen_ticks(), strict=True)],
            }
        )
    return rows


def show(row: dict) -> str:
    ran = " ".join(f"{t:.1f}" for t in row["ran_ms"])
    return (
        f"  ratio {row['ratio']:.2f}  copy {row['copy_ms']:.1f} ms  levels {row['levels_ms']:.1f}"
        f" ms  two busiest threads ran {ran} ms (copy included)  longest run-queue wait"
        f" {row['wait_ms']:.2f} ms  stolen ticks {row['stolen']}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=150)
    parser.add_argument("--size", type=int, default=2048)
    parser.add_argument("--show", type=int, default=6)
    args = parser.parse_args()
    material, what = real_set(args.size)
    print(f"data: {what}")
    for label, data, schema in cases(material):
        by_ratio = sorted(pairs(data, schema, args.pairs), key=lambda row: row["ratio"])
        ratios = [row["ratio"] for row in by_ratio]
        print(
            f"levels, {label} / copy: median {statistics.median(ratios):.2f}, 90th percentile"
            f" {ratios[int(0.9 * len(ratios))]:.2f}, max {ratios[-1]:.2f} ({len(ratios)} pairs)"
        )
        print(" highest:")
        for row in by_ratio[::-1][: args.show]:
            print(show(row))
        print(" typical:")
        middle = len(by_ratio) // 2
        for row in by_ratio[middle : middle + min(3, args.show)]:
            print(show(row))


if __name__ == "__main__":
    main()
