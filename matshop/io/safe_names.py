"""File names that no input can turn into a path: the one rule for every writer.

Names written into an output folder are built from data (a material's name
from a manifest or a folder, a preset's ``fileName`` template, ``--name``).
That data must never decide *where* matshop writes, so:

- :func:`safe_stem` turns any text into a plain stem (letters and digits of
  any script, ``_ . -``; no separator, no leading dot, no control character,
  bounded length in bytes), used for the ``{material}`` part of every written
  name;
- :func:`check_file_name` is the last gate in :mod:`matshop.io.fileset`: a
  name that is not one plain entry of the output folder is refused before
  anything is written, whatever code built it.
"""

from __future__ import annotations

import re
import unicodedata

from ..errors import MatshopError

#: the stem leaves room for ``_<tag>.<ext>`` and the writer's temp-file affixes
#: within the 255-byte file-name limit of common file systems (UTF-8 bytes)
MAX_STEM_BYTES = 100
#: the longest written file name (temp names add ~20 characters to it)
MAX_FILE_NAME_BYTES = 200

#: anything but letters and digits of any script, ``_``, ``.`` and ``-``
_UNSAFE = re.compile(r"[^\w.\-]+")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def safe_stem(name: object, fallback: str = "material") -> str:
    """``name`` as a plain file-name stem: unsafe runs become ``_``, dots and
    separators cannot lead, at most :data:`MAX_STEM_BYTES` bytes of UTF-8.

    >>> safe_stem("../../ESCAPED")
    'ESCAPED'
    >>> safe_stem("/home/me/.bashrc")
    'home_me_.bashrc'
    >>> safe_stem("Holz_Oberfläche")
    'Holz_Oberfläche'
    >>> safe_stem("")
    'material'
    """
    text = _UNSAFE.sub("_", unicodedata.normalize("NFC", str(name))).strip("._-")
    # cut on a character boundary: a partial UTF-8 sequence is dropped
    text = text.encode("utf-8", "ignore")[:MAX_STEM_BYTES].decode("utf-8", "ignore")
    return text.rstrip("._-") or fallback


def file_name_problem(name: object) -> str | None:
    """Why ``name`` is not one plain entry of a folder, or None if it is."""
    if not isinstance(name, str) or not name:
        return "an empty file name"
    shown = repr(name[:60])
    if name in (".", ".."):
        return f"file name {shown} names a folder"
    if "/" in name or "\\" in name or (len(name) > 1 and name[1] == ":"):
        return f"file name {shown} holds a path separator"
    if _CONTROL.search(name):
        return f"file name {shown} holds a control character"
    try:
        size = len(name.encode("utf-8"))
    except UnicodeEncodeError:
        return f"file name {shown} is not valid text"
    if size > MAX_FILE_NAME_BYTES:
        return f"file name {shown}... is longer than {MAX_FILE_NAME_BYTES} bytes"
    return None


def check_file_name(name: str, where: object = None) -> str:
    """``name`` if it is one plain entry of a folder; else a one-line :class:`MatshopError`."""
    problem = file_name_problem(name)
    if problem is not None:
        raise MatshopError(f"refusing to write: {problem}", where)  # type: ignore[arg-type]
    return name
