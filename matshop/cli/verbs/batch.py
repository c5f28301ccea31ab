"""``matshop batch RECIPE INPUT... OUT``: a recipe over a library, on Dask.

Dask loads only when a batch runs, so ``matshop batch --help`` stays fast.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

_DESCRIPTION = """\
Apply RECIPE to every texture set under the INPUT folders (searched recursively;
a folder may hold several materials) as one task per set on Dask distributed: a
local cluster of --workers processes, or the workers of a running scheduler.
Each set is read, edited and written all-or-nothing into OUT, mirroring the
library's folders; OUT/batch-report.jsonl gets one line per set. A failing set
never stops the others. Exit status: 0 all ok, 1 some failed, 2 bad recipe or
arguments.
"""

_EPILOG = """\
recipe (TOML, the CLI's words; paths relative to the recipe):
  [[ops]]
  op = "blur"
  sigma_px = 2
  params = ["normal", "roughness"]
  mask = "masks/edges.png"

  [export]                    # optional: preset, size, glb, mtlx, strict
  preset = "gltf"

examples:
  matshop batch cleanup.toml library/ out/ --workers 4
  matshop batch cleanup.toml library/ --out out/ --scheduler tcp://10.0.0.5:8786
  matshop batch cleanup.toml library/ out/ --pattern "ambientcg/*" --resume
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = _DESCRIPTION
    parser.epilog = _EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("recipe", type=Path, metavar="RECIPE", help="TOML recipe")
    parser.add_argument(
        "inputs",
        type=Path,
        nargs="+",
        metavar="INPUT",
        help="library folders or maps of sets; without --out the last one is OUT",
    )
    parser.add_argument("--out", type=Path, metavar="OUT", help="output folder")
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--workers", type=int, metavar="N", help="local worker processes (default: the cores)"
    )
    where.add_argument(
        "--scheduler", metavar="ADDRESS", help="a running Dask scheduler, tcp://HOST:PORT"
    )
    parser.add_argument("--pattern", metavar="GLOB", help="only sets whose folder/path matches")
    parser.add_argument("--preset", help="export preset (over the recipe's [export])")
    parser.add_argument("--size", type=int, metavar="N", help="export longest side, power of two")
    parser.add_argument(
        "--resume", action="store_true", help="skip sets the report in OUT lists as done"
    )
    parser.add_argument("--force", action="store_true", help="overwrite existing files")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from ...batch.runner import run_batch
    from ...errors import MatshopError

    inputs = list(args.inputs)
    out = args.out
    if out is None:
        if len(inputs) < 2:
            raise MatshopError("batch needs an output folder: RECIPE INPUT... OUT, or --out DIR")
        out = inputs.pop()

    def echo(line: str) -> None:
        tqdm.write(line, file=sys.stdout)
        if not line.startswith("ok"):
            print(f"matshop: {line}", file=sys.stderr)

    report = run_batch(
        args.recipe,
        inputs,
        out,
        workers=args.workers,
        scheduler=args.scheduler,
        pattern=args.pattern,
        resume=args.resume,
        force=args.force,
        preset=args.preset,
        size=args.size,
        echo=echo,
        progress=sys.stderr.isatty(),
    )
    print(report.summary())
    return report.exit_status
