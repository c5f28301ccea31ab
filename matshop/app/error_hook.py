"""The editor's one catch of the engine's error type for what no command handled.

A slot called by Qt that raises has nowhere to go but ``sys.excepthook``, which
prints a traceback on a terminal the artist may not have. The editor installs
:func:`install` at start: a :class:`MatshopError` (the engine's one type for a
user's bad value or file) escaping any slot becomes its one line in the window's
status bar; anything else is a bug, still printed whole, and the status bar says
so. Commands that must recover (keep a field's old text, abandon a stroke, keep
the document modified) still catch where they recover; this is where the rest
lands.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from types import TracebackType

from ..errors import MatshopError

Hook = Callable[[type[BaseException], BaseException, TracebackType | None], object]


def install(show: Callable[[str], None], previous: Hook | None = None) -> Hook:
    """Route escaped errors to ``show`` (a status-bar message); returns the hook installed."""
    chained = previous or sys.excepthook

    def hook(kind: type[BaseException], error: BaseException, tb: TracebackType | None) -> None:
        if isinstance(error, MatshopError):
            show(str(error))
            return
        chained(kind, error, tb)
        show(f"Internal error: {kind.__name__}: {error} (details printed on the terminal)")

    sys.excepthook = hook
    return hook
