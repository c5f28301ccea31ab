"""Variance kept on sampled (tabulated) distributions, against closed forms and brute force.

Widening a lobe by a slope variance ``v`` convolves its slope distribution with a
Gaussian of per-axis variance ``v / 2`` (docs/variance.md). The truths here are worked
out without matshop's widening:

- Beckmann slopes are Gaussian, so a Beckmann table widened by ``v`` is the Beckmann
  of ``m'^2 = m^2 + v``, whose CDF ``1 - exp(-tan^2 / m'^2)`` is written by hand;
- any lobe: a Monte Carlo convolution (slopes drawn from the closed-form GGX or from
  the table read as matshop stores it, a Gaussian slope added, histogrammed by angle);
- GGX is not closed under the convolution; its analytic rule (``alpha'^2 = alpha^2 +
  v``) is compared within the tolerance this file states.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.images import read_image, write_image
from matshop.material import Schema
from matshop.ops import get_op
from matshop.ops.sampled_widening import widen_tabulated
from matshop.ops.variance import widen_lobes
from matshop.spaces.sampled import d_from_beckmann, d_from_ggx

N = 128
EDGES = np.arange(N + 1) * (0.5 * math.pi / N)
S2 = np.sin(EDGES) ** 2
MEASURE = math.pi * np.diff(S2)  # 2 pi integral cos sin over each bin
SIZE = 16


def _cdf(d: np.ndarray) -> np.ndarray:
    """CDF at the bin edges of tables ``(..., N)`` read as constant per bin."""
    mass = np.clip(np.asarray(d, np.float64), 0, None) * MEASURE
    c = np.concatenate([np.zeros((*mass.shape[:-1], 1)), np.cumsum(mass, -1)], -1)
    return c / c[..., -1:]


def _beckmann_cdf(m: float) -> np.ndarray:
    with np.errstate(over="ignore"):
        return 1.0 - np.exp(-(np.tan(EDGES) ** 2) / (m * m))


def _ggx_cdf(alpha: float) -> np.ndarray:
    t2 = np.tan(EDGES) ** 2
    return np.where(np.isfinite(t2), t2 / (alpha * alpha + t2), 1.0)


def _convolved_cdf(slopes_r: np.ndarray, v: float, seed: int) -> np.ndarray:
    """Brute force: rings of radius ``slopes_r`` at uniform azimuth plus a Gaussian
    slope of per-axis variance ``v / 2``, histogrammed by angle: CDF at the bin edges."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0, 2 * math.pi, slopes_r.size)
    sigma = math.sqrt(v / 2)
    x = slopes_r * np.cos(phi) + sigma * rng.standard_normal(slopes_r.size)
    y = slopes_r * np.sin(phi) + sigma * rng.standard_normal(slopes_r.size)
    counts = np.histogram(np.arctan(np.hypot(x, y)), EDGES)[0]
    return np.concatenate([[0.0], np.cumsum(counts)]) / slopes_r.size


def _ggx_slopes(alpha: float, count: int, seed: int) -> np.ndarray:
    """Slope radii of the closed-form GGX lobe: ``tan^2 = alpha^2 y / (1 - y)``."""
    y = np.random.default_rng(seed).uniform(0, 1, count)
    return alpha * np.sqrt(y / (1 - y))


def _table_slopes(d: np.ndarray, count: int, seed: int) -> np.ndarray:
    """Slope radii drawn from a table read as matshop reads it: bin by mass, then uniform
    in sin^2 inside the bin."""
    rng = np.random.default_rng(seed)
    mass = np.clip(d.astype(np.float64), 0, None) * MEASURE
    k = rng.choice(N, count, p=mass / mass.sum())
    u = S2[k] + rng.uniform(0, 1, count) * (S2[k + 1] - S2[k])
    return np.sqrt(u / (1 - u))


# --------------------------------------------------------------------------- the widening


@pytest.mark.parametrize("m", [0.1, 0.3, 0.8])
@pytest.mark.parametrize("v", [1e-3, 0.01, 0.1, 1.0])
def test_a_beckmann_table_widens_into_the_beckmann_of_the_analytic_rule(m: float, v: float):
    got = _cdf(widen_tabulated(d_from_beckmann(m), v))
    err = np.abs(got - _beckmann_cdf(math.sqrt(m * m + v))).max()
    # measured: <= 1.4e-3 for lobes at least ~8 bins wide (m >= 0.1)
    assert err < 2e-3, err


