"""Pen pressure in stroke files, replayed by ``matshop paint``: each one-dab stroke's radius
and opacity are the brush's times its curve at the pressure, the curves computed here with
scipy's PchipInterpolator on the file's points; flow follows its own curve."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from matshop.cli import main
from matshop.io.project import load_project
from matshop.layers import Rect

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
SIZE_CURVE = [[0, 0.2], [0.6, 0.5], [1, 1]]
OPACITY_CURVE = [[0, 0], [0.3, 0.6], [1, 0.9]]
FLOW_CURVE = [[0, 0.1], [1, 0.5]]
RADIUS_PX, OPACITY = 18.0, 0.9


def pchip(points: list[list[float]]):
    return PchipInterpolator(*np.array(points, dtype=float).T)


def replay(tmp_path: Path, brush: dict, centres: list[tuple[int, int, float]]) -> np.ndarray:
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(SAMPLE)]) == 0
    assert main(["layer", "add", str(project), "paint", "--name", "P"]) == 0
    strokes = [
        {
            "layer": "P",
            "brush": brush,
            "swatch": {"name": "red", "values": {"base_color": [0.8, 0.1, 0.1]}},
            "points": [[x + 0.5, y + 0.5, p]],
        }
        for x, y, p in centres
    ]
    path = tmp_path / "strokes.json"
    path.write_text(json.dumps({"strokes": strokes}))
    assert main(["paint", str(project), "--stroke", str(path)]) == 0
    doc = load_project(project).document
    layer = next(layer for layer in doc.layers if layer.name == "P")
    return layer.coverage(Rect(0, 0, doc.width, doc.height))


def test_size_and_opacity_follow_their_curves(tmp_path: Path) -> None:
    brush = {
        "radius_px": RADIUS_PX,
        "hardness": 1.0,
        "opacity": OPACITY,
        "size_pressure": SIZE_CURVE,
        "opacity_pressure": OPACITY_CURVE,
    }
    centres = [(60, 60, 0.35), (180, 60, 0.6), (300, 60, 0.8), (420, 60, 1.0)]
    cover = replay(tmp_path, brush, centres)
    for x, y, pressure in centres:
        dab = cover[y - 40 : y + 40, x - 40 : x + 40]
        opacity = OPACITY * float(pchip(OPACITY_CURVE)(pressure))
        assert dab[40, 40] == pytest.approx(opacity, abs=1e-4)
        radius = np.sqrt(dab.sum() / (opacity * np.pi))  # a hard dab covers its disc's area
        assert radius == pytest.approx(RADIUS_PX * float(pchip(SIZE_CURVE)(pressure)), abs=0.05)


def test_flow_follows_its_curve_and_unknown_curves_are_refused(tmp_path: Path, capsys) -> None:
    brush = {"radius_px": 10.0, "hardness": 1.0, "flow": 0.8, "flow_pressure": FLOW_CURVE}
    cover = replay(tmp_path, brush, [(100, 100, 0.25)])
    assert cover[100, 100] == pytest.approx(0.8 * float(pchip(FLOW_CURVE)(0.25)), abs=1e-4)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"brush": {"tilt_pressure": FLOW_CURVE}, "points": [[1, 1]]}))
    assert main(["paint", str(tmp_path / "p.matshop"), "--stroke", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.json" in err[0] and "tilt_pressure" in err[0]
