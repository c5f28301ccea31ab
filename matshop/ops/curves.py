"""Curves and levels: a tone curve applied in edit space.

A curve maps a magnitude in [0, 1] to a magnitude. Scalars and color
channels go through it per channel (``p~' = curve(p~)``, after remapping the
parameter's range to [0, 1]); vector parameters (frame rotations, inverse
CDFs) are scaled along themselves, ``p~' = p~ curve(|p~|) / |p~|``, so a
frame keeps its tilt direction and a lobe its shape family. Which range maps
to [0, 1] is the ``remap`` parameter (:mod:`.tone_range`): by default the
values' own robust range in this image (so an S-curve raises the contrast of
what is there, as in the paper's Fig. 7(b)), or the space's fixed range. The
curve is a monotone cubic through the control points. A curve of up to five
points, and levels (its gamma a vectorised power), are evaluated exactly from
their pieces in a vectorised pass (``_pieces.py``, 2x faster on 3 channels);
more points go through a uniform lookup table (``curve_lut``, whose
interpolation errs below 1e-6 for moderate bends). One fused pass per texel.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numba
import numpy as np

from ..material import Schema
from ._fresh import empty_touched_soon
from ._kernels import line_tables, lut_apply
from ._pieces import (
    POWER_ROWS,
    Pieces,
    pieces_apply,
    power_constants,
    power_tiles,
    split_exponent,
)
from .selection import Selection
from .spec import WHOLE_IMAGE, OpError, OpSpec, OpTarget, ParamSpec, Reach
from .tone_range import CLIP_PERCENT, REMAPS, Remap, ToneRange, tail_slope, tone_ranges

#: LUT entries over [0, 1]; the PCHIP's linear-interpolation error at this
#: density is below 1e-6 for any curve with moderate bends.
LUT_SIZE = 4096

IDENTITY_POINTS = ((0.0, 0.0), (1.0, 1.0))


def curve_lut(points: Sequence[tuple[float, float]], size: int = LUT_SIZE) -> np.ndarray:
    """Sample the monotone cubic through ``points`` (x increasing) on ``size`` steps of [0, 1].

    Outside the control points the curve continues with the end values'
    straight line through the nearest two points.
    """
    return _curve_at(points, np.linspace(0.0, 1.0, size))


def _curve_at(points: Sequence[tuple[float, float]], t: np.ndarray) -> np.ndarray:
    """The curve of :func:`curve_lut` at ``t``, value by value (so the same bits)."""
    xs = np.array([p[0] for p in points], dtype=np.float64)
    ys = np.array([p[1] for p in points], dtype=np.float64)
    if len(xs) == 2:
        return (ys[0] + (t - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])).astype(np.float64)
    from scipy.interpolate import PchipInterpolator  # here: scipy.interpolate takes 0.2 s to import

    inside = PchipInterpolator(xs, ys, extrapolate=False)(t)
    left = ys[0] + (t - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])
    right = ys[-1] + (t - xs[-1]) * (ys[-1] - ys[-2]) / (xs[-1] - xs[-2])
    return np.where(t < xs[0], left, np.where(t > xs[-1], right, inside))


def levels_lut(
    in_black: float,
    in_white: float,
    gamma: float,
    out_black: float,
    out_white: float,
    size: int = LUT_SIZE,
) -> np.ndarray:
    """Photoshop-style levels as a LUT over [0, 1]."""
    t = np.linspace(0.0, 1.0, size)
    x = np.clip((t - in_black) / (in_white - in_black), 0.0, 1.0)
    return out_black + (out_white - out_black) * x ** (1.0 / gamma)


def _end_slopes(lut: Callable[[], np.ndarray], tail: float) -> tuple[float, float]:
    """Slopes beyond [0, 1]: ``tail`` (remap="data") or the table's end segments (-1)."""
    if tail >= 0:
        return tail, tail
    table = lut()
    last = table.size - 1
    return float(table[1] - table[0]) * last, float(table[-1] - table[-2]) * last


