"""The curves kernels against the straightforward numpy formulation.

The reference below is written plainly in float64: the curve itself (scipy's
PCHIP through the points with :func:`curve_lut`'s straight ends, or levels'
closed form), straight lines beyond [0, 1], and for vector groups the magnitude
through the curve. Curves of a few points and levels run as polynomial pieces
(``_pieces.py``) and must match that exactly (to float32 rounding); curves of
many points interpolate the table, within the table's own error. The ranges
are the ops' own (:func:`curve_ranges`); they are checked separately against
``np.percentile`` of the same texels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from matshop.io.material_io import load_material
from matshop.material import Schema
from matshop.ops.curves import curve_lut, curve_ranges, curves, levels, levels_lut
from matshop.ops.selection import Selection
from matshop.ops.tone_range import MAX_SAMPLES, _sample, percentiles, tail_slope

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
SCHEMA = Schema.from_names(["base_color", "distribution", "normal", "metallic"])
POINTS = [(0.0, 0.05), (0.3, 0.6), (0.7, 0.75), (1.0, 0.9)]  # five pieces with the tails
THREE_POINTS = [(0.0, 0.1), (0.4, 0.6), (1.0, 0.95)]  # four pieces: the short kernel loop
INSIDE_POINTS = [(0.1, 0.0), (0.3, 0.5), (0.8, 1.0)]  # straight lines to 0 and to 1
TWO_POINTS = [(0.2, 0.1), (0.9, 0.8)]  # a line


def edit_array(height: int = 41, width: int = 53) -> np.ndarray:
    rng = np.random.default_rng(11)
    edit = rng.normal(0.4, 0.5, (height, width, SCHEMA.edit_width)).astype(np.float32)
    edit[3, 4, SCHEMA.edit_slices["normal"]] = 0.0  # a zero vector stays zero
    edit[5, 6, :3] = [1e30, -1e30, 0.0]  # far outside: the end lines, no wild index
    return edit


def exact_curve(points):
    """``f(t)`` on [0, 1] of a curve's control points: PCHIP, straight lines past the ends."""
    xs, ys = np.array(points, dtype=np.float64).T

    def f(t: np.ndarray) -> np.ndarray:
        if len(xs) == 2:
            return ys[0] + (t - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])
        left = ys[0] + (t - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])
        right = ys[-1] + (t - xs[-1]) * (ys[-1] - ys[-2]) / (xs[-1] - xs[-2])
        inside = PchipInterpolator(xs, ys)(np.clip(t, xs[0], xs[-1]))
        return np.where(t < xs[0], left, np.where(t > xs[-1], right, inside))

    return f


def exact_levels(in_black, in_white, gamma, out_black, out_white):
    def f(t: np.ndarray) -> np.ndarray:
        v = np.clip((t - in_black) / (in_white - in_black), 0.0, 1.0)
        return out_black + (out_white - out_black) * v ** (1.0 / gamma)

    return f


def table_curve(lut):
    """``f(t)`` as the table interpolates it (curves of many points)."""
    return lambda t: np.interp(t, np.linspace(0.0, 1.0, lut.size), lut)


def curve_at(f, lut: np.ndarray, t: np.ndarray, tail: float) -> np.ndarray:
    """``f`` on [0, 1], continued beyond by lines: slope ``tail``, or (space remap, tail < 0)
    the table's end segments, as the ops document."""
    out = f(np.clip(t, 0.0, 1.0))
    last = lut.size - 1
    low = (lut[1] - lut[0]) * last if tail < 0 else tail
    high = (lut[-1] - lut[-2]) * last if tail < 0 else tail
    below, above = t < 0, t > 1
    out[below] = f(np.zeros(1))[0] + t[below] * low
    out[above] = f(np.ones(1))[0] + (t[above] - 1.0) * high
    return out


