"""Integer file codes from one fused pass equal numpy's ``rint(clip(v, 0, 1) * top)``,
and non-finite pixels are still refused with the one-line message."""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest

from matshop.errors import MatshopError
from matshop.io._codes import to_codes
from matshop.io.images import write_image


def values(dtype, top: int) -> np.ndarray:
    rng = np.random.default_rng(7)
    v = rng.uniform(-0.2, 1.2, (37, 41, 3)).astype(dtype)
    # exact halves between codes (round half to even), both ends, tiny and huge values
    halves = (np.arange(0, 200) + 0.5) / top
    v.reshape(-1)[: halves.size] = halves.astype(dtype)
    v.reshape(-1)[-6:] = [0.0, 1.0, -0.0, 1e-30, 1e30, -1e30]
    return v


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("depth", ["uint8", "uint16"])
def test_codes_equal_numpys_formulation(dtype, depth) -> None:
    top = np.iinfo(depth).max
    v = values(dtype, top)
    expected = np.rint(np.clip(v, 0.0, 1.0) * top).astype(depth)
    codes, bad = to_codes(v, depth)
    assert bad == 0 and codes.dtype == np.dtype(depth)
    np.testing.assert_array_equal(codes, expected)
    strided = v[:, ::2, 1:]  # a view: neither contiguous nor whole
    codes, _ = to_codes(strided, depth)
    np.testing.assert_array_equal(codes, expected[:, ::2, 1:])


def test_non_finite_values_are_counted() -> None:
    v = np.zeros((4, 5, 2), np.float32)
    v[1, 2, 0], v[3, 4, 1], v[0, 0, 1] = np.nan, np.inf, -np.inf
    assert to_codes(v, "uint8")[1] == 3


def test_written_file_holds_the_codes_and_non_finite_is_refused(tmp_path) -> None:
    v = values(np.float32, 255)
    write_image(tmp_path / "a.png", v)
    inp = oiio.ImageInput.open(str(tmp_path / "a.png"))
    back = inp.read_image(0, 0, 0, 3, "uint8")
    inp.close()
    np.testing.assert_array_equal(back, np.rint(np.clip(v, 0, 1) * 255).astype(np.uint8))
    v[3, 3, 0] = np.nan
    with pytest.raises(MatshopError, match=r"b.png.*NaN or Inf values in 1 of 1517 texels"):
        write_image(tmp_path / "b.png", v)
    assert not (tmp_path / "b.png").exists()
