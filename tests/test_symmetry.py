"""Mirror painting in texture space: a symmetric stroke paints, texel for texel, the stroke
painted without symmetry and its np.flip images (the truth is the flip of an ordinary
stroke, not the mirror code), in one undo step, and a stroke file replays it via the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.project import load_project
from matshop.layers import AddLayer, Document, History, Rect, SetMask
from matshop.material import Material, Schema
from matshop.paint import Brush, StrokeSample, Swatch, Symmetry, paint_stroke

SCHEMA = Schema.from_names(["base_color", "roughness"])
WIDTH, HEIGHT = 96, 80  # not square: x and y mirror about different lines
BRONZE = Swatch("bronze", {"base_color": (0.45, 0.25, 0.08), "roughness": (0.3,)})
# a wiggle in the top-left quadrant, clear of both centre lines (and of the edges)
PATH = [StrokeSample(8 + 3 * i, 9 + 12 * np.sin(i / 3.0) ** 2, 0.4 + 0.05 * i) for i in range(11)]
BRUSH = Brush(radius_px=5.5, hardness=0.4, spacing=0.2, flow=0.7)
FULL = Rect(0, 0, WIDTH, HEIGHT)
FLIPS = {"x": [(), (1,)], "y": [(), (0,)], "xy": [(), (1,), (0,), (0, 1)]}


def make_doc() -> tuple[Document, History, int]:
    rng = np.random.default_rng(3)
    maps = {
        "base_color": rng.uniform(0.05, 0.9, (HEIGHT, WIDTH, 3)).astype(np.float32),
        "roughness": rng.uniform(0.1, 0.9, (HEIGHT, WIDTH, 1)).astype(np.float32),
    }
    doc = Document.from_material(Material("base", SCHEMA, maps), tile_size=32)
    history = History(doc)
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    return doc, history, layer.id


def coverage(doc: Document, layer_id: int) -> np.ndarray:
    return doc.layer(layer_id).coverage(FULL)


def union(images: list[np.ndarray]) -> np.ndarray:
    """What alpha-over of independent strokes leaves: 1 - prod(1 - a)."""
    return 1.0 - np.prod([1.0 - a for a in images], axis=0)


@pytest.mark.parametrize("name", ["x", "y", "xy"])
def test_a_mirrored_stroke_paints_the_stroke_and_its_flips(name: str) -> None:
    plain_doc, _, plain = make_doc()
    paint_stroke(plain_doc, plain, PATH, BRUSH, swatch=BRONZE, wrap=False)
    alone = coverage(plain_doc, plain)
    assert alone.max() > 0.69 and alone[:, WIDTH // 2 :].max() == 0.0  # one quadrant only
    doc, history, layer_id = make_doc()
    paint_stroke(doc, layer_id, PATH, BRUSH, swatch=BRONZE, wrap=False, symmetry=name)
    expected = sum(np.flip(alone, axis=axes) for axes in FLIPS[name])  # disjoint images
    np.testing.assert_allclose(coverage(doc, layer_id), expected, atol=1e-6, rtol=0)
    # and nothing else: the material is untouched where no image covers
    covered = expected > 0
    assert np.array_equal(doc.flatten_edit()[~covered], plain_doc.flatten_edit()[~covered])


def test_a_stroke_across_the_centre_line_builds_up_like_two_strokes() -> None:
    # dabs and their mirror images overlap at the line: alpha-over, whatever the order
    path = [StrokeSample(WIDTH / 2 - 7 + 2 * i, 30 + i) for i in range(8)]
    plain_doc, _, plain = make_doc()
    paint_stroke(plain_doc, plain, path, BRUSH, swatch=BRONZE)
    alone = coverage(plain_doc, plain)
    doc, _, layer_id = make_doc()
    paint_stroke(doc, layer_id, path, BRUSH, swatch=BRONZE, symmetry="x")
    expected = union([alone, np.flip(alone, axis=1)])
    np.testing.assert_allclose(coverage(doc, layer_id), expected, atol=2e-6, rtol=0)


@pytest.mark.parametrize("target", ["pixels", "mask"])
def test_the_eraser_and_the_mask_brush_mirror_too(target: str) -> None:
    def erased(symmetry: str) -> np.ndarray:
        doc, history, layer_id = make_doc()
        if target == "pixels":  # a layer painted all over, then erased
            everywhere = [StrokeSample(WIDTH / 2, HEIGHT / 2)]
            paint_stroke(doc, layer_id, everywhere, Brush(radius_px=80, hardness=1), swatch=BRONZE)
            options = {"mode": "erase"}
        else:  # a mask showing everything, then painted black
            history.push(SetMask(layer_id, doc.new_mask(1.0)))
            options = {"target": "mask", "mask_value": 0.0}
        paint_stroke(doc, layer_id, PATH, BRUSH, symmetry=symmetry, history=history, **options)
        layer = doc.layer(layer_id)
        left = coverage(doc, layer_id) if target == "pixels" else layer.mask.read(FULL)
        return np.asarray(left).reshape(HEIGHT, WIDTH)

    alone = erased("none")
    assert alone.min() < 0.31 and alone.max() == 1.0
    # what is left is what each image leaves, multiplied: prod(flip(left))
    expected = np.prod([np.flip(alone, axis=axes) for axes in FLIPS["xy"]], axis=0)
    np.testing.assert_allclose(erased("xy"), expected, atol=1e-6, rtol=0)


def test_one_undo_step_takes_back_every_mirror_image() -> None:
    doc, history, layer_id = make_doc()
    steps = history.report().undo_steps
    paint_stroke(doc, layer_id, PATH, BRUSH, swatch=BRONZE, symmetry="xy", history=history)
    assert history.report().undo_steps == steps + 1
    assert np.count_nonzero(coverage(doc, layer_id)[HEIGHT // 2 :, WIDTH // 2 :]) > 50
    history.undo()
    assert not coverage(doc, layer_id).any()


def test_symmetry_names_and_the_clone_stamp() -> None:
    assert Symmetry.parse("yx") == Symmetry(True, True) and Symmetry.parse("xy").name == "xy"
    assert not Symmetry.parse("none")
    doc, _, layer_id = make_doc()
    with pytest.raises(ValueError, match="symmetry must be"):
        paint_stroke(doc, layer_id, PATH, BRUSH, swatch=BRONZE, symmetry="z")
    with pytest.raises(ValueError, match="does not mirror"):
        paint_stroke(doc, layer_id, PATH, BRUSH, mode="clone", symmetry="x")


# ---------------------------------------------------------------- stroke files, the CLI

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def _replayed(tmp_path: Path, name: str, symmetry: str | None) -> np.ndarray:
    project = tmp_path / f"{name}.matshop"
    assert main(["new", str(project), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(project), "paint", "--name", "P"]) == 0
    stroke = {
        "brush": {"radius_px": 14, "hardness": 0.5, "flow": 0.8},
        "swatch": {"name": "red", "values": {"base_color": [0.8, 0.1, 0.1]}},
        "points": [[40, 60, 0.5], [150, 90, 1.0], [200, 30]],
    }
    if symmetry is not None:
        stroke["symmetry"] = symmetry
    strokes = tmp_path / f"{name}.json"
    strokes.write_text(json.dumps({"strokes": [stroke]}))
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 0
    doc = load_project(project).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    return layer.coverage(Rect(0, 0, doc.width, doc.height))


def test_a_stroke_file_with_symmetry_replays_the_flipped_stroke(tmp_path: Path) -> None:
    alone = _replayed(tmp_path, "plain", None)
    mirrored = _replayed(tmp_path, "mirrored", "xy")
    assert alone[256:, :].max() == 0 and alone[:, 256:].max() == 0  # the top-left quadrant
    expected = sum(np.flip(alone, axis=axes) for axes in FLIPS["xy"])
    np.testing.assert_allclose(mirrored, expected, atol=1e-6, rtol=0)


def test_a_bad_symmetry_in_a_stroke_file_is_one_line(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(project), "paint"]) == 0
    before = project.read_bytes()
    stroke = tmp_path / "bad.json"
    stroke.write_text(json.dumps({"points": [[1, 2]], "symmetry": "diagonal"}))
    capfd.readouterr()
    assert main(["paint", str(project), "--stroke", str(stroke)]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.json" in err[0] and "symmetry must be" in err[0], err
    assert project.read_bytes() == before