def reference(edit, f, lut, *, schema, params, remap) -> np.ndarray:
    selection = Selection(edit, schema=schema, params=params, mask=None, op="curves")
    ranges = curve_ranges(edit, schema=schema, params=params, remap=remap)
    tail = tail_slope(remap)
    out = edit.astype(np.float64)
    for group, tone in zip(selection.groups, ranges, strict=True):
        channels = selection.channels[group.channels]
        values = edit[..., channels].astype(np.float64)
        if tone.vector:
            magnitude = np.sqrt((values**2 * group.quadrature).sum(-1))
            t = (magnitude - tone.lo[0]) / tone.span[0]
            mapped = np.maximum(tone.lo[0] + tone.span[0] * curve_at(f, lut, t, tail), 0.0)
            safe = np.where(magnitude > 0, magnitude, 1.0)
            gain = np.where(magnitude > 0, mapped / safe, 0.0)
            out[..., channels] = values * gain[..., None]
        else:
            for i, c in enumerate(channels):
                t = (values[..., i] - tone.lo[i]) / tone.span[i]
                out[..., c] = tone.lo[i] + tone.span[i] * curve_at(f, lut, t, tail)
    return out


@pytest.mark.parametrize("remap", ["data", "space"])
@pytest.mark.parametrize(
    "params", [None, ["normal"], ["metallic", "base_color"], ["distribution", "metallic"]]
)
@pytest.mark.parametrize("points", [POINTS, THREE_POINTS, INSIDE_POINTS, TWO_POINTS])
def test_curves_equal_the_numpy_formulation(remap, params, points) -> None:
    edit = edit_array()
    got = curves(edit, points=points, schema=SCHEMA, params=params, remap=remap)
    f, lut = exact_curve(points), curve_lut(points)
    expected = reference(edit, f, lut, schema=SCHEMA, params=params, remap=remap)
    finite = np.abs(expected) < 1e6
    # float32 arithmetic: a few float32 ulps of the values and of the curve's reach
    np.testing.assert_allclose(got[finite], expected[finite], rtol=3e-6, atol=3e-6)
    far = edit[5, 6, :3]
    if params is None or "base_color" in params:
        # the end lines continue monotonically, with no index out of the table
        assert got[5, 6, 0] > 1e20 and got[5, 6, 1] < -1e20
    else:
        assert np.array_equal(got[5, 6, :3], far)
    assert np.array_equal(got[3, 4, SCHEMA.edit_slices["normal"]], np.zeros(3)) or (
        params is not None and "normal" not in params
    )


def test_levels_without_schema_equal_the_numpy_formulation() -> None:
    edit = edit_array(64, 70)[..., :10]
    args = (0.1, 0.8, 1.7, 0.05, 0.95)
    got = levels(edit, **dict(zip(LEVELS_NAMES, args, strict=True)))
    expected = reference(
        edit, exact_levels(*args), levels_lut(*args), schema=None, params=None, remap="data"
    )
    finite = np.abs(expected) < 1e6
    np.testing.assert_allclose(got[finite], expected[finite], rtol=3e-6, atol=3e-6)


LEVELS_NAMES = ("in_black", "in_white", "gamma", "out_black", "out_white")


@pytest.mark.parametrize("remap", ["data", "space"])
@pytest.mark.parametrize(
    "args",
    [
        (0.1, 0.8, 1.0, 0.05, 0.95),
        (0.0, 1.0, 1.0, 0.2, 0.7),
        (0.2, 0.9, 1.0, 0.1, 0.7),
        (0.1, 0.9, 1.4, 0.0, 1.0),  # the benchmark's
        (0.0, 1.0, 0.45, 0.1, 0.9),
        (0.05, 0.7, 2.2, 0.2, 0.8),
    ],
)
def test_levels_equal_the_closed_form(remap, args) -> None:
    """Levels run as pieces (lines, and a power for the gamma): the closed form exactly."""
    assert_levels_are_the_closed_form(remap, args, tolerance=3e-6)


@pytest.mark.parametrize("remap", ["data", "space"])
@pytest.mark.parametrize("args", [(-0.2, 1.3, 1.4, 0.0, 1.0), (0.1, 1.5, 0.7, 0.1, 0.9)])
def test_levels_with_input_points_outside_0_1_continue_from_the_ramp(remap, args) -> None:
    """Input points beyond the op's range (a script may pass them): the end lines
    start where the ramp is at 0 and 1, not at the output points (the table path)."""
    assert_levels_are_the_closed_form(remap, args, tolerance=1e-5)


