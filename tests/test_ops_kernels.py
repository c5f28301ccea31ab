"""The fused pointwise kernels of the ops equal their numpy formulas."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.material import Schema
from matshop.ops.curves import apply_lut, curve_lut
from matshop.ops.scale import scale

RNG = np.random.default_rng(3)
SCHEMA = Schema.from_names(["base_color", "roughness", "normal", "metallic"])


def edit_array() -> np.ndarray:
    return RNG.uniform(-0.5, 1.5, (33, 47, SCHEMA.edit_width)).astype(np.float32)


@pytest.mark.parametrize("params", [None, ["base_color", "roughness"], ["roughness", "metallic"]])
def test_masked_scale_is_the_lerp_of_the_scaled_values(params) -> None:
    edit = edit_array()
    mask = RNG.random(edit.shape[:2], dtype=np.float32)
    mask[:5] = 0.0
    mask[-5:] = 1.0
    out = scale(edit, factor=0.3, schema=SCHEMA, params=params, mask=mask)
    names = params or SCHEMA.names
    channels = np.concatenate([np.arange(SCHEMA.edit_width)[SCHEMA.edit_slices[n]] for n in names])
    m = mask[..., None]
    expected = edit.copy()
    selected = edit[..., channels]
    expected[..., channels] = (1 - m) * selected + m * (np.float32(0.3) * selected)
    np.testing.assert_allclose(out, expected, rtol=2e-7, atol=1e-7)
    # mask 0 and 1 are bit-exact: the input and the plain scale
    assert np.array_equal(out[:5], edit[:5])
    plain = scale(edit, factor=0.3, schema=SCHEMA, params=params)
    assert np.array_equal(out[-5:], plain[-5:])


def test_lut_kernel_matches_interpolation_with_linear_extension() -> None:
    edit = edit_array()
    lut = curve_lut([(0, 0), (0.25, 0.6), (1, 1)]).astype(np.float64)
    out = apply_lut(
        edit, lut, schema=SCHEMA, params=["base_color"], mask=None, op="curves", remap="space"
    )
    grid = np.linspace(0, 1, lut.size)
    value = edit[..., :3].astype(np.float64)
    expected = np.interp(value, grid, lut)
    # beyond [0, 1] the end segments continue as straight lines
    step = grid[1]
    below, above = value < 0, value > 1
    expected[below] = lut[0] + value[below] * (lut[1] - lut[0]) / step
    expected[above] = lut[-1] + (value[above] - 1) * (lut[-1] - lut[-2]) / step
    np.testing.assert_allclose(out[..., :3], expected, atol=3e-6)
    assert np.array_equal(out[..., 3:], edit[..., 3:])
