"""The ``matshop`` command.

Every verb is a thin shell over the same engine the editor uses. User
errors (bad files, bad options) print one line and exit with status 2;
nothing is written when a command fails.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from . import __version__
from .errors import MatshopError

EXIT_USAGE = 2

_DESCRIPTION = """\
matshop edits spatially-varying materials (texture sets) in editing spaces,
where plain image operations respect what each parameter means.

examples:
  matshop info path/to/textures/            what is in a texture set
  matshop convert in/ out/                  import -> edit space -> back -> write
  matshop convert in/ out/ --sampled-distribution
                                            replace GGX roughness by a sampled
                                            128-bin microfacet distribution (EXR)
  matshop demo                              the headless pipeline on the bundled sample
"""


# Verbs that live beside their engine package. Each module has
# ``add_parsers(verbs)``, which may import only the standard library (so that
# `matshop --help` stays fast), and ``run(args) -> int``; every parser it adds
# sets ``verb_module`` through ``set_defaults`` so ``main`` can dispatch to it.
_VERB_MODULES = (
    "matshop.export.verbs",
    "matshop.render.verbs",
    "matshop.project_verbs",
    "matshop.batch.verbs",
    "matshop.app.verbs",
)


def _has_display() -> bool:
    """Whether a bare ``matshop`` can open a window (else it prints its help)."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _repo_sample() -> Path:
    return Path(__file__).resolve().parent.parent / "resources" / "sample"


def _parse_spaces(pairs: Sequence[str]) -> dict[str, str]:
    from .material import PARAMETER_KINDS  # not at import: `matshop --help` stays fast
    from .spaces import all_spaces

    spaces = {}
    for pair in pairs:
        param, sep, space = (part.strip() for part in pair.partition("="))
        if not sep or not param or not space:
            raise MatshopError(f"--space expects PARAMETER=SPACE, got {pair!r}")
        if param not in PARAMETER_KINDS:
            known = ", ".join(PARAMETER_KINDS)
            raise MatshopError(f"--space {pair}: unknown parameter {param!r} (known: {known})")
        if space not in all_spaces():
            raise MatshopError(
                f"--space {pair}: unknown editing space {space!r} (see `matshop spaces`)"
            )
        spaces[param] = space
    return spaces


def _parse_maps(pairs: Sequence[str]) -> dict[str, Path | None]:
    maps: dict[str, Path | None] = {}
    for pair in pairs:
        slot, sep, file = pair.partition("=")
        if not sep or not slot.strip():
            raise MatshopError(
                f"--map expects SLOT=FILE (FILE empty: leave the slot out), got {pair!r}"
            )
        maps[slot.strip()] = Path(file) if file else None
    return maps


def check_number(value: float, option: str, lo: float, hi: float) -> float:
    """``value`` of a numeric option if finite and within [lo, hi]; else a one-line error."""
    if not (math.isfinite(value) and lo <= value <= hi):
        raise MatshopError(f"{option} must be a number from {lo:g} to {hi:g}, got {value:g}")
    return value


def add_load_options(parser: argparse.ArgumentParser) -> None:
    """Options of every verb that loads a texture set."""
    parser.add_argument(
        "--space",
        action="append",
        default=[],
        metavar="PARAM=SPACE",
        help="editing space for one parameter, e.g. roughness=ggx_alpha or "
        "base_color=gamma22 (repeatable; see `matshop spaces`)",
    )
    parser.add_argument(
        "--normal-convention",
        choices=("opengl", "directx"),
        help="green channel convention of the normal map (default: from the file "
        "name, else a confident guess from the map, else opengl)",
    )
    parser.add_argument(
        "--material",
        metavar="NAME",
        help="which material of a folder that holds several (`matshop info FOLDER` lists them)",
    )
    parser.add_argument(
        "--map",
        action="append",
        default=[],
        metavar="SLOT=FILE",
        help="load FILE as SLOT, adding to or overriding what detection found, e.g. "
        "metallic=../shared/king_metallic.jpg (repeatable; SLOT= leaves a slot out)",
    )


