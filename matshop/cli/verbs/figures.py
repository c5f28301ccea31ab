"""``matshop figures OUTDIR``: the seed paper's figures with their measurements."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Render the seed paper's figures (interpolation strips, analytic fits, "
        "frame blur and unsharp masking, distribution and profile plots, an op gallery) "
        "into OUTDIR as PNGs, and print the measurement each one makes its point with."
    )
    parser.add_argument("outdir", type=Path, metavar="OUTDIR")
    parser.add_argument(
        "--only", help="comma-separated figure names (e.g. fig3,fig5); default: all"
    )
    parser.add_argument(
        "--data",
        type=Path,
        help="texture set for the gallery (default: ../shared/data/chessboard if present, "
        "else the bundled sample)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...figures import make_figures

    only = [name.strip() for name in args.only.split(",")] if args.only else None
    results = make_figures(args.outdir, only=only, data=args.data)
    for result in results:
        print(f"{result.name}: {result.path.name}: {result.measurement}")
    return 0
