"""Atomic file replacement: write a temp file beside the target, fsync, rename.

Readers of ``path`` see either the old file or the complete new one, never a
half-written file; on any failure the temp file is removed and ``path`` is left
untouched. Used by image export and project saves.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from matshop.errors import MatshopError
from matshop.io.leftovers import clean_leftovers, owner_tag


def temp_path_for(path: Path) -> Path:
    """A fresh hidden name beside ``path`` that keeps its extension last.

    ``dir/name.png`` -> ``dir/.name.tmp-<pid>-1a2b3c4d.png`` (OpenImageIO picks the
    format from the extension, so the real one must stay at the end; the pid
    lets :func:`~matshop.io.leftovers.clean_leftovers` tell a dead writer's
    file from a live one's). The stem
    is cut short so that a target name near the file system's limit still has a
    temp name.
    """
    return path.with_name(f".{path.stem[:100]}.tmp-{owner_tag()}{path.suffix[:20]}")


@contextlib.contextmanager
def atomic_target(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temp path to write; on clean exit it replaces ``path`` atomically.

    The temp file is created empty (exclusively, so no other writer owns the
    name) with the default permissions of a new file. The caller writes it
    completely and closes it inside the ``with`` block.
    """
    target = Path(path)
    if target.is_dir():
        raise MatshopError("is a directory, not a file", target)
    if not target.parent.is_dir():
        raise MatshopError(f"cannot write: folder {target.parent} does not exist", target)
    clean_leftovers(target.parent)  # temp files of killed saves, not of running ones
    tmp = temp_path_for(target)
    try:
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    except OSError as exc:
        raise MatshopError(f"cannot write: {exc.strerror or exc}", target) from exc
    try:
        yield tmp
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise MatshopError(f"cannot write: {exc.strerror or exc}", target) from exc
        raise
    _fsync_dir(target.parent)


def _fsync_dir(folder: Path) -> None:
    """Make the rename durable (best effort: not every platform can)."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
