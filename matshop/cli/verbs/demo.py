"""``matshop demo``: the headless pipeline on the bundled sample."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ...errors import MatshopError
from ...io.material_io import load_material
from ...material import Material
from .convert import convert
from .info import describe

#: the repository's sample (scripts/make_sample.py writes it)
SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "sample"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Run matshop on the bundled sample: describe it, convert it "
        "through edit space and back, and derive a sampled-distribution set."
    )
    parser.add_argument("sample", type=Path, nargs="?", default=None, help="texture set")
    parser.add_argument(
        "--out", type=Path, default=Path("matshop-demo"), help="output folder (./matshop-demo)"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    sample = args.sample or SAMPLE
    if not sample.exists():
        raise MatshopError("bundled sample not found (run scripts/make_sample.py)", sample)
    material, report = load_material(sample)
    print(describe(material, report))
    print()
    for label, sub, sampled in (
        ("round trip through edit space", "roundtrip", False),
        ("with a sampled 128-bin distribution", "sampled", True),
    ):
        back, written, errors = convert(
            sample, args.out / sub, sampled_distribution=sampled, force=True
        )
        print(f"{label}: {len(written)} files in {args.out / sub}")
        for name, error in errors.items():
            print(f"  {name:14s} worst error {error}")
    _demo_layers(material, args.out)
    return 0


def _demo_layers(material: Material, out: Path) -> None:
    """A layered project: a bronze brush stroke, then rust through a gradient mask."""
    from ...io.images import write_image
    from ...io.material_io import save_material
    from ...io.project import save_project
    from ...layers import AddLayer, Document, History, SetMask
    from ...paint import Brush, StrokeSample, StrokeSession, Swatch
    from ...render.render import render

    doc = Document.from_material(material)
    history = History(doc)
    height, width = doc.size
    names = set(doc.schema.names)
    bronze = Swatch(
        "bronze",
        {
            k: v
            for k, v in {
                "base_color": (0.45, 0.25, 0.08),
                "roughness": (0.3,),
                "metallic": (1.0,),
                "normal": (0.0, 0.0, 1.0),
            }.items()
            if k in names
        },
    )
    paint = doc.new_paint_layer("Bronze", parameters=bronze.parameters)
    history.push(AddLayer(paint))
    stroke = StrokeSession(
        doc, paint.id, Brush(radius_px=width / 40, hardness=0.7), swatch=bronze, history=history
    )
    t = np.linspace(0.0, 1.0, 64)
    stroke.add(
        StrokeSample(width * (0.1 + 0.8 * x), height * (0.5 + 0.3 * np.sin(6 * x)), 0.3 + 0.7 * x)
        for x in t
    )
    stroke.end()
    if {"base_color", "roughness"} <= names:
        rust_value, _ = Swatch(
            "rust", {"base_color": (0.3, 0.08, 0.03), "roughness": (0.85,)}
        ).edit_values(doc.schema)
        rust = doc.new_fill_layer("Rust", value=rust_value, parameters=["base_color", "roughness"])
        history.push(AddLayer(rust))
        # a smooth periodic gradient across the (tiling) texture: no seam at its edge
        ramp = (0.5 - 0.5 * np.cos(np.linspace(0, 2 * np.pi, width, endpoint=False))).astype(
            np.float32
        )
        history.push(SetMask(rust.id, doc.new_mask(array=np.repeat(ramp[None, :], height, 0))))
    project = out / "layered.matshop"
    save_project(doc, project)
    flattened = doc.flatten_physical()
    written = save_material(flattened, out / "layered", overwrite=True)
    image = render(flattened, scene="sphere", size=256)
    write_image(out / "layered_ball.png", image.display()[..., :3])
    print(
        f"layered project (a bronze stroke, rust through a gradient mask): {project}, "
        f"flattened to {len(written)} files in {out / 'layered'}, "
        f"rendered to {out / 'layered_ball.png'}"
    )
