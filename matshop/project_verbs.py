"""Headless verbs on ``.matshop`` projects: new, layer, paint, flatten.

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
from pathlib import Path
from typing import Any

VERB_MODULE = "matshop.project_verbs"


def add_parsers(verbs: Any) -> None:
    from .cli import add_load_options  # stdlib only; loaded already when verbs are built

    new = verbs.add_parser(
        "new",
        help="create a .matshop project (from a texture set, or empty)",
        description="Create the project PROJECT. With --from, its bottom layer is the "
        "texture set; otherwise give --size and --params for an empty document.",
    )
    new.add_argument("project", type=Path, metavar="PROJECT")
    new.add_argument("--from", dest="source", type=Path, help="texture set (folder or one map)")
    new.add_argument("--size", help="WIDTHxHEIGHT of an empty document, e.g. 2048x2048")
    new.add_argument("--params", help="parameters of an empty document, e.g. base_color,roughness")
    new.add_argument("--force", action="store_true", help="overwrite an existing project")
    add_load_options(new)
    new.set_defaults(verb_module=VERB_MODULE, action="new")

    layer = verbs.add_parser(
        "layer",
        help="add, list, change or remove layers of a project",
        description="Edit the layer stack of a project.",
    )
    actions = layer.add_subparsers(dest="layer_action", metavar="ACTION", required=True)
    add = actions.add_parser(
        "add",
        help="add a paint, fill, filter or group layer on top (or at --index, or into --group)",
        epilog="examples: layer add p.matshop fill --value base_color=0.6,0.25,0.1 "
        "--value roughness=0.8 | layer add p.matshop fill --from rust/ --mask m.png | "
        "layer add p.matshop filter --op bilateral sigma_px=6 | layer add p.matshop paint",
    )
    add.add_argument("project", type=Path, metavar="PROJECT")
    add.add_argument("kind", choices=("paint", "fill", "filter", "group"))
    add.add_argument("--name")
    add.add_argument("--opacity", type=float)
    add.add_argument("--blend", help="normal, add, subtract, multiply or detail")
    add.add_argument("--params", help="parameters the layer affects (default: all)")
    add.add_argument("--hidden", action="store_true", help="add it hidden")
    add.add_argument("--index", type=int, help="stack position (0 = bottom; default: top)")
    add.add_argument("--group", help="put it into this group (just below the group layer)")
    add.add_argument(
        "--value",
        action="append",
        default=[],
        metavar="PARAM=V[,V...]",
        help="fill: a constant physical value (repeatable), e.g. roughness=0.8",
    )
    add.add_argument("--from", dest="source", type=Path, help="fill: a texture set")
    add.add_argument(
        "--op", nargs="+", metavar=("NAME", "KEY=VALUE"), help="filter: the op and its parameters"
    )
    add.add_argument("--mask", type=Path, help="grayscale image as the layer's mask")
    add.add_argument(
        "--mask-generator",
        nargs="+",
        metavar=("NAME", "KEY=VALUE"),
        help="a mask generated from the material's normals as they are when the layer is "
        "added: cavity, edge or ao, with radius_px (4), level (0.5), contrast (1), "
        "blur_px (0), invert (false); e.g. --mask-generator cavity radius_px=6 contrast=2",
    )
    add.set_defaults(verb_module=VERB_MODULE, action="layer-add")

    listing = actions.add_parser("list", help="list the layers, bottom to top")
    listing.add_argument("project", type=Path, metavar="PROJECT")
    listing.set_defaults(verb_module=VERB_MODULE, action="layer-list")

    change = actions.add_parser(
        "set",
        help="change layer properties: name, visible, opacity, blend, parameters",
        epilog="example: layer set p.matshop Rust opacity=0.5 blend=multiply visible=false",
    )
    change.add_argument("project", type=Path, metavar="PROJECT")
    change.add_argument("layer", metavar="LAYER", help="layer name or id")
    change.add_argument("settings", nargs="+", metavar="KEY=VALUE")
    change.set_defaults(verb_module=VERB_MODULE, action="layer-set")

    remove = actions.add_parser("remove", help="remove a layer")
    remove.add_argument("project", type=Path, metavar="PROJECT")
    remove.add_argument("layer", metavar="LAYER", help="layer name or id")
    remove.set_defaults(verb_module=VERB_MODULE, action="layer-remove")

    paint = verbs.add_parser(
        "paint",
        help="paint brush strokes from a JSON file into a project",
        description="Replay the strokes of FILE.json (see matshop.paint.strokefile for the "
        "format: points with pressure, brush settings, a material swatch, erase, mask or "
        "clone-stamp strokes) into PROJECT, one undoable step per stroke.",
    )
    paint.add_argument("project", type=Path, metavar="PROJECT")
    paint.add_argument("--stroke", type=Path, required=True, metavar="FILE.json")
    paint.add_argument("--layer", help="layer for strokes that name none (default: top paint)")
    paint.set_defaults(verb_module=VERB_MODULE, action="paint")

    recover = verbs.add_parser(
        "recover",
        help="restore a project from its autosave (recovery) file",
        description="If PROJECT has an autosave newer than itself (the editor writes "
        "one while you work), replace the project with it, atomically.",
    )
    recover.add_argument("project", type=Path, metavar="PROJECT")
    recover.set_defaults(verb_module=VERB_MODULE, action="recover")

    flatten = verbs.add_parser(
        "flatten",
        help="flatten a project and write it as a texture set",
        description="Composite every visible layer in edit space, convert back once and "
        "write <material>_<parameter> files into the folder OUT.",
    )
    flatten.add_argument("project", type=Path, metavar="PROJECT")
    flatten.add_argument("output", type=Path, metavar="OUT")
    flatten.add_argument("--force", action="store_true", help="overwrite existing files")
    flatten.set_defaults(verb_module=VERB_MODULE, action="flatten")


def run(args: argparse.Namespace) -> int:
    from . import project_commands

    return project_commands.run(args)
