"""``matshop new PROJECT``: a .matshop project from a texture set, or an empty one."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from ...errors import MatshopError, naming
from ...io.project import save_project
from ...layers import Document
from ...material import Schema
from ..options import add_load_options, load_options
from ..project import about_project, names, refuse_to_replace_autosave

MAX_SIDE = 65536


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Create the project PROJECT. With --from, its bottom layer is the "
        "texture set; otherwise give --size and --params for an empty document."
    )
    parser.add_argument("project", type=Path, metavar="PROJECT")
    parser.add_argument("--from", dest="source", type=Path, help="texture set (folder or one map)")
    parser.add_argument("--size", help="WIDTHxHEIGHT of an empty document, e.g. 2048x2048")
    parser.add_argument(
        "--params", help="parameters of an empty document, e.g. base_color,roughness"
    )
    parser.add_argument("--force", action="store_true", help="overwrite an existing project")
    add_load_options(parser)
    parser.set_defaults(run=run)


@about_project
def run(args: argparse.Namespace) -> int:
    path: Path = args.project
    if path.exists() and not args.force:
        raise MatshopError("already exists (use --force to overwrite)", path)
    refuse_to_replace_autosave(path)
    if args.source is not None:
        from ...io.material_io import load_material

        if args.size or args.params:
            raise MatshopError("--size and --params are for empty documents, not with --from")
        material, _ = load_material(args.source, **load_options(args))
        doc = Document.from_material(material)
    else:
        if not args.size or not args.params:
            raise MatshopError("give --from TEXTURE_SET, or --size and --params for an empty one")
        with naming(what="--params"):
            schema = Schema.from_names(names(args.params) or [])
        height, width = _size(args.size)
        doc = Document(schema, height, width, name=path.name.split(".")[0])
    save_project(doc, path)
    print(f"created {path}: {doc.width}x{doc.height}, {', '.join(doc.schema.names)}")
    return 0


def _size(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not match:
        raise MatshopError(f"--size expects WIDTHxHEIGHT, got {text!r}")
    width, height = int(match[1]), int(match[2])
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        raise MatshopError(f"--size must be 1 to {MAX_SIDE} texels per side, got {text}")
    return height, width
