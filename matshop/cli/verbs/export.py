"""``matshop export IN OUT --preset NAME``: what an engine loads, as a preset says.

numpy and OpenImageIO load only when an export runs, so ``matshop export --help``
stays fast.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...errors import MatshopError
from ..options import add_load_options, add_output_options, add_png_level_option, load_options

#: the choices of --mtlx-shader (mtlx.SHADING_MODELS' names; kept here so --help stays light)
SHADING_MODEL_NAMES = ("open_pbr_surface", "standard_surface", "gltf_pbr")
#: --keep-variance in words; the editor's export dialog says the same
KEEP_VARIANCE_HELP = "keep normal variance in roughness when downsizing"

_DESCRIPTION = """\
Load the texture set IN (a folder or one of its maps) and write what an engine
loads into the folder OUT, as the preset says: file names, channel packing
(ORM, Unity metallic-smoothness and mask maps), color encoding, bit depth,
format and normal convention. 8-bit outputs are dithered; nothing is written
unless every file succeeds; existing files are replaced only with --force.
"""

_EPILOG = """\
examples:
  matshop export in/ out/ --preset unreal
  matshop export in/ out/ --preset gltf --glb --mtlx --size 1024
  matshop export in/ out/ --preset unreal --usdz --mesh model.obj
  matshop export in/ out/ --preset-file studio.toml --strict
  matshop export --list-presets
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = _DESCRIPTION
    parser.epilog = _EPILOG
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument(
        "input", type=Path, nargs="?", metavar="IN", help="texture folder, map or .matshop project"
    )
    add_output_options(parser, optional=True)
    add_png_level_option(parser, default="the preset's pngLevel, else the built-in level")
    parser.add_argument("--preset", help="built-in preset name (see --list-presets)")
    parser.add_argument(
        "--preset-file", type=Path, help="your own preset, JSON or TOML (Substance-like shape)"
    )
    parser.add_argument(
        "--list-presets", action="store_true", help="list the built-in presets and exit"
    )
    parser.add_argument(
        "--size", type=int, metavar="N", help="longest side in texels, a power of two"
    )
    parser.add_argument(
        "--keep-variance",
        action=argparse.BooleanOptionalAction,
        help=f"{KEEP_VARIANCE_HELP} (with --size N): widen the roughness by the normal "
        "detail the reduction removes, so the smaller set keeps the look from afar "
        "(default: the preset's keepVariance, false in the built-in presets)",
    )
    parser.add_argument("--name", help="material name in file names (default: the set's name)")
    parser.add_argument("--glb", action="store_true", help="also write <name>.glb with a mesh")
    parser.add_argument(
        "--mesh", type=Path, help="Wavefront OBJ for --glb and --usd (default: a UV sphere)"
    )
    parser.add_argument(
        "--mtlx", action="store_true", help="also write <name>.mtlx (a MaterialX material)"
    )
    parser.add_argument(
        "--mtlx-shader",
        choices=SHADING_MODEL_NAMES,
        default=SHADING_MODEL_NAMES[0],
        help="the MaterialX surface shader of --mtlx and of the USD's mtlx context "
        "(default: open_pbr_surface, OpenPBR Surface)",
    )
    parser.add_argument(
        "--usd",
        action="store_true",
        help="also write <name>.usda: the mesh with a UsdPreviewSurface material reading the "
        "textures and the MaterialX material as its mtlx render context",
    )
    parser.add_argument(
        "--usdz", action="store_true", help="also write <name>.usdz (the .usda and its textures)"
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="fail when the preset needs a parameter the material lacks "
        "(default: fill it with the engine's default and say so)",
    )
    add_load_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...export.presets import builtin_preset_names, load_preset

    if args.list_presets:
        for name in builtin_preset_names():
            preset = load_preset(name)
            print(f"{name:12s} {preset.description}")
        return 0
    if args.input is None or args.output is None:
        raise MatshopError("export needs IN and OUT (or --list-presets)")
    if (args.preset is None) == (args.preset_file is None):
        raise MatshopError("give exactly one of --preset NAME or --preset-file FILE")
    if args.keep_variance and args.size is None:
        raise MatshopError("--keep-variance only applies with --size N")
    if args.mesh is not None and not (args.glb or args.usd or args.usdz):
        raise MatshopError("--mesh is only used with --glb, --usd or --usdz")
    preset = load_preset(args.preset, path=args.preset_file)

    from ...export.core import export_material
    from ...io.inputs import load_flattened
    from ...io.normal_convention import convention_line

    material = load_flattened(args.input, **load_options(args))
    summary = export_material(
        material,
        preset,
        args.output,
        name=args.name,
        size=args.size,
        keep_variance=args.keep_variance,
        strict=args.strict,
        force=args.force,
        glb=args.glb,
        mesh=args.mesh,
        mtlx=args.mtlx,
        usd=args.usd,
        usdz=args.usdz,
        mtlx_shader=args.mtlx_shader,
        png_level=args.png_level,
    )
    read_as = convention_line(material.sources)
    for line in ([read_as] if read_as else []) + summary.lines():
        print(line)
    return 0
