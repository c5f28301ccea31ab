"""``matshop info PATH``: what is in a texture set (or a project's layer stack)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...io.material_io import LoadReport, load_material
from ...material import Material
from ..options import add_load_options, load_options

_ENCODINGS = {
    "srgb": "sRGB (exact)",
    "gamma22": "gamma 2.2",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Detect the texture set at PATH (a folder or one of its files) and "
        "describe every map: parameter, file, bit depth, color encoding, normal "
        "convention and editing space."
    )
    parser.add_argument(
        "path", type=Path, help="texture folder, one map of the set, or a .matshop project"
    )
    add_load_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...io.inputs import is_project

    if is_project(args.path):  # a project: its size, parameters and layer stack
        from .layer import list_layers

        return list_layers(args.path)
    material, report = load_material(args.path, **load_options(args))
    print(describe(material, report))
    return 0


def _encoding(material: Material, name: str) -> str:
    space = material.schema[name].space.name
    if space in _ENCODINGS:
        return _ENCODINGS[space]
    source = material.sources.get(name, {})
    if "convention" in source:
        return f"{source['convention']} normals ({source['convention_source']})"
    if "inverted" in source:
        return "linear (inverted gloss)"
    if "packed" in source:
        return f"linear ({source['packed']} channel {'RGBA'[source['channel']]})"
    return "linear"


def describe(material: Material, report: LoadReport) -> str:
    """The human-readable summary ``matshop info`` prints."""
    height, width = material.size
    ts = report.texture_set
    lines = [f"texture set {material.name!r} in {ts.folder}: {width} x {height} texels", ""]
    header = ("parameter", "file", "format", "depth", "encoding", "edit space")
    rows = []
    for param in material.schema.parameters:
        source = material.sources.get(param.name, {})
        file = Path(source.get("file", "-")).name
        info = next((i for i in report.infos.values() if Path(i.path).name == file), None)
        rows.append(
            (
                param.name,
                file,
                info.format if info else "-",
                info.bit_depth if info else source.get("bit_depth", "-"),
                _encoding(material, param.name),
                f"{param.space.name} ({param.phys_channels}->{param.edit_channels})",
            )
        )
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    for row in [header, *rows]:
        cells = (str(c).ljust(w) for c, w in zip(row, widths, strict=True))
        lines.append(("  " + "  ".join(cells)).rstrip())
    lines.append("")
    lines.append(
        f"edit vector: {material.schema.edit_width} channels per texel "
        f"({', '.join(f'{n} {s}' for n, s in _slices(material))})"
    )
    lines.extend(report.notes)
    unloaded = sorted((path.name, why) for path, why, _ in ts.unloaded())
    lines.extend(f"not used: {name} ({why})" for name, why in unloaded)
    return "\n".join(lines)


def _slices(material: Material) -> list[tuple[str, str]]:
    return [(name, f"[{sl.start}:{sl.stop}]") for name, sl in material.schema.edit_slices.items()]
