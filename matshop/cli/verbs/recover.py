"""``matshop recover PROJECT``: replace a project with its newer autosave."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...errors import MatshopError
from ...io.project import find_recovery, load_project, save_project
from ..project import about_project


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "If PROJECT has an autosave newer than itself (the editor writes "
        "one while you work), replace the project with it, atomically."
    )
    parser.add_argument("project", type=Path, metavar="PROJECT")
    parser.set_defaults(run=run)


@about_project
def run(args: argparse.Namespace) -> int:
    recovery = find_recovery(args.project)
    if recovery is None:
        raise MatshopError("has no autosave newer than itself", args.project)
    project = load_project(recovery)  # a damaged autosave fails here, the project untouched
    save_project(project.document, args.project, settings=project.settings)  # discards it
    print(f"restored {args.project} from {recovery.name}")
    return 0
