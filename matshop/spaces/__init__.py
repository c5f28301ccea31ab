"""Editing spaces, one module per parameter family.

Each family module exposes ``SPACES``, a dict from registry name to a ready
:class:`~matshop.spaces.base.Space` instance. The registry is assembled
lazily so that importing one family (or this package) stays cheap.
"""

from __future__ import annotations

import importlib
from functools import cache

from ..errors import UnknownName
from .base import EditRange, Space

_FAMILY_MODULES = (
    "color",
    "scalar",
    "phong",
    "ashikhmin_shirley",
    "beckmann",
    "ggx",
    "sampled",
    "subsurface",
    "frame",
)

__all__ = ["EditRange", "Space", "all_spaces", "get_space"]


@cache
def all_spaces() -> dict[str, Space]:
    """Every registered space by name."""
    registry: dict[str, Space] = {}
    for module_name in _FAMILY_MODULES:
        module = importlib.import_module(f"{__name__}.{module_name}")
        for name, space in module.SPACES.items():
            if name in registry:
                raise RuntimeError(f"editing space {name!r} registered twice")
            registry[name] = space
    return registry


def get_space(name: str) -> Space:
    """The space registered as ``name``; a clear error lists the known ones."""
    registry = all_spaces()
    try:
        return registry[name]
    except KeyError:
        known = ", ".join(sorted(registry))
        raise UnknownName(f"unknown editing space {name!r} (known: {known})") from None
