"""The normal-map convention guess, on maps whose convention is known.

Maps come from ``normal_corpus.py`` (height fields baked to normals, written
by real PNG / JPEG encoders and read back as a load does), from closed-form
gradients, and from the shared chessboard set (OpenGL: MaterialX's chess set,
published as the glTF sample "ABeautifulGame"; glTF normals are +Y).
The full calibration is ``benchmarks/normal_convention.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from normal_corpus import MapSpec, ci_specs, read_map, write_corpus, write_map

from matshop.spaces.frame import CONFIDENT_GUESS, encode_normal_map, guess_normal_convention
from matshop.spaces.normal_convention import _SIGMA, _TILE, _slopes, _tile_evidence

CHESSBOARD_NORMAL = (
    Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard" / "chessboard_normal.jpg"
)
#: families whose heights carry mixed derivatives everywhere: the guess must commit on them
DETAILED = ("noise", "rocks", "fabric", "scratches", "mixed", "atlas")


@pytest.fixture(scope="module")
def ci_corpus(tmp_path_factory) -> list[tuple[MapSpec, str, float]]:
    folder = tmp_path_factory.mktemp("normal_corpus")
    out = []
    for spec, path in write_corpus(ci_specs(), folder):
        out.append((spec, *guess_normal_convention(read_map(path))))
    return out


def test_confident_guesses_on_the_ci_corpus_are_right(ci_corpus):
    wrong = [
        (spec.name, guess, round(conf, 3))
        for spec, guess, conf in ci_corpus
        if conf >= CONFIDENT_GUESS and guess != spec.convention
    ]
    assert wrong == []
    assert {spec.convention for spec, _, _ in ci_corpus} == {"opengl", "directx"}
    assert {spec.encoding[:3] for spec, _, _ in ci_corpus} == {"png", "jpg"}


def test_the_guess_commits_on_detailed_maps(ci_corpus):
    detailed = [(s, g, c) for s, g, c in ci_corpus if s.family in DETAILED]
    assert len(detailed) >= 30
    confident = [c >= CONFIDENT_GUESS for _, _, c in detailed]
    assert np.mean(confident) >= 0.9
    assert all(g == s.convention for s, g, _ in detailed)


def test_pure_grooves_stay_below_the_threshold(ci_corpus):
    """f(u) + g(v): the flipped map is the gradient of f(u) - g(v); nothing can tell."""
    grooves = [(s, c) for s, _, c in ci_corpus if s.family == "grooves"]
    assert grooves
    assert all(c < CONFIDENT_GUESS for _, c in grooves), grooves


@pytest.mark.parametrize("encoding", ["png8", "jpg50", "jpg90_444"])
@pytest.mark.parametrize("size", [256, 512])
def test_closed_form_separable_heights_are_not_confident(tmp_path, size, encoding):
    r, c = np.mgrid[0:size, 0:size].astype(np.float64)
    # h = 3 sin(c/3) + 2 cos(r/5) + r^2/1000: normals from its closed-form gradient (v up)
    dh_du = np.cos(c / 3)
    dh_dv = 2 / 5 * np.sin(r / 5) - r / 500
    normals = np.stack([-dh_du, -dh_dv, np.ones_like(c)], -1)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    for convention in ("opengl", "directx"):
        spec = MapSpec("closed-form", "tiled", size, "exact", encoding, convention, 0)
        _, confidence = guess_normal_convention(read_map(write_map(normals, spec, tmp_path)))
        assert confidence < CONFIDENT_GUESS


def analytic_bumps(size: int, seed: int) -> np.ndarray:
    """OpenGL normals of a sum of Gaussian bumps, from the closed-form gradient."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:size, 0:size].astype(np.float64)
    u, v = c, -r  # v is up
    dh_du = np.zeros_like(u)
    dh_dv = np.zeros_like(u)
    for _ in range(60):
        cu, cv = rng.uniform(0, size), -rng.uniform(0, size)
        sigma, amp = rng.uniform(3.0, 12.0), rng.uniform(-4.0, 4.0)
        g = amp * np.exp(-((u - cu) ** 2 + (v - cv) ** 2) / (2 * sigma**2))
        dh_du += -g * (u - cu) / sigma**2
        dh_dv += -g * (v - cv) / sigma**2
    n = np.stack([-dh_du, -dh_dv, np.ones_like(u)], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("convention", ["opengl", "directx"])
@pytest.mark.parametrize("encoding", ["png8", "jpg75"])
def test_closed_form_bumps_are_guessed_confidently(tmp_path, seed, convention, encoding):
    spec = MapSpec("bumps-closed-form", "tiled", 256, "exact", encoding, convention, seed)
    rgb = read_map(write_map(analytic_bumps(256, seed), spec, tmp_path))
    guess, confidence = guess_normal_convention(rgb)
    assert guess == convention
    assert confidence >= CONFIDENT_GUESS


def test_flipping_a_channel_flips_the_answer_with_the_same_confidence():
    """The guess is about the handedness of (red, green): flipping either swaps it."""
    codes = np.round(encode_normal_map(analytic_bumps(128, 3)) * 255).astype(np.uint8)
    guess, confidence = guess_normal_convention(codes)
    for channel in (0, 1):
        flipped = codes.copy()
        flipped[..., channel] = 255 - flipped[..., channel]
        other, confidence_flipped = guess_normal_convention(flipped)
        assert {guess, other} == {"opengl", "directx"}
        assert confidence_flipped == pytest.approx(confidence, abs=1e-9)
    # integer codes, the same values as floats, and the RGB view of an RGBA read agree
    as_float = codes.astype(np.float32) / np.float32(255)
    rgba = np.concatenate([as_float, np.ones_like(as_float[..., :1])], axis=-1)
    for other_input in (as_float, rgba[..., :3]):
        other, other_confidence = guess_normal_convention(other_input)
        assert other == guess and other_confidence == pytest.approx(confidence, abs=1e-6)


def test_flat_and_tiny_maps_cannot_tell():
    assert guess_normal_convention(np.full((8, 8, 3), 0.5)) == ("opengl", 0.0)
    assert guess_normal_convention(np.full((1, 1, 3), 0.7)) == ("opengl", 0.0)  # a 1x1 set
    assert guess_normal_convention(np.full((300, 200, 3), 128, np.uint8)) == ("opengl", 0.0)
    rng = np.random.default_rng(0)
    for shape in ((2, 2, 3), (3, 5, 3), (17, 40, 3)):
        guess, confidence = guess_normal_convention(rng.random(shape))
        assert guess in ("opengl", "directx") and 0.0 <= confidence < 1.0


def test_tile_evidence_matches_a_direct_sum():
    """The numba kernel against the per-loop formula written out in numpy."""
    rng = np.random.default_rng(5)
    rgb = rng.uniform(0.2, 0.8, (70, 53, 3)).astype(np.float32)
    rgb[..., 2] = rng.uniform(0.75, 1.0, rgb.shape[:2])
    p, q = _slopes(rgb, 1.0)
    n = 2.0 * rgb.astype(np.float64) - 1.0
    np.testing.assert_allclose(p, -n[..., 0] / n[..., 2], rtol=1e-5)
    np.testing.assert_allclose(q, -n[..., 1] / n[..., 2], rtol=1e-5)
    p, q = p.astype(np.float64), q.astype(np.float64)
    a = 0.5 * ((q[:-1, 1:] + q[1:, 1:]) - (q[:-1, :-1] + q[1:, :-1]))
    b = 0.5 * ((p[:-1, :-1] + p[:-1, 1:]) - (p[1:, :-1] + p[1:, 1:]))
    e = 2 * a * b / (a * a + b * b + _SIGMA**2)
    tiles = _tile_evidence(p.astype(np.float32), q.astype(np.float32), _TILE, _SIGMA**2)
    rows, cols = tiles.shape
    expected = e[: rows * _TILE, : cols * _TILE].reshape(rows, _TILE, cols, _TILE).sum(axis=(1, 3))
    assert (rows, cols) == (69 // _TILE, 52 // _TILE)
    np.testing.assert_allclose(tiles, expected, rtol=1e-4, atol=1e-4)


def test_chessboard_normal_map():
    if not CHESSBOARD_NORMAL.exists():
        pytest.skip(f"{CHESSBOARD_NORMAL} not present (shared data absent)")
    rgb = read_map(CHESSBOARD_NORMAL)
    guess, confidence = guess_normal_convention(rgb)
    flipped = rgb.copy()
    flipped[..., 1] = 1.0 - flipped[..., 1]
    guess_flipped, confidence_flipped = guess_normal_convention(flipped)
    print(f"\nchessboard_normal.jpg: {guess} (confidence {confidence:.3f})")
    # mostly flat with axis-aligned square edges: little to see, but what it sees is right
    assert guess == "opengl"
    assert guess_flipped == "directx"
    assert confidence == pytest.approx(confidence_flipped, abs=1e-6)