def test_a_beckmann_table_one_bin_wide_is_limited_by_its_bins() -> None:
    # m = 0.02 is 1.6 bins of 0.7 deg: the table reads its mass as uniform inside each
    # bin, and widening that shape is not widening the true peak. Measured 0.026 at
    # v = 1e-5 (sigma a fifth of a bin), 1.3e-3 once the Gaussian spans a few bins.
    for v, tol in ((1e-5, 0.03), (1e-3, 0.015), (0.01, 2e-3)):
        got = _cdf(widen_tabulated(d_from_beckmann(0.02), v))
        assert np.abs(got - _beckmann_cdf(math.sqrt(0.02**2 + v))).max() < tol


@pytest.mark.parametrize(("alpha", "v"), [(0.05, 0.01), (0.09, 0.0188), (0.3, 0.1), (0.6, 1.0)])
def test_widening_matches_a_brute_force_convolution(alpha: float, v: float) -> None:
    table = d_from_ggx(alpha)
    got = _cdf(widen_tabulated(table, v))
    # 2M samples: the brute force's own error is ~1e-3 at worst over 129 edges
    brute = _convolved_cdf(_table_slopes(table, 2_000_000, 1), v, 2)
    assert np.abs(got - brute).max() < 2.5e-3


@pytest.mark.parametrize("alpha", [0.1, 0.3, 0.6])
@pytest.mark.parametrize("ratio", [0.1, 0.5, 1.0])
def test_a_ggx_table_against_the_analytic_ggx_rule(alpha: float, ratio: float) -> None:
    # GGX convolved with a Gaussian is not GGX; for v <= alpha^2 the two widenings
    # agree to within 0.12 v / alpha^2 in CDF (measured <= 0.11; they part further
    # beyond, 0.2 at v = 20 alpha^2, where the convolution keeps a Gaussian core)
    v = ratio * alpha * alpha
    got = _cdf(widen_tabulated(d_from_ggx(alpha), v))
    err = np.abs(got - _ggx_cdf(math.sqrt(alpha * alpha + v))).max()
    assert err <= 0.12 * ratio, err


def test_no_variance_changes_no_bit_and_a_widened_lobe_is_never_narrower() -> None:
    rng = np.random.default_rng(3)
    table = d_from_ggx(rng.uniform(0.05, 0.8, 64))
    v = np.where(np.arange(64) % 2 == 0, 0.0, rng.lognormal(-4, 2, 64))
    out = widen_tabulated(table, v)
    assert np.array_equal(out[v == 0], table[v == 0])
    # a radially decreasing slope density only spreads outwards (Anderson's theorem):
    # every quantile grows, up to the kernel's discretisation
    c_in, c_out = _cdf(table), _cdf(out)
    assert np.all(c_out <= c_in + 2e-4)
    # mass is conserved: still normalised tables
    np.testing.assert_allclose(np.sum(out.astype(np.float64) * MEASURE, -1), 1.0, atol=1e-5)


# --------------------------------------------------------------------------- through the ops


def _tilted(theta_x: float, theta_y: float) -> np.ndarray:
    n = np.array([math.tan(theta_x), math.tan(theta_y), 1.0])
    return n / np.linalg.norm(n)


def _checker(a: np.ndarray, b: np.ndarray, size: int = SIZE) -> np.ndarray:
    rows, cols = np.mgrid[0:size, 0:size]
    return np.where(((rows + cols) % 2 == 0)[..., None], a, b).astype(np.float32)


TILT_A, TILT_B = (0.25, 0.0), (0.0, 0.1)
# a checkerboard of the two averaged to uniform loses |s_a - s_b|^2 / 4, by hand
HAND_TRACE = (math.tan(0.25) ** 2 + math.tan(0.1) ** 2) / 4


def _edit(schema: Schema, **maps: np.ndarray) -> np.ndarray:
    parts = [schema[name].space.to_edit(maps[name]) for name in schema.names]
    return np.concatenate(parts, axis=2).astype(np.float32)


def _blur(schema: Schema, edit: np.ndarray, keep: bool) -> np.ndarray:
    spec = get_op("blur")
    values = spec.bind({"sigma_px": 4.0, "keep_variance": keep})
    return spec.function(edit, schema=schema, params="normal", **values)


def _distribution(schema: Schema, edit: np.ndarray) -> np.ndarray:
    block = np.ascontiguousarray(edit[..., schema.edit_slices["distribution"]])
    return schema["distribution"].space.from_edit(block)


