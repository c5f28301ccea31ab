"""Tips, dynamics and stencils in stroke files, replayed by `matshop paint`.

Truths: two replays of one file paint the same bytes; they equal the engine
painting the same stroke from the same files (the API, in this process); a
stroke written by ``stroke_json`` replays to the bytes of the stroke it
describes; a stencil of zeros in a file blocks the stroke. Bad input is one
stderr line naming the file, exit 2, the project unchanged.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from matshop.cli import main
from matshop.io.project import load_project
from matshop.layers import Rect
from matshop.paint import (
    Brush,
    Dynamics,
    StrokeSample,
    StrokeSession,
    Swatch,
    load_stencil,
    load_tip,
    procedural_tip,
)
from matshop.paint.strokefile import load_strokes, stroke_json

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
POINTS = [[40, 60, 0.5], [150, 90, 1.0], [200, 30], [260, 140, 0.8]]


@pytest.fixture
def project(tmp_path: Path) -> Path:
    path = tmp_path / "p.matshop"
    assert main(["new", str(path), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(path), "paint", "--name", "P"]) == 0
    return path


@pytest.fixture
def images(tmp_path: Path) -> Path:
    folder = tmp_path / "brushes"
    folder.mkdir()
    rows, cols = np.mgrid[0:48, 0:36]
    cv2.imwrite(str(folder / "leaf.png"), ((cols * 7 + rows * 3) % 256).astype(np.uint8))
    stencil = np.zeros((200, 300), np.uint8)
    stencil[:, 150:] = 255
    cv2.imwrite(str(folder / "half.png"), stencil)
    cv2.imwrite(str(folder / "shut.png"), np.zeros((400, 400), np.uint8))
    return folder


def pixels(layer, doc) -> bytes:
    """A paint layer's values and coverage, every texel, as bytes."""
    return layer.pixels.read(Rect(0, 0, doc.width, doc.height)).tobytes()


def layer_bytes(project: Path) -> bytes:
    doc = load_project(project).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    return pixels(layer, doc)


def coverage(project: Path) -> np.ndarray:
    doc = load_project(project).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    return layer.coverage(Rect(0, 0, doc.width, doc.height))


STROKES = [
    {
        "brush": {
            "radius_px": 18,
            "flow": 0.8,
            "tip": {"image": "brushes/leaf.png"},
            "rotation": "follow",
            "size_jitter": 0.4,
            "angle_jitter_deg": 25,
            "scatter_across": 0.6,
        },
        "swatch": {"name": "red", "values": {"base_color": [0.8, 0.1, 0.1]}},
        "seed": 9,
        "stencil": {
            "image": "brushes/half.png",
            "centre": [150, 80],
            "scale": 1.5,
            "angle_deg": 20,
        },
        "points": POINTS,
    },
    {
        "brush": {
            "radius_px": 12,
            "tip": {"procedural": "spots", "seed": 4},
            "rotation": "random",
            "scatter_along": 1.0,
        },
        "swatch": {"name": "dark", "values": {"base_color": [0.1, 0.1, 0.1]}},
        "seed": 3,
        "symmetry": "x",
        "points": [[30, 300], [120, 260], [200, 330]],
    },
]


def test_a_stroke_file_with_tips_and_a_stencil_replays_identically(
    tmp_path: Path, project: Path, images: Path
) -> None:
    strokes = tmp_path / "strokes.json"
    strokes.write_text(json.dumps({"strokes": STROKES}))
    copy = tmp_path / "copy.matshop"
    shutil.copy(project, copy)
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 0
    assert main(["paint", str(copy), "--stroke", str(strokes)]) == 0
    painted = layer_bytes(project)
    assert painted == layer_bytes(copy)
    assert coverage(project).max() > 0.3

    # the same strokes through the engine, from objects built here (not from the file)
    doc = load_project(_fresh(tmp_path)).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    tip = load_tip(images / "leaf.png")
    stencil = load_stencil(images / "half.png").placed((150.0, 80.0), 1.5, 20.0)
    brushes = [
        Brush(
            radius_px=18,
            flow=0.8,
            tip=tip,
            dynamics=Dynamics(
                rotation="follow", size_jitter=0.4, angle_jitter_deg=25, scatter_across=0.6
            ),
        ),
        Brush(
            radius_px=12,
            tip=procedural_tip("spots", 4),
            dynamics=Dynamics(rotation="random", scatter_along=1.0),
        ),
    ]
    options = [
        {"swatch": Swatch("red", {"base_color": (0.8, 0.1, 0.1)}), "seed": 9, "stencil": stencil},
        {"swatch": Swatch("dark", {"base_color": (0.1, 0.1, 0.1)}), "seed": 3, "symmetry": "x"},
    ]
    for brush, extra, data in zip(brushes, options, STROKES, strict=True):
        session = StrokeSession(doc, layer.id, brush, **extra)
        session.add([StrokeSample(*map(float, p)) for p in data["points"]])
        session.end()
    assert pixels(layer, doc) == painted


def _fresh(tmp_path: Path) -> Path:
    path = tmp_path / "fresh.matshop"
    assert main(["new", str(path), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(path), "paint", "--name", "P"]) == 0
    return path


