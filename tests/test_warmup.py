"""``matshop warm-up`` and its stamp: how the editor tells a warm numba cache from a cold one.

numba keys a cached kernel by its source file's modification time and size, the
argument types and the CPU; the stamp records the same facts, so it must read stale
exactly when one of them changes. Checked against edits made here: a kernel module's
recorded mtime or size moved, another CPU, another numba, a stamp from nowhere. The
end-to-end truth (after a warm-up from an empty cache the editor compiles nothing) is
``tests/test_first_use.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from matshop import warmup
from matshop.cli import main
from matshop.warmup import stamp as stamp_module


@pytest.fixture
def stamp(tmp_path, monkeypatch) -> Path:
    """A stamp written now for the kernels this process has loaded, in a private place."""
    from matshop.io.images import write_image
    from matshop.spaces import get_space

    # a few kernel modules in this process (the real warm-up loads them all)
    get_space("srgb").to_edit(np.full((4, 4, 3), 0.5, np.float32))
    write_image(tmp_path / "x.png", np.zeros((4, 4, 3), np.float32))
    path = tmp_path / "cache" / warmup.STAMP_NAME
    monkeypatch.setattr(stamp_module, "stamp_path", lambda: path)
    warmup.write_stamp()
    return path


def _edit(path: Path, change) -> None:
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


def test_a_fresh_stamp_is_warm_and_lists_the_kernel_modules(stamp: Path) -> None:
    assert warmup.is_warm()
    sources = json.loads(stamp.read_text())["sources"]
    names = {Path(f).name for f in sources}
    assert {"_kernels.py", "_codes.py"} <= names, names
    for file, (mtime, size) in sources.items():
        assert Path(file).stat().st_size == size and Path(file).stat().st_mtime == mtime


@pytest.mark.parametrize(
    "change",
    [
        lambda d: next(iter(d["sources"].values())).__setitem__(0, 0.0),  # source edited
        lambda d: next(iter(d["sources"].values())).__setitem__(1, -1),  # size changed
        lambda d: d.__setitem__("cpu", "another-cpu"),
        lambda d: d.__setitem__("features", "+nothing"),
        lambda d: d.__setitem__("numba", "0.0.1"),
        lambda d: d.__setitem__("sources", {}),
        lambda d: d["sources"].__setitem__("/no/such/kernel.py", [0.0, 1]),
    ],
    ids=["mtime", "size", "cpu", "features", "numba", "no sources", "gone"],
)
def test_a_stamp_goes_cold_when_what_numba_keys_on_changes(stamp: Path, change) -> None:
    _edit(stamp, change)
    assert not warmup.is_warm()


def test_no_stamp_or_a_broken_one_reads_cold(stamp: Path) -> None:
    stamp.write_text("{not json")
    assert not warmup.is_warm()
    stamp.unlink()
    assert not warmup.is_warm()


def test_warm_up_if_cold_does_nothing_on_a_warm_cache(warm_kernels, capsys) -> None:
    # the session fixture ran ``matshop warm-up --if-cold`` in a child, on the real cache
    assert warmup.is_warm()
    assert main(["warm-up", "--if-cold"]) == 0
    assert "already compiled" in capsys.readouterr().out


def _imported_from(module: str, cwd: Path) -> str:
    """How a fresh interpreter that may not write bytecode loaded ``module`` (``-v``'s line)."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("PYTHONPYCACHEPREFIX", None)
    done = subprocess.run(
        [sys.executable, "-v", "-c", f"import {module}"],
        capture_output=True, text=True, cwd=cwd, env=env, check=True,
    )  # fmt: skip
    stem = module.rsplit(".", 1)[-1]
    lines = [line for line in done.stderr.splitlines() if f"{stem}.py" in line and "#" in line]
    return "\n".join(lines)


def test_the_bytecode_written_is_what_python_imports(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "mod.py").write_text("VALUE = 42\n")
    # without it, a process that may not write bytecode compiles the source
    assert "code object from" in _imported_from("pkg.mod", tmp_path)
    assert warmup.compile_package(package)
    assert "matches" in _imported_from("pkg.mod", tmp_path)
    # an edited source makes the bytecode stale: Python compiles the source again
    (package / "mod.py").write_text("VALUE = 43  # edited\n")
    assert "code object from" in _imported_from("pkg.mod", tmp_path)


def test_a_warm_up_leaves_matshop_importing_its_bytecode(tmp_path: Path) -> None:
    assert warmup.compile_package()
    found = _imported_from("matshop.material", tmp_path)
    assert "matches" in found and "material.py" in found, found