def test_blur_to_uniform_widens_a_beckmann_table_by_the_lost_variance() -> None:
    schema = Schema.from_names(["base_color", "distribution", "normal"])
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    table = np.broadcast_to(d_from_beckmann(0.2), (SIZE, SIZE, N))
    color = np.random.default_rng(2).uniform(0, 1, (SIZE, SIZE, 3)).astype(np.float32)
    edit = _edit(schema, base_color=color, distribution=table, normal=normal)
    out = _blur(schema, edit, keep=True)
    got = _cdf(_distribution(schema, out))
    err = np.abs(got - _beckmann_cdf(math.sqrt(0.2**2 + HAND_TRACE))).max()
    assert err < 2e-3, err
    plain = _blur(schema, edit, keep=False)
    lobe = schema.edit_slices["distribution"]
    others = np.ones(edit.shape[2], bool)
    others[lobe] = False
    assert np.array_equal(out[..., others], plain[..., others])
    # every quantile (edit value) at least the plain one's
    assert np.all(out[..., lobe] >= plain[..., lobe])


def test_a_constant_tilt_keeps_every_bit_of_a_sampled_lobe() -> None:
    schema = Schema.from_names(["distribution", "normal"])
    rng = np.random.default_rng(4)
    normal = np.broadcast_to(_tilted(0.3, -0.2), (SIZE, SIZE, 3)).astype(np.float32)
    table = d_from_ggx(rng.uniform(0.05, 0.6, (SIZE, SIZE)))
    edit = _edit(schema, distribution=table, normal=normal)
    assert np.array_equal(_blur(schema, edit, keep=True), _blur(schema, edit, keep=False))
    cov = np.zeros((SIZE, SIZE, 3))
    assert np.array_equal(widen_lobes(edit, schema, cov), edit)


def test_a_two_peaked_lobe_is_never_narrowed_anywhere() -> None:
    # a ring-shaped lobe (mass at 30 deg, none at the normal): the convolution moves
    # some of its mass inwards, which the option must not do (roughness never reduced)
    schema = Schema.from_names(["distribution", "normal"])
    ring = np.zeros(N, np.float32)
    ring[40:46] = 1.0
    ring /= np.sum(ring * MEASURE)
    rng = np.random.default_rng(5)
    tilt = rng.normal(0, 0.2, (SIZE, SIZE, 2))
    normal = np.concatenate([np.tan(tilt), np.ones((SIZE, SIZE, 1))], axis=2)
    normal = (normal / np.linalg.norm(normal, axis=2, keepdims=True)).astype(np.float32)
    edit = _edit(schema, distribution=np.broadcast_to(ring, (SIZE, SIZE, N)), normal=normal)
    kept, plain = _blur(schema, edit, keep=True), _blur(schema, edit, keep=False)
    lobe = schema.edit_slices["distribution"]
    assert np.all(kept[..., lobe] >= plain[..., lobe])
    assert np.mean(kept[..., lobe] > plain[..., lobe]) > 0.3


# --------------------------------------------------------------------------- real path


def _write_set(folder: Path, normal: np.ndarray, table: np.ndarray) -> None:
    folder.mkdir()
    size = normal.shape[0]
    color = np.random.default_rng(6).uniform(0, 1, (size, size, 3))
    write_image(folder / "v_basecolor.png", color, bit_depth="uint16")
    write_image(folder / "v_normal_gl.png", 0.5 * normal + 0.5, bit_depth="uint16")
    tables = np.broadcast_to(table, (size, size, N))
    write_image(folder / "v_distribution.exr", tables, bit_depth="float")


def test_apply_cli_widens_a_ggx_table_like_a_brute_force_convolution(tmp_path: Path) -> None:
    # GGX alpha = 0.09 stored as a table; blurred to uniform it loses HAND_TRACE
    # (2.3 alpha^2): the truth is the closed-form GGX lobe's slopes plus a Gaussian
    _write_set(tmp_path / "in", _checker(_tilted(*TILT_A), _tilted(*TILT_B)), d_from_ggx(0.09))
    out = tmp_path / "out"
    argv = ["apply", str(tmp_path / "in"), str(out), "--op", "blur", "sigma_px=4"]
    assert main([*argv, "keep_variance=true", "--params", "normal"]) == 0
    got, _ = read_image(out / "v_distribution.exr")
    brute = _convolved_cdf(_ggx_slopes(0.09, 2_000_000, 7), HAND_TRACE, 8)
    # the table's bins (alpha is 7 of them) and the brute force's noise: 3e-3
    assert np.abs(_cdf(got) - brute).max() < 3e-3
    src, _ = read_image(tmp_path / "in" / "v_basecolor.png")
    assert np.array_equal(read_image(out / "v_basecolor.png")[0], src)


