"""numpy's huge pages: the warm-up measures them, every matshop process follows the record.

The truth is the kernel's own account: ``AnonHugePages`` in ``/proc/self/smaps_rollup``
says how much of a fresh process's memory it backed with huge pages, after the
process filled a large numpy array.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from matshop import huge_pages
from matshop.cli import main

pytestmark = pytest.mark.skipif(
    not (huge_pages.huge_pages_possible() and Path("/proc/self/smaps_rollup").exists()),
    reason="this kernel gives no transparent huge pages",
)

_PROBE = """
import sys
if sys.argv[1] == "numpy first":
    import numpy, matshop
else:
    import matshop, numpy
filled = numpy.empty(64 << 20, numpy.uint8)
filled.fill(1)  # kept alive while the kernel is asked
with open("/proc/self/smaps_rollup") as status:
    print(next(int(line.split()[1]) for line in status if line.startswith("AnonHugePages")))
"""


def _huge_kb(cache: Path, order: str, **env: str) -> int:
    """Kilobytes of huge pages backing a fresh process that imported matshop and numpy in
    ``order`` and filled 64 MB, with ``cache`` as the user's cache folder."""
    base = {k: v for k, v in os.environ.items() if k != huge_pages.NUMPY_SWITCH}
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, order],
        env={**base, "XDG_CACHE_HOME": str(cache), **env},
        capture_output=True, text=True, check=True, timeout=120,
    )  # fmt: skip
    return int(done.stdout)


def _record(cache: Path, content: str) -> None:
    (cache / "matshop").mkdir(parents=True, exist_ok=True)
    (cache / "matshop" / huge_pages.RECORD_NAME).write_text(content)


@pytest.mark.parametrize("order", ["matshop first", "numpy first"])
def test_a_record_against_huge_pages_turns_them_off(tmp_path: Path, order: str) -> None:
    if _huge_kb(tmp_path, order) == 0:  # no record: numpy's default, huge pages
        pytest.skip("the kernel gave numpy no huge pages even unasked-against")
    _record(tmp_path, json.dumps({"use_huge_pages": False}))
    assert _huge_kb(tmp_path, order) == 0


def test_the_users_own_setting_and_a_broken_record_leave_numpy_alone(tmp_path: Path) -> None:
    _record(tmp_path, json.dumps({"use_huge_pages": False}))
    if _huge_kb(tmp_path, "matshop first", NUMPY_MADVISE_HUGEPAGE="1") == 0:
        pytest.skip("the kernel gave numpy no huge pages although asked")
    _record(tmp_path, "{not json")
    assert _huge_kb(tmp_path, "matshop first") > 0
    _record(tmp_path, json.dumps({"use_huge_pages": True}))
    assert _huge_kb(tmp_path, "matshop first") > 0


def test_a_followed_record_reaches_child_processes_but_not_a_baseline(tmp_path: Path) -> None:
    _record(tmp_path, json.dumps({"use_huge_pages": False}))
    probe = (
        "import os, matshop.huge_pages as h;"
        "print(os.environ.get(h.NUMPY_SWITCH), h.environment_without_choice().get(h.NUMPY_SWITCH))"
    )
    base = {k: v for k, v in os.environ.items() if k != huge_pages.NUMPY_SWITCH}
    done = subprocess.run(
        [sys.executable, "-c", probe],
        env={**base, "XDG_CACHE_HOME": str(tmp_path)},
        capture_output=True, text=True, check=True, timeout=60,
    )  # fmt: skip
    assert done.stdout.split() == ["0", "None"]


def test_warm_up_measures_once_and_records_what_it_measured(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # small and without the pauses: what is checked is the record, not this machine
    monkeypatch.setattr(huge_pages, "MEGABYTES", 16)
    monkeypatch.setattr(huge_pages, "SETTLE_S", 0.0)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    from matshop import warmup

    if not warmup.is_warm():
        pytest.skip("the kernel cache is cold: --if-cold would run the whole warm-up")
    assert main(["warm-up", "--if-cold"]) == 0
    out = capsys.readouterr().out
    record = json.loads((tmp_path / "matshop" / huge_pages.RECORD_NAME).read_text())
    assert record["megabytes"] == 16
    tries = huge_pages.TRIES
    assert len(record["huge_pages_s"]) == len(record["small_pages_s"]) == tries
    assert all(0 < seconds < 60 for seconds in record["huge_pages_s"] + record["small_pages_s"])
    slower = record["huge_pages_median_s"] > huge_pages.SLOWER_BY * record["small_pages_median_s"]
    assert record["use_huge_pages"] is not slower
    assert f"huge pages {record['huge_pages_median_s']:.2f} s" in out
    assert huge_pages.recorded_choice(tmp_path / "matshop" / huge_pages.RECORD_NAME) is (
        record["use_huge_pages"]
    )
    # a second --if-cold finds the record and measures nothing
    assert main(["warm-up", "--if-cold"]) == 0
    assert "memory:" not in capsys.readouterr().out


def test_a_measurement_that_fails_records_nothing_and_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 16 TB: the child's numpy refuses the allocation, as under a memory cap
    monkeypatch.setattr(huge_pages, "MEGABYTES", 1 << 24)
    monkeypatch.setattr(huge_pages, "SETTLE_S", 0.0)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    from matshop import warmup

    said: list[str] = []
    warmup.choose_huge_pages(said.append)
    assert len(said) == 1 and "could not measure" in said[0], said
    assert not (tmp_path / "matshop" / huge_pages.RECORD_NAME).exists()