def load_options(args: argparse.Namespace) -> dict[str, Any]:
    """The keyword arguments of ``load_material`` that :func:`add_load_options` parsed."""
    return {
        "spaces": _parse_spaces(args.space),
        "normal_convention": args.normal_convention,
        "material": args.material,
        "maps": _parse_maps(args.map),
    }


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="matshop",
        description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"matshop {__version__}")
    verbs = parser.add_subparsers(dest="verb", metavar="COMMAND")

    info = verbs.add_parser(
        "info",
        help="show the parameters, sizes and encodings of a texture set",
        description="Detect the texture set at PATH (a folder or one of its files) and "
        "describe every map: parameter, file, bit depth, color encoding, normal "
        "convention and editing space.",
    )
    info.add_argument(
        "path", type=Path, help="texture folder, one map of the set, or a .matshop project"
    )
    add_load_options(info)

    convert = verbs.add_parser(
        "convert",
        help="import a texture set, convert to edit space and back, write it",
        description="Import IN, convert every parameter into its editing space and "
        "back, and write the set into the folder OUT as <material>_<parameter> "
        "files. Prints the worst round-trip error of each parameter.",
    )
    convert.add_argument("input", type=Path, metavar="IN", help="texture folder or one map")
    convert.add_argument("output", type=Path, metavar="OUT", help="output folder")
    convert.add_argument(
        "--sampled-distribution",
        action="store_true",
        help="replace GGX roughness by a sampled microfacet distribution "
        "(128 bins in theta, written as a named-channel EXR)",
    )
    convert.add_argument("--force", action="store_true", help="overwrite existing files")
    add_load_options(convert)

    apply = verbs.add_parser(
        "apply",
        help="apply image operations in edit space and write the result",
        description="Import IN, apply each --op in order in edit space on the selected "
        "parameters, convert back and write the set into the folder OUT. "
        "Run `matshop ops` for the operations and their parameters.",
        epilog="example: matshop apply in/ out/ --op blur sigma_px=4 --op scale factor=0.8 "
        "--params normal,roughness --mask mask.png",
    )
    apply.add_argument("input", type=Path, metavar="IN", help="texture folder or one map")
    apply.add_argument("output", type=Path, metavar="OUT", help="output folder")
    apply.add_argument(
        "--op",
        nargs="+",
        action="append",
        required=True,
        metavar=("NAME", "KEY=VALUE"),
        help="an operation and its parameters (repeatable; applied in order)",
    )
    apply.add_argument(
        "--params",
        help="comma-separated parameters to edit, e.g. base_color,roughness,normal "
        "(default: all; aliases kd, ks, albedo work)",
    )
    apply.add_argument("--mask", type=Path, help="grayscale image blending every op's result")
    apply.add_argument("--force", action="store_true", help="overwrite existing files")
    add_load_options(apply)

    verbs.add_parser(
        "ops",
        help="list the operations and their parameters",
        description="List every operation with its parameters, units, defaults and ranges.",
    )

    verbs.add_parser(
        "spaces",
        help="list the editing spaces",
        description="List every editing space with its widths and meaning.",
    )

    demo = verbs.add_parser(
        "demo",
        help="run the main job on the bundled sample material",
        description="Run matshop on the bundled sample: describe it, convert it "
        "through edit space and back, and derive a sampled-distribution set.",
    )
    demo.add_argument("sample", type=Path, nargs="?", default=None, help="texture set")
    demo.add_argument(
        "--out", type=Path, default=Path("matshop-demo"), help="output folder (./matshop-demo)"
    )
    for module_name in _VERB_MODULES:
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name is None or not module_name.startswith(exc.name):
                raise
            continue  # a verb package not built yet
        module.add_parsers(verbs)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.verb is None:
        if _has_display() and importlib.util.find_spec("PySide6") is not None:
            return importlib.import_module("matshop.app.verbs").start()
        parser.print_help()
        return EXIT_USAGE
    from . import commands  # keeps `matshop --help` fast: no numpy/OIIO import

    try:
        module_name = getattr(args, "verb_module", None)
        if module_name is not None:
            return importlib.import_module(module_name).run(args)
        return commands.run(args)
    except MatshopError as exc:
        print(f"matshop: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("matshop: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # `matshop info | head`: quiet exit, no traceback
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    raise SystemExit(main())