def test_export_keep_variance_widens_a_sampled_lobe_when_downsizing(tmp_path: Path) -> None:
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B), 64)
    _write_set(tmp_path / "in", normal, d_from_beckmann(0.2))
    args = [str(tmp_path / "in"), "--preset", "raw", "--size", "8"]
    assert main(["export", args[0], str(tmp_path / "kept"), *args[1:], "--keep-variance"]) == 0
    assert main(["export", args[0], str(tmp_path / "plain"), *args[1:]]) == 0
    kept, _ = read_image(next((tmp_path / "kept").glob("*distribution*")))
    plain, _ = read_image(next((tmp_path / "plain").glob("*distribution*")))
    assert kept.shape == (8, 8, N)
    assert np.abs(_cdf(plain) - _beckmann_cdf(0.2)).max() < 1e-3
    # Lanczos-3 over the checkerboard leaves the midpoint up to its ripple
    err = np.abs(_cdf(kept) - _beckmann_cdf(math.sqrt(0.2**2 + HAND_TRACE))).max()
    assert err < 3e-3, err


def test_a_filter_layer_widens_a_sampled_lobe_through_a_project(tmp_path: Path) -> None:
    # the layer selects only the normal; keep_variance writes the distribution too
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    _write_set(tmp_path / "in", normal, d_from_beckmann(0.2))
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(tmp_path / "in")]) == 0
    layer = ["layer", "add", str(project), "filter", "--op", "blur", "sigma_px=4"]
    assert main([*layer, "keep_variance=true", "--params", "normal"]) == 0
    assert main(["flatten", str(project), str(tmp_path / "out")]) == 0
    got, _ = read_image(tmp_path / "out" / "v_distribution.exr")
    err = np.abs(_cdf(got) - _beckmann_cdf(math.sqrt(0.2**2 + HAND_TRACE))).max()
    assert err < 2e-3, err


def test_viewport_mips_widen_a_beckmann_table_and_sample_the_widened_lobe() -> None:
    """The GL viewport's mip chain with keep variance (``shading_maps.mip_chain``) on a
    sampled lobe: the checkerboard's 2x2 averages lose ``HAND_TRACE``, so level 1's table
    is Beckmann(sqrt(m^2 + HAND_TRACE)) (closed-form CDF), and the nodes the shader
    samples the environment with are that lobe's closed-form quantiles
    ``atan(m' sqrt(-ln(1 - y)))``; level 0 and the plain chain keep the source table."""
    from matshop.viewport.gl import sampled_lobe, shading_maps

    schema = Schema.from_names(["base_color", "distribution", "normal"])
    m = 0.2
    maps = {
        "base_color": np.full((SIZE, SIZE, 3), 0.5, np.float32),
        "distribution": np.broadcast_to(d_from_beckmann(m), (SIZE, SIZE, N)).copy(),
        "normal": _checker(_tilted(*TILT_A), _tilted(*TILT_B)),
    }
    packed = shading_maps.pack(schema, maps)
    plain = shading_maps.mip_chain(packed, 2, N)
    kept = shading_maps.mip_chain(packed, 2, N, widen="sampled")
    assert np.array_equal(kept["distribution"][0], plain["distribution"][0])
    source = _cdf(d_from_beckmann(m))
    assert np.abs(_cdf(plain["distribution"][1][..., :N]) - source).max() < 1e-6
    wide = math.sqrt(m * m + HAND_TRACE)
    err = np.abs(_cdf(kept["distribution"][1][..., :N]) - _beckmann_cdf(wide)).max()
    assert err < 2e-3, err
    y = sampled_lobe.node_levels(N).astype(np.float64)
    nodes = kept["distribution"][1][..., 4 * sampled_lobe.table_layers(N) :]
    truth = np.arctan(wide * np.sqrt(-np.log1p(-y)))
    # measured 2.6e-4 rad (a table bin is 1.2e-2); the unwidened nodes are 6.9e-2 off
    assert np.abs(nodes - truth).max() < 1e-3
    for name in ("kd_ao", "ks_lobe", "normal_lobe"):
        for level in range(3):
            assert np.array_equal(kept[name][level], plain[name][level])
