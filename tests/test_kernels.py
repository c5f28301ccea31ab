"""The fused numba kernels against plain numpy formulas, and the ``*_into`` contract.

``matshop/spaces/_kernels.py`` replaces numpy's ``**``, ``arctan``, ``tan``,
``sin``/``cos`` by vectorisable float64 polynomials and runs each editing
space in one strided pass. Here: the math helpers against numpy in float64
over wide ranges, every curve and frame kernel against the numpy formulation
(including NaN, inf, signed zeros, poles), every memory layout the kernels
accept, and ``Space.to_edit_into`` / ``from_edit_into``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from matshop.material import Material, Schema
from matshop.spaces import _kernels as K
from matshop.spaces import get_space, phong
from matshop.spaces.color import linear_to_srgb, srgb_to_linear
from matshop.spaces.frame import (
    NormalFrameSpace,
    NormalTangentFrameSpace,
    _normal_log,
    _normalize_or_z,
    _quat_rotate_x,
    _quat_rotate_z,
    quat_exp,
)
from matshop.spaces.ggx import alpha_from_edit, alpha_to_edit, median_from_edit, median_to_edit

F32_EPS = float(np.finfo(np.float32).eps)
SPECIAL = np.array(
    [0.0, -0.0, 1.0, -1.0, 0.5, 1e-45, -1e-45, 1e-38, 3.4e38, -3.4e38, np.inf, -np.inf, np.nan],
    dtype=np.float32,
)


@njit(error_model="numpy")
def _helpers(x):
    out = np.empty((8, x.shape[0]))
    for i in range(x.shape[0]):
        v = x[i]
        out[0, i] = K.atan_unit(min(abs(v), 1.0))
        out[1, i] = K.atan2_upper(abs(v), v - 0.5)
        c, s = K.cos_sinc(abs(v))
        out[2, i] = c
        out[3, i] = s
        out[4, i] = K.log_pos(abs(v))
        out[5, i] = K.exp_clamped(v)
        out[6, i] = K.pow_pos(abs(v), 2.4)
        out[7, i] = K.pow_pos(abs(v), 1.0 / 2.4)
    return out


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))


def test_math_helpers_match_numpy_in_float64() -> None:
    rng = np.random.default_rng(0)
    x = np.concatenate(
        [rng.uniform(-1, 1, 20000), rng.uniform(-50, 50, 20000), [0.0, 1.0, -1.0, 0.5, 1.5]]
    )
    got = _helpers(x)
    a = np.abs(x)
    assert np.max(np.abs(got[0] - np.arctan(np.minimum(a, 1.0)))) < 1e-11
    assert np.max(np.abs(got[1] - np.arctan2(a, x - 0.5))) < 1e-11
    assert np.max(np.abs(got[2] - np.cos(a))) < 1e-14
    sinc = np.divide(np.sin(a), a, out=np.ones_like(a), where=a > 0)
    assert np.max(np.abs(got[3] - sinc)) < 1e-14
    pos = a > 0
    assert np.max(np.abs(got[4][pos] - np.log(a[pos]))) < 1e-10
    assert _rel(got[5], np.exp(x)) < 5e-13
    assert _rel(got[6][pos], a[pos] ** 2.4) < 1e-10
    assert _rel(got[7][pos], a[pos] ** (1 / 2.4)) < 1e-10
    # wide ranges: log/pow over every float32 magnitude, exp to its clamp, sin/cos to 1e6
    wide = np.geomspace(1e-45, 3.4e38, 5001)
    got = _helpers(wide)
    assert np.max(np.abs(got[4] - np.log(wide))) < 1e-10
    assert _rel(got[6], wide**2.4) < 1e-9
    assert _rel(got[7], wide ** (1 / 2.4)) < 1e-9
    t = np.linspace(-700, 700, 5001)
    assert _rel(_helpers(t)[5], np.exp(t)) < 5e-13
    phi = np.geomspace(1e-3, 1e6, 5001)
    got = _helpers(phi)
    assert np.max(np.abs(got[2] - np.cos(phi))) < 1e-9
    assert np.max(np.abs(got[3] * phi - np.sin(phi))) < 1e-9
    # past the reduction's range the pair stays on the unit circle
    huge = np.array([1e15, 1e20, 1e30, 3e38])
    got = _helpers(huge)
    np.testing.assert_allclose(got[2] ** 2 + (got[3] * huge) ** 2, 1.0, atol=1e-12)


# ---------------------------------------------------------------------------
# per-channel curves


def _srgb_decode_ref(v: np.ndarray) -> np.ndarray:
    v = v.astype(np.float64)
    m = np.abs(v)
    with np.errstate(invalid="ignore"):
        out = np.where(m <= 0.04045, m / 12.92, ((m + 0.055) / 1.055) ** 2.4)
    return np.copysign(out, v)


def _srgb_encode_ref(v: np.ndarray) -> np.ndarray:
    v = v.astype(np.float64)
    m = np.abs(v)
    with np.errstate(invalid="ignore"):
        out = np.where(m <= 0.0031308, m * 12.92, 1.055 * m ** (1 / 2.4) - 0.055)
    return np.copysign(out, v)


def _clip(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return np.clip(v.astype(np.float64), lo, hi)


_PHONG_E = (float(phong._MEDIAN_E_MIN), float(phong._MEDIAN_E_MAX))

CURVES = {
    "srgb_decode": (K.SRGB_DECODE, {}, _srgb_decode_ref),
    "srgb_encode": (K.SRGB_ENCODE, {}, _srgb_encode_ref),
    "srgb_encode_clamped": (
        K.SRGB_ENCODE,
        {"lo": 0, "hi": 1},
        lambda v: _srgb_encode_ref(_clip(v, 0, 1)),
    ),
    "gamma": (K.POWER, {"lo": 0, "p": 2.2}, lambda v: _clip(v, 0, np.inf) ** 2.2),
    "gamma_inv": (K.POWER, {"lo": 0, "hi": 1, "p": 1 / 2.2}, lambda v: _clip(v, 0, 1) ** (1 / 2.2)),
    "atan_square": (K.ATAN_SQUARE, {"lo": 0, "hi": 1}, lambda v: np.arctan(_clip(v, 0, 1) ** 2)),
    "sqrt_tan": (
        K.SQRT_TAN,
        {"lo": 0, "hi": math.pi / 4},
        lambda v: np.sqrt(np.clip(np.tan(_clip(v, 0, math.pi / 4)), 0, 1)),
    ),
    "square": (K.SQUARE, {"lo": 0, "hi": 1}, lambda v: _clip(v, 0, 1) ** 2),
    "sqrt": (K.SQRT, {"lo": 0, "hi": 1}, lambda v: np.sqrt(_clip(v, 0, 1))),
    "identity": (K.IDENTITY, {}, lambda v: v.astype(np.float64)),
    # Phong's median angle (phong.py's closed forms in float64, expm1 / log1p for tiny angles)
    "phong_median": (
        K.PHONG_MEDIAN_TO_EDIT,
        {"lo": 0},
        lambda v: 2 * np.arcsin(np.sqrt(-0.5 * np.expm1(-np.log(2) / (_clip(v, 0, np.inf) + 2)))),
    ),
    "phong_median_inverse": (
        K.PHONG_MEDIAN_FROM_EDIT,
        {"lo": _PHONG_E[0], "hi": _PHONG_E[1], "p": phong.N_MAX},
        lambda v: np.clip(
            -np.log(2) / np.log1p(-2 * np.sin(_clip(v, *_PHONG_E) / 2) ** 2) - 2, 0, phong.N_MAX
        ),
    ),
    "clamp": (K.IDENTITY, {"lo": -0.5, "hi": 2.0}, lambda v: _clip(v, -0.5, 2.0)),
}


def _curve_inputs() -> np.ndarray:
    rng = np.random.default_rng(1)
    values = np.concatenate(
        [
            rng.uniform(0, 1, 30000),
            rng.uniform(-3, 3, 3000),
            np.geomspace(1e-40, 1e30, 3000),
            np.arange(65536) / 65535.0,
            SPECIAL,
        ]
    )
    return values.astype(np.float32)


@pytest.mark.parametrize("name", sorted(CURVES))
def test_curves_match_numpy_to_a_float32_ulp(name: str) -> None:
    curve, kwargs, reference = CURVES[name]
    x = _curve_inputs()
    got = K.transfer(x, np.empty_like(x), curve, **kwargs)
    with np.errstate(invalid="ignore", over="ignore"):
        ref = reference(x).astype(np.float32)  # the exact value rounded to float32
    nan = np.isnan(ref)
    assert np.array_equal(np.isnan(got), nan), x[np.isnan(got) != nan]
    same = got[~nan] == ref[~nan]
    with np.errstate(invalid="ignore"):  # inf - inf where both are inf (counted as same)
        ulps = np.abs(got[~nan].astype(np.float64) - ref[~nan]) / np.maximum(
            np.abs(ref[~nan].astype(np.float64)) * F32_EPS, np.finfo(np.float32).smallest_subnormal
        )
    assert np.all(same | (ulps <= 1.0)), (x[~nan][~same][:5], got[~nan][~same][:5])
    # odd symmetry and signed zeros of the sRGB curves
    if name in ("srgb_decode", "srgb_encode"):
        assert np.array_equal(np.signbit(got[~nan]), np.signbit(x[~nan]))


def _float32_grid(lo: float, hi: float, step: int) -> np.ndarray:
    """Every ``step``-th float32 between ``lo`` and ``hi`` (by bit pattern), plus ``hi``."""
    a, b = np.array([lo, hi], np.float32).view(np.uint32)
    return np.append(np.arange(a, b, step, dtype=np.uint32).view(np.float32), np.float32(hi))


@pytest.mark.parametrize("curve", ["srgb_decode", "srgb_encode"])
def test_srgb_rational_fast_path_over_a_dense_float32_grid(curve: str) -> None:
    """Blocks within [-1, 1] use rational functions: within an ulp everywhere in (knee, 1]."""
    knee = 0.04045 if curve == "srgb_decode" else 0.0031308
    x = _float32_grid(knee, 1.0, 37)
    code, _, reference = CURVES[curve]
    got = K.transfer(x, np.empty_like(x), code).astype(np.float64)
    exact = reference(x)
    assert np.max(np.abs(got - exact) / exact) < 1.5 * F32_EPS / 2  # float32 rounding only
    np.testing.assert_array_equal(K.transfer(-x, np.empty_like(x), code), -got.astype(np.float32))


@pytest.mark.parametrize("curve", ["phong_median", "phong_median_inverse"])
def test_phong_median_over_a_dense_float32_grid(curve: str) -> None:
    """The fitted polynomials over the whole domain (every 2^9-th float32 exponent up
    to N_MAX, every 2^6-th angle between the clamps): within an ulp of numpy's float64
    closed forms, and equal to them rounded nearly everywhere -- also next to n = 0,
    where the inverse's factor pi/4 - e keeps the digits a difference would lose."""
    code, kwargs, reference = CURVES[curve]
    if curve == "phong_median":
        x = _float32_grid(0.0, phong.N_MAX, 1 << 9)
    else:
        x = _float32_grid(*_PHONG_E, 1 << 6)
        x = np.concatenate([x, _float32_grid(0.785, _PHONG_E[1], 1)])  # n from 0 to 1e-3
    got = K.transfer(x, np.empty_like(x), code, **kwargs)
    exact = reference(x).astype(np.float32)
    ulps = np.abs(got.astype(np.float64) - exact) / np.maximum(
        np.spacing(np.abs(exact)), np.finfo(np.float32).smallest_subnormal
    )
    assert ulps.max() <= 1.0
    assert np.mean(got == exact) > 0.999


