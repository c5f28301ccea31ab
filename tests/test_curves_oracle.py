"""Curves from the file on disk to the file written, against a hand-computed curve.

The truth: the source file's codes read with OpenImageIO, the sRGB transfer
function of CONVENTIONS.md written out here, and scipy's PchipInterpolator
through the control points (the monotone cubic the op documents). The op runs
through the API's real path: open a folder, apply, save, read the files back.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
from oracle import file_codes as codes
from oracle import srgb_decode as decode
from oracle import srgb_encode as encode
from scipy.interpolate import PchipInterpolator

import matshop

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
POINTS = [(0.0, 0.0), (0.25, 0.1), (0.6, 0.75), (1.0, 1.0)]


def curve(t: np.ndarray) -> np.ndarray:
    return PchipInterpolator(*zip(*POINTS, strict=True))(np.clip(t, 0.0, 1.0))


def _edited(tmp_path: Path, **options) -> Path:
    folder = tmp_path / "in"
    shutil.copytree(SAMPLE, folder)
    m = matshop.open(folder)
    m.apply("curves", points=POINTS, **options)
    m.save(tmp_path / "out")
    return tmp_path / "out"


def test_a_curve_on_the_space_range_is_the_cubic_on_linear_values(tmp_path: Path) -> None:
    out = _edited(tmp_path, params=["base_color", "metallic"], remap="space")
    source = codes(SAMPLE / "tiles_basecolor.png")[..., :3] / 255
    expected = np.rint(encode(curve(decode(source))) * 255)
    written = codes(out / "tiles_basecolor.png")[..., :3]
    assert np.abs(written - expected).max() <= 1
    metal = codes(SAMPLE / "tiles_metallic.png")[..., 0] / 255
    assert (
        np.abs(codes(out / "tiles_metallic.png")[..., 0] - np.rint(curve(metal) * 255)).max() <= 1
    )
    # the parameters not selected are the source's, code for code
    assert np.array_equal(codes(out / "tiles_ao.png"), codes(SAMPLE / "tiles_ao.png"))


def test_a_curve_on_the_data_range_spans_the_values_in_the_image(tmp_path: Path) -> None:
    """remap=data: per colour channel, the median maps to 0.5 and the wider of its
    distances to the 0.5th / 99.5th percentiles to 0 and 1; outside, slope 1."""
    out = _edited(tmp_path, params=["base_color"], remap="data", clip_percent=0.5)
    linear = decode(codes(SAMPLE / "tiles_basecolor.png")[..., :3] / 255)
    expected = np.empty_like(linear)
    for c in range(3):
        x = linear[..., c]
        median = np.median(x)
        reach = max(median - np.percentile(x, 0.5), np.percentile(x, 99.5) - median)
        lo, span = median - reach, 2 * reach
        t = (x - lo) / span
        inside = curve(t)
        # past the range the curve continues with slope 1 (in the range's units)
        y = np.where(t < 0, t, np.where(t > 1, 1 + (t - 1), inside))
        expected[..., c] = lo + span * y
    want = np.rint(encode(expected) * 255)
    written = codes(out / "tiles_basecolor.png")[..., :3]
    worst = np.abs(written - want)
    assert np.percentile(worst, 99.9) <= 1 and worst.max() <= 2, worst.max()
    # and it is the data's range, not the space's: the two results differ
    space = _edited(tmp_path / "s", params=["base_color"], remap="space")
    assert np.abs(codes(space / "tiles_basecolor.png")[..., :3] - written).max() > 10
