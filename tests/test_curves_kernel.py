"""The one-pass curves kernel against the straightforward numpy formulation.

The reference below is the path the kernel replaced, written plainly in
float64: ``np.interp`` in the table, straight lines beyond it, and for vector
groups the magnitude through the curve. The ranges are the ops' own
(:func:`curve_ranges`); they are checked separately against ``np.percentile``
of the same texels.
"""

from __future__ import annotations

import numpy as np
import pytest

from matshop.material import Schema
from matshop.ops.curves import curve_lut, curve_ranges, curves, levels, levels_lut
from matshop.ops.selection import Selection
from matshop.ops.tone_range import MAX_SAMPLES, _sample, percentiles, tail_slope

SCHEMA = Schema.from_names(["base_color", "distribution", "normal", "metallic"])
POINTS = [(0.0, 0.05), (0.3, 0.6), (0.7, 0.75), (1.0, 0.9)]


def edit_array(height: int = 41, width: int = 53) -> np.ndarray:
    rng = np.random.default_rng(11)
    edit = rng.normal(0.4, 0.5, (height, width, SCHEMA.edit_width)).astype(np.float32)
    edit[3, 4, SCHEMA.edit_slices["normal"]] = 0.0  # a zero vector stays zero
    edit[5, 6, :3] = [1e30, -1e30, 0.0]  # far outside: the end lines, no wild index
    return edit


def curve_at(lut: np.ndarray, t: np.ndarray, tail: float) -> np.ndarray:
    """The table at ``t`` (float64), continued beyond [0, 1] as the kernel documents."""
    grid = np.linspace(0.0, 1.0, lut.size)
    out = np.interp(t, grid, lut)
    step = grid[1]
    low = (lut[1] - lut[0]) / step if tail < 0 else tail
    high = (lut[-1] - lut[-2]) / step if tail < 0 else tail
    below, above = t < 0, t > 1
    out[below] = lut[0] + t[below] * low
    out[above] = lut[-1] + (t[above] - 1.0) * high
    return out


def reference(edit, lut, *, schema, params, remap) -> np.ndarray:
    selection = Selection(edit, schema=schema, params=params, mask=None, op="curves")
    ranges = curve_ranges(edit, schema=schema, params=params, remap=remap)
    tail = tail_slope(remap)
    out = edit.astype(np.float64)
    for group, tone in zip(selection.groups, ranges, strict=True):
        channels = selection.channels[group.channels]
        values = edit[..., channels].astype(np.float64)
        if tone.vector:
            magnitude = np.sqrt((values**2 * group.quadrature).sum(-1))
            t = (magnitude - tone.lo[0]) / tone.span[0]
            mapped = np.maximum(tone.lo[0] + tone.span[0] * curve_at(lut, t, tail), 0.0)
            safe = np.where(magnitude > 0, magnitude, 1.0)
            gain = np.where(magnitude > 0, mapped / safe, 0.0)
            out[..., channels] = values * gain[..., None]
        else:
            for i, c in enumerate(channels):
                t = (values[..., i] - tone.lo[i]) / tone.span[i]
                out[..., c] = tone.lo[i] + tone.span[i] * curve_at(lut, t, tail)
    return out


@pytest.mark.parametrize("remap", ["data", "space"])
@pytest.mark.parametrize(
    "params", [None, ["normal"], ["metallic", "base_color"], ["distribution", "metallic"]]
)
def test_curves_equal_the_numpy_formulation(remap, params) -> None:
    edit = edit_array()
    got = curves(edit, points=POINTS, schema=SCHEMA, params=params, remap=remap)
    expected = reference(edit, curve_lut(POINTS), schema=SCHEMA, params=params, remap=remap)
    finite = np.abs(expected) < 1e6
    # float32 lines a + x b: a few float32 ulps of the values and of the curve's reach
    np.testing.assert_allclose(got[finite], expected[finite], rtol=3e-6, atol=3e-6)
    far = edit[5, 6, :3]
    if params is None or "base_color" in params:
        # the end lines continue monotonically, with no index out of the table
        assert got[5, 6, 0] > 1e20 and got[5, 6, 1] < -1e20
    else:
        assert np.array_equal(got[5, 6, :3], far)
    assert np.array_equal(got[3, 4, SCHEMA.edit_slices["normal"]], np.zeros(3)) or (
        params is not None and "normal" not in params
    )


def test_levels_without_schema_equal_the_numpy_formulation() -> None:
    edit = edit_array(64, 70)[..., :10]
    lut = levels_lut(0.1, 0.8, 1.7, 0.05, 0.95)
    got = levels(edit, in_black=0.1, in_white=0.8, gamma=1.7, out_black=0.05, out_white=0.95)
    expected = reference(edit, lut, schema=None, params=None, remap="data")
    finite = np.abs(expected) < 1e6
    np.testing.assert_allclose(got[finite], expected[finite], rtol=3e-6, atol=3e-6)


def test_percentiles_are_numpys() -> None:
    rng = np.random.default_rng(2)
    for dtype in (np.float32, np.float64):
        for count in (1, 2, 9, 1000, 4099):
            values = (rng.normal(size=(count, 4)) * 7).astype(dtype)
            cuts = [0.5, 50.0, 99.5]
            assert np.array_equal(percentiles(values, cuts), np.percentile(values, cuts, axis=0))


def test_the_sample_is_the_fixed_random_draw_of_texels() -> None:
    edit = np.random.default_rng(4).random((600, 520, 5), dtype=np.float32)
    block = edit[..., 1:4]  # a channel slice, as curves sees it
    index = np.sort(np.random.default_rng(0).integers(0, 600 * 520, MAX_SAMPLES))
    rows, cols = np.divmod(index, 520)
    assert np.array_equal(_sample(block), block[rows, cols])
