"""Reading the small JSON files users hand us (stroke files, swatch libraries, presets)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ..errors import MatshopError

#: JSON inputs are settings, not data: a bigger file is a mistake, not a workload
MAX_JSON_BYTES = 64 << 20


def read_json(path: str | os.PathLike[str], kind: str) -> Any:
    """The parsed JSON at ``path``; problems are one line naming the file and ``kind``."""
    path = Path(path)
    try:
        if path.stat().st_size > MAX_JSON_BYTES:
            raise MatshopError(f"too large for a {kind} (over {MAX_JSON_BYTES >> 20} MiB)", path)
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise MatshopError("file not found", path) from None
    except IsADirectoryError:
        raise MatshopError(f"is a folder, not a {kind}", path) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise MatshopError(f"not a {kind} ({exc.__class__.__name__}: {exc})", path) from None
