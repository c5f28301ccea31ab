"""`matshop apply` imports what the ops it runs need and nothing more: no Qt, no scipy.special
(its import costs ~0.3 s of CPU, a fifth of a whole blur run), no scipy.linalg nor cffi (numba's
probes for them, skipped by the command: matshop.cli.startup), not the document model nor the other
ops. A fresh interpreter runs the real command on the bundled sample and lists what was
imported when it exits."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"

_PROBE = """
import atexit, runpy, sys
out_list = sys.argv.pop(1)
def listed():
    with open(out_list, "w") as f:
        f.write("\\n".join(sorted(sys.modules)))
atexit.register(listed)
runpy.run_module("matshop", run_name="__main__", alter_sys=True)
"""

NEVER_FOR_A_BLUR = (
    "PySide6",
    "pyqtgraph",
    "scipy.special",
    "scipy.linalg",
    "cffi",
    "scipy.ndimage",
    "scipy.spatial",
    "scipy.interpolate",
    "matshop.layers",
    "matshop.ops.bilateral",
    "matshop.ops.clone",
    "matshop.ops.curves",
)


def _apply(tmp_path: Path, *op: str) -> set[str]:
    listing = tmp_path / "modules.txt"
    command = [sys.executable, "-c", _PROBE, str(listing), "apply", str(SAMPLE)]
    command += [str(tmp_path / "out"), "--op", *op]
    subprocess.run(command, capture_output=True, text=True, timeout=300, check=True)
    assert sorted(p.suffix for p in (tmp_path / "out").iterdir()) == [".png"] * 5
    return set(listing.read_text().split())


def test_a_blur_imports_none_of_the_rest(tmp_path: Path) -> None:
    modules = _apply(tmp_path, "blur", "sigma_px=2")
    assert "matshop.ops.blur" in modules and "cv2" in modules
    assert sorted(set(NEVER_FOR_A_BLUR) & modules) == []


def test_the_probe_sees_what_another_op_imports(tmp_path: Path) -> None:
    # guards against a probe that can never fail
    modules = _apply(tmp_path, "curves", "points=0,0;0.5,0.3;1,1")
    assert {"matshop.ops.curves", "scipy.interpolate"} <= modules
