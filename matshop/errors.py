"""The one exception users see.

``MatshopError`` carries a one-line, human-readable message naming the file
and the problem. The CLI prints ``str(error)`` and exits with status 2; the app
shows it in a message box. Anything else escaping is a bug.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator


class MatshopError(Exception):
    """A user-facing error: ``"{path}: {problem}"``, always one line.

    Multi-line problems (e.g. OpenImageIO's error text) are joined with ``"; "``.
    """

    def __init__(self, problem: str, path: str | os.PathLike[str] | None = None) -> None:
        lines = [" ".join(line.split()) for line in str(problem).splitlines()]
        self.problem = "; ".join(line.removesuffix(".") for line in lines if line)
        self.path = None if path is None else os.fspath(path)
        super().__init__(self.problem if self.path is None else f"{self.path}: {self.problem}")


@contextlib.contextmanager
def naming(path: str | os.PathLike[str]) -> Iterator[None]:
    """Errors raised inside that name no file are about ``path`` (e.g. the project a
    verb works on): the one line says which file the problem belongs to."""
    try:
        yield
    except MatshopError as exc:
        if exc.path is not None:
            raise
        raise MatshopError(exc.problem, path) from None
