"""``matshop paint PROJECT --stroke FILE.json``: replay brush strokes into a project."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...errors import MatshopError, naming
from ...io.project import save_project
from ...layers.layer import PaintLayer
from ...paint.painter import StrokeSession
from ...paint.strokefile import load_strokes
from ..project import about_project, find_layer, open_project


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Replay the strokes of FILE.json (see matshop.paint.strokefile for the "
        "format: points with pressure, brush settings with tips, jitter and scatter, a "
        "material swatch, a seed, a stencil, erase, mask or clone-stamp strokes) into "
        "PROJECT, one undoable step per stroke."
    )
    parser.add_argument("project", type=Path, metavar="PROJECT")
    parser.add_argument("--stroke", type=Path, required=True, metavar="FILE.json")
    parser.add_argument("--layer", help="layer for strokes that name none (default: top paint)")
    parser.set_defaults(run=run)


@about_project
def run(args: argparse.Namespace) -> int:
    strokes = load_strokes(args.stroke)  # a bad stroke file fails before the project is read
    doc, history, settings = open_project(args.project)
    default = find_layer(doc, args.layer, args.project) if args.layer else None
    if default is None:
        painted = [layer for layer in doc if isinstance(layer, PaintLayer)]
        default = painted[-1] if painted else None
    total = 0
    for number, stroke in enumerate(strokes, 1):
        if stroke.layer is not None:
            layer = find_layer(doc, stroke.layer, args.stroke)
        elif default is not None:
            layer = default
        else:
            raise MatshopError(
                "no paint layer: add one with `matshop layer add PROJECT paint`", args.project
            )
        with naming(args.stroke, what=f"stroke {number}"):
            session = StrokeSession(doc, layer.id, stroke.brush, history=history, **stroke.options)
        if session.note:
            print(f"stroke {number}: {session.note}")
            if stroke.layer is None:  # later strokes go where this one went
                default = doc.layer(session.layer_id)
        session.add(stroke.samples)
        session.end()
        total += session.dabs
    save_project(doc, args.project, settings=settings)
    print(f"painted {len(strokes)} stroke(s), {total} dabs, into {args.project}")
    return 0
