"""Curves and levels over the data's own range: contrast on real data, layers, old projects.

Truth: the output files' pixels decoded here with OpenCV and numpy (tilt from
``2 rgb - 1``, luminance from the sRGB formula), the op applied to the whole
image at once, and the curve formula written out.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import cv2
import numpy as np
import pytest

from matshop.cli import main
from matshop.io.project import load_project, save_project
from matshop.layers import Document
from matshop.material import Material, Schema
from matshop.ops import get_op
from matshop.ops.curves import curve_ranges, curves, levels

CHESSBOARD = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"
#: the contrast S-curve of the paper's Fig. 7(b)
S_CURVE = [(0.0, 0.0), (0.25, 0.1), (0.75, 0.9), (1.0, 1.0)]
RNG = np.random.default_rng(3)


def _rgb(path: Path) -> np.ndarray:
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    scale = 65535.0 if image.dtype == np.uint16 else 255.0
    return image[..., ::-1].astype(np.float64) / scale


def _tilt_deg(path: Path) -> np.ndarray:
    n = _rgb(path) * 2.0 - 1.0
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.degrees(np.arccos(np.clip(n[..., 2], -1.0, 1.0)))


def _luminance(path: Path) -> np.ndarray:
    v = _rgb(path)
    linear = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    return linear @ np.array([0.2126, 0.7152, 0.0722])


@pytest.mark.skipif(not CHESSBOARD.is_dir(), reason="shared chessboard texture set not present")
def test_s_curve_raises_contrast_on_the_chessboard(tmp_path: Path) -> None:
    """The real path: files -> ``matshop apply --op curves`` -> files, measured from pixels.

    Measured (2K chessboard): tilt spread x1.11, luminance spread x1.37; over the
    space's fixed range (remap=space, the old behaviour) x0.211 and x0.559.
    """
    out = tmp_path / "out"
    points = ";".join(f"{x:g},{y:g}" for x, y in S_CURVE)
    args = ["apply", str(CHESSBOARD), str(out), "--op", "curves", f"points={points}"]
    assert main([*args, "--params", "base_color,normal"]) == 0
    tilt_in = _tilt_deg(CHESSBOARD / "chessboard_normal.jpg")
    (normal_out,) = out.glob("*normal*.png")  # the name carries the convention written
    (color_out,) = out.glob("*base*color*.png")
    tilt_out = _tilt_deg(normal_out)
    lum_in = _luminance(CHESSBOARD / "chessboard_base_color.jpg")
    lum_out = _luminance(color_out)
    tilt_gain, lum_gain = tilt_out.std() / tilt_in.std(), lum_out.std() / lum_in.std()
    print(f"\nS-curve on the chessboard: tilt spread x{tilt_gain:.3f}, luminance x{lum_gain:.3f}")
    assert tilt_gain > 1.04
    assert lum_gain > 1.2


def _material(height: int = 96, width: int = 80) -> Material:
    schema = Schema.from_names(["base_color", "normal"])
    normal = RNG.normal(size=(height, width, 3)) * [0.2, 0.2, 1] + [0, 0, 1]
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    color = RNG.random((height, width, 3)) ** 2
    color[: height // 2] *= 0.3  # tiles with different value ranges
    maps = {"base_color": color.astype(np.float32), "normal": normal.astype(np.float32)}
    return Material("m", schema, maps)


def test_a_data_range_curves_layer_reads_the_whole_image_not_each_tile() -> None:
    material = _material()
    doc = Document.from_material(material, tile_size=32)
    layer = doc.new_filter_layer("curves", op_params={"points": S_CURVE})
    doc.insert_layer(layer)
    spec = get_op("curves")
    assert spec.reach_of(layer.op_params) is None  # global
    assert spec.reach_of({**layer.op_params, "remap": "space"}) == 0  # pointwise
    edit = material.to_edit()
    want = curves(edit.data, points=S_CURVE, schema=edit.schema)
    np.testing.assert_allclose(doc.flatten_edit(), want, atol=1e-6)


def test_ranges_describe_what_the_curve_spans() -> None:
    edit = _material().to_edit()
    data = edit.data.astype(np.float64)
    ranges = {r.group: r for r in curve_ranges(edit.data, schema=edit.schema)}
    m = np.linalg.norm(data[..., edit.schema.edit_slices["normal"]], axis=-1).reshape(-1)
    low, median, high = np.percentile(m, [0.5, 50, 99.5])
    reach = max(median - low, high - median)
    frame = ranges["normal"]
    assert frame.vector and frame.source == ("data",)
    np.testing.assert_allclose([frame.lo[0], frame.span[0]], [median - reach, 2 * reach])
    assert frame.describe().startswith("normal |v| [")
    space = {r.group: r for r in curve_ranges(edit.data, schema=edit.schema, remap="space")}
    np.testing.assert_allclose([space["normal"].lo[0], space["normal"].span[0]], [0, np.pi / 2])
    # a constant channel has no data range: the space's range stands in, and says so
    flat = edit.data.copy()
    flat[..., edit.schema.edit_slices["base_color"]] = 0.2
    color = curve_ranges(flat, schema=edit.schema, params="base_color")[0]
    assert color.source == ("space",) * 3 and "(space)" in color.describe()


def _drop_remap_from_manifest(path: Path) -> None:
    """Rewrite a project as one saved before curves had ``remap``/``clip_percent``."""
    with zipfile.ZipFile(path) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    manifest = json.loads(members["manifest.json"])
    for entry in manifest["layers"]:
        if entry.get("op") in ("curves", "levels"):
            entry["op_params"].pop("remap")
            entry["op_params"].pop("clip_percent")
    members["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)


def test_projects_saved_before_remap_keep_their_look(tmp_path: Path) -> None:
    """Old manifests (no ``remap``) load with the fixed range they were made with;
    new layers default to the data's range and save it."""
    material = _material()
    doc = Document.from_material(material, tile_size=32)
    doc.insert_layer(doc.new_filter_layer("curves", op_params={"points": S_CURVE}))
    doc.insert_layer(doc.new_filter_layer("levels", op_params={"gamma": 1.5}))
    fresh = tmp_path / "new.matshop"
    save_project(doc, fresh)
    loaded = load_project(fresh).document
    assert [layer.op_params["remap"] for layer in loaded.layers[1:]] == ["data", "data"]

    old = tmp_path / "old.matshop"
    save_project(doc, old)
    _drop_remap_from_manifest(old)
    loaded = load_project(old).document
    assert [layer.op_params["remap"] for layer in loaded.layers[1:]] == ["space", "space"]
    edit = material.to_edit()
    want = curves(edit.data, points=S_CURVE, schema=edit.schema, remap="space")
    want = levels(want, gamma=1.5, schema=edit.schema, remap="space")
    np.testing.assert_allclose(loaded.flatten_edit(), want, atol=1e-6)
