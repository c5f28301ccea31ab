"""``matshop flatten PROJECT OUT``: composite a project and write it as a texture set."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...io.material_io import save_material
from ...progress import progress_bar
from ..options import add_output_options, add_png_level_option
from ..project import about_project, open_project


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Composite every visible layer in edit space, convert back once and "
        "write <material>_<parameter> files into the folder OUT."
    )
    parser.add_argument("project", type=Path, metavar="PROJECT")
    add_output_options(parser)
    add_png_level_option(parser)
    parser.set_defaults(run=run)


@about_project
def run(args: argparse.Namespace) -> int:
    doc, _, _ = open_project(args.project, for_writing=False)
    material = doc.flatten_physical()
    with progress_bar("writing") as report:
        written = save_material(
            material, args.output, overwrite=args.force, progress=report, png_level=args.png_level
        )
    for path in written:
        print(f"wrote {path}")
    return 0
