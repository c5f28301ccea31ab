"""The command's start-up shortcuts (matshop.cli.startup): while a verb runs the cyclic
collector runs rarely, and the caller's thresholds come back afterwards, also when the
verb fails; after `matshop apply` skipped numba's probes for scipy's BLAS and cffi,
compiled np.convolve, np.correlate and np.dot in the same process still give numpy's
answers (np.dot imports scipy's BLAS when it is compiled, as before)."""

from __future__ import annotations

import argparse
import gc
import subprocess
import sys
from pathlib import Path

import pytest

import matshop.cli.verbs.info as info
from matshop.cli import main

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"

_PROBE = """
import contextlib, io, sys
import numpy as np
from numba import njit
from matshop.cli import main

with contextlib.redirect_stdout(io.StringIO()):
    assert main(["apply", sys.argv[1], sys.argv[2], "--op", "blur", "sigma_px=1"]) == 0
skipped = "scipy.linalg" not in sys.modules and "cffi" not in sys.modules

@njit
def maths(a, b):
    return np.convolve(a, b), np.correlate(a, b), np.dot(a, b)

rng = np.random.default_rng(0)
a, b = rng.normal(size=50), rng.normal(size=50)
conv, corr, dot = maths(a, b)
right = (
    np.allclose(conv, np.convolve(a, b))
    and np.allclose(corr, np.correlate(a, b))
    and np.isclose(dot, np.dot(a, b))
)
print(skipped, right, "scipy.linalg" in sys.modules)
"""


def test_numba_still_right_after_the_blas_check_was_skipped(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, str(SAMPLE), str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    skipped, right, blas_later = done.stdout.split()
    assert skipped == "True" and right == "True" and blas_later == "True"


@pytest.mark.parametrize("target", [SAMPLE, SAMPLE / "absent"])
def test_a_verb_runs_with_rare_collections_and_restores_them(
    target: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = []
    real = info.run

    def run(args: argparse.Namespace) -> int:
        seen.append(gc.get_threshold())
        return real(args)

    monkeypatch.setattr(info, "run", run)
    before = gc.get_threshold()
    assert main(["info", str(target)]) == (0 if target.exists() else 2)
    assert seen[0][0] == 50_000 and seen[0][1:] == before[1:]
    assert gc.get_threshold() == before


_SETUP_PROBE = """
import sys, threading
import numpy as np
from matshop import jit_setup
from matshop.io.material_io import load_material

def setups():
    return [t for t in threading.enumerate() if t.name == "matshop-jit-setup"]

assert not jit_setup._started.is_set()
material, _ = load_material(sys.argv[1])
edit = material.to_edit()  # a kernel on this thread while the set-up may still run
started = jit_setup._started.is_set()
for thread in setups():
    thread.join(60)
jit_setup.start_in_background()  # once per process: no second thread
same_size = edit.data.shape[:2] == material.maps["base_color"].shape[:2]
print(started, len(setups()), same_size and bool(np.isfinite(edit.data).all()))
"""


def test_a_load_sets_numba_up_on_a_thread_once(tmp_path: Path) -> None:
    """In a fresh process the load's first kernel races numba's set-up on the thread
    ``load_material`` started; both finish and later calls start nothing."""
    done = subprocess.run(
        [sys.executable, "-c", _SETUP_PROBE, str(SAMPLE)],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    assert done.stdout.split() == ["True", "0", "True"]