def curve_pieces(points: Sequence[tuple[float, float]], tail: float) -> Pieces | None:
    """The curve of :func:`curve_lut` as polynomial pieces (None: too many points).

    The PCHIP's own cubics between the points (scipy's coefficients), the
    straight lines :func:`curve_lut` continues with before the first and after
    the last point, and beyond [0, 1] lines of the slopes ``tail`` gives.
    """
    from scipy.interpolate import PchipInterpolator

    xs = np.array([p[0] for p in points], dtype=np.float64)
    ys = np.array([p[1] for p in points], dtype=np.float64)
    # the table's first and last entries, without the table (its 4096 points
    # took a quarter of a small image's whole call)
    at_0, at_1 = _curve_at(points, np.array([0.0, 1.0]))
    below, above = _end_slopes(lambda: curve_lut(points), tail)
    first = (ys[1] - ys[0]) / (xs[1] - xs[0])
    pieces: list[tuple[float, tuple[float, ...]]] = [(0.0, (at_0, below))]
    if len(xs) == 2:
        pieces.append((0.0, (at_0, first)))
    else:
        if xs[0] > 0.0:
            pieces.append((0.0, (at_0, first)))
        c = PchipInterpolator(xs, ys).c  # (4, pieces), highest power first
        pieces += [(xs[i], tuple(c[::-1, i])) for i in range(len(xs) - 1)]
        if xs[-1] < 1.0:
            pieces.append((xs[-1], (ys[-1], (ys[-1] - ys[-2]) / (xs[-1] - xs[-2]))))
    pieces.append((1.0, (at_1, above)))
    return Pieces.build(pieces)


def levels_pieces(
    in_black: float, in_white: float, gamma: float, out_black: float, out_white: float, tail: float
) -> Pieces | None:
    """:func:`levels_lut` as pieces: straight lines, and between the input points
    a line (``gamma`` 1) or ``out_black + (out_white - out_black) v^(1 / gamma)``;
    None (the table) for input points outside [0, 1], where the end lines start
    from values inside the ramp."""
    if in_black < 0.0 or in_white > 1.0:
        return None
    below, above = _end_slopes(
        lambda: levels_lut(in_black, in_white, gamma, out_black, out_white), tail
    )
    pieces: list[tuple[float, tuple[float, ...]]] = [(0.0, (out_black, below))]
    inv_width = 1.0 / (in_white - in_black)
    if gamma != 1.0:  # one power piece over [0, 1], clamped at the input points
        pieces.append((0.0, (out_black, out_white - out_black, inv_width, in_black)))
    else:
        if in_black > 0.0:
            pieces.append((0.0, (out_black,)))
        pieces.append((in_black, (out_black, (out_white - out_black) * inv_width)))
        if in_white < 1.0:
            pieces.append((in_white, (out_white,)))
    pieces.append((1.0, (out_white, above)))
    return Pieces.build(pieces, exponent=1.0 / gamma)


def apply_lut(
    edit: np.ndarray,
    lut: np.ndarray | Callable[[], np.ndarray],
    *,
    schema: Schema | None,
    params: Sequence[str] | str | None,
    mask: np.ndarray | None,
    op: str,
    remap: Remap = "data",
    clip_percent: float = CLIP_PERCENT,
    pieces: Callable[[float], Pieces | None] | None = None,
) -> np.ndarray:
    """Run a [0, 1] -> [0, 1] curve over the selected parameters (per channel or by magnitude).

    ``pieces(tail)``, when given and not None, is the same curve as polynomial
    pieces (:mod:`._pieces`), evaluated exactly in a vectorised pass; else the
    table ``lut`` (or what it returns, when a function: built only if needed)
    is interpolated.
    """
    selection = Selection(edit, schema=schema, params=params, mask=mask, op=op)
    block = selection.take(edit)
    fresh = empty_touched_soon(block.shape)  # its page faults overlap the ranges' reading
    ranges = tone_ranges(block, selection.groups, remap=remap, clip_percent=clip_percent)
    tail = tail_slope(remap)
    curve = pieces(tail) if pieces is not None else None
    result = fresh.result()
    if curve is not None:
        _apply_pieces(block, selection.groups, ranges, curve, result)
        return selection.put(edit, result)
    lut = np.ascontiguousarray(lut() if callable(lut) else lut, dtype=np.float64)
    # every group in one pass; a vector's channels keep an unused identity line
    width = block.shape[2]
    ab = np.zeros((width, lut.size + 1, 2), dtype=np.float32)
    ab[..., 1] = 1.0
    to_pos, shift = np.zeros(width), np.zeros(width)
    vectors = []
    for group, tone in zip(selection.groups, ranges, strict=True):
        if tone.vector:
            vectors.append((group, line_tables(lut, tone.lo[0], tone.span[0], tail)))
            continue
        for c, lo, span in zip(group.channels, tone.lo, tone.span, strict=True):
            ab[c], to_pos[c], shift[c] = line_tables(lut, lo, span, tail)
    groups = [g for g, _ in vectors]
    lut_apply(
        block,
        ab,
        to_pos,
        shift,
        np.concatenate([g.channels for g in groups] or [[]]).astype(np.int64),
        np.cumsum([0] + [len(g.channels) for g in groups]).astype(np.int64),
        np.concatenate([g.quadrature for g in groups] or [[]]).astype(np.float64),
        np.stack([t[0] for _, t in vectors] or [ab[0]]),
        np.array([t[1:] for _, t in vectors] or [(0.0, 0.0)], dtype=np.float64),
        result,
    )
    return selection.put(edit, result)


