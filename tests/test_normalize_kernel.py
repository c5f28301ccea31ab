"""The fused normal renormalisation, decoding and encoding equal the numpy formulation
they replaced, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.spaces.frame import (
    _TINY_LENGTH,
    _normalize_or_z,
    decode_normal_map,
    encode_normal_map,
)


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


def numpy_decode(rgb: np.ndarray, convention: str) -> np.ndarray:
    """The numpy formulation the fused decode replaced: ``2 rgb - 1``, flip, renormalise."""
    n = np.float32(2.0) * rgb - np.float32(1.0)
    if convention == "directx":
        n[..., 1] = -n[..., 1]
    return numpy_normalize_or_z(n)


def numpy_encode(normal: np.ndarray, convention: str) -> np.ndarray:
    """The numpy formulation the fused encode replaced: renormalise, flip, ``clip(n/2 + 1/2)``."""
    n = numpy_normalize_or_z(normal)
    if convention == "directx":
        n[..., 1] = -n[..., 1]
    f32 = np.float32
    return np.clip(f32(0.5) * n + f32(0.5), f32(0.0), f32(1.0))


@pytest.mark.parametrize("convention", ["opengl", "directx"])
def test_decode_and_encode_are_numpy_bit_for_bit(convention: str) -> None:
    rng = np.random.default_rng(2)
    rgb = rng.uniform(-0.2, 1.2, (97, 61, 3)).astype(np.float32)
    rgb[0, :6] = [
        [0.5, 0.5, 0.5],
        [np.nan, 0, 1],
        [np.inf, 0.5, 0.5],
        [0, 0, 0],
        [1, 1, 1],
        [1e-30, 0.5, 0.5],
    ]
    normal = (rng.normal(size=(97, 61, 3)) * rng.uniform(1e-6, 1e6, (97, 61, 1))).astype(np.float32)
    normal[0, :5] = [[0, 0, 0], [np.nan, 1, 0], [1e-20, 0, 0], [np.inf, 0, 0], [0, -1, 0]]
    with np.errstate(invalid="ignore"):
        decoded, encoded = numpy_decode(rgb, convention), numpy_encode(normal, convention)
    got_decoded = decode_normal_map(rgb, convention=convention)
    got_encoded = encode_normal_map(normal, convention=convention)
    assert got_decoded.dtype == got_encoded.dtype == np.float32
    assert np.array_equal(got_decoded, decoded, equal_nan=True)
    assert np.array_equal(got_encoded, encoded, equal_nan=True)
    # the flat pixel is +z both ways; a zero normal encodes as flat; NaN stays NaN
    flat = [0.5, 0.5, 1.0]
    assert np.array_equal(got_decoded[0, 0], [0, 0, 1]) and np.array_equal(got_encoded[0, 0], flat)
    assert np.isnan(got_encoded[0, 3]).any()


def test_encode_leaves_its_input_alone_and_flips_green_for_directx() -> None:
    normal = np.array([0.0, 3.0, 4.0], np.float32)  # (0, 0.6, 0.8) once unit
    np.testing.assert_allclose(encode_normal_map(normal), [0.5, 0.8, 0.9], atol=1e-7)
    np.testing.assert_allclose(
        encode_normal_map(normal, convention="directx"), [0.5, 0.2, 0.9], atol=1e-7
    )
    assert np.array_equal(normal, [0.0, 3.0, 4.0])
