"""``matshop spaces``: every editing space, the parameters it is the default for, its aliases."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = "List every editing space with its widths and meaning."
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...material import PARAMETER_KINDS
    from ...spaces import all_spaces

    spaces = sorted(all_spaces().items())
    defaults: dict[str, list[str]] = {}
    for kind in PARAMETER_KINDS.values():
        defaults.setdefault(kind.default_space, []).append(kind.name)
    # several names may register one space (same kind, same meaning): the first
    # name in order is the space, the others its aliases
    first_name: dict[tuple, str] = {}
    for name, space in spaces:
        first_name.setdefault((type(space), space.description), name)
    rows = [("space", "channels", "default for", "meaning")]
    for name, space in spaces:
        primary = first_name[(type(space), space.description)]
        meaning = space.description if primary == name else f"alias of {primary}"
        channels = f"{space.phys_channels} -> {space.edit_channels}"
        rows.append((name, channels, ", ".join(defaults.get(name, [])) or "-", meaning))
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    for row in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(row[:3], widths, strict=True)), row[3])
    return 0
