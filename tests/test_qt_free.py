"""The engine packages never pull in Qt, OpenGL or pyqtgraph (DESIGN.md section 2)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import pytest

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
    "matshop.derive",
    "matshop.cli",
    "matshop.commands",
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
