"""The engine packages never pull in Qt, OpenGL or pyqtgraph (DESIGN.md section 2)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

from matshop.cli.registry import VERBS

ENGINE_MODULES = [
    "matshop.spaces",
    "matshop.material",
    "matshop.io",
    "matshop.io.images",
    "matshop.io.textureset",
    "matshop.io.material_io",
    "matshop.ops",
    "matshop.layers",
    "matshop.paint",
    "matshop.render",
    "matshop.figures",
    "matshop.figures.edits",
    "matshop.derive",
    "matshop.batch",
    "matshop.cli",
    *(verb.module for verb in VERBS.values()),  # every verb's module, `open` included
]
FORBIDDEN = ("PySide6", "OpenGL", "pyqtgraph")

_PROBE = """
import sys
{imports}
from matshop.spaces import all_spaces
all_spaces()  # every family module, not just the package
leaked = sorted(m for m in {forbidden!r} if m in sys.modules)
print(",".join(leaked))
"""


def _leaked(modules: list[str]) -> list[str]:
    code = _PROBE.format(imports="\n".join(f"import {m}" for m in modules), forbidden=FORBIDDEN)
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    return [m for m in result.stdout.strip().split(",") if m]


def test_engine_imports_leave_qt_out() -> None:
    assert _leaked(ENGINE_MODULES) == []


@pytest.mark.skipif(importlib.util.find_spec("PySide6") is None, reason="PySide6 not installed")
def test_the_probe_would_see_qt_if_it_were_imported() -> None:
    # guards against a probe that can never fail
    assert _leaked(["PySide6.QtCore"]) == ["PySide6"]


def test_import_linter_contract_is_kept() -> None:
    """The pyproject contract, checked statically (catches imports that run lazily too)."""
    root = Path(__file__).resolve().parents[1]
    code = (
        "import sys; from importlinter.cli import lint_imports; "
        f"sys.exit(lint_imports(config_filename={str(root / 'pyproject.toml')!r}, no_cache=True))"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=root
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 kept, 0 broken" in result.stdout
