"""Image operations on edit-space arrays: pure functions plus their descriptions.

Each op module exposes its functions and ``SPECS``, a tuple of
:class:`~matshop.ops.spec.OpSpec`. The registry is assembled lazily:
:func:`get_op` imports only the module that declares the op asked for (a
command that blurs need not import the bilateral lattice or the clone's
mesh), :func:`all_ops` imports every one.
"""

from __future__ import annotations

import importlib
import threading

from .spec import OpError, OpSpec, ParamSpec

#: op name -> the module declaring it, in menu order (tests/test_ops_registry.py holds
#: this table to the modules' SPECS)
OP_MODULES = {
    "scale": "scale",
    "curves": "curves",
    "levels": "curves",
    "blur": "blur",
    "bilateral": "bilateral_ops",
    "detail": "bilateral_ops",
    "composite": "composite",
    "clone": "clone",
}

__all__ = ["OP_MODULES", "OpError", "OpSpec", "ParamSpec", "all_ops", "get_op"]

#: the ops declared so far; all_ops() returns this very dict, in menu order once complete
_registry: dict[str, OpSpec] = {}
_loaded: set[str] = set()
# the editor's workers may look ops up while the UI lists them; reentrant in case an op
# module looks another op up while it is imported
_lock = threading.RLock()


def _declare(module_name: str) -> None:
    if module_name in _loaded:
        return
    module = importlib.import_module(f"{__name__}.{module_name}")
    for spec in module.SPECS:
        if OP_MODULES.get(spec.name) != module_name:
            raise RuntimeError(f"op {spec.name!r} of module {module_name} is not in OP_MODULES")
        _registry[spec.name] = spec
    _loaded.add(module_name)


def all_ops() -> dict[str, OpSpec]:
    """Every registered op by name, in menu order."""
    with _lock:
        if len(_loaded) < len(set(OP_MODULES.values())):
            for module_name in OP_MODULES.values():
                _declare(module_name)
            for name in OP_MODULES:  # reinserted in menu order, in the same dict
                _registry[name] = _registry.pop(name)
    return _registry


def get_op(name: str) -> OpSpec:
    """The op registered as ``name``, or a clear error listing the known ones."""
    if name not in OP_MODULES:
        raise OpError(f"unknown op {name!r} (known: {', '.join(OP_MODULES)})")
    with _lock:
        _declare(OP_MODULES[name])
    return _registry[name]