LAYOUTS = ["packed", "strided_in", "strided_out", "both_strided", "reversed", "3d", "0d", "empty"]


def _layout(layout: str, values: np.ndarray, channels: int) -> tuple[np.ndarray, np.ndarray]:
    """(src, dst) views in the given memory layout; src holds ``values``."""
    n = values.size // channels
    rows = values[: n * channels].reshape(n, channels)
    if layout == "packed":
        return rows.copy(), np.zeros_like(rows)
    wide_src = np.full((n, channels + 5), 7.0, np.float32)
    wide_src[:, 2 : 2 + channels] = rows
    wide_dst = np.full((n, channels + 5), 7.0, np.float32)
    if layout == "strided_in":
        return wide_src[:, 2 : 2 + channels], np.zeros_like(rows)
    if layout == "strided_out":
        return rows.copy(), wide_dst[:, 1 : 1 + channels]
    if layout == "both_strided":
        return wide_src[:, 2 : 2 + channels], wide_dst[:, 1 : 1 + channels]
    if layout == "reversed":  # negative strides: through packed copies
        return rows[::-1].copy()[::-1], np.zeros_like(rows)[::-1]
    if layout == "3d":  # a crop: leading axes that cannot be merged into one
        img = np.zeros((4, n // 4 + 3, channels), np.float32)
        img[:, : n // 4] = rows[: 4 * (n // 4)].reshape(4, n // 4, channels)
        out = np.full((4, n // 4 + 3, channels + 2), 7.0, np.float32)
        return img[:, : n // 4], out[:, 1 : n // 4 + 1, 1 : 1 + channels]
    if layout == "0d":
        return values[:1].reshape(()).copy(), np.zeros((), np.float32)
    return rows[:0], np.zeros_like(rows[:0])


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("channels", [1, 3, 4, 6, 11])
def test_transfer_layouts(layout: str, channels: int) -> None:
    values = np.random.default_rng(2).uniform(-0.2, 1.2, 6000).astype(np.float32)
    src, dst = _layout(layout, values, channels)
    before = src.copy()
    wide = dst.base if dst.base is not None else dst
    untouched = wide.copy()
    result = K.transfer(src, dst, K.SRGB_DECODE)
    assert result is dst
    np.testing.assert_array_equal(src, before)
    packed = K.transfer(src.copy(), np.empty(src.shape, np.float32), K.SRGB_DECODE)
    np.testing.assert_array_equal(dst, packed)
    # nothing outside the view was written
    if wide is not dst and layout in ("strided_out", "both_strided", "3d"):
        mask = np.ones(wide.shape, bool)
        if layout == "3d":
            mask[:, 1 : dst.shape[1] + 1, 1 : 1 + channels] = False
        else:
            mask[:, 1 : 1 + channels] = False
        np.testing.assert_array_equal(wide[mask], untouched[mask])


def test_transfer_refuses_bad_arguments() -> None:
    x = np.zeros((4, 3), np.float32)
    with pytest.raises(ValueError, match="shapes differ"):
        K.transfer(x, np.zeros((4, 2), np.float32), K.IDENTITY)
    with pytest.raises(TypeError, match="float32"):
        K.transfer(x, np.zeros((4, 3)), K.IDENTITY)
    frozen = np.zeros((4, 3), np.float32)
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        K.transfer(x, frozen, K.IDENTITY)


def test_public_color_and_ggx_functions_take_out() -> None:
    x = np.linspace(0, 1, 1001, dtype=np.float32).reshape(7, 143)
    for fn in (srgb_to_linear, linear_to_srgb):
        wide = np.zeros((7, 150), np.float32)
        out = wide[:, 3:146]
        assert fn(x, out=out) is out
        np.testing.assert_array_equal(out, fn(x))
        assert not wide[:, :3].any() and not wide[:, 146:].any()
    for fn in (alpha_to_edit, alpha_from_edit, median_to_edit, median_from_edit):
        out = np.empty_like(x)
        assert fn(x, out=out) is out
        np.testing.assert_array_equal(out, fn(x))
    # scalars and lists still work
    assert float(srgb_to_linear(np.float32(1.0))) == 1.0
    np.testing.assert_allclose(linear_to_srgb([0.0, 1.0]), [0.0, 1.0])


def test_ggx_median_matches_the_numpy_formula() -> None:
    r = np.concatenate([np.linspace(-0.5, 1.5, 20001), [np.nan]]).astype(np.float32)[:, None]
    space = get_space("ggx")
    edit = space.to_edit(r)
    with np.errstate(invalid="ignore"):
        ref = np.arctan(np.clip(r.astype(np.float64), 0, 1) ** 2)
    np.testing.assert_allclose(edit, ref, rtol=F32_EPS, atol=1e-12)
    e = np.concatenate([np.linspace(-1, 2, 20001), [np.nan]]).astype(np.float32)[:, None]
    with np.errstate(invalid="ignore"):
        ref = np.sqrt(np.clip(np.tan(np.clip(e.astype(np.float64), 0, np.pi / 4)), 0, 1))
    np.testing.assert_allclose(space.from_edit(e), ref, rtol=F32_EPS, atol=1e-12)


# ---------------------------------------------------------------------------
# frames


def _unit_and_special_normals(rng: np.random.Generator) -> np.ndarray:
    n = rng.normal(size=(20000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    eps = 10.0 ** rng.uniform(-9, -2, size=(400, 1))
    near = rng.normal(size=(400, 3)) * eps
    near[:200, 2] = 1.0
    near[200:, 2] = -1.0
    special = [
        [0, 0, 1],
        [0, 0, -1],
        [0, 0, 0],
        [0, 0, 5],
        [1, 0, 0],
        [0, -1, 0],
        [3, 4, 0],
        [np.nan, 0, 1],
        [0, 0, np.inf],
        [1e-13, 0, 0],
        [1e-30, 1e-30, -1],
    ]
    return np.concatenate([n, near, special]).astype(np.float32)


def _quat_exp64(e: np.ndarray) -> np.ndarray:
    e = e.astype(np.float64)
    phi = np.linalg.norm(e, axis=-1, keepdims=True)
    sinc = np.divide(np.sin(phi), phi, out=np.ones_like(phi), where=phi > 0)
    return np.concatenate([np.cos(phi), sinc * e], axis=-1)


def _rotate64(q: np.ndarray) -> np.ndarray:
    """(R z, R x) of float64 unit quaternions."""
    w, x, y, z = q.T
    n = [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)]
    t = [1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)]
    return np.stack(n + t, axis=-1)


def test_normal_kernel_matches_the_numpy_formulation() -> None:
    rng = np.random.default_rng(3)
    n = _unit_and_special_normals(rng)
    edit = NormalFrameSpace().to_edit(n)
    with np.errstate(all="ignore"):
        ref = _normal_log(_normalize_or_z(n))
    finite = np.all(np.isfinite(n), axis=1)
    np.testing.assert_allclose(edit[finite], ref[finite], atol=1e-6)
    # non-finite normals count as flat (numpy gave NaN for infinities)
    np.testing.assert_array_equal(edit[~finite], 0.0)
    assert np.all(edit[:, 2] == 0.0)
    # from_edit: arbitrary 3-vectors, including twist, huge and non-finite values
    e = np.concatenate(
        [
            rng.normal(size=(20000, 3)) * 2,
            rng.uniform(-50, 50, size=(2000, 3)),
            [[0, 0, 0], [0, 0, 1.3], [np.pi / 2, 0, 0], [1e30, 2e30, 0], [np.nan, 0, 0]],
            [[np.inf, 0, 0], [0, -np.inf, 1]],
        ]
    ).astype(np.float32)
    back = NormalFrameSpace().from_edit(e)
    with np.errstate(all="ignore"):
        ref = _normalize_or_z(_quat_rotate_z(quat_exp(e)))
    small = np.linalg.norm(e.astype(np.float64), axis=1) < 10
    np.testing.assert_allclose(back[small], ref[small], atol=2e-6)
    # numpy's float32 sin/cos lose digits for large angles: float64 truth there
    moderate = np.linalg.norm(e.astype(np.float64), axis=1) < 1e3
    q64 = _quat_exp64(e[moderate])
    np.testing.assert_allclose(back[moderate], _rotate64(q64)[:, :3], atol=2e-7)
    np.testing.assert_allclose(np.linalg.norm(back.astype(np.float64), axis=1), 1.0, atol=1e-6)
    bad = ~np.all(np.isfinite(e), axis=1)
    np.testing.assert_array_equal(back[bad], np.tile([0, 0, 1], (bad.sum(), 1)))


def test_frame_kernel_matches_the_numpy_formulation() -> None:
    rng = np.random.default_rng(4)
    n = _unit_and_special_normals(rng)
    t = rng.normal(size=n.shape).astype(np.float32) * 2
    t[:50] = 3 * n[:50]  # parallel tangents: smallest-rotation frame
    t[50:100] = 0.0
    t[100:110] = np.nan
    frames = np.concatenate([n, t], axis=1)
    space = NormalTangentFrameSpace()
    edit = space.to_edit(frames)
    with np.errstate(all="ignore"):
        ref = space._reference_to_edit(frames)
    finite = np.all(np.isfinite(n), axis=1)
    # q and -q (|q~| near pi/2) are the same rotation; compare the rotations
    mats = [quat_exp(x.astype(np.float64)) for x in (edit[finite], ref[finite])]
    dist = np.minimum(np.abs(mats[0] - mats[1]).max(-1), np.abs(mats[0] + mats[1]).max(-1))
    assert dist.max() < 2e-6
    e = np.concatenate(
        [rng.normal(size=(20000, 3)), rng.uniform(-50, 50, (100, 3)), [[np.nan, 1, 0]]]
    ).astype(np.float32)
    back = space.from_edit(e)
    q = quat_exp(e[:20000])
    ref = np.concatenate([_quat_rotate_z(q), _quat_rotate_x(q)], axis=-1)
    np.testing.assert_allclose(back[:20000], ref, atol=2e-6)
    np.testing.assert_allclose(back[:-1], _rotate64(_quat_exp64(e[:-1])), atol=2e-7)
    # non-finite edits give the flat frame (numpy gave NaN)
    np.testing.assert_array_equal(back[-1], [0, 0, 1, 1, 0, 0])


@pytest.mark.parametrize("layout", ["packed", "strided_in", "strided_out", "both_strided", "3d"])
@pytest.mark.parametrize("code", [K.NORMAL_TO_EDIT, K.NORMAL_FROM_EDIT, K.FRAME_TO_EDIT])
def test_frame_layouts(layout: str, code: int) -> None:
    c_in, c_out = K.FRAME_CHANNELS[code]
    values = np.random.default_rng(5).normal(size=1200 * c_in).astype(np.float32)
    src, _ = _layout(layout, values, c_in)
    if layout in ("packed", "strided_in"):
        dst = np.zeros((*src.shape[:-1], c_out), np.float32)
    elif layout == "3d":
        dst = np.zeros((*src.shape[:-1], c_out + 4), np.float32)[..., 2 : 2 + c_out]
    else:
        dst = np.zeros((src.shape[0], c_out + 5), np.float32)[:, 1 : 1 + c_out]
    assert K.frames(src, dst, code) is dst
    packed = K.frames(src.copy(), np.empty(dst.shape, np.float32), code)
    np.testing.assert_array_equal(dst, packed)
    with pytest.raises(ValueError, match="expected"):
        K.frames(src, np.zeros((*src.shape[:-1], c_out + 1), np.float32), code)


# ---------------------------------------------------------------------------
# Space.to_edit_into / from_edit_into and the material loop


@pytest.mark.parametrize(
    "name", ["srgb", "gamma22", "identity", "identity_unbounded", "ggx", "ggx_alpha", "normal",
             "normal_tangent", "phong", "sampled"]
)  # fmt: skip
def test_into_equals_allocating_conversion(name: str) -> None:
    space = get_space(name)
    rng = np.random.default_rng(6)
    phys = rng.uniform(0.0, 1.0, size=(6, 5, space.phys_channels)).astype(np.float32)
    if name.startswith("normal"):
        phys[..., :3] += [0, 0, 1]
    edit = space.to_edit(phys)
    wide = np.full((6, 5, space.edit_channels + 3), 9.0, np.float32)
    out = wide[..., 2 : 2 + space.edit_channels]
    assert space.to_edit_into(phys, out) is out
    np.testing.assert_array_equal(out, edit)
    assert np.all(wide[..., :2] == 9.0) and np.all(wide[..., 2 + space.edit_channels :] == 9.0)
    back = space.from_edit(out)
    wide_back = np.full((6, 5, space.phys_channels + 1), 9.0, np.float32)
    out_back = wide_back[..., 1:]
    assert space.from_edit_into(out, out_back) is out_back
    np.testing.assert_array_equal(out_back, back)
    with pytest.raises(ValueError, match="shape"):
        space.to_edit_into(phys, np.zeros((6, 4, space.edit_channels), np.float32))
    with pytest.raises(TypeError, match="float32"):
        space.from_edit_into(edit, np.zeros(back.shape, np.float64))
    with pytest.raises(ValueError, match="channel"):
        space.to_edit_into(phys[..., :0], out)


def test_material_round_trip_writes_through_the_kernels() -> None:
    rng = np.random.default_rng(7)
    normal = rng.normal(size=(33, 20, 3)) * [0.3, 0.3, 1] + [0, 0, 1]
    maps = {
        "base_color": rng.random((33, 20, 3), dtype=np.float32),
        "metallic": rng.random((33, 20, 1), dtype=np.float32),
        "roughness": rng.random((33, 20, 1), dtype=np.float32),
        "normal": (normal / np.linalg.norm(normal, axis=-1, keepdims=True)).astype(np.float32),
    }
    material = Material("m", Schema.from_names(list(maps)), maps)
    edit = material.to_edit()
    for param in material.schema.parameters:
        np.testing.assert_array_equal(edit[param.name], param.space.to_edit(maps[param.name]))
    back = edit.to_physical()
    for param in material.schema.parameters:
        np.testing.assert_array_equal(
            back.maps[param.name], param.space.from_edit(edit[param.name])
        )
        np.testing.assert_allclose(back.maps[param.name], maps[param.name], atol=2e-6)