def _apply_pieces(
    block: np.ndarray, groups: list, ranges: list[ToneRange], curve: Pieces, result: np.ndarray
) -> None:
    """The pieces through ``block`` (H, W, k) into ``result``: per channel, vectors by magnitude."""
    height, width, channels = block.shape
    lo = np.zeros(channels)
    span = np.ones(channels)
    vectors, bounds, quadrature, vector_ranges = [], [0], [], []
    for group, tone in zip(groups, ranges, strict=True):
        if tone.vector:
            vectors += list(group.channels)
            bounds.append(len(vectors))
            quadrature += list(group.quadrature)
            vector_ranges.append((tone.lo[0], tone.span[0]))
        else:
            lo[group.channels], span[group.channels] = tone.lo, tone.span
    # the ranges as the kernel reads them: float32
    lo32, span32 = lo.astype(np.float32), span.astype(np.float32)
    vector_lo, vector_span = np.array(vector_ranges or [(0.0, 1.0)], dtype=np.float32).T
    if curve.exponent != 1.0:
        constants = (
            power_tiles(power_constants(lo32, span32, curve.breaks, curve.coeffs)),
            power_constants(vector_lo, vector_span, curve.breaks, curve.coeffs),
        )
        tiled = np.zeros(0, dtype=np.float32)
        lo_tiles, inv_tiles, span_tiles = tiled, tiled, tiled
    else:
        unused = np.zeros((1, len(POWER_ROWS)), dtype=np.float32)
        constants = (unused, unused)
        lo_tiles, span_tiles = np.tile(lo32, width), np.tile(span32, width)
        inv_tiles = np.tile((1.0 / span).astype(np.float32), width)
    pieces_apply(
        np.ascontiguousarray(block),
        lo_tiles,
        inv_tiles,
        span_tiles,
        np.array(vectors, dtype=np.int64),
        np.array(bounds, dtype=np.int64),
        np.array(quadrature, dtype=np.float64),
        np.stack([vector_lo, 1.0 / vector_span, vector_span], axis=1).astype(np.float32),
        constants,
        curve.breaks,
        curve.coeffs,
        split_exponent(curve.exponent),
        result,
        numba.get_num_threads(),
        np.zeros(1, dtype=np.int64),
    )


def curve_ranges(
    edit: np.ndarray,
    *,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    remap: Remap = "data",
    clip_percent: float = CLIP_PERCENT,
) -> list[ToneRange]:
    """The interval [0, 1] of a curve (or levels) stands for, per channel group of ``edit``.

    What :func:`curves` and :func:`levels` use with the same arguments; the
    curves dialog shows it under the plot.
    """
    selection = Selection(edit, schema=schema, params=params, mask=None, op="curves")
    return tone_ranges(
        selection.take(edit), selection.groups, remap=remap, clip_percent=clip_percent
    )


def curves(
    edit: np.ndarray,
    *,
    points: Sequence[tuple[float, float]] = IDENTITY_POINTS,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
    remap: Remap = "data",
    clip_percent: float = CLIP_PERCENT,
) -> np.ndarray:
    """Apply a tone curve given by control points ``[(x, y), ...]`` in [0, 1].

    ``remap`` chooses what [0, 1] spans (:mod:`.tone_range`). The identity
    curve returns an exact copy (no rounding through the table).
    """
    if tuple(map(tuple, points)) == IDENTITY_POINTS:
        Selection(edit, schema=schema, params=params, mask=mask, op="curves")  # validate
        return np.array(edit, dtype=np.float32, copy=True)
    return apply_lut(
        edit,
        lambda: curve_lut(points),
        schema=schema,
        params=params,
        mask=mask,
        op="curves",
        remap=remap,
        clip_percent=clip_percent,
        pieces=lambda tail: curve_pieces(points, tail),
    )