def assert_levels_are_the_closed_form(remap: str, args: tuple, tolerance: float) -> None:
    """Levels ``args`` (:data:`LEVELS_NAMES`) on :func:`edit_array` against the float64
    closed form continued by the op's end lines, within ``tolerance`` (rtol and atol)."""
    edit = edit_array()
    got = levels(edit, schema=SCHEMA, remap=remap, **dict(zip(LEVELS_NAMES, args, strict=True)))
    f, lut = exact_levels(*args), levels_lut(*args)
    expected = reference(edit, f, lut, schema=SCHEMA, params=None, remap=remap)
    finite = np.abs(expected) < 1e6
    np.testing.assert_allclose(got[finite], expected[finite], rtol=tolerance, atol=tolerance)


def test_a_power_curve_whose_lines_do_not_start_from_it_is_refused() -> None:
    """The kernel adds the end lines' slopes to a power held flat beyond 0 and 1, so
    it reads only their slopes: pieces where that would change the curve are refused."""
    from matshop.ops._pieces import Pieces

    power = (0.1, 0.8, 1.25, 0.1)  # 0.1 + 0.8 clamp(1.25 (t - 0.1), 0, 1)^p: flat beyond
    Pieces.build([(0.0, (0.1, 1.0)), (0.0, power), (1.0, (0.9, 1.0))], exponent=0.7)
    for pieces in (
        [(0.0, (0.2, 1.0)), (0.0, power), (1.0, (0.9, 1.0))],  # the line below starts elsewhere
        [(0.0, (0.1, 1.0)), (0.0, power), (1.0, (1.0, 1.0))],  # the line above too
        [(0.0, (0.1, 1.0)), (0.0, (0.1, 0.8, 0.8, 0.1)), (1.0, (0.74, 1.0))],  # rising past 1
        [(0.0, (0.1, 1.0)), (0.0, power), (0.9, (0.9, 1.0))],  # the line above not from 1
    ):
        with pytest.raises(ValueError, match="exponent"):
            Pieces.build(pieces, exponent=0.7)


@pytest.mark.parametrize("params", [None, ["base_color"]])
@pytest.mark.parametrize("args", [(0.1, 0.9, 1.4, 0.0, 1.0), (0.02, 0.6, 0.45, 0.1, 0.85)])
def test_levels_on_real_maps_equal_the_closed_form(params, args) -> None:
    """The repository's sample set read from its files (colour, scalars and a normal
    map, so a frame goes by magnitude): levels against the float64 closed form."""
    material, _ = load_material(SAMPLE)
    edit = material.to_edit()
    named = dict(zip(LEVELS_NAMES, args, strict=True))
    got = levels(edit.data, schema=edit.schema, params=params, **named)
    expected = reference(
        edit.data, exact_levels(*args), levels_lut(*args),
        schema=edit.schema, params=params, remap="data",
    )  # fmt: skip
    np.testing.assert_allclose(got, expected, rtol=3e-6, atol=3e-6)
    assert np.abs(got - edit.data).max() > 0.05  # the maps did change


@pytest.mark.parametrize("gamma", [1.4, 0.5, 2.2, 0.01, 100.0])
def test_the_gamma_is_the_power_to_float32_rounding(gamma) -> None:
    """Levels 0..1 on [0, 1] (fixed range) is ``x^(1 / gamma)``: against numpy in float64.

    Every float32 exponent is covered (subnormals, 0 and 1 included). Up to
    2.5 ulp of the result for gammas of 0.5 to 2.2; within 1.2e-7 (an ulp of
    1) absolute for any gamma, which is what a tone curve's output sees.
    """
    rng = np.random.default_rng(5)
    x = np.ldexp(rng.uniform(1.0, 2.0, 60_000), rng.integers(-149, 0, 60_000))
    x = np.concatenate([x.astype(np.float32), [0.0, 1.0, 1e-45, 0.5, 0.70710677, 0.7071068]])
    x = np.concatenate([x, rng.random(40_000)]).astype(np.float32)
    got = levels(x.reshape(1, -1, 1), gamma=gamma, remap="space")[0, :, 0].astype(np.float64)
    expected = x.astype(np.float64) ** (1.0 / gamma)
    error = np.abs(got - expected)
    assert error.max() <= 1.2e-7
    if 0.5 <= gamma <= 2.2:
        normal = expected >= np.finfo(np.float32).tiny
        ulp = np.spacing(expected[normal].astype(np.float32)).astype(np.float64)
        assert (error[normal] / ulp).max() <= 2.5


