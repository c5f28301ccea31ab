"""Tests for the local-frame spaces (normal maps, normal + tangent frames, height maps).

Independent truth: scipy.spatial.transform.Rotation (a second implementation of
rotation matrix <-> quaternion <-> rotation vector, with ``log q = rotvec / 2``)
and scipy's Slerp; closed-form normals of analytic height fields.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation, Slerp

from matshop.spaces.base import EditRange
from matshop.spaces.frame import (
    SPACES,
    NormalFrameSpace,
    NormalTangentFrameSpace,
    decode_normal_map,
    encode_normal_map,
    guess_normal_convention,
    height_to_normal,
    quat_exp,
    quat_from_matrix,
    quat_log,
    quat_rotate,
)

NORMAL = NormalFrameSpace()
FRAME = NormalTangentFrameSpace()
Z = np.array([0.0, 0.0, 1.0])
#: one 8-bit code changes a decoded component by 2/255; three of them at most
ONE_8BIT_STEP = math.sqrt(3.0) * 2.0 / 255.0
#: float32 round trips stay far below an 8-bit step
FLOAT_TOL = 2e-6

#: these properties run numpy on small arrays: 60 examples, no per-example deadline
#: (set per test, so importing this module changes no other test's settings)
PROPERTY = settings(max_examples=60, deadline=None)


# ---------------------------------------------------------------------------
# helpers (float64, independent of the module)


def angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between vectors, accurate near 0 and pi (atan2 of |a x b| and a . b)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def random_unit(rng: np.random.Generator, count: int, hemisphere: bool = False) -> np.ndarray:
    v = rng.normal(size=(count, 3))
    if hemisphere:
        v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def frames_of(rot: Rotation) -> np.ndarray:
    """(n, t) = (R z, R x) for scipy rotations, shape (N, 6)."""
    m = rot.as_matrix().reshape(-1, 3, 3)
    return np.concatenate([m[:, :, 2], m[:, :, 0]], axis=-1)


def assert_unit(v: np.ndarray, tol: float = 1e-5) -> None:
    assert np.all(np.isfinite(v))
    np.testing.assert_allclose(np.linalg.norm(v.astype(np.float64), axis=-1), 1.0, atol=tol)


def assert_orthonormal_frames(frame: np.ndarray, tol: float = 1e-5) -> None:
    n, t = frame[..., :3].astype(np.float64), frame[..., 3:].astype(np.float64)
    assert_unit(n, tol)
    assert_unit(t, tol)
    np.testing.assert_allclose(np.sum(n * t, axis=-1), 0.0, atol=tol)


def unit_vectors():
    """Hypothesis: unit 3-vectors, including the poles and near-poles."""
    comps = st.floats(-1.0, 1.0, allow_nan=False, width=64)
    generic = st.tuples(comps, comps, comps).filter(lambda v: sum(c * c for c in v) > 1e-6)
    tiny = st.floats(-1e-6, 1e-6, allow_nan=False)
    near_pole = st.tuples(tiny, tiny, st.sampled_from([-1.0, 1.0]))
    poles = st.sampled_from([(0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (1.0, 0.0, 0.0), (0.0, -1.0, 0.0)])
    return st.one_of(generic, near_pole, poles).map(
        lambda v: np.asarray(v, dtype=np.float64) / np.linalg.norm(v)
    )


# ---------------------------------------------------------------------------
# registry and contract


def test_registry_and_attributes():
    assert set(SPACES) == {"normal", "normal_tangent"}
    assert isinstance(SPACES["normal"], NormalFrameSpace)
    assert isinstance(SPACES["normal_tangent"], NormalTangentFrameSpace)
    for space in SPACES.values():
        assert space.edit_channels == 3
        assert space.curve_mode == "vector"
        assert space.edit_range == EditRange(0.0, math.pi / 2)
    # the range is tight: q_s >= 0 keeps |log q| (half the angle) within pi/2
    rng = np.random.default_rng(7)
    frames = rng.normal(size=(20000, 6))
    frames[:, :3] /= np.linalg.norm(frames[:, :3], axis=1, keepdims=True)
    frames[:, 3:] /= np.linalg.norm(frames[:, 3:], axis=1, keepdims=True)
    for space, phys in ((SPACES["normal"], frames[:, :3]), (SPACES["normal_tangent"], frames)):
        magnitude = np.linalg.norm(space.to_edit(phys.astype(np.float32)), axis=1)
        assert magnitude.max() <= space.edit_range.hi + 1e-5
        assert magnitude.max() > 0.95 * space.edit_range.hi
    assert SPACES["normal"].phys_channels == 3
    assert SPACES["normal_tangent"].phys_channels == 6


@pytest.mark.parametrize("space", [NORMAL, FRAME], ids=lambda s: s.name)
@pytest.mark.parametrize("lead", [(), (7,), (2, 3, 4)])
def test_shapes_dtype_and_input_untouched(space, lead):
    rng = np.random.default_rng(1)
    phys = frames_of(Rotation.random(int(np.prod(lead)), random_state=2))
    phys = phys[:, : space.phys_channels].reshape(*lead, space.phys_channels)
    for dtype in (np.float32, np.float64):
        src = phys.astype(dtype)
        before = src.copy()
        edit = space.to_edit(src)
        assert edit.shape == (*lead, 3) and edit.dtype == np.float32
        np.testing.assert_array_equal(src, before)
        edit_in = (edit + rng.normal(size=edit.shape)).astype(dtype)
        edit_before = edit_in.copy()
        back = space.from_edit(edit_in)
        assert back.shape == (*lead, space.phys_channels) and back.dtype == np.float32
        np.testing.assert_array_equal(edit_in, edit_before)


@pytest.mark.parametrize("space", [NORMAL, FRAME], ids=lambda s: s.name)
def test_wrong_channel_counts_raise(space):
    with pytest.raises(ValueError, match=r"expected \d channel\(s\) on the last axis"):
        space.to_edit(np.zeros((4, space.phys_channels + 1), np.float32))
    with pytest.raises(ValueError, match="expected 3 channel"):
        space.from_edit(np.zeros((4, 2), np.float32))
    with pytest.raises(ValueError, match="expected"):
        space.to_edit(np.float32(1.0))
    with pytest.raises(ValueError, match="expected 3 channel"):
        decode_normal_map(np.zeros((2, 2, 4)))
    with pytest.raises(ValueError, match="expected 3 channel"):
        encode_normal_map(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="'opengl' or 'directx'"):
        decode_normal_map(np.zeros((2, 3)), convention="vulkan")
    with pytest.raises(ValueError, match=r"\(H, W, 3\)"):
        guess_normal_convention(np.zeros((8, 3)))
    with pytest.raises(ValueError, match="height image"):
        height_to_normal(np.zeros((4, 4, 3)))


# ---------------------------------------------------------------------------
# normal-only frames


@PROPERTY
@given(unit_vectors())
def test_normal_round_trip_hypothesis(n):
    edit = NORMAL.to_edit(n)
    assert np.all(np.isfinite(edit))
    # smallest rotation: axis in the xy plane, |log q| = half the tilt angle
    assert abs(edit[2]) == 0.0
    np.testing.assert_allclose(2 * np.linalg.norm(edit), angle_between(n, Z), atol=1e-6)
    back = NORMAL.from_edit(edit)
    assert_unit(back)
    assert angle_between(n, back) < FLOAT_TOL
    # scipy's exp of the rotation vector 2 q~ takes z to n as well
    assert angle_between(Rotation.from_rotvec(2.0 * edit.astype(np.float64)).apply(Z), n) < 2e-6


def test_normal_round_trip_dense_and_poles():
    rng = np.random.default_rng(3)
    n = random_unit(rng, 100_000)
    eps = 10.0 ** rng.uniform(-9, -2, size=(2000, 1))
    near = random_unit(rng, 2000) * eps
    near[:1000, 2] = 1.0
    near[1000:, 2] = -1.0
    n = np.concatenate([n, near, [[0, 0, 1], [0, 0, -1]]])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    back = NORMAL.from_edit(NORMAL.to_edit(n.astype(np.float32)))
    err = angle_between(n, back)
    print(f"\nnormal space: worst float32 round-trip angle {err.max():.3g} rad")
    assert err.max() < FLOAT_TOL


def test_normal_special_values():
    edit = NORMAL.to_edit(np.array([[0, 0, 1], [0, 0, -1], [0, 0, 0], [0, 0, 5]], np.float32))
    np.testing.assert_array_equal(edit[0], 0.0)
    np.testing.assert_allclose(edit[1], [math.pi / 2, 0, 0])  # half turn about x
    np.testing.assert_array_equal(edit[2], 0.0)  # zero length -> flat
    np.testing.assert_array_equal(edit[3], 0.0)  # unnormalised input is fine
    np.testing.assert_allclose(NORMAL.from_edit(edit[1]), [0, 0, -1], atol=1e-6)
    # twist-only edits (z component) leave the normal flat
    np.testing.assert_allclose(NORMAL.from_edit(np.array([0, 0, 1.3])), [0, 0, 1], atol=1e-6)


@PROPERTY
@given(arrays(np.float64, (5, 3), elements=st.floats(-50.0, 50.0)))
def test_normal_from_arbitrary_edits_is_unit(edit):
    assert_unit(NORMAL.from_edit(edit))


@pytest.mark.parametrize("convention", ["opengl", "directx"])
def test_normal_8bit_round_trip(convention):
    """8-bit file -> decode -> to_edit -> from_edit -> encode -> 8-bit file."""
    rng = np.random.default_rng(4)
    codes = np.round(
        encode_normal_map(random_unit(rng, 200_000, hemisphere=True), convention=convention) * 255
    ).astype(np.uint8)
    n_in = decode_normal_map(codes, convention=convention)
    n_out = NORMAL.from_edit(NORMAL.to_edit(n_in))
    codes_out = np.round(encode_normal_map(n_out, convention=convention) * 255).astype(np.uint8)
    step = np.abs(codes_out.astype(int) - codes).max()
    err = angle_between(n_in, decode_normal_map(codes_out, convention=convention))
    # decode renormalises, so an 8-bit triplet that was not unit length may re-encode one
    # code off even without any editing; the editing space itself adds nothing to that
    baseline = np.round(encode_normal_map(n_in, convention=convention) * 255).astype(np.uint8)
    print(
        f"\n8-bit {convention}: worst angle {err.max():.3g} rad ({np.degrees(err.max()):.3f} deg),"
        f" max code change {step}, {np.mean(np.any(codes_out != codes, -1)):.2%} of pixels changed,"
        f" {np.sum(np.any(codes_out != baseline, -1))} differ from plain decode/encode"
    )
    assert step <= 1
    assert err.max() <= ONE_8BIT_STEP
    assert np.mean(np.any(codes_out != baseline, -1)) < 1e-3
    assert angle_between(n_in, n_out).max() < FLOAT_TOL


# ---------------------------------------------------------------------------
# normal + tangent frames


def test_quat_from_matrix_matches_scipy_including_half_turns():
    rng = np.random.default_rng(5)
    axes = random_unit(rng, 500)
    angles = np.concatenate(
        [np.full(200, np.pi), np.pi - 10.0 ** rng.uniform(-6, -1, 200), [0.0] * 100]
    )
    rots = Rotation.concatenate(
        [Rotation.random(5000, random_state=6), Rotation.from_rotvec(axes * angles[:, None])]
    )
    q = quat_from_matrix(rots.as_matrix()).astype(np.float64)
    ref = rots.as_quat()[:, [3, 0, 1, 2]]  # scipy is scalar-last
    assert np.all(q[:, 0] >= 0)
    # q and -q are the same rotation (only ambiguous when w == 0)
    dist = np.minimum(np.abs(q - ref).max(-1), np.abs(q + ref).max(-1))
    assert dist.max() < 1e-6


def test_quat_helpers_match_scipy():
    rots = Rotation.random(2000, random_state=7)
    rotvec = rots.as_rotvec()
    q = quat_exp(rotvec / 2.0).astype(np.float64)
    np.testing.assert_allclose(
        q[:, 1:] * np.sign(q[:, :1]),
        rots.as_quat()[:, :3] * np.sign(rots.as_quat()[:, 3:]),
        atol=1e-6,
    )
    np.testing.assert_allclose(quat_log(q), rotvec / 2.0, atol=1e-6)
    np.testing.assert_allclose(quat_log(-q), rotvec / 2.0, atol=1e-6)  # sign is fixed first
    v = random_unit(np.random.default_rng(8), 2000)
    np.testing.assert_allclose(quat_rotate(q, v), rots.apply(v), atol=1e-6)


def test_frame_round_trip_against_scipy():
    rots = Rotation.random(20_000, random_state=9)
    frames = frames_of(rots).astype(np.float32)
    edit = FRAME.to_edit(frames)
    # log q = rotvec / 2, compared as rotations (rotvecs of angle ~pi are sign-ambiguous)
    mats = Rotation.from_rotvec(2.0 * edit.astype(np.float64)).as_matrix()
    np.testing.assert_allclose(mats, rots.as_matrix(), atol=2e-6)
    away_from_pi = rots.magnitude() < np.pi - 1e-3
    np.testing.assert_allclose(edit[away_from_pi], rots.as_rotvec()[away_from_pi] / 2.0, atol=2e-6)
    back = FRAME.from_edit(edit)
    assert_orthonormal_frames(back)
    err_n = angle_between(frames[:, :3], back[:, :3])
    err_t = angle_between(frames[:, 3:], back[:, 3:])
    print(f"\nframe space: worst round-trip angle n {err_n.max():.3g} rad, t {err_t.max():.3g} rad")
    assert max(err_n.max(), err_t.max()) < FLOAT_TOL
    # from_edit against scipy's exp of the same edit values
    ref = frames_of(Rotation.from_rotvec(2.0 * edit.astype(np.float64)))
    np.testing.assert_allclose(back, ref, atol=2e-6)


@PROPERTY
@given(st.integers(0, 2**32 - 1))
def test_frame_round_trip_hypothesis(seed):
    rot = Rotation.random(random_state=seed)
    frame = frames_of(rot)[0]
    back = FRAME.from_edit(FRAME.to_edit(frame))
    assert angle_between(frame[:3], back[:3]) < FLOAT_TOL
    assert angle_between(frame[3:], back[3:]) < FLOAT_TOL


def test_frame_gram_schmidt_and_degenerate_tangents():
    rng = np.random.default_rng(10)
    n = random_unit(rng, 1000)
    t_raw = rng.normal(size=(1000, 3)) * 3.0
    n_scaled = n * rng.uniform(0.2, 5.0, size=(1000, 1))
    edit = FRAME.to_edit(np.concatenate([n_scaled, t_raw], -1))
    t_ref = t_raw - np.sum(t_raw * n, -1, keepdims=True) * n
    t_ref /= np.linalg.norm(t_ref, axis=-1, keepdims=True)
    back = FRAME.from_edit(edit)
    assert angle_between(back[:, :3], n).max() < FLOAT_TOL
    assert angle_between(back[:, 3:], t_ref).max() < FLOAT_TOL
    # t parallel to n, or zero: the normal-only (smallest rotation) frame
    for t_bad in (n * 2.0, -n, np.zeros_like(n)):
        edit_bad = FRAME.to_edit(np.concatenate([n, t_bad], -1))
        np.testing.assert_allclose(edit_bad, NORMAL.to_edit(n), atol=2e-6)
    poles = np.array([[0, 0, 1, 0, 0, 1], [0, 0, -1, 0, 0, 0], [0, 0, 0, 0, 0, 0]], np.float32)
    assert_orthonormal_frames(FRAME.from_edit(FRAME.to_edit(poles)))


# ---------------------------------------------------------------------------
# linearity of edit space


@pytest.mark.parametrize("space", [NORMAL, FRAME], ids=lambda s: s.name)
def test_linear_combinations_stay_valid(space):
    rng = np.random.default_rng(11)
    layers = [
        space.to_edit(frames_of(Rotation.random(5000, random_state=s))[:, : space.phys_channels])
        for s in range(4)
    ]
    weights = rng.uniform(-3.0, 3.0, size=(4, 5000, 1))
    combo = sum(w * e for w, e in zip(weights, layers, strict=True))
    back = space.from_edit(combo)
    if space is NORMAL:
        assert_unit(back)
    else:
        assert_orthonormal_frames(back)


@PROPERTY
@given(arrays(np.float64, (6, 3), elements=st.floats(-50.0, 50.0)))
def test_frame_from_arbitrary_edits_is_orthonormal(edit):
    assert_orthonormal_frames(FRAME.from_edit(edit))


def test_scaling_edit_is_slerp_from_identity():
    rots = Rotation.random(300, random_state=12)
    edit = FRAME.to_edit(frames_of(rots))
    normal_edit = NORMAL.to_edit(frames_of(rots)[:, :3])
    for w in (0.0, 0.25, 0.5, 0.8, 1.0):
        ours = FRAME.from_edit(w * edit)
        ours_n = NORMAL.from_edit(w * normal_edit)
        ref = np.empty((len(rots), 6))
        ref_n = np.empty((len(rots), 3))
        for i in range(len(rots)):
            key = Rotation.concatenate([Rotation.identity(), rots[i]])
            ref[i] = frames_of(Slerp([0.0, 1.0], key)([w]))[0]
            # normal-only: slerp along the smallest rotation z -> n
            small = Rotation.from_rotvec(2.0 * normal_edit[i].astype(np.float64))
            key_n = Rotation.concatenate([Rotation.identity(), small])
            ref_n[i] = Slerp([0.0, 1.0], key_n)([w]).apply(Z)[0]
        np.testing.assert_allclose(ours, ref, atol=3e-6)
        np.testing.assert_allclose(ours_n, ref_n, atol=3e-6)


def test_scaling_edit_scales_perturbation_angle():
    rng = np.random.default_rng(13)
    n = random_unit(rng, 5000, hemisphere=True)
    edit = NORMAL.to_edit(n)
    np.testing.assert_allclose(NORMAL.from_edit(0.0 * edit), np.tile(Z, (5000, 1)), atol=1e-7)
    tilt = angle_between(n, Z)
    small = tilt < np.pi / 2
    doubled = angle_between(NORMAL.from_edit(2.0 * edit), Z)
    np.testing.assert_allclose(doubled[small], 2.0 * tilt[small], atol=2e-6)
    halved = angle_between(NORMAL.from_edit(0.5 * edit), Z)
    np.testing.assert_allclose(halved, 0.5 * tilt, atol=2e-6)
    # normal + tangent: the rotation angle doubles
    rots = Rotation.random(5000, random_state=14)
    rots = rots[rots.magnitude() < np.pi / 2]
    edit = FRAME.to_edit(frames_of(rots))
    flat = FRAME.from_edit(0.0 * edit)
    np.testing.assert_allclose(flat, np.tile([0, 0, 1, 1, 0, 0], (len(rots), 1)), atol=1e-7)
    back = FRAME.from_edit(2.0 * edit).astype(np.float64)
    t, n2 = back[:, 3:], back[:, :3]
    mats = np.stack([t, np.cross(n2, t), n2], axis=-1)
    np.testing.assert_allclose(
        Rotation.from_matrix(mats).magnitude(), 2 * rots.magnitude(), atol=5e-6
    )


# ---------------------------------------------------------------------------
# file conventions and height maps


def test_decode_encode_known_values_and_conventions():
    rgb = np.array([[0.5, 0.5, 1.0], [1.0, 0.5, 0.5], [0.5, 1.0, 0.5], [0.5, 0.5, 0.5]])
    expected_gl = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    np.testing.assert_allclose(decode_normal_map(rgb), expected_gl, atol=1e-7)
    # DirectX: +green means -Y (down the image) in our OpenGL-space normals
    expected_dx = expected_gl * [1, -1, 1]
    expected_dx[3] = [0, 0, 1]
    np.testing.assert_allclose(decode_normal_map(rgb, convention="directx"), expected_dx, atol=1e-7)
    # integer files are scaled by their dtype's maximum
    flat8 = decode_normal_map(np.array([128, 128, 255], np.uint8))
    assert angle_between(flat8, Z) < 1.0 / 255 * 2
    flat16 = decode_normal_map(np.array([32768, 32768, 65535], np.uint16))
    assert angle_between(flat16, Z) < 1e-4

    rng = np.random.default_rng(15)
    n = random_unit(rng, 1000, hemisphere=True)
    gl = encode_normal_map(n)
    dx = encode_normal_map(n, convention="directx")
    assert gl.dtype == np.float32 and gl.min() >= 0 and gl.max() <= 1
    np.testing.assert_allclose(dx, gl * [1, -1, 1] + [0, 1, 0], atol=1e-7)  # green inverted
    np.testing.assert_allclose(decode_normal_map(gl), n, atol=1e-6)
    np.testing.assert_allclose(decode_normal_map(dx, convention="directx"), n, atol=1e-6)
    flipped = dx.copy()
    flipped[:, 1] = 1 - flipped[:, 1]
    np.testing.assert_allclose(
        decode_normal_map(dx, convention="directx"), decode_normal_map(flipped), atol=1e-7
    )
    before = gl.copy()
    decode_normal_map(gl, convention="directx")
    np.testing.assert_array_equal(gl, before)


@pytest.mark.parametrize("wrap", [False, True])
def test_height_to_normal_linear_ramps(wrap):
    rows, cols = 16, 20
    r, c = np.mgrid[0:rows, 0:cols].astype(np.float64)
    slope, strength = 0.3, 2.0
    tan_tilt = slope * strength
    inner = (slice(1, -1), slice(1, -1))  # a ramp is not periodic: skip the wrap seam
    # rising to the right: the normal leans left, tilt atan(k a)
    n = height_to_normal(slope * c, strength=strength, wrap=wrap)
    expected = np.array([-tan_tilt, 0.0, 1.0]) / math.hypot(tan_tilt, 1.0)
    np.testing.assert_allclose(n[inner], np.broadcast_to(expected, n[inner].shape), atol=1e-6)
    # rising towards the top of the image (v is up, rows go down): the normal leans down
    n = height_to_normal(slope * (rows - 1 - r), strength=strength, wrap=wrap)
    expected = np.array([0.0, -tan_tilt, 1.0]) / math.hypot(tan_tilt, 1.0)
    np.testing.assert_allclose(n[inner], np.broadcast_to(expected, n[inner].shape), atol=1e-6)
    if not wrap:  # one-sided differences keep the slope up to the border
        np.testing.assert_allclose(n, np.broadcast_to(expected, n.shape), atol=1e-6)
    assert n.dtype == np.float32 and n.shape == (rows, cols, 3)
    # a raised bump in the OpenGL convention: green above the centre, red right of it
    bump = np.exp(-((r - 8) ** 2 + (c - 10) ** 2) / 8.0)
    rgb = encode_normal_map(height_to_normal(bump, wrap=wrap))
    assert rgb[5, 10, 1] > 0.55 and rgb[11, 10, 1] < 0.45
    assert rgb[8, 13, 0] > 0.55 and rgb[8, 7, 0] < 0.45


def test_height_to_normal_periodic_closed_form_and_shapes():
    rows, cols, amp = 8, 32, 1.7
    c = np.arange(cols)
    h = np.tile(amp * np.sin(2 * np.pi * c / cols), (rows, 1))
    # central difference of a sampled sine, exactly
    dh_du = amp * np.cos(2 * np.pi * c / cols) * np.sin(2 * np.pi / cols)
    expected = np.stack([-dh_du, np.zeros(cols), np.ones(cols)], -1)
    expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
    n = height_to_normal(h, wrap=True)
    np.testing.assert_allclose(n, np.broadcast_to(expected, n.shape), atol=1e-6)
    batch = np.stack([h, 2 * h])[..., None]  # (2, H, W, 1)
    nb = height_to_normal(batch, strength=0.5)
    assert nb.shape == (2, rows, cols, 3)
    np.testing.assert_allclose(nb[1], height_to_normal(h, strength=1.0), atol=1e-7)


@pytest.mark.parametrize("convention", ["opengl", "directx"])
def test_decoding_in_place_is_the_same_bits_and_leaves_views_alone(convention) -> None:
    """A loader's own contiguous float32 pixels are decoded over themselves, to the bits
    a new array gets; a strided view (the RGB of an RGBA file) is never written."""
    rng = np.random.default_rng(5)
    rgb = rng.random((64, 48, 3), dtype=np.float32)
    rgb[3, 4] = 0.5  # a zero-length texel: the flat normal
    expected = decode_normal_map(rgb, convention=convention)
    pixels = rgb.copy()
    got = decode_normal_map(pixels, convention=convention, in_place=True)
    assert np.shares_memory(got, pixels) and np.array_equal(got, expected)
    rgba = np.concatenate([rgb, np.ones((64, 48, 1), np.float32)], axis=2)
    before = rgba.copy()
    view = decode_normal_map(rgba[..., :3], convention=convention, in_place=True)
    assert np.array_equal(rgba, before) and np.array_equal(view, expected)
