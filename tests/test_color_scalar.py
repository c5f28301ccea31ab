"""sRGB / gamma 2.2 color spaces and identity scalars against their closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from matshop.spaces import get_space
from matshop.spaces.color import linear_to_srgb, srgb_to_linear


def _reference_decode(v: float) -> float:
    """IEC 61966-2-1 written out independently, in float64."""
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def test_srgb_matches_the_standard_formula_on_every_8bit_code() -> None:
    codes = np.arange(256) / 255.0
    ours = srgb_to_linear(codes.astype(np.float32))
    reference = np.array([_reference_decode(v) for v in codes])
    assert np.abs(ours - reference).max() < 1e-6


@pytest.mark.parametrize("name", ["srgb", "gamma22"])
@pytest.mark.parametrize("bits", [8, 16])
def test_every_integer_code_round_trips_to_itself(name: str, bits: int) -> None:
    space = get_space(name)
    top = (1 << bits) - 1
    codes = np.arange(top + 1, dtype=np.float64)
    rgb = np.repeat((codes / top).astype(np.float32)[:, None], 3, axis=1)
    back = space.from_edit(space.to_edit(rgb))
    worst = np.abs(np.rint(back.astype(np.float64) * top) - codes[:, None]).max()
    assert worst == 0, f"{name}: {bits}-bit codes moved by {worst}"


def test_halving_linear_halves_reflectance_not_the_encoded_value() -> None:
    space = get_space("srgb")
    encoded = np.array([[0.8, 0.5, 0.2]], dtype=np.float32)
    halved = space.from_edit(0.5 * space.to_edit(encoded))
    assert np.allclose(srgb_to_linear(halved), 0.5 * srgb_to_linear(encoded), atol=1e-6)
    assert not np.allclose(halved, 0.5 * encoded, atol=1e-2)


def test_gamma22_is_the_papers_power_law() -> None:
    space = get_space("gamma22")
    x = np.linspace(0, 1, 101, dtype=np.float32)[:, None].repeat(3, axis=1)
    assert np.allclose(space.to_edit(x), x.astype(np.float64) ** 2.2, atol=1e-6)


@given(arrays(np.float32, (7, 3), elements=st.floats(-4, 4, width=32)))
def test_out_of_range_edits_come_back_in_range(edit: np.ndarray) -> None:
    for name in ("srgb", "gamma22"):
        phys = get_space(name).from_edit(edit)
        assert phys.dtype == np.float32
        assert np.all((phys >= 0) & (phys <= 1))


def test_encode_inverts_decode_to_float_precision() -> None:
    x = np.linspace(0, 1, 10001, dtype=np.float32)
    assert np.abs(linear_to_srgb(srgb_to_linear(x)) - x).max() < 2e-6


def test_identity_clamps_only_on_the_way_back() -> None:
    space = get_space("identity")
    edit = space.to_edit(np.array([[0.25], [1.0]], dtype=np.float32)) * 2
    assert np.array_equal(edit, np.array([[0.5], [2.0]], dtype=np.float32))
    assert np.array_equal(space.from_edit(edit), np.array([[0.5], [1.0]], dtype=np.float32))
    unbounded = get_space("identity_unbounded")
    assert unbounded.from_edit(np.array([[-3.0]], dtype=np.float32))[0, 0] == -3.0


def test_inputs_are_never_modified_and_wrong_widths_are_refused() -> None:
    space = get_space("srgb")
    rgb = np.full((2, 2, 3), 0.5, dtype=np.float32)
    before = rgb.copy()
    space.from_edit(space.to_edit(rgb))
    assert np.array_equal(rgb, before)
    with pytest.raises(ValueError, match="3 channel"):
        space.to_edit(np.zeros((2, 2, 4), dtype=np.float32))
