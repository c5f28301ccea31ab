"""The op registry's table names every op where it is declared, and looking one op up
imports only the module that declares it (a blur never loads the bilateral lattice,
the clone's mesh, scipy.special or scipy.spatial)."""

from __future__ import annotations

import importlib
import pkgutil
import subprocess
import sys

import matshop.ops
from matshop.ops import OP_MODULES, all_ops, get_op


def test_the_table_matches_what_each_module_declares() -> None:
    declared = {}
    for info in pkgutil.iter_modules(matshop.ops.__path__):
        module = importlib.import_module(f"matshop.ops.{info.name}")
        for spec in getattr(module, "SPECS", ()):
            declared[spec.name] = info.name
    assert declared == OP_MODULES


def test_all_ops_is_the_registry_get_op_reads_in_menu_order() -> None:
    registry = all_ops()
    assert list(registry) == list(OP_MODULES)
    assert all(get_op(name) is spec for name, spec in registry.items())


_PROBE = """
import sys
from matshop.ops import get_op
get_op(sys.argv[1])
print(" ".join(sorted(m for m in sys.modules if m.startswith(("matshop.ops.", "scipy.s")))))
"""


def _imported_for(op: str) -> set[str]:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, op], capture_output=True, text=True, timeout=120, check=True
    )
    return set(done.stdout.split())


def test_looking_up_one_op_imports_its_module_only() -> None:
    blur = _imported_for("blur")
    assert "matshop.ops.blur" in blur
    assert not blur & {"matshop.ops.bilateral_ops", "matshop.ops.clone", "matshop.ops.curves"}
    assert not {m for m in blur if m.startswith("scipy.")}  # scipy.special, scipy.spatial
    # the probe sees the others when they are asked for
    assert {"matshop.ops.bilateral_ops", "matshop.ops.bilateral"} <= _imported_for("detail")
