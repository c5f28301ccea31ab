"""What the project verbs (new, layer, paint, recover, flatten) share.

A pipeline builds and renders layered projects without the editor::

    matshop new rusty.matshop --from steel/
    matshop layer add rusty.matshop fill --name Rust --from rust/ --mask gradient.png
    matshop layer add rusty.matshop paint --name Scratches --params roughness
    matshop paint rusty.matshop --stroke scratches.json
    matshop layer add rusty.matshop filter --op blur sigma_px=2 --params normal
    matshop flatten rusty.matshop out/

Every verb changes the document only through the same reversible edits the
editor uses, and saves the project atomically: a failing command leaves the
file as it was.
"""

from __future__ import annotations

import argparse
import functools
import sys
from collections.abc import Callable
from pathlib import Path

from ..errors import MatshopError, naming
from ..io.project import find_recovery, load_project
from ..layers import Document, History, Layer

Run = Callable[[argparse.Namespace], int]


def about_project(run: Run) -> Run:
    """A project verb: every message it gives names the project it is about."""

    @functools.wraps(run)
    def named(args: argparse.Namespace) -> int:
        with naming(args.project):
            return run(args)

    return named


def names(text: str | None) -> list[str] | None:
    """``a, b,c`` -> ["a", "b", "c"]; None stays None (all)."""
    return None if text is None else [n.strip() for n in text.split(",") if n.strip()]


def refuse_to_replace_autosave(path: Path) -> None:
    """A save removes the project's autosave: never do that to one newer than the project."""
    recovery = find_recovery(path)
    if recovery is not None:
        raise MatshopError(
            f"has a newer autosave ({recovery.name}) that saving would discard: "
            f"`matshop recover {path}` restores it, or delete it to discard it",
            path,
        )


def open_project(path: Path, *, for_writing: bool = True) -> tuple[Document, History, dict]:
    """Load a project; a verb that will save it first makes sure no autosave is lost."""
    if for_writing:
        refuse_to_replace_autosave(path)
    project = load_project(path)
    recovery = None if for_writing else find_recovery(path)
    if recovery is not None:
        print(
            f"matshop: note: {path} has a newer autosave ({recovery.name}); "
            f"`matshop recover {path}` restores it",
            file=sys.stderr,
        )
    return project.document, History(project.document), project.settings


def find_layer(doc: Document, key: str | int, path: Path | None = None) -> Layer:
    """A layer by name, or by id (a number that is no layer's name)."""
    if isinstance(key, str):
        named = [layer for layer in doc if layer.name == key]
        if len(named) == 1:
            return named[0]
        if len(named) > 1:
            raise MatshopError(f"{len(named)} layers are named {key!r}: use the id", path)
        if not key.isdigit():
            raise MatshopError(f"no layer named {key!r} ({_layer_names(doc)})", path)
    layer_id = int(key)
    for layer in doc:
        if layer.id == layer_id:
            return layer
    raise MatshopError(f"no layer with id {layer_id} ({_layer_names(doc)})", path)


def _layer_names(doc: Document) -> str:
    return "layers: " + (", ".join(f"{layer.id} {layer.name!r}" for layer in doc) or "none")
