"""Export to engines: presets, channel packing, writing, glTF and MaterialX.

A preset is data (JSON or TOML, in the shape of Substance 3D Painter's export
presets): a table of output files, each built by packing channels of the
material's physical parameters, with a color encoding, bit depth, format and
normal convention. The modules, one idea each:

- :mod:`.presets`  the preset model, loading and validation (built-in and user files)
- :mod:`.pack`     pure functions: a Material + one output spec -> one float array
- :mod:`.quantize` dithering to 8-bit codes
- :mod:`.resize`   power-of-two resizing, filtered in editing space
- :mod:`.core`     :func:`export_material`, tying the above together
- :mod:`.reimport` reading an export back into a Material (the round-trip check)
- :mod:`.gltf`, :mod:`.obj`, :mod:`.mtlx`  glTF binary with a mesh, MaterialX documents
- :mod:`.verbs`    the ``matshop export`` command

This package's ``__init__`` imports nothing heavy, so that ``matshop --help``
(which imports :mod:`.verbs`) stays fast; the public names load on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "export_material": "core",
    "ExportSummary": "core",
    "load_preset": "presets",
    "builtin_preset_names": "presets",
    "Preset": "presets",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)
