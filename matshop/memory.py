"""How much memory an allocation may take, so that sizes from files are checked first.

A header, manifest or option declares sizes (a 16K document, 2 GB of tiles, a
65536-texel export); matshop compares what they would allocate with the
memory the machine has *before* allocating, and refuses in one line instead of
swapping for minutes or dying in a ``MemoryError``.

``MATSHOP_MEMORY_LIMIT`` (bytes, or with a K/M/G suffix) caps what matshop
assumes is available, e.g. for a batch worker sharing a node (tests use it
to check the refusals on any machine).
"""

from __future__ import annotations

import os
import re

from .errors import MatshopError

#: the share of available memory one allocation plan may take (the rest is for
#: the copies a pipeline makes and for everything else running)
USABLE_FRACTION = 0.8
_FALLBACK = 8 << 30
_SUFFIX = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def _meminfo_available() -> int | None:
    try:
        with open("/proc/meminfo", encoding="ascii") as file:
            for line in file:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup_room() -> int | None:
    """What a cgroup v2 memory limit leaves (containers), if one is set."""
    try:
        with open("/sys/fs/cgroup/memory.max", encoding="ascii") as file:
            limit = file.read().strip()
        if limit == "max":
            return None
        with open("/sys/fs/cgroup/memory.current", encoding="ascii") as file:
            used = int(file.read().strip())
        return max(int(limit) - used, 0)
    except (OSError, ValueError):
        return None


def _env_limit() -> int | None:
    text = os.environ.get("MATSHOP_MEMORY_LIMIT", "").strip().upper()
    match = re.fullmatch(r"(\d+)\s*([KMGT]?)I?B?", text)
    return int(match[1]) * _SUFFIX[match[2]] if match else None


def available_bytes() -> int:
    """Memory matshop may use now: the least of free RAM, a cgroup's room and the env cap."""
    found = [v for v in (_meminfo_available(), _cgroup_room(), _env_limit()) if v is not None]
    if not found:
        try:
            found = [os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")]
        except (ValueError, OSError, AttributeError):
            found = [_FALLBACK]
    return min(found)


def format_bytes(nbytes: float) -> str:
    for unit, size in (("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if nbytes >= size:
            return f"{nbytes / size:.1f} {unit}"
    return f"{int(nbytes)} bytes"


def require_memory(nbytes: float, what: str, path: str | os.PathLike[str] | None = None) -> None:
    """Refuse (one line naming ``what`` and ``path``) if ``nbytes`` will not fit in memory."""
    room = available_bytes() * USABLE_FRACTION
    if nbytes > room:
        raise MatshopError(
            f"{what} needs about {format_bytes(nbytes)} of memory, more than the "
            f"{format_bytes(room)} available",
            path,
        )
