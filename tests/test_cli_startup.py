"""The command's start-up shortcuts (matshop.cli.startup): while a verb runs the cyclic
collector runs rarely, and the caller's thresholds come back afterwards, also when the
verb fails; a verb loads its kernels from numba's cache without setting numba's compiler
up (test_apply_imports: nor does it import scipy's BLAS or cffi for numba's probes),
writes the same bytes as the same verb run without these shortcuts, and numba still
compiles new kernels right afterwards (np.convolve, np.correlate, np.dot against numpy;
np.dot imports scipy's BLAS then)."""

from __future__ import annotations

import argparse
import contextlib
import gc
import subprocess
import sys
from pathlib import Path

import pytest

import matshop.cli.verbs.info as info
from matshop.cli import main
from matshop.kernel_cache import cached_kernels_without_compiler_set_up

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"

_APPLY = [
    "apply",
    "{sample}",
    "{out}",
    "--op",
    "blur",
    "sigma_px=1",
    "--op",
    "curves",
    "points=0,0;0.5,0.3;1,1",
]

_PROBE = """
import contextlib, io, sys
import numpy as np
from numba import njit
from numba.core import caching
from matshop.cli import build_parser, main

command = [w.format(sample=sys.argv[1], out=sys.argv[2]) for w in sys.argv[4:]]
with contextlib.redirect_stdout(io.StringIO()):
    if sys.argv[3] == "main":
        assert main(command) == 0
    else:  # the verb itself, without the command's start-up shortcuts
        args = build_parser(command).parse_args(command)
        assert args.run(args) == 0
# the compiler's set-up imports numba's implementation modules; a cached load does not
only_set_up_imports = ("numba.cpython.printimpl", "numba.np.polynomial.polynomial_core")
set_up = any(m in sys.modules for m in only_set_up_imports)
restored = not getattr(caching.Cache.load_overload, "lean", False)

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
print(set_up, restored, right, "scipy.linalg" in sys.modules)
"""


def _run_apply(how: str, out: Path) -> list[str]:
    command = [sys.executable, "-c", _PROBE, str(SAMPLE), str(out), how, *_APPLY]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600, check=True)
    return done.stdout.split()


def test_a_verb_loads_cached_kernels_without_the_compiler_and_writes_the_same_bytes(
    tmp_path: Path,
) -> None:
    # the bare verb first: it fills numba's cache, should a kernel not be in it yet.
    # Each run prints: compiler set up, numba's loader restored, a new kernel's answers
    # right, scipy's BLAS imported once np.dot was compiled
    assert _run_apply("verb", tmp_path / "plain") == ["True", "True", "True", "True"]
    assert _run_apply("main", tmp_path / "lean") == ["False", "True", "True", "True"]
    plain = sorted((tmp_path / "plain").iterdir())
    lean = sorted((tmp_path / "lean").iterdir())
    assert [p.name for p in plain] == [p.name for p in lean] and len(plain) == 5
    for a, b in zip(plain, lean, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name


class _FailingCache:
    """What a cache load that breaks half way looks like to the shortcut."""

    @contextlib.contextmanager
    def _guard_against_spurious_io_errors(self):
        yield

    def _load_overload(self, sig, target_context):
        raise RuntimeError("a registry this load did not install")


def test_a_load_that_fails_without_the_set_up_is_done_numbas_own_way(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from numba.core import caching

    calls = []
    monkeypatch.setattr(
        caching.Cache, "load_overload", lambda self, sig, ctx: calls.append(sig) or "loaded"
    )
    full = caching.Cache.load_overload
    with cached_kernels_without_compiler_set_up():
        lean = caching.Cache.load_overload
        assert lean is not full
        assert lean(_FailingCache(), "sig", object()) == "loaded"
    assert calls == ["sig"]
    assert caching.Cache.load_overload is full


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