def test_stroke_json_writes_what_replays_to_the_same_bytes(
    tmp_path: Path, project: Path, images: Path
) -> None:
    doc = load_project(_fresh(tmp_path)).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    brush = Brush(
        radius_px=15.5,
        spacing=0.07,
        tip=procedural_tip("scratches", 8),
        dynamics=Dynamics(
            rotation="follow",
            angle_deg=12.5,
            size_jitter=0.25,
            angle_jitter_deg=10,
            scatter_along=0.2,
            scatter_across=0.3,
        ),
    )
    options = {
        "swatch": Swatch("teal", {"base_color": (0.1, 0.6, 0.55), "roughness": (0.2,)}),
        "seed": 123456789,
        "stencil": load_stencil(images / "half.png").placed((201.25, 77.5), 0.75, -33.0),
    }
    samples = [
        StrokeSample(30.1 + 7.3 * i, 100.7 + 40 * np.sin(i / 3.1), 0.3 + 0.05 * i)
        for i in range(14)
    ]
    session = StrokeSession(doc, layer.id, brush, **options)
    for sample in samples:  # fed one by one, like pointer events
        session.add([sample])
    session.end()
    expected = pixels(layer, doc)
    strokes = tmp_path / "written.json"
    strokes.write_text(json.dumps(stroke_json(brush, session.samples, layer="P", **options)))
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 0
    assert layer_bytes(project) == expected
    assert load_strokes(strokes)[0].options["seed"] == 123456789


def test_a_stencil_of_zeros_in_a_file_blocks_the_stroke(
    tmp_path: Path, project: Path, images: Path, capfd
) -> None:
    stroke = {**STROKES[0], "stencil": {"image": "brushes/shut.png", "centre": [150, 80]}}
    strokes = tmp_path / "shut.json"
    strokes.write_text(json.dumps(stroke))
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 0
    assert not coverage(project).any()


BAD = [
    ({"tip": {"image": "brushes/missing.png"}}, "missing.png"),
    ({"tip": {"image": "brushes/not_an_image.png"}}, "not_an_image.png"),
    ({"tip": {"image": "brushes/black.png"}}, "black everywhere"),
    ({"tip": "sparkles"}, "unknown tip 'sparkles'"),
    ({"tip": {"procedural": "noise", "seed": -1}}, "seed"),
    ({"size_jitter": 5}, "size_jitter must lie in [0, 1]"),
    ({"scatter_across": 1e6}, "scatter_across must lie in"),
    ({"angle_jitter_deg": 720}, "angle_jitter_deg must lie in"),
    ({"rotation": "spin"}, "rotation must be"),
    ({"rotation": 3}, "rotation must be"),
]


@pytest.mark.parametrize(("brush", "message"), BAD)
def test_bad_tips_and_dynamics_are_one_line(
    tmp_path: Path, project: Path, images: Path, capfd, brush, message
) -> None:
    (images / "not_an_image.png").write_text("hello")
    cv2.imwrite(str(images / "black.png"), np.zeros((8, 8), np.uint8))
    before = project.read_bytes()
    strokes = tmp_path / "bad.json"
    strokes.write_text(json.dumps({"brush": {"radius_px": 9, **brush}, "points": [[5, 5]]}))
    capfd.readouterr()
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.json" in err[0] and message in err[0], err
    assert "Traceback" not in err[0]
    assert project.read_bytes() == before


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ({"seed": 1.5}, "seed must be an integer"),
        ({"seed": -3}, "seed must be an integer"),
        ({"stencil": {"image": "brushes/half.png", "scale": 0}}, "stencil scale must lie in"),
        ({"stencil": {"image": "brushes/nope.png"}}, "nope.png"),
        ({"stencil": {"centre": [1, 2]}}, "stencil must be"),
        ({"stencil": {"image": "brushes/half.png", "centre": [1]}}, "stencil centre"),
    ],
)
def test_bad_seeds_and_stencils_are_one_line(
    tmp_path: Path, project: Path, images: Path, capfd, extra, message
) -> None:
    before = project.read_bytes()
    strokes = tmp_path / "bad.json"
    strokes.write_text(json.dumps({"points": [[5, 5]], **extra}))
    capfd.readouterr()
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.json" in err[0] and message in err[0], err
    assert project.read_bytes() == before


def test_the_readme_stroke_file_replays(tmp_path: Path, project: Path) -> None:
    """The README's tips-and-stencil stroke file, as written, with the images it names."""
    import re

    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = text[text.index("### Brush tips and stencils") :]
    stroke = re.search(r"```json\n(.*?)```", section, re.S).group(1)
    (tmp_path / "tips").mkdir()
    (tmp_path / "stencils").mkdir()
    rows, cols = np.mgrid[0:64, 0:64]
    cv2.imwrite(
        str(tmp_path / "tips" / "leaf.png"),
        (255 * (np.hypot(rows - 32, cols - 32) < 28)).astype(np.uint8),
    )
    cv2.imwrite(
        str(tmp_path / "stencils" / "letters.png"), (255 * (cols % 16 < 8)).astype(np.uint8)
    )
    (tmp_path / "readme.json").write_text(stroke)
    assert main(["paint", str(project), "--stroke", str(tmp_path / "readme.json")]) == 0
    assert coverage(project).max() > 0.5
