"""The option groups several verbs share, each defined once.

- load options (``--space``, ``--normal-convention``, ``--material``, ``--map``):
  how every verb that reads a texture set reads it; :func:`load_options` turns
  them into the keyword arguments of :func:`matshop.io.material_io.load_material`.
- output options (``OUT``, ``--force``): where a verb that writes files writes
  them, and whether it may replace what is there; ``--png-level`` how hard its PNGs
  are compressed.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from ..io.png_settings import PNG_LEVEL


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
        "spaces": parse_spaces(args.space),
        "normal_convention": args.normal_convention,
        "material": args.material,
        "maps": parse_maps(args.map),
    }


def parse_spaces(pairs: Iterable[str]) -> dict[str, str]:
    """``--space PARAM=SPACE`` words -> {parameter: space}, each name checked."""
    from ..material import PARAMETER_KINDS  # not at import: `matshop VERB --help` stays fast
    from ..spaces import all_spaces

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


def parse_maps(pairs: Sequence[str]) -> dict[str, Path | None]:
    """``--map SLOT=FILE`` words -> {slot: file, or None to leave the slot out}."""
    maps: dict[str, Path | None] = {}
    for pair in pairs:
        slot, sep, file = pair.partition("=")
        if not sep or not slot.strip():
            raise MatshopError(
                f"--map expects SLOT=FILE (FILE empty: leave the slot out), got {pair!r}"
            )
        maps[slot.strip()] = Path(file) if file else None
    return maps


def add_png_level_option(parser: argparse.ArgumentParser, *, default: str | None = None) -> None:
    """``--png-level N``: the zlib level of the PNGs a verb writes (None: the writer's default).

    ``default`` is the help's word for what happens without the option.
    """
    parser.add_argument(
        "--png-level",
        type=int,
        choices=range(10),
        metavar="N",
        help=f"zlib level of PNG files, 0 (fastest, largest) to 9 (slowest, smallest); "
        f"default: {default or PNG_LEVEL}",
    )


def add_output_options(
    parser: argparse.ArgumentParser,
    *,
    what: str = "output folder",
    optional: bool = False,
    force_help: str = "overwrite existing files",
) -> None:
    """``OUT`` (where the verb writes) and ``--force`` (replace what is there)."""
    parser.add_argument(
        "output", type=Path, metavar="OUT", nargs="?" if optional else None, help=what
    )
    parser.add_argument("--force", action="store_true", help=force_help)
