"""Temp files and staging folders of dead processes: named by owner, cleaned on the next write.

Every temp file (:mod:`.atomic`) and staging folder (:mod:`.fileset`) carries
the process id that made it. A process killed mid-save (``kill -9``, a power
cut) leaves them behind; the next matshop that writes into the same folder
removes those whose owner no longer runs, and rolls back a file set whose
renames were interrupted half way (from the plan and backups its staging
folder holds), so the folder shows the old set, whole. Leftovers of a process
that still runs are never touched.
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import shutil
from pathlib import Path

#: ``.<stem>.tmp-<pid>-<random>[.ext]`` (:func:`matshop.io.atomic.temp_path_for`)
TEMP_FILE = re.compile(r"\..*\.tmp-(\d+)-[0-9a-f]{8}(\.[^.]*)?")
#: ``.matshop-staging-<pid>-<random>`` (:func:`matshop.io.fileset.write_all`)
STAGING_DIR = re.compile(r"\.matshop-staging-(\d+)-.+")
#: inside a staging folder: the names being renamed into place, one a line
PLAN_NAME = ".plan"
BACKUP_DIR = ".previous"


def owner_tag() -> str:
    """``<pid>-<random>``: this process's mark in a temp name."""
    return f"{os.getpid()}-{secrets.token_hex(4)}"


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # another user's live process (or a pid we cannot ask about): keep
    return True


def roll_back(staging: Path, out: Path) -> None:
    """Undo the renames a dead writer made from ``staging`` into ``out``.

    The plan lists every name; a name with a backup had an old file (put it
    back), a name no longer staged was moved in new (take it out), a name
    still staged was never moved (nothing to do).
    """
    try:
        names = (staging / PLAN_NAME).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return  # the rename phase never began: out was not touched
    backup = staging / BACKUP_DIR
    for name in names:
        if not name or "/" in name or name in (".", ".."):
            continue
        with contextlib.suppress(OSError):
            if (backup / name).exists():
                os.replace(backup / name, out / name)
            elif not (staging / name).exists():
                os.unlink(out / name)


def clean_leftovers(folder: str | os.PathLike[str]) -> list[Path]:
    """Remove the temp files and staging folders in ``folder`` whose process is dead.

    Returns what was removed. Never raises: cleaning is a courtesy, the
    write that follows must not fail because of it.
    """
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        staging = STAGING_DIR.fullmatch(entry.name)
        temp = None if staging else TEMP_FILE.fullmatch(entry.name)
        match = staging or temp
        if match is None or _alive(int(match[1])):
            continue
        path = Path(entry.path)
        with contextlib.suppress(OSError):
            if staging and entry.is_dir(follow_symlinks=False):
                roll_back(path, Path(folder))
                shutil.rmtree(path)
            elif temp and entry.is_file(follow_symlinks=False):
                path.unlink()
            else:
                continue
            removed.append(path)
    return removed
