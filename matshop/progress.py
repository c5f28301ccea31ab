"""Progress reporting for long work, shared by the CLI and the API.

The engine reports progress through plain callbacks ``(done, total)``; this
module turns them into a terminal progress bar (tqdm on stderr, shown only
when stderr is a terminal, so pipelines and logs stay clean).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager

from .material import ProgressCallback


@contextmanager
def progress_bar(description: str, *, enabled: bool | None = None) -> Iterator[ProgressCallback]:
    """Yield a ``(done, total)`` callback drawing a bar labelled ``description``."""
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        yield lambda done, total: None
        return
    from tqdm import tqdm

    bar = tqdm(desc=description, total=None, unit="step", leave=False, file=sys.stderr)

    def update(done: int, total: int) -> None:
        if bar.total != total:
            bar.reset(total=total)
        bar.n = done
        bar.refresh()

    try:
        yield update
    finally:
        bar.close()
