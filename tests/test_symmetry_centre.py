"""A moved mirror centre: a symmetric stroke paints, texel for texel, the stroke and an
independent second stroke through the points ``2c - x`` the test computes itself; past
the texture's border that second stroke wraps (tiling, the default) or is clipped
(``wrap=False``), and the mirror image does the same. Stroke files carry the centre."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.project import load_project
from matshop.layers import AddLayer, Document, History, Rect
from matshop.material import Material, Schema
from matshop.paint import Brush, StrokeSample, Swatch, Symmetry, paint_stroke

SCHEMA = Schema.from_names(["base_color", "roughness"])
WIDTH, HEIGHT = 96, 80
BRONZE = Swatch("bronze", {"base_color": (0.45, 0.25, 0.08), "roughness": (0.3,)})
BRUSH = Brush(radius_px=5.5, hardness=0.4, spacing=0.2, flow=0.7)
FULL = Rect(0, 0, WIDTH, HEIGHT)
# a wiggle right of x = 50 and below y = 40
PATH = [(52 + 3 * i, 44 + 10 * np.sin(i / 3.0) ** 2, 0.4 + 0.05 * i) for i in range(11)]


def painted(points, *, wrap: bool, symmetry: Symmetry | None = None) -> np.ndarray:
    rng = np.random.default_rng(3)
    maps = {
        "base_color": rng.uniform(0.05, 0.9, (HEIGHT, WIDTH, 3)).astype(np.float32),
        "roughness": rng.uniform(0.1, 0.9, (HEIGHT, WIDTH, 1)).astype(np.float32),
    }
    doc = Document.from_material(Material("base", SCHEMA, maps), tile_size=32)
    history = History(doc)
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    samples = [StrokeSample(*p) for p in points]
    options = {} if symmetry is None else {"symmetry": symmetry}
    paint_stroke(doc, layer.id, samples, BRUSH, swatch=BRONZE, wrap=wrap, **options)
    return doc.layer(layer.id).coverage(FULL)


def union(*images: np.ndarray) -> np.ndarray:
    """What alpha-over of independent strokes leaves: 1 - prod(1 - a)."""
    return 1.0 - np.prod([1.0 - a for a in images], axis=0)


@pytest.mark.parametrize(
    ("cx", "cy", "wrap"),
    [
        (40.5, 30.0, True),  # mirror images inside the texture, the centre a texel centre
        (23.0, 17.5, True),  # past the left and top borders: wrapped to the other side
        (23.0, 17.5, False),  # the same, clipped at the border
    ],
)
def test_a_moved_centre_mirrors_to_2c_minus_x(cx: float, cy: float, wrap: bool) -> None:
    symmetry = Symmetry(True, True, centre=(cx, cy))
    mirrored = painted(PATH, wrap=wrap, symmetry=symmetry)
    # the truth: the same stroke plus independent strokes through the mirrored points
    flips = [
        [(2 * cx - x, y, p) for x, y, p in PATH],
        [(x, 2 * cy - y, p) for x, y, p in PATH],
        [(2 * cx - x, 2 * cy - y, p) for x, y, p in PATH],
    ]
    strokes = [painted(PATH, wrap=wrap)] + [painted(f, wrap=wrap) for f in flips]
    np.testing.assert_allclose(mirrored, union(*strokes), atol=2e-6, rtol=0)
    if wrap:  # nothing lost at the border: all four images carry the same paint
        assert all(np.isclose(s.sum(), strokes[0].sum(), rtol=1e-5) for s in strokes)
    elif cx < 30:  # clipped: the images past the border lose what lies beyond it
        assert strokes[1].sum() < 0.8 * strokes[0].sum()


def test_the_centre_snaps_to_half_texels_and_stays_inside() -> None:
    assert Symmetry(True, False, (30.3, 10.74)).centre == (30.5, 10.5)
    assert Symmetry(True, False, (30.2, 10.76)).centre == (30.0, 11.0)
    assert Symmetry(True).centre_in(96, 80) == (48.0, 40.0)
    assert Symmetry(True, True, (-5.0, 500.0)).centre_in(96, 80) == (0.0, 80.0)
    assert Symmetry.parse("x", (12, 7)) == Symmetry(True, False, (12.0, 7.0))
    with pytest.raises(ValueError, match="symmetry centre"):
        Symmetry(True, False, (float("nan"), 1.0))


# ---------------------------------------------------------------- stroke files, the CLI

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
STROKE = {
    "brush": {"radius_px": 14, "hardness": 0.5, "flow": 0.8},
    "swatch": {"name": "red", "values": {"base_color": [0.8, 0.1, 0.1]}},
    "points": [[300, 60, 0.5], [380, 90, 1.0], [420, 30]],
}


def replayed(tmp_path: Path, name: str, strokes: list[dict]) -> np.ndarray:
    project = tmp_path / f"{name}.matshop"
    assert main(["new", str(project), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(project), "paint", "--name", "P"]) == 0
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps({"strokes": strokes}))
    assert main(["paint", str(project), "--stroke", str(path)]) == 0
    doc = load_project(project).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    return layer.coverage(Rect(0, 0, doc.width, doc.height))


def test_a_stroke_file_replays_the_moved_centre(tmp_path: Path) -> None:
    cx = 330.5
    mirrored = replayed(
        tmp_path, "mirrored", [{**STROKE, "symmetry": "x", "symmetry_centre": [cx, 5]}]
    )
    by_hand = {**STROKE, "points": [[2 * cx - p[0], *p[1:]] for p in STROKE["points"]]}
    two = replayed(tmp_path, "two", [STROKE, by_hand])  # the second stroke mirrored by hand
    assert mirrored.max() > 0.79 and mirrored[:, : int(2 * cx - 420 - 15)].max() == 0
    np.testing.assert_allclose(mirrored, two, atol=2e-6, rtol=0)


@pytest.mark.parametrize("centre", ["[1, 2, 3]", '"middle"', "[1, true]", "[1e9, 0]"])
def test_a_bad_centre_in_a_stroke_file_is_one_line(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], centre: str
) -> None:
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(project), "paint"]) == 0
    before = project.read_bytes()
    stroke = tmp_path / "bad.json"
    stroke.write_text(f'{{"points": [[1, 2]], "symmetry": "x", "symmetry_centre": {centre}}}')
    capfd.readouterr()
    assert main(["paint", str(project), "--stroke", str(stroke)]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.json" in err[0] and "symmetry_centre" in err[0], err
    assert project.read_bytes() == before
