"""Autosave: a recovery file beside the project that the app or CLI can offer to restore.

``dir/name.matshop`` autosaves to ``dir/.name.matshop.recovery``, a complete
project in the same format (so :func:`~matshop.io.project.load_project` reads
it), written atomically like any save. A normal save removes it. One that is
not newer than its project was superseded (its removal failed), so
:func:`find_recovery` does not offer it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from ..layers import Document
from .project_store import write_project


def autosave_path(path: str | os.PathLike[str]) -> Path:
    """Where the recovery file of the project at ``path`` lives."""
    target = Path(path)
    return target.with_name(f".{target.name}.recovery")


def write_recovery(
    document: Document, path: str | os.PathLike[str], settings: dict[str, Any] | None = None
) -> Path:
    """Autosave ``document`` (the project at ``path``) to its recovery file; returns it.

    The project file itself is not touched.
    """
    recovery = autosave_path(path)
    write_project(document, recovery, settings)
    return recovery


def find_recovery(path: str | os.PathLike[str]) -> Path | None:
    """The recovery file of ``path`` if there is one newer than the project, else None."""
    recovery = autosave_path(path)
    try:
        saved = recovery.stat().st_mtime_ns
    except OSError:
        return None
    try:
        project = Path(path).stat().st_mtime_ns
    except OSError:
        return recovery  # never saved normally (or deleted): the autosave is all there is
    return recovery if saved > project else None


def discard_recovery(path: str | os.PathLike[str]) -> None:
    """Remove the recovery file of ``path``, if any."""
    recovery = autosave_path(path)
    try:
        recovery.unlink(missing_ok=True)
    except OSError as exc:
        raise MatshopError(
            f"cannot remove the recovery file: {exc.strerror or exc}", recovery
        ) from None