def levels(
    edit: np.ndarray,
    *,
    in_black: float = 0.0,
    in_white: float = 1.0,
    gamma: float = 1.0,
    out_black: float = 0.0,
    out_white: float = 1.0,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
    remap: Remap = "data",
    clip_percent: float = CLIP_PERCENT,
) -> np.ndarray:
    """Input black/white points, gamma, output black/white points (all in [0, 1] of the range).

    ``remap`` chooses the range (:mod:`.tone_range`).
    """
    check_input_points({"in_black": in_black, "in_white": in_white}, OpTarget())
    return apply_lut(
        edit,
        lambda: levels_lut(in_black, in_white, gamma, out_black, out_white),
        schema=schema,
        params=params,
        mask=mask,
        op="levels",
        remap=remap,
        clip_percent=clip_percent,
        pieces=lambda tail: levels_pieces(in_black, in_white, gamma, out_black, out_white, tail),
    )


def check_input_points(values: Mapping[str, Any], target: OpTarget) -> None:
    """Levels maps [in_black, in_white] onto the output range: it must not be empty."""
    if values["in_white"] <= values["in_black"]:
        raise OpError(
            f"levels: in_white ({values['in_white']:g}) must exceed in_black "
            f"({values['in_black']:g})"
        )


def tone_reach(values: Mapping[str, Any], target: OpTarget) -> Reach:
    """remap="data" reads the value range of the whole image; "space" is pointwise."""
    return 0 if values["remap"] == "space" else WHOLE_IMAGE


_UNIT = (0.0, 1.0)

#: the parameters both ops share: which range [0, 1] spans
REMAP_PARAMS = (
    ParamSpec(
        "remap",
        "choice",
        "data",
        "what [0, 1] spans: data = the values in this image (median at 0.5, the "
        "robust range inside; per channel, |v| for frames and lobes), space = the "
        "space's fixed range",
        choices=REMAPS,
        missing="space",
    ),
    ParamSpec(
        "clip_percent",
        "float",
        CLIP_PERCENT,
        "remap=data: percentiles below this and above 100 minus it are outliers "
        "(left out of the range, passed through with slope 1)",
        unit="%",
        hard_range=(0.0, 25.0),
        ui_range=(0.0, 5.0),
    ),
)

CURVES_SPEC = OpSpec(
    name="curves",
    label="Curves",
    summary="tone curve over each parameter's own robust range in the image (or the "
    "space's fixed range): per channel for colors/scalars, by magnitude for frames and lobes",
    function=curves,
    params=(
        ParamSpec(
            "points",
            "points",
            IDENTITY_POINTS,
            "control points x,y;x,y;... in [0, 1] of the range set by remap",
            hard_range=(0.0, 1.0),
        ),
        *REMAP_PARAMS,
    ),
    linear=False,
    reach=tone_reach,
)

LEVELS_SPEC = OpSpec(
    name="levels",
    label="Levels",
    summary="black point, white point and gamma over each parameter's own robust range "
    "in the image (or the space's fixed range)",
    function=levels,
    params=(
        ParamSpec("in_black", "float", 0.0, "input black point", hard_range=_UNIT, ui_range=_UNIT),
        ParamSpec("in_white", "float", 1.0, "input white point", hard_range=_UNIT, ui_range=_UNIT),
        ParamSpec(
            "gamma", "float", 1.0, "midtone gamma", hard_range=(0.01, 100.0), ui_range=(0.1, 10.0)
        ),
        ParamSpec(
            "out_black",
            "float",
            0.0,
            "output black point",
            hard_range=(-10.0, 10.0),
            ui_range=_UNIT,
        ),
        ParamSpec(
            "out_white",
            "float",
            1.0,
            "output white point",
            hard_range=(-10.0, 10.0),
            ui_range=_UNIT,
        ),
        *REMAP_PARAMS,
    ),
    linear=False,
    checks=(check_input_points,),
    reach=tone_reach,
)

SPECS = (CURVES_SPEC, LEVELS_SPEC)