@pytest.mark.parametrize("remap", ["data", "space"])
def test_a_curve_of_many_points_interpolates_its_table(remap) -> None:
    """More points than the pieces hold: the table path, within the table's own error."""
    points = [(0.0, 0.0), (0.1, 0.2), (0.2, 0.25), (0.35, 0.5), (0.5, 0.52), (0.6, 0.7)]
    points += [(0.75, 0.72), (0.9, 0.95), (1.0, 1.0)]
    edit = edit_array()
    got = curves(edit, points=points, schema=SCHEMA, remap=remap)
    lut = curve_lut(points)
    expected = reference(edit, table_curve(lut), lut, schema=SCHEMA, params=None, remap=remap)
    finite = np.abs(expected) < 1e6
    np.testing.assert_allclose(got[finite], expected[finite], rtol=3e-6, atol=3e-6)
    exact = reference(edit, exact_curve(points), lut, schema=SCHEMA, params=None, remap=remap)
    np.testing.assert_allclose(got[finite], exact[finite], rtol=1e-4, atol=1e-4)


@pytest.fixture(params=["sort", "radix"])
def order_path(request, monkeypatch) -> str:
    """Both ways to the order statistics, whichever this CPU would take (``_order``)."""
    from matshop.ops import _order

    monkeypatch.setattr(_order, "METHOD", request.param)
    return request.param


def test_percentiles_are_numpys(order_path) -> None:
    rng = np.random.default_rng(2)
    for dtype in (np.float32, np.float64):
        for count in (1, 2, 9, 1000, 4099):
            values = (rng.normal(size=(count, 4)) * 7).astype(dtype)
            cuts = [0.5, 50.0, 99.5]
            assert np.array_equal(percentiles(values, cuts), np.percentile(values, cuts, axis=0))


def _hard_columns(rng: np.random.Generator, count: int) -> np.ndarray:
    """Columns as real maps have them: flat areas, a few levels, both zeros, huge ranges."""
    normal = rng.normal(size=count)
    return np.stack(
        [
            np.where(rng.random(count) < 0.75, 0.0, np.abs(normal)),  # a flat normal map
            rng.integers(0, 2, count).astype(float),  # metallic: 0 or 1
            np.round(rng.random(count) * 255) / 255,  # 8-bit levels
            np.where(rng.random(count) < 0.5, -0.0, normal),  # both zeros
            rng.random(count) ** 8 * 1e30,  # many octaves
            np.full(count, 0.25),  # constant
        ],
        axis=1,
    )


@pytest.mark.parametrize("count", [1, 3, 70, 5000, 1 << 18])
def test_percentiles_of_real_looking_columns_are_numpys(count: int, order_path) -> None:
    """The radix select and the sort (``_order``) against numpy's percentiles, on the
    columns that put most values into one bucket; float32 and float64 (a frame's
    magnitudes), any cut."""
    rng = np.random.default_rng(count)
    values = _hard_columns(rng, count)
    for dtype in (np.float32, np.float64):
        for cuts in ([0.5, 50.0, 99.5], [0.0, 100.0], [12.3, 12.4, 77.0]):
            expected = np.percentile(values.astype(dtype), cuts, axis=0)
            assert np.array_equal(percentiles(values.astype(dtype), cuts), expected)


def _drawn_index(texels: int) -> np.ndarray:
    """The documented draw: MAX_SAMPLES texels from seed 0, in order."""
    return np.sort(np.random.default_rng(0).integers(0, texels, MAX_SAMPLES))


