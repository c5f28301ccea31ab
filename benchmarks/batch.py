"""Batch throughput: sets per second on a Dask LocalCluster against a serial loop, one run.

    python benchmarks/batch.py [--sets 8] [--workers 1 2] [--noop 200]

Data: ``--sets`` copies (symbolic links) of the shared 2K chessboard set, or a
synthetic 1K set when it is absent. Recipe: a cleanup an artist runs on a
library (blur normal and roughness by 2 px, an S-curve on base color), written
as raw maps. Baseline: the same task function over the same sets in a plain
loop in this process, after a warm-up. Each cluster is started and warmed
(one task per worker) before timing, so the rates are steady-state; the
start-up is printed on its own. Scheduler overhead: wall time per no-op task
over ``--noop`` tasks on the same cluster.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import CHESSBOARD

from matshop.batch import find_sets, load_recipe, run_batch
from matshop.batch.task import run_set

RECIPE = """
[[ops]]
op = "blur"
sigma_px = 2
params = ["normal", "roughness"]

[[ops]]
op = "curves"
points = "0,0;0.25,0.2;0.75,0.8;1,1"
params = ["base_color"]
"""


def make_library(root: Path, sets: int) -> str:
    if CHESSBOARD.is_dir():
        files, what = sorted(CHESSBOARD.iterdir()), "shared chessboard, 2K"
    else:
        from matshop.io.images import write_image

        rng = np.random.default_rng(0)
        src = root / "synthetic"
        src.mkdir(parents=True)
        for name, c in (("base_color", 3), ("roughness", 1), ("metallic", 1)):
            write_image(src / f"synthetic_{name}.png", rng.random((1024, 1024, c), np.float32))
        files, what = sorted(src.iterdir()), "synthetic 1K (chessboard absent)"
    for i in range(sets):
        folder = root / "library" / f"set{i:03d}"
        folder.mkdir(parents=True)
        for f in files:
            os.symlink(f.resolve(), folder / f.name)
    return what


def noop(x: int) -> int:
    return x


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=8)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--noop", type=int, default=200)
    args = parser.parse_args()
    from distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        what = make_library(root, args.sets)
        (root / "recipe.toml").write_text(RECIPE)
        recipe = load_recipe(root / "recipe.toml")
        jobs = find_sets([root / "library"])
        print(f"{len(jobs)} sets ({what}); {os.cpu_count()} cores on this machine")

        run_set(jobs[0], recipe, str(root / "warm"), force=True)
        start = time.perf_counter()
        for job in jobs:
            row = run_set(job, recipe, str(root / "serial"), force=True)
            assert row["status"] == "ok", row["error"]
        serial = time.perf_counter() - start
        serial_rate = len(jobs) / serial
        print(f"serial loop in this process: {serial_rate:6.3f} sets/s ({serial:.1f} s)")

        for n in args.workers:
            t0 = time.perf_counter()
            with (
                LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    host="127.0.0.1",
                    dashboard_address=None,
                    env={"NUMBA_NUM_THREADS": str(max(1, (os.cpu_count() or 1) // n))},
                ) as cluster,
                Client(cluster) as client,
            ):
                warm = [
                    client.submit(run_set, jobs[0], recipe, str(root / f"warm{n}"), force=True,
                                  workers=[w], pure=False)
                    for w in client.scheduler_info()["workers"]
                ]  # fmt: skip
                client.gather(warm)
                startup = time.perf_counter() - t0
                t1 = time.perf_counter()
                report = run_batch(
                    recipe, root / "library", root / f"out{n}", scheduler=cluster.scheduler_address
                )
                wall = time.perf_counter() - t1
                assert report.exit_status == 0, report.failed
                t2 = time.perf_counter()
                client.gather(client.map(noop, range(args.noop), pure=False))
                per_task = (time.perf_counter() - t2) / args.noop
            rate = len(jobs) / wall
            peak = max(r["peak_rss_mb"] for r in report.rows)
            print(
                f"batch, {n} worker(s):          {rate:6.3f} sets/s ({wall:.1f} s)  "
                f"ratio to serial {rate / serial_rate:5.2f} (ideal {n})  "
                f"cluster start+warm {startup:.1f} s  "
                f"scheduler {per_task * 1e3:.1f} ms/no-op task  peak worker RSS {peak:.0f} MB"
            )


if __name__ == "__main__":
    main()
