"""Which kernels a process compiled, and the stamp that says a cache is warm.

numba keys a cached kernel by its source file's modification time and size, the
argument types and the target CPU (name and features). The stamp, written next to the
cache after a warm-up, records the same facts but the types (the warm-up's jobs see to
those), so :func:`is_warm` can tell a warm cache from a cold or stale one without
compiling anything.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path
from typing import Any

STAMP_NAME = "matshop-warm-up.json"


def kernels() -> dict[str, Any]:
    """Every cached numba kernel of matshop imported so far, by ``module.name``."""
    from numba.core.registry import CPUDispatcher

    found = {}
    for module_name, module in list(sys.modules.items()):
        if not module_name.startswith("matshop.") or module is None:
            continue
        for name, value in list(vars(module).items()):
            if (
                isinstance(value, CPUDispatcher)
                and value.py_func.__module__ == module_name
                and value._cache.__class__.__name__ != "NullCache"  # cache=True
            ):
                found[f"{module_name}.{name}"] = value
    return found


def compile_counts() -> tuple[int, int]:
    """(signatures compiled, signatures loaded from the disk cache) in this process so far."""
    compiled = loaded = 0
    for kernel in kernels().values():
        compiled += sum(kernel.stats.cache_misses.values())
        loaded += sum(kernel.stats.cache_hits.values())
    return compiled, loaded


def stamp_path() -> Path:
    """Where numba keeps the cache of matshop's kernels (per NUMBA_CACHE_DIR), and the stamp."""
    from ..io._codes import _codes

    try:  # numba's own answer: in-tree __pycache__, NUMBA_CACHE_DIR, or the user cache
        folder = Path(_codes._cache.cache_path)
    except AttributeError:  # a numba without it: a stamp never found reads as cold
        folder = Path(tempfile.gettempdir())
    return folder / STAMP_NAME


def _target() -> dict[str, Any]:
    """What numba's cache entries depend on besides the sources."""
    import llvmlite.binding as llvm
    import numba

    return {
        "numba": numba.__version__,
        "python": sys.version.split()[0],
        "cpu": llvm.get_host_cpu_name(),
        "features": llvm.get_host_cpu_features().flatten(),
    }


def _source_stamp(path: str) -> list[float]:
    stat = Path(path).stat()
    return [stat.st_mtime, stat.st_size]


def write_stamp() -> Path:
    """Record the target and every kernel module's (mtime, size) after a warm-up."""
    files = sorted({kernel.py_func.__code__.co_filename for kernel in kernels().values()})
    stamp = {**_target(), "sources": {f: _source_stamp(f) for f in files}}
    path = stamp_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    scratch = path.with_suffix(".tmp")
    scratch.write_text(json.dumps(stamp, indent=1))
    scratch.replace(path)
    return path


def is_warm() -> bool:
    """True when a warm-up ran on these sources, this numba and this CPU (nothing compiled)."""
    try:
        stamp = json.loads(stamp_path().read_text())
        if {k: stamp.get(k) for k in _target()} != _target() or not stamp["sources"]:
            return False
        return all(_source_stamp(f) == list(s) for f, s in stamp["sources"].items())
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return False
