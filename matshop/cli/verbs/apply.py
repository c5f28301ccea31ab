"""``matshop apply IN OUT --op NAME KEY=VALUE ...``: image operations in edit space."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...progress import progress_bar
from ..options import add_load_options, add_output_options, add_png_level_option, load_options
from .convert import print_convention


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Import IN, apply each --op in order in edit space on the selected "
        "parameters, convert back and write the set into the folder OUT. "
        "Run `matshop ops` for the operations and their parameters."
    )
    parser.epilog = (
        "example: matshop apply in/ out/ --op blur sigma_px=4 --op scale factor=0.8 "
        "--params normal,roughness --mask mask.png"
    )
    parser.add_argument("input", type=Path, metavar="IN", help="texture folder or one map")
    add_output_options(parser)
    add_png_level_option(parser)
    parser.add_argument(
        "--op",
        nargs="+",
        action="append",
        required=True,
        metavar=("NAME", "KEY=VALUE"),
        help="an operation and its parameters (repeatable; applied in order)",
    )
    parser.add_argument(
        "--params",
        help="comma-separated parameters to edit, e.g. base_color,roughness,normal "
        "(default: all; aliases kd, ks, albedo work)",
    )
    parser.add_argument("--mask", type=Path, help="grayscale image blending every op's result")
    add_load_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...api import EditableMaterial
    from ...opchain import run_steps, step_from_words
    from ...ops import get_op

    # parse every op before any work, so a typo in the last one costs nothing
    params = None if args.params is None else args.params.split(",")
    steps = [step_from_words(words, params=params, mask=args.mask) for words in args.op]
    m = EditableMaterial.from_path(args.input, **load_options(args))
    print_convention(m.edit)
    with progress_bar("applying") as report:
        run_steps(m, steps, progress=report)
    with progress_bar("writing") as report:
        written = m.save(
            args.output, overwrite=args.force, progress=report, png_level=args.png_level
        )
    for name, bound, names in m.history:
        spec = get_op(name)
        settings = " ".join(f"{k}={spec.param(k).format(v)}" for k, v in bound.items())
        print(f"applied {name} {settings} to {', '.join(names)}")
    for path in written:
        print(f"wrote {path}")
    return 0
