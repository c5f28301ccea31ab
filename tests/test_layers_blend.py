"""Blend modes in edit space against their closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.layers.blend import BLEND_MODES, blend, mean_of, weighted_mean

RNG = np.random.default_rng(7)
B = RNG.normal(0.3, 0.5, (9, 11, 4)).astype(np.float32)
L = RNG.normal(0.5, 0.7, (9, 11, 4)).astype(np.float32)
A = RNG.random((9, 11)).astype(np.float32)
A[0, :] = 0.0
A[1, :] = 1.0
MEAN = L.mean(axis=(0, 1)).astype(np.float32)


def closed_form(mode: str, b: np.ndarray, v: np.ndarray, a: np.ndarray, mean: np.ndarray):
    """The table in matshop.layers.blend, in float32 numpy, operation for operation."""
    a = a[..., None]
    one = np.float32(1.0)
    return {
        "normal": (one - a) * b + a * v,
        "add": b + a * v,
        "subtract": b - a * v,
        "multiply": (one - a) * b + a * (b * v),
        "detail": b + a * (v - mean),
    }[mode]


@pytest.mark.parametrize("mode", list(BLEND_MODES))
def test_mode_equals_its_closed_form(mode: str) -> None:
    got = blend(mode, B, L, A, mean=MEAN)
    assert got.dtype == np.float32
    assert np.array_equal(got, closed_form(mode, B, L, A, MEAN))


@pytest.mark.parametrize("mode", list(BLEND_MODES))
def test_zero_weight_keeps_the_composite_exactly(mode: str) -> None:
    got = blend(mode, B, L, np.zeros_like(A), mean=MEAN)
    assert np.array_equal(got, B)


def test_full_weight_limits() -> None:
    one = np.ones_like(A)
    assert np.array_equal(blend("normal", B, L, one), L)
    assert np.array_equal(blend("multiply", B, L, one), B * L)
    assert np.array_equal(blend("add", B, L, one), B + L)


@pytest.mark.parametrize("mode", list(BLEND_MODES))
def test_linear_flag_tells_the_truth(mode: str) -> None:
    """Linear modes: f(s B1 + t B2, s L1 + t L2) == s f(B1, L1) + t f(B2, L2) (means follow)."""
    spec = BLEND_MODES[mode]
    b2 = RNG.normal(size=B.shape).astype(np.float32)
    l2 = RNG.normal(size=L.shape).astype(np.float32)
    s, t = 0.75, -1.5
    mean2 = l2.mean(axis=(0, 1)).astype(np.float32)
    f = lambda b, v, m: blend(mode, b, v, A, mean=m).astype(np.float64)  # noqa: E731
    mix = f(
        (s * B + t * b2).astype(np.float32),
        (s * L + t * l2).astype(np.float32),
        (s * MEAN + t * mean2).astype(np.float32),
    )
    parts = s * f(B, L, MEAN) + t * f(b2, l2, mean2)
    assert np.allclose(mix, parts, atol=1e-4) == spec.linear


def test_blend_in_place_on_a_strided_view() -> None:
    below = B.copy()
    view = below[..., 1:3]
    blend("normal", view, L[..., 1:3], A, out=view)
    expected = B.copy()
    expected[..., 1:3] = closed_form("normal", B[..., 1:3], L[..., 1:3], A, MEAN[1:3])
    assert np.array_equal(below, expected)


def test_broadcast_constant_layer() -> None:
    value = np.array([1.0, 2.0, 3.0, 4.0], np.float32)
    got = blend("add", B, np.broadcast_to(value, B.shape), A)
    assert np.array_equal(got, closed_form("add", B, np.broadcast_to(value, B.shape), A, MEAN))


def test_detail_needs_a_mean_and_unknown_modes_fail() -> None:
    with pytest.raises(ValueError, match="mean"):
        blend("detail", B, L, A)
    with pytest.raises(ValueError, match="known"):
        blend("screen", B, L, A)


def test_weighted_mean() -> None:
    weights = RNG.random((9, 11)).astype(np.float32)
    total, weight = weighted_mean(L, weights)
    expected = (L * weights[..., None]).sum(axis=(0, 1)) / weights.sum()
    assert np.allclose(mean_of(total, weight), expected, rtol=1e-5)
    assert np.array_equal(mean_of(total, 0.0), np.zeros(4, np.float32))


def test_only_multiply_is_nonlinear() -> None:
    assert {name for name, mode in BLEND_MODES.items() if not mode.linear} == {"multiply"}
