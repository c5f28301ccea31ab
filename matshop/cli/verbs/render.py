"""``matshop render IN OUT``: a texture set on a sphere, a swatch or a mesh, as an image."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...errors import MatshopError
from ..options import add_load_options, add_output_options, load_options

if TYPE_CHECKING:
    from ...render.environment_choice import EnvironmentChoice


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Render the texture set IN with the reference renderer (microfacet "
        "BRDF with the set's lobe, normal/tangent frames, SubEdit subsurface when the "
        "set has profiles) under an HDR environment and write a tone-mapped sRGB image."
    )
    parser.epilog = (
        "examples: matshop render rock/ rock.png --size 512 | "
        "matshop render rock/ swatch.png --scene swatch | "
        "matshop render rock/ m.png --scene mesh.obj --env sky.exr --light=-1,1,1:3 "
        "(a leading minus needs the = form)"
    )
    parser.add_argument(
        "input",
        type=Path,
        metavar="IN",
        help="texture folder, one map, or a .matshop project (flattened)",
    )
    add_output_options(
        parser, what="output image (.png, .exr, ...)", force_help="overwrite an existing image"
    )
    parser.add_argument(
        "--scene", default="sphere", help="sphere (default), swatch, or a path to an .obj mesh"
    )
    parser.add_argument(
        "--env",
        default="studio",
        help="studio (default), sky, uniform (radiance 1), uniform:L, or an equirectangular "
        ".hdr/.exr file (the editor's View > Lighting offers the same)",
    )
    parser.add_argument(
        "--env-rotation",
        type=float,
        default=0.0,
        metavar="DEG",
        help="turn the environment about up (+y) by DEG degrees; positive carries it to the "
        "camera's right (0)",
    )
    parser.add_argument("--size", type=int, default=512, help="image size in pixels (512)")
    parser.add_argument(
        "--samples", type=int, default=32, help="environment samples per pixel (32)"
    )
    parser.add_argument(
        "--exposure",
        type=float,
        default=0.0,
        help="exposure in stops: the linear radiance times 2^stops before the tone map, "
        "also in an .exr/.hdr output (0)",
    )
    parser.add_argument(
        "--tonemap", choices=("aces", "linear"), default="aces", help="tone curve (aces)"
    )
    parser.add_argument(
        "--light",
        action="append",
        default=[],
        metavar="X,Y,Z[:E]",
        help="a directional light towards X,Y,Z (camera on +z, y up) with irradiance E "
        "(one value or R,G,B; default 3); repeatable",
    )
    parser.add_argument(
        "--no-env", action="store_true", help="directional lights only (no environment light)"
    )
    parser.add_argument(
        "--background",
        default="environment",
        help="environment (default), transparent, or R,G,B linear radiance",
    )
    parser.add_argument(
        "--tiles", type=float, help="texture repeats (sphere: around the equator; default 2)"
    )
    add_load_options(parser)
    parser.set_defaults(run=run)


def check_number(value: float, option: str, lo: float, hi: float) -> float:
    """``value`` of a numeric option if finite and within [lo, hi]; else a one-line error."""
    if not (math.isfinite(value) and lo <= value <= hi):
        raise MatshopError(f"{option} must be a number from {lo:g} to {hi:g}, got {value:g}")
    return value


def _floats(text: str, what: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise MatshopError(f"{what} expects comma-separated numbers, got {text!r}") from None
    return [check_number(v, what, -1e6, 1e6) for v in values]


def parse_light(text: str):
    """``X,Y,Z[:E]`` or ``X,Y,Z:R,G,B`` -> DirectionalLight."""
    from ...render.integrator import DirectionalLight

    direction, _, energy = text.partition(":")
    xyz = _floats(direction, "--light")
    if len(xyz) != 3 or not any(xyz):
        raise MatshopError(f"--light needs a non-zero direction X,Y,Z, got {direction!r}")
    e = _floats(energy, "--light") if energy else [3.0]
    if len(e) not in (1, 3) or min(e) < 0:
        raise MatshopError(
            f"--light irradiance must be one or three non-negative values, got {energy!r}"
        )
    return DirectionalLight(tuple(xyz), tuple(e * 3 if len(e) == 1 else e))


def describe(choice: EnvironmentChoice) -> str:
    """The environment part of the summary line: its source, turn and exposure."""
    turn = f" turned {choice.rotation_deg:g} deg" if choice.rotation_deg else ""
    stops = f" at {choice.exposure_stops:+g} stops" if choice.exposure_stops else ""
    return f"{choice.source}{turn}{stops}"


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ...io.images import write_image
    from ...io.inputs import load_flattened
    from ...progress import progress_bar
    from ...render.environment_choice import EXPOSURE_RANGE_STOPS, EnvironmentChoice
    from ...render.render import render

    if args.output.exists() and not args.force:
        raise MatshopError("exists (use --force to overwrite)", args.output)
    if args.size < 1 or args.size > 8192:
        raise MatshopError(f"--size must be in 1..8192, got {args.size}")
    if args.samples < 1 or args.samples > 4096:
        raise MatshopError(f"--samples must be in 1..4096, got {args.samples}")
    scene = args.scene
    if scene not in ("sphere", "swatch"):
        if not Path(scene).is_file():
            raise MatshopError("no such mesh (use sphere, swatch or an .obj file)", scene)
    lights = tuple(parse_light(t) for t in args.light)
    if args.no_env and not lights:
        raise MatshopError("--no-env needs at least one --light")
    background: Any = args.background
    transparent = background == "transparent"
    if transparent:
        background = (0.0, 0.0, 0.0)
    elif background != "environment":
        rgb = _floats(background, "--background")
        if len(rgb) != 3:
            raise MatshopError(f"--background expects R,G,B, got {args.background!r}")
        background = tuple(rgb)
    options = {}
    check_number(args.exposure, "--exposure", *EXPOSURE_RANGE_STOPS)
    check_number(args.env_rotation, "--env-rotation", -1e6, 1e6)
    choice = EnvironmentChoice.parse(args.env, args.env_rotation, args.exposure)
    if args.tiles is not None:
        check_number(args.tiles, "--tiles", 1e-3, 1e4)
        # a sphere is twice as long around as from pole to pole
        options["tiles"] = (args.tiles, args.tiles / 2.0) if scene == "sphere" else args.tiles
    material = load_flattened(args.input, **load_options(args))
    environment = None if args.no_env else choice.load()
    with progress_bar(f"render {args.size}x{args.size}") as report:
        image = render(
            material,
            scene=scene,
            size=args.size,
            environment=environment,
            environment_scale=0.0 if args.no_env else 1.0,
            lights=lights,
            samples=args.samples,
            background=background,
            progress=report,
            scene_options=options,
        )
    suffix = args.output.suffix.lower()
    if suffix in (".exr", ".hdr"):
        # what the tone map would be given: the radiance at the chosen exposure
        radiance = image.radiance * np.float32(2.0**choice.exposure_stops)
        pixels = np.concatenate([radiance, image.alpha[..., None]], axis=2)
        write_image(args.output, pixels if transparent else radiance, bit_depth="float")
    else:
        pixels = image.display(exposure=choice.exposure_stops, tonemap=args.tonemap)
        write_image(args.output, pixels if transparent else pixels[..., :3])
    covered = image.radiance[image.alpha > 0]
    mean = covered.mean(axis=0) if covered.size else np.zeros(3)
    print(
        f"{args.output}: {args.size}x{args.size} {args.scene}, "
        f"env {'none' if args.no_env else describe(choice)},"
        f" {len(lights)} light(s); mean linear radiance on the object "
        f"{mean[0]:.3f} {mean[1]:.3f} {mean[2]:.3f}"
    )
    return 0
