"""Run every benchmark script and print one table: goal, ratio, verdict (``make bench``).

    python benchmarks/table.py [--only NAME ...] [--timeout S]

Each script runs in its own process (numba's threads and caches start fresh)
and reports its goals as ``GOAL`` lines (``_common.goal``); scripts without a
goal are listed with how they ended. The ratio is the median of the script's
paired runs, with their spread; the load average is printed with the table
because these ratios move with it on a shared machine, and the CPU because they
move with that too (the compiled kernels' vector width: levels read 2.7-3.3 on an
Intel with AVX-512, 3.8-5.0 on an AMD EPYC with AVX2). The load average does not
see a virtual machine's neighbours: the ``steal`` column does, the share of the
time this machine's CPUs wanted to run while the script ran but the hypervisor
ran someone else (``/proc/stat``). Ratios taken under heavy steal say little
about the code: levels at 10 channels read 5.4 in a run with 54% stolen, 3.0 in
runs of the same code minutes before.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from _common import GOAL

HERE = Path(__file__).resolve().parent
NOT_BENCHMARKS = {"_common.py", "table.py"}


def run(script: Path, timeout: float) -> tuple[list[list[str]], str]:
    """The goal rows a script printed, and how it ended."""
    start = time.perf_counter()
    try:
        done = subprocess.run(
            [sys.executable, str(script)],
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=HERE.parent,
        )
    except subprocess.TimeoutExpired as stopped:
        out = stopped.stdout.decode() if isinstance(stopped.stdout, bytes) else stopped.stdout
        ended = f"stopped after {timeout:.0f} s"
    else:
        out = done.stdout
        ended = (
            "ok"
            if done.returncode == 0
            else f"exit {done.returncode}: " + (done.stderr.strip().splitlines() or ["?"])[-1]
        )
    rows = [line.split("\t")[1:] for line in (out or "").splitlines() if line.startswith(GOAL)]
    return rows, f"{ended}, {time.perf_counter() - start:.0f} s"


def cpu_ticks() -> tuple[int, int]:
    """(ticks the CPUs ran this machine's work, ticks stolen by the hypervisor), all CPUs."""
    try:
        with open("/proc/stat", encoding="utf-8") as stat:
            fields = [int(x) for x in stat.readline().split()[1:9]]
    except (OSError, ValueError):
        return 0, 0
    user, nice, system, _idle, _iowait, irq, softirq, steal = fields
    return user + nice + system + irq + softirq, steal


def steal_share(before: tuple[int, int], after: tuple[int, int]) -> str:
    """The stolen share of the time work wanted the CPUs between two :func:`cpu_ticks`."""
    ran, stolen = after[0] - before[0], after[1] - before[1]
    return f"{100.0 * stolen / (ran + stolen):.0f}%" if ran + stolen > 0 else "?"


def cpu() -> str:
    """The CPU's model, LLVM's name for it (what numba compiles for) and its widest vectors."""
    from llvmlite import binding

    model = "unknown model"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            model = next(
                line.split(":", 1)[1].strip() for line in info if line.startswith("model name")
            )
    except (OSError, StopIteration):
        pass
    features = binding.get_host_cpu_features()
    vectors = "AVX-512" if features.get("avx512f") else "AVX2" if features.get("avx2") else "SSE"
    return f"CPU {model} (LLVM {binding.get_host_cpu_name()}, {vectors})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", help="script names (without .py) to run")
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds per script")
    args = parser.parse_args()
    scripts = sorted(p for p in HERE.glob("*.py") if p.name not in NOT_BENCHMARKS)
    if args.only:
        scripts = [p for p in scripts if p.stem in args.only]
    load_before = os.getloadavg()
    table, ended = [], []
    for script in scripts:
        print(f"running {script.name} ...", file=sys.stderr, flush=True)
        ticks = cpu_ticks()
        rows, how = run(script, args.timeout)
        steal = steal_share(ticks, cpu_ticks())
        table += [(script.stem, *row, steal) for row in rows]
        ended.append(f"{script.name}: {len(rows)} goal(s), {how}")
    load_after = os.getloadavg()
    width = max([len(r[1]) for r in table] + [4])
    print(
        f"{'script':11s} {'goal':{width}s} {'ratio':>7s} {'spread':>15s} {'limit':>7s}"
        f"  {'verdict':8s} steal"
    )
    for script, name, median, low, high, limit, verdict, steal in table:
        spread = f"{float(low):.2f}-{float(high):.2f}"
        ratio = f"{float(median):7.2f}"
        print(
            f"{script:11s} {name:{width}s} {ratio} {spread:>15s} {limit:>7s}  {verdict:8s} {steal}"
        )
    met = sum(r[-2] == "met" for r in table)
    print(
        f"{met} of {len(table)} goals met; load average (1, 5, 15 min) "
        f"{' '.join(f'{x:.2f}' for x in load_before)} before, "
        f"{' '.join(f'{x:.2f}' for x in load_after)} after; {os.cpu_count()} CPUs"
    )
    print(cpu())
    for line in ended:
        print(f"  {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
