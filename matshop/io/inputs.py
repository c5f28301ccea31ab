"""What a verb that reads "a material" accepts: a texture set or a ``.matshop`` project."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..errors import naming
from ..material import Material

PROJECT_SUFFIX = ".matshop"


def is_project(path: str | os.PathLike[str]) -> bool:
    return Path(path).suffix.lower() == PROJECT_SUFFIX


def load_flattened(path: str | os.PathLike[str], **load_options: Any) -> Material:
    """A texture set as loaded, or a project flattened (edit space, then from_edit once).

    ``load_options`` (spaces, normal convention) apply to texture sets; a
    project carries its own.
    """
    if is_project(path):
        from .project import load_project

        with naming(path):
            return load_project(path).document.flatten_physical()
    from .material_io import load_material

    material, _ = load_material(path, **load_options)
    return material
