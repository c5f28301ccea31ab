"""``.matshop`` project files: save and load a layer document with the app's settings.

The public front door; the format lives in :mod:`.project_format` (manifest
and its validation), the container in :mod:`.project_store` (zip, atomic
write, checked reads) and autosave in :mod:`.recovery`.

>>> save_project(doc, "rust.matshop", settings={"active_layer": 3})   # doctest: +SKIP
>>> project = load_project("rust.matshop")                            # doctest: +SKIP
>>> project.document.flatten_edit()                                   # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from ..layers import Document
from .project_format import FORMAT_VERSION
from .project_store import DEFAULT_MAX_BYTES, Project, read_project, write_project
from .recovery import autosave_path, discard_recovery, find_recovery, write_recovery

__all__ = [
    "DEFAULT_MAX_BYTES",
    "FORMAT_VERSION",
    "Project",
    "autosave_path",
    "discard_recovery",
    "find_recovery",
    "load_project",
    "save_project",
    "write_recovery",
]


def save_project(
    document: Document,
    path: str | os.PathLike[str],
    *,
    settings: dict[str, Any] | None = None,
) -> None:
    """Save ``document`` (and the app's JSON ``settings``) to ``path`` atomically.

    The previous file survives any failure. A successful save removes the
    project's recovery file: it holds nothing newer any more.

    Raises
    ------
    MatshopError : one line naming the file (unwritable folder, NaN values, ...).
    """
    write_project(document, path, settings)
    # the save itself succeeded: a recovery file that will not go is only stale,
    # and find_recovery ignores recovery files older than their project
    with contextlib.suppress(MatshopError):
        discard_recovery(path)


def load_project(path: str | os.PathLike[str], *, max_bytes: int = DEFAULT_MAX_BYTES) -> Project:
    """Load the project at ``path``, checking everything before building the document.

    ``max_bytes`` caps the memory the project's layers may take (a tampered
    file cannot make the loader inflate more). The file is only read.

    Raises
    ------
    MatshopError : one line naming the file and the problem (not a project,
        truncated, damaged, tampered, or made by a newer matshop).
    """
    return read_project(Path(path), max_bytes)
