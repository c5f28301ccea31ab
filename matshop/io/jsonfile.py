"""Reading the small JSON files users hand us (stroke files, swatch libraries, presets)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from .guard import read_input_file

#: JSON inputs are settings, not data: a bigger file is a mistake, not a workload
MAX_JSON_BYTES = 64 << 20
#: no setting needs more digits; Python refuses > 4300 anyway, with a traceback
MAX_INT_DIGITS = 40


def read_json(path: str | os.PathLike[str], kind: str) -> Any:
    """The parsed JSON at ``path``; problems are one line naming the file and ``kind``."""
    path = Path(path)
    data = read_input_file(path, kind, MAX_JSON_BYTES)
    try:
        return json.loads(data.decode("utf-8"), parse_int=bounded_int)
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise MatshopError(f"not a {kind} ({exc.__class__.__name__}: {exc})", path) from None


def bounded_int(text: str) -> int:
    """JSON integers as Python ints, refusing absurd lengths (int() is quadratic in them)."""
    if len(text.lstrip("-")) > MAX_INT_DIGITS:
        raise ValueError(f"a {len(text)}-digit integer")
    return int(text)
