"""``matshop convert IN OUT``: import -> edit space -> back -> write, with the round-trip error."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from ...io.material_io import load_material, save_material
from ...material import EditMaterial, Material
from ...progress import progress_bar
from ..options import add_load_options, add_output_options, add_png_level_option, load_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Import IN, convert every parameter into its editing space and "
        "back, and write the set into the folder OUT as <material>_<parameter> "
        "files. Prints the worst round-trip error of each parameter."
    )
    parser.add_argument("input", type=Path, metavar="IN", help="texture folder or one map")
    add_output_options(parser)
    add_png_level_option(parser)
    parser.add_argument(
        "--sampled-distribution",
        action="store_true",
        help="replace GGX roughness by a sampled microfacet distribution "
        "(128 bins in theta, written as a named-channel EXR)",
    )
    add_load_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    back, written, errors = convert(
        args.input,
        args.output,
        sampled_distribution=args.sampled_distribution,
        force=args.force,
        png_level=args.png_level,
        **load_options(args),
    )
    print_convention(back)
    for path in written:
        print(f"wrote {path}")
    for name, error in errors.items():
        print(f"round trip {name}: worst error {error}")
    return 0


def convert(
    input_path: Path,
    output: Path,
    *,
    sampled_distribution: bool = False,
    force: bool = False,
    png_level: int | None = None,
    **load: Any,
) -> tuple[Material, list[Path], dict[str, str]]:
    """import -> edit space -> back -> write; returns what was written and the errors.

    ``png_level``: zlib level of the PNGs (default: the writer's). ``load`` are the
    keyword arguments of :func:`~matshop.io.material_io.load_material`.
    """
    material, _ = load_material(input_path, **load)
    if sampled_distribution:
        from ...derive import with_sampled_distribution

        material = with_sampled_distribution(material)
    with progress_bar("to edit space") as report:
        edit = material.to_edit(progress=report)
    with progress_bar("from edit space") as report:
        back = edit.to_physical(progress=report)
    with progress_bar("writing") as report:
        written = save_material(back, output, overwrite=force, progress=report, png_level=png_level)
    return back, written, roundtrip_errors(material, back)


def roundtrip_errors(before: Material, after: Material) -> dict[str, str]:
    """Worst error per parameter, in the unit a user reads it in."""
    errors = {}
    for param in before.schema.parameters:
        a = before.maps[param.name].astype(np.float64)
        b = after.maps[param.name].astype(np.float64)
        if param.name == "normal":
            cos = np.clip(np.sum(a[..., :3] * b[..., :3], axis=-1), -1.0, 1.0)
            errors[param.name] = f"{np.degrees(np.arccos(cos.min())):.3f} deg"
        elif param.phys_channels > 3:
            scale = np.abs(a).sum(axis=-1).mean()
            rel = np.abs(a - b).sum(axis=-1).mean() / max(scale, 1e-12)
            errors[param.name] = f"{100 * rel:.3f}% mean relative L1"
        else:
            errors[param.name] = f"{255 * np.abs(a - b).max():.3f} / 255"
    return errors


def print_convention(material: Material | EditMaterial) -> None:
    """Say how the normal map was read: a wrong guess would flip every file written."""
    from ...io.normal_convention import convention_line

    line = convention_line(material.sources)
    if line is not None:
        print(line)
