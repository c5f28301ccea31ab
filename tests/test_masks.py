"""One mask reader: layer masks, op masks and clone regions read a mask file alike, as
its brightness (gray, or the Rec. 709 luminance of a color image; see matshop.io.masks).

The files are written byte by byte here (binary PPM/PGM), so the expected values come
from the bytes and the luminance weights, not from the reader under test.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from matshop.api import EditableMaterial, load_mask
from matshop.io.material_io import load_material
from matshop.layers import AddLayer, Document, History
from matshop.ops import get_op

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
HEIGHT, WIDTH = 512, 512  # the sample's size
#: Rec. 709 luminance weights (ITU-R BT.709)
R, G, B = 0.2126, 0.7152, 0.0722


def _ppm(path: Path, rgb: np.ndarray) -> Path:
    height, width, _ = rgb.shape
    path.write_bytes(b"P6\n%d %d\n255\n" % (width, height) + rgb.astype(np.uint8).tobytes())
    return path


def _stripes(path: Path) -> Path:
    """Three vertical bands: pure green, pure red, pure blue + a white square in the red."""
    rgb = np.zeros((HEIGHT, WIDTH, 3), np.uint8)
    rgb[:, :170, 1] = 255
    rgb[:, 170:340, 0] = 255
    rgb[:, 340:, 2] = 255
    rgb[200:260, 200:260] = 255
    return _ppm(path, rgb)


def _expected() -> np.ndarray:
    want = np.empty((HEIGHT, WIDTH), np.float64)
    want[:, :170], want[:, 170:340], want[:, 340:] = G, R, B
    want[200:260, 200:260] = R + G + B
    return want


def test_a_color_mask_reads_as_its_luminance(tmp_path: Path) -> None:
    mask = load_mask(_stripes(tmp_path / "m.ppm"), (HEIGHT, WIDTH))
    np.testing.assert_allclose(mask, _expected(), atol=1e-6)


def test_a_gray_mask_reads_as_its_gray(tmp_path: Path) -> None:
    gray = (np.arange(WIDTH) % 256).astype(np.uint8)[None].repeat(4, axis=0)
    path = tmp_path / "g.pgm"
    path.write_bytes(b"P5\n%d 4\n255\n" % WIDTH + gray.tobytes())
    np.testing.assert_allclose(load_mask(path, (4, WIDTH)), gray / 255.0, atol=1e-6)


@pytest.fixture(scope="module")
def sample():
    material, _ = load_material(SAMPLE)
    return material.to_edit()


def test_a_clone_region_file_is_where_the_same_mask_reads_over_a_half(
    sample, tmp_path: Path
) -> None:
    """Green band and white square (luminance > 0.5) are the region; the red band (its
    first channel is 1, its luminance 0.21) and the blue one are not."""
    path = _stripes(tmp_path / "m.ppm")
    region = get_op("clone").param("region").validate(path, "clone")
    assert np.array_equal(region, _expected() > 0.5)
    assert region[:, :170].all() and region[200:260, 200:260].all()
    assert not region[:, 170:200].any() and not region[:, 340:].any()
    # the same file as an op mask and as a clone region, through the real paths
    doc = Document.from_material(sample)
    layer = doc.new_filter_layer("clone", op_params={"region": path, "offset": (0, 40)})
    History(doc).push(AddLayer(layer))
    assert np.array_equal(layer.op_params["region"], region)
    scaled = EditableMaterial(sample).apply("scale", factor=0.0, mask=path).edit.data
    np.testing.assert_allclose(scaled, sample.data * (1 - _expected()[..., None]), atol=2e-6)
