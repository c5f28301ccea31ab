"""Image operations on edit-space arrays: pure functions plus their descriptions.

Each op module exposes its functions and ``SPECS``, a tuple of
:class:`~matshop.ops.spec.OpSpec`. The registry is assembled lazily so
importing one op stays cheap.
"""

from __future__ import annotations

import importlib
from functools import cache

from .spec import OpError, OpSpec, ParamSpec

_OP_MODULES = ("scale", "curves", "blur", "bilateral_ops", "composite", "clone")

__all__ = ["OpError", "OpSpec", "ParamSpec", "all_ops", "get_op"]


@cache
def all_ops() -> dict[str, OpSpec]:
    """Every registered op by name, in menu order."""
    registry: dict[str, OpSpec] = {}
    for module_name in _OP_MODULES:
        module = importlib.import_module(f"{__name__}.{module_name}")
        for spec in module.SPECS:
            if spec.name in registry:
                raise RuntimeError(f"op {spec.name!r} registered twice")
            registry[spec.name] = spec
    return registry


def get_op(name: str) -> OpSpec:
    """The op registered as ``name``, or a clear error listing the known ones."""
    registry = all_ops()
    if name not in registry:
        raise OpError(f"unknown op {name!r} (known: {', '.join(registry)})")
    return registry[name]
