"""All-or-nothing writing of a set of files into one folder.

A texture set or an export is several files that only make sense together (a
material whose ORM is new but whose normal map is old is wrong in an engine). So every file
is first written into a hidden staging folder beside its target; only when
all of them succeeded are they renamed into place. A failure while writing
leaves the folder as it was. Renames are atomic one by one; if a rename
fails half way, the files already moved are taken back out and the old ones
(kept as hard links, or copies) are put back.

Existing files are replaced only with ``force``; the check runs before any
work, so a refused export costs nothing. Files are written several at a time
(:mod:`.overlap`), except those that read the others (a package).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Callable, Sequence
from contextlib import closing
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from ..errors import MatshopError
from .leftovers import BACKUP_DIR, PLAN_NAME, clean_leftovers
from .overlap import in_order
from .safe_names import check_file_name


@dataclass(frozen=True)
class PendingFile:
    """A file to write: its name in the output folder and how to write it."""

    name: str
    #: writes the complete file at the given (staging) path
    write: Callable[[Path], None]
    #: the writer reads the other files from the staging folder (a package of them),
    #: so it runs after every other file is written
    reads_others: bool = False


def check_targets(out_dir: Path, names: Sequence[str], *, force: bool) -> None:
    """Refuse clashes with existing files (without ``force``) and bad folders."""
    clean_leftovers(out_dir)  # a killed writer's staging folder: its renames are rolled back
    if out_dir.exists() and not out_dir.is_dir():
        raise MatshopError("output exists and is not a folder", out_dir)
    for name in names:  # the last gate: no name may lead out of out_dir
        check_file_name(name, out_dir)
        if name in (PLAN_NAME, BACKUP_DIR):
            raise MatshopError(f"refusing to write: {name!r} is matshop's own", out_dir)
    if len(set(names)) != len(names):
        raise MatshopError("the export would write one file name twice", out_dir)
    existing = [n for n in names if (out_dir / n).exists()]
    if existing and not force:
        more = f" and {len(existing) - 1} more" if len(existing) > 1 else ""
        raise MatshopError(
            f"{existing[0]}{more} already exist(s); use --force to overwrite", out_dir
        )
    for name in existing:
        if (out_dir / name).is_dir():
            raise MatshopError("is a folder, cannot overwrite it with a file", out_dir / name)


def write_one(pending: PendingFile, path: Path) -> None:
    """Write one staged file (a seam: tests replace it to simulate failures)."""
    pending.write(path)


def write_all(
    out_dir: str | os.PathLike,
    files: Sequence[PendingFile],
    *,
    force: bool,
    progress: Callable[[int, int], None] | None = None,
) -> list[Path]:
    """Write ``files`` into ``out_dir`` all-or-nothing; return the final paths.

    ``progress(done, total)`` is called before the first file and after each staged
    one; an exception it raises (a cancel) is a failure like any other: nothing is moved
    into ``out_dir`` and a folder this call created is removed.
    """
    out = Path(out_dir)
    names = [f.name for f in files]
    check_targets(out, names, force=force)
    created = not out.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".matshop-staging-{os.getpid()}-", dir=out))
    except OSError as exc:
        raise MatshopError(f"cannot write here: {exc.strerror or exc}", out) from None
    try:
        if progress is not None:
            progress(0, len(files))
        alone = [f for f in files if not f.reads_others]
        tasks = [partial(_write_staged, f, staging, out) for f in alone]
        with closing(in_order(tasks)) as written:
            for done, _ in enumerate(written, 1):
                if progress is not None:
                    progress(done, len(files))
        for done, pending in enumerate([f for f in files if f.reads_others], len(alone) + 1):
            _write_staged(pending, staging, out)
            if progress is not None:
                progress(done, len(files))
        return _move_into_place(staging, out, names)
    except BaseException:
        if created:  # a failed write leaves no empty output folder behind
            shutil.rmtree(staging, ignore_errors=True)
            with contextlib.suppress(OSError):
                out.rmdir()
        raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _write_staged(pending: PendingFile, staging: Path, out: Path) -> None:
    try:
        write_one(pending, staging / pending.name)
    except OSError as exc:
        raise MatshopError(f"cannot write: {exc.strerror or exc}", out / pending.name) from None
    except MatshopError as exc:  # name the file the user asked for, not the staged one
        raise MatshopError(exc.problem, out / pending.name) from None


def _move_into_place(staging: Path, out: Path, names: Sequence[str]) -> list[Path]:
    backup = staging / BACKUP_DIR
    backup.mkdir()
    # the plan, durable before the first rename: if this process dies half way,
    # the next writer here rolls the folder back from it (leftovers.roll_back)
    plan = staging / PLAN_NAME
    with open(plan, "w", encoding="utf-8") as file:
        file.write("\n".join(names))
        file.flush()
        os.fsync(file.fileno())
    kept: list[str] = []
    moved: list[str] = []
    try:
        for name in names:
            target = out / name
            if target.exists():
                _keep(target, backup / name)
                kept.append(name)
            os.replace(staging / name, target)
            moved.append(name)
    except OSError as exc:
        for name in moved:
            with contextlib.suppress(OSError):
                os.unlink(out / name)
        for name in kept:
            with contextlib.suppress(OSError):
                os.replace(backup / name, out / name)
        raise MatshopError(f"cannot write: {exc.strerror or exc}", out) from None
    with contextlib.suppress(OSError):
        fd = os.open(out, os.O_RDONLY)
        try:
            os.fsync(fd)  # make the renames durable
        finally:
            os.close(fd)
    plan.unlink()  # done: from here on a leftover staging folder means nothing to undo
    return [out / name for name in names]


def _keep(target: Path, copy: Path) -> None:
    """A second name for ``target``'s current content, to restore it on failure."""
    try:
        os.link(target, copy)
    except OSError:
        shutil.copy2(target, copy)
