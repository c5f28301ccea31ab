"""Reads and writes on threads keep the sequential contracts: order, first failure,
nothing started after a stop, a bounded number in flight; fd 2 survives muting."""

from __future__ import annotations

import os
import threading
import time
from contextlib import closing
from pathlib import Path

import numpy as np
import pytest

from matshop.errors import MatshopError
from matshop.io import images
from matshop.io.material_io import load_material
from matshop.io.overlap import in_order

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


class Recorder:
    """Tasks that note when they start and how many run at once."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.started: list[int] = []
        self.running = 0
        self.most = 0

    def task(self, i: int, seconds: float = 0.02, fail: bool = False):
        def run() -> int:
            with self.lock:
                self.started.append(i)
                self.running += 1
                self.most = max(self.most, self.running)
            time.sleep(seconds)
            with self.lock:
                self.running -= 1
            if fail:
                raise ValueError(f"task {i}")
            return i

        return run


def test_results_in_order_at_most_window_at_once() -> None:
    rec = Recorder()
    # later tasks finish first: the order of results is still the order of tasks
    tasks = [rec.task(i, seconds=0.05 - 0.01 * i) for i in range(5)]
    assert list(in_order(tasks, window=2)) == [0, 1, 2, 3, 4]
    assert rec.most <= 2  # (that they do run at once: the barrier test below)


def test_tasks_really_run_at_once() -> None:
    barrier = threading.Barrier(2, timeout=10)  # broken (an error) if they ran one by one
    assert list(in_order([barrier.wait, barrier.wait], window=2)) in ([0, 1], [1, 0])


def test_the_first_failure_in_order_is_raised() -> None:
    rec = Recorder()
    tasks = [rec.task(0, 0.1), rec.task(1, 0.01, fail=True), rec.task(2, 0.0, fail=True)]
    with pytest.raises(ValueError, match="task 1"):
        list(in_order(tasks, window=2))


def test_stopping_starts_nothing_more() -> None:
    rec = Recorder()
    tasks = [rec.task(i) for i in range(6)]
    with closing(in_order(tasks, window=2)) as results:
        for result in results:
            if result == 1:
                break
    assert rec.running == 0  # closing waited for what was in flight
    # task 2 was handed to the pool when result 0 was taken (it may have been cancelled
    # before it began); task 3 would only have been handed over after result 1
    assert sorted(rec.started) in ([0, 1], [0, 1, 2])


def test_window_one_runs_in_the_callers_thread() -> None:
    seen = []
    tasks = [lambda: seen.append(threading.get_ident()) or len(seen) for _ in range(3)]
    assert list(in_order(tasks, window=1)) == [1, 2, 3]
    assert set(seen) == {threading.get_ident()}


def test_stderr_is_restored_after_reads_on_threads(tmp_path: Path) -> None:
    before = os.fstat(2)
    material, _ = load_material(SAMPLE)
    after = os.fstat(2)
    assert (after.st_dev, after.st_ino) == (before.st_dev, before.st_ino)
    assert images._silenced["count"] == 0
    assert len(material.schema.names) >= 4


def test_a_corrupt_map_among_several_is_named(tmp_path: Path) -> None:
    for path in SAMPLE.iterdir():
        (tmp_path / path.name).write_bytes(path.read_bytes())
    broken = tmp_path / "tiles_normal.png"
    broken.write_bytes(broken.read_bytes()[:200])  # header intact, pixels cut
    before = os.fstat(2)
    with pytest.raises(MatshopError) as err:
        load_material(tmp_path)
    assert err.value.path == str(broken) or "tiles_normal.png" in str(err.value)
    assert "\n" not in str(err.value)
    assert (os.fstat(2).st_ino, images._silenced["count"]) == (before.st_ino, 0)


def test_maps_read_on_threads_equal_maps_read_one_by_one() -> None:
    material, _ = load_material(SAMPLE)
    for name, array in material.maps.items():
        if name == "normal":
            continue  # decoded; the others are the files' own values
        source = Path(material.sources[name]["file"])
        pixels, _ = images.read_image(source)
        np.testing.assert_array_equal(array, pixels[..., : array.shape[2]])
