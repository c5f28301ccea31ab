"""What matshop agrees to open: regular files with text names, never a FIFO or a device.

``st_size`` alone says nothing about a FIFO (it blocks the reader forever) or
``/dev/zero`` (endless): every input path is checked with ``stat`` before
OpenImageIO, zipfile or a JSON parser touches it, and small settings files
are read through a non-blocking descriptor whose ``fstat`` is checked again.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ..errors import MatshopError

_KINDS = {
    stat.S_IFIFO: "a FIFO (named pipe)",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
}


def _a(kind: str) -> str:
    return f"{'an' if kind[:1] in 'aeiou' else 'a'} {kind}"


def _not_regular(mode: int) -> str:
    return _KINDS.get(stat.S_IFMT(mode), "not a regular file")


def check_text_name(path: str | os.PathLike[str]) -> Path:
    """``path`` if its name is valid UTF-8 (OpenImageIO and zip names need text)."""
    path = Path(path)
    try:
        str(path).encode("utf-8")
    except UnicodeEncodeError:
        raise MatshopError(
            "the file name is not valid UTF-8 text; rename it", ascii(str(path))[1:-1]
        ) from None
    return path


def check_input_file(path: str | os.PathLike[str], kind: str) -> os.stat_result:
    """The ``stat`` of ``path`` if it is a readable regular file; else one line why not."""
    path = check_text_name(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        problem = "dangling symbolic link" if path.is_symlink() else "file not found"
        raise MatshopError(problem, path) from None
    except OSError as exc:
        raise MatshopError(f"cannot read: {exc.strerror or exc}", path) from None
    if stat.S_ISDIR(info.st_mode):
        raise MatshopError(f"is a folder, not {_a(kind)}", path)
    if not stat.S_ISREG(info.st_mode):
        raise MatshopError(f"is {_not_regular(info.st_mode)}, not {_a(kind)}", path)
    return info


def read_input_file(path: str | os.PathLike[str], kind: str, max_bytes: int) -> bytes:
    """The bytes of a small input file (stroke, preset, swatch library), at most ``max_bytes``."""
    path = Path(path)
    check_input_file(path, kind)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise MatshopError(f"cannot read: {exc.strerror or exc}", path) from None
    with os.fdopen(fd, "rb") as file:
        info = os.fstat(fd)  # the file opened may not be the one checked (a race)
        if not stat.S_ISREG(info.st_mode):
            raise MatshopError(f"is {_not_regular(info.st_mode)}, not {_a(kind)}", path)
        if info.st_size > max_bytes:
            raise MatshopError(f"too large for {_a(kind)} (over {max_bytes >> 20} MiB)", path)
        try:
            data = file.read(max_bytes + 1)
        except OSError as exc:
            raise MatshopError(f"cannot read: {exc.strerror or exc}", path) from None
    if len(data) > max_bytes:
        raise MatshopError(f"too large for {_a(kind)} (over {max_bytes >> 20} MiB)", path)
    return data
