"""Which green-channel convention a normal map is read in, and why.

The policy (CONVENTIONS.md): a convention the user gives wins; then a token
in the file name (``_NormalGL``, ``_nor_dx``); then a guess from the pixels,
but only when it is confident (:data:`~matshop.spaces.frame.CONFIDENT_GUESS`,
chosen by measurement on a corpus with known answers); otherwise OpenGL, the
convention of glTF, MaterialX, Blender, Godot and Unity, said aloud. A wrong
confident guess would flip every export of the map, so the threshold errs on
the side of the default.

What matshop writes carries its convention in the file name
(:data:`CONVENTION_TOKENS`), so reading matshop's own output never guesses.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..spaces.frame import CONFIDENT_GUESS, guess_normal_convention

#: the file-name token matshop writes after ``_normal`` for each convention
CONVENTION_TOKENS = {"opengl": "gl", "directx": "dx"}
#: the metadata matshop writes into every normal map (PNG text, EXR, TIFF attribute)
CONVENTION_ATTRIBUTE = "matshop:normal_convention"

DEFAULT_CONVENTION = "opengl"


class ConventionChoice(NamedTuple):
    convention: str  #: "opengl" or "directx"
    source: str  #: how it was decided, a few words: "file name", "default"...
    note: str | None = None  #: a sentence for the user when the default was taken


def decide_convention(
    rgb: np.ndarray,
    *,
    given: str | None = None,
    from_name: str | None = None,
    from_metadata: object = None,
) -> ConventionChoice:
    """Which convention the encoded normal map ``rgb`` ``(H, W, 3)`` is read in, and why.

    ``from_metadata`` is the file's :data:`CONVENTION_ATTRIBUTE`, if any (a
    value other than a known convention is ignored). ``source`` is one of
    ``"given"``, ``"file name"``, ``"file metadata"``, ``"guessed (confidence
    0.83)"`` or ``"default"``; the default comes with a ``note``.
    """
    if given is not None:
        return ConventionChoice(given, "given")
    if from_name is not None:
        return ConventionChoice(from_name, "file name")
    if from_metadata in CONVENTION_TOKENS:
        return ConventionChoice(str(from_metadata), "file metadata")
    guess, confidence = guess_normal_convention(rgb)
    if confidence >= CONFIDENT_GUESS:
        return ConventionChoice(guess, f"guessed (confidence {confidence:.2f})")
    return ConventionChoice(
        DEFAULT_CONVENTION,
        "default",
        f"read as {DEFAULT_CONVENTION} normals by default: the map's own guess ({guess}, "
        f"confidence {confidence:.2f}) is below {CONFIDENT_GUESS:.2f}, the least acted on; "
        "choose with --normal-convention or the Normal map control of the editor's open dialog",
    )


def convention_line(sources: dict[str, dict]) -> str | None:
    """How a loaded material's normal map was read, one line for the user (None: no map)."""
    normal = sources.get("normal") or {}
    if "convention" not in normal:
        return None
    name = Path(str(normal.get("file", "normal map"))).name
    line = f"{name}: {normal['convention']} normals ({normal.get('convention_source', '?')})"
    note = normal.get("convention_note")
    return f"{line}; {note}" if note else line
