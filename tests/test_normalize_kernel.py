"""The fused normal renormalisation equals the numpy formulation it replaced, bit for bit."""

from __future__ import annotations

import numpy as np

from matshop.spaces.frame import _TINY_LENGTH, _normalize_or_z, decode_normal_map


def numpy_normalize_or_z(v: np.ndarray) -> np.ndarray:
    f32 = np.float32
    length = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    ok = length > _TINY_LENGTH
    out = np.where(ok, v / np.where(ok, length, f32(1.0)), f32(0.0))
    out[..., 2] = np.where(ok[..., 0], out[..., 2], f32(1.0))
    return out.astype(np.float32, copy=False)


def test_same_bits_as_numpy_including_zero_tiny_nan_and_inf() -> None:
    rng = np.random.default_rng(0)
    v = rng.normal(size=(129, 67, 3)).astype(np.float32) * rng.uniform(1e-6, 1e6, (129, 67, 1))
    v = v.astype(np.float32)
    v[0, :4] = [[0, 0, 0], [np.nan, 1, 0], [1e-20, 0, 0], [np.inf, 0, 0]]
    with np.errstate(invalid="ignore"):
        expected = numpy_normalize_or_z(v)
    got = _normalize_or_z(v)
    assert got.shape == v.shape and got.dtype == np.float32
    assert np.array_equal(got, expected, equal_nan=True)
    assert np.array_equal(got[0, 0], [0, 0, 1]) and np.array_equal(got[0, 2], [0, 0, 1])


def test_a_strided_view_and_8_bit_codes_decode_like_numpy() -> None:
    codes = np.random.default_rng(1).integers(0, 256, (40, 50, 4), dtype=np.uint8)[..., :3]
    n = np.float32(2.0) * (codes.astype(np.float32) / np.float32(255)) - np.float32(1.0)
    assert np.array_equal(decode_normal_map(codes), numpy_normalize_or_z(n))
