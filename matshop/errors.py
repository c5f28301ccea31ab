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


class InvalidValue(MatshopError, ValueError):
    """A value the engine refuses (a parameter out of range, of the wrong type, or
    inconsistent with another): one line naming the value and what is wrong.

    Also a ValueError, so code that validates with plain Python checks and
    callers that catch ValueError keep working.
    """


@contextlib.contextmanager
def naming(
    path: str | os.PathLike[str] | None = None, *, what: str | None = None
) -> Iterator[None]:
    """Errors raised inside are about ``path`` when they name no file (e.g. the project
    a verb works on) and, given ``what``, about that part of it ("stroke 3",
    "--value"): the one line says where the problem is. The error keeps its type."""
    try:
        yield
    except MatshopError as exc:
        if what is not None:
            exc.problem = f"{what}: {exc.problem}"
        if exc.path is None and path is not None:
            exc.path = os.fspath(path)
        exc.args = (exc.problem if exc.path is None else f"{exc.path}: {exc.problem}",)
        raise


class UnknownName(InvalidValue, KeyError):
    """A name (an editing space, a parameter) that matshop does not know.

    Also a KeyError, as a lookup that fails; it reads as its sentence, not
    quoted as a plain KeyError would be.
    """

    def __str__(self) -> str:
        return Exception.__str__(self)
