"""``matshop open [PATH]``: start the editor (Qt is imported only when it runs)."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Start the matshop editor. PATH may be a texture set (a folder or one "
        "of its maps) or a .matshop project."
    )
    parser.add_argument(
        "path", type=Path, nargs="?", metavar="PATH", help="texture set or project to open"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...app import launch

    return launch.start(args.path)