def test_the_sample_is_the_fixed_random_draw_of_texels() -> None:
    """Channel by channel (planes), from a strided channel slice and a contiguous block."""
    edit = np.random.default_rng(4).random((600, 520, 5), dtype=np.float32)
    index = _drawn_index(600 * 520)
    assert index.size == MAX_SAMPLES
    rows, cols = np.divmod(index, 520)
    for block in (edit[..., 1:4], edit):  # a channel slice, as curves sees it
        assert np.array_equal(_sample(block), block[rows, cols].T)
    small = edit[:100, :90]  # fewer texels than the draw: all of them
    assert np.array_equal(_sample(small), small.reshape(-1, 5).T)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, -np.nan])
def test_a_value_that_is_not_finite_leaves_its_texel_out_of_its_group_only(bad, order_path) -> None:
    """Every texel is read (fewer than the draw): each group's range is ``np.percentile``
    over the texels where all its channels are finite, whichever kind of value is not."""
    edit = edit_array(120, 90)
    colour = SCHEMA.edit_slices["base_color"]
    normal = SCHEMA.edit_slices["normal"]
    edit[7, 9, colour.start + 1] = bad
    edit[50:52, 3, normal.start + 2] = bad
    selection = Selection(edit, schema=SCHEMA, params=None, mask=None, op="curves")
    texels = edit.reshape(-1, edit.shape[2]).astype(np.float64)
    for group, tone in zip(selection.groups, curve_ranges(edit, schema=SCHEMA), strict=True):
        values = texels[:, selection.channels[group.channels]]
        if tone.vector:
            values = np.sqrt((values**2 * group.quadrature).sum(axis=1, keepdims=True))
        kept = np.isfinite(values).all(axis=1)
        assert kept.sum() == texels.shape[0] - {"base_color": 1, "normal": 2}.get(group.name, 0)
        low, median, high = np.percentile(values[kept], [0.5, 50.0, 99.5], axis=0)
        reach = np.maximum(median - low, high - median)
        np.testing.assert_allclose(tone.lo, median - reach, rtol=1e-6, atol=1e-7)


def test_ranges_are_the_percentiles_of_the_drawn_texels() -> None:
    """Each group's range from ``np.percentile`` of its drawn values: per channel, and of
    the magnitude for vectors (a frame, and the 128-channel distribution with its weights);
    texels with a NaN or an infinity in a group are left out of that group only."""
    edit = edit_array(700, 400)
    edit[7, 9, 0] = np.nan
    edit[8, 9, SCHEMA.edit_slices["normal"].start] = np.inf
    selection = Selection(edit, schema=SCHEMA, params=None, mask=None, op="curves")
    index = _drawn_index(700 * 400)
    drawn = edit.reshape(-1, edit.shape[2])[index].astype(np.float64)
    ranges = curve_ranges(edit, schema=SCHEMA)
    for group, tone in zip(selection.groups, ranges, strict=True):
        values = drawn[:, selection.channels[group.channels]]
        if tone.vector:
            values = np.sqrt((values**2 * group.quadrature).sum(axis=1, keepdims=True))
        values = values[np.isfinite(values).all(axis=1)]
        low, median, high = np.percentile(values, [0.5, 50.0, 99.5], axis=0)
        reach = np.maximum(median - low, high - median)
        np.testing.assert_allclose(tone.lo, median - reach, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(tone.span, 2.0 * reach, rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("channels, count", [(3, 1 << 18), (5, 3000), (2, 1), (1, 1025)])
def test_vector_magnitudes_of_the_sample_are_numpys_bits(channels, count) -> None:
    """The sample's magnitudes (``_gather.plane_magnitudes``, chunked channel by channel)
    are numpy's ``sqrt((v**2 * q).sum(-1))`` bit for bit, so a vector's range is the
    same whichever way its values are read."""
    from matshop.ops._gather import plane_magnitudes

    rng = np.random.default_rng(channels)
    planes = (rng.normal(size=(channels + 2, count)) * 3).astype(np.float32)
    picked = np.arange(1, channels + 1)
    quadrature = rng.random(channels)
    got = np.empty(count)
    plane_magnitudes(planes, picked, quadrature, got)
    expected = np.sqrt((planes[picked].T.astype(np.float64) ** 2 * quadrature).sum(-1))
    assert np.array_equal(got, expected)
