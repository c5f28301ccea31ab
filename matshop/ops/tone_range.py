"""The interval of edit values a tone curve's [0, 1] axis spans, per channel group.

Curves and levels map each parameter to [0, 1] before the curve and back after
it. Two choices (the ops' ``remap`` parameter):

- ``"data"`` (default): by the values *in this image*, robustly (the paper: "the
  length of each parameter ... appropriately remapped in the [0, 1] range"). Per
  channel for colors and scalars, of the (quadrature-weighted) magnitude for
  vectors (frames, inverse CDFs): the median ``m`` goes to 0.5 and
  ``[m - r, m + r]`` to [0, 1], ``r`` the larger distance from ``m`` to the
  ``clip_percent``-th and ``(100 - clip_percent)``-th percentiles. So the whole
  robust range lies inside [0, 1] and a contrast S-curve pivots on the typical
  value: every texel moves away from the median, which raises the spread of any
  histogram -- also the lopsided ones of real maps (three quarters of the
  chessboard's normals are flat: stretching its 0.5-99.5 percentile range
  linearly put the flat floor at 0 and the S-curve flattened the bumps). Beyond
  [0, 1] (the outliers) the curve continues with slope 1: they keep their
  distance from the range's end instead of being clipped by a curve that ends flat;
- ``"space"``: the space's fixed theoretical range (``EditRange``; vectors from
  0 to its span, e.g. pi/2 for frames), the same for every image; the table's
  end segments continue beyond it (the behaviour before ``remap`` existed).

A group whose data range is (nearly) empty -- a flat normal map, a constant
color -- falls back to the space's range, so a curve on it still does something
predictable instead of dividing by zero. Percentiles come from at most
:data:`MAX_SAMPLES` texels drawn at random with a fixed seed (a robust
statistic needs no more, and a 4K map stays cheap).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import InvalidValue
from ._gather import gather_planes, plane_magnitudes
from ._order import order_statistics
from .selection import ChannelGroup

Remap = Literal["data", "space"]
REMAPS: tuple[str, ...] = ("data", "space")
#: default robust cut: the 0.5th to 99.5th percentiles (MATH.md "Curves / levels")
CLIP_PERCENT = 0.5
#: texels read at most for the percentiles. What the estimate's error depends on is
#: the number of independent places: 2^16 single texels come as close to all texels'
#: range ``[m - r, m + r]`` as the 2^18 texels in runs of 16 drawn before (2^14
#: places), or closer, at a quarter of the values to gather and sort. Error of the
#: ends in units of the exact span, 12 draws each (``benchmarks/tone_range_sample.py``),
#: mean / 90th percentile / worst: on the real 10-channel set 0.0027 / 0.0073 / 0.0239
#: against 0.0034 / 0.0122 / 0.0239; worst of eight photographs and textures 0.0137
#: against 0.0301 (photo by photo the mean lower, or within 0.0001)
MAX_SAMPLES = 1 << 16
#: a data range narrower than this fraction of the space's span counts as empty
_MIN_SPAN_FRACTION = 1e-4


@dataclass(frozen=True)
class ToneRange:
    """What [0, 1] of the curve means for one channel group: ``lo + t * span``.

    With ``remap="data"`` the median is at ``t = 0.5``.
    """

    group: str
    vector: bool
    #: per channel of the group (one entry for a vector: its magnitude)
    lo: np.ndarray
    span: np.ndarray
    #: "data" or "space" (what was used, after any fallback)
    source: tuple[str, ...]

    def describe(self) -> str:
        """``name [lo, hi] (data)``, one interval per channel (rounded for display)."""
        parts = [
            f"[{lo:.4g}, {lo + span:.4g}]" + ("" if src == "data" else " (space)")
            for lo, span, src in zip(self.lo, self.span, self.source, strict=True)
        ]
        label = f"{self.group} |v|" if self.vector else self.group
        return f"{label} {', '.join(parts)}"


def _space_range(group: ChannelGroup) -> tuple[float, float]:
    er = group.edit_range
    span = er.span if np.isfinite(er.span) else 1.0
    if group.curve_mode == "vector":
        return 0.0, float(span)
    lo = er.lo if np.isfinite(er.lo) else 0.0
    return float(lo), float(span)


@functools.lru_cache(maxsize=8)
def _sample_index(height: int, width: int) -> np.ndarray:
    """Flat indices of :data:`MAX_SAMPLES` texels, a fixed draw per image size (with
    replacement), in order of place, so the gather reads the map forwards."""
    index = np.random.default_rng(0).integers(0, height * width, MAX_SAMPLES)
    index.sort()
    index.flags.writeable = False
    return index


def _sample(block: np.ndarray) -> np.ndarray:
    """At most :data:`MAX_SAMPLES` texels as planes ``(k, n)``, drawn with a fixed seed.

    Random places rather than a stride: a regular stride aliases with
    axis-aligned structure (a board's 1-2 texel bevels are all hit or all
    missed, which moved the chessboard's 99.5th tilt percentile from 9.2 to 6.9
    degrees); a fixed seed keeps every run, tile and preview identical. Planes,
    so each channel's sort and a vector's magnitudes read contiguous values.
    """
    height, width, channels = block.shape
    texels = block.reshape(height * width, channels)  # a view for channel slices too
    if height * width <= MAX_SAMPLES:
        return np.ascontiguousarray(texels.T)
    index = _sample_index(height, width)
    planes = np.empty((channels, index.size), dtype=block.dtype)
    gather_planes(texels, index, planes)
    return planes


def percentiles(values: np.ndarray, cuts: list[float]) -> np.ndarray:
    """``np.percentile(values, cuts, axis=0)`` (linear) of finite ``values``."""
    found = _plane_percentiles(values.T, cuts)
    if found is None:
        raise InvalidValue("percentiles of values that are not all finite")
    return found


def _plane_percentiles(
    planes: np.ndarray, cuts: list[float], rows: np.ndarray | None = None
) -> np.ndarray | None:
    """:func:`percentiles` of the rows of ``planes`` ``(k, n)`` (those of ``rows``:
    all by default): ``(len(cuts), len(rows))``; None when a value is not finite.

    numpy's own partitions once per cut and column, five to ten times slower
    than a sort on the real set's planes; :mod:`._order` sorts or
    radix-selects, whichever this CPU does faster, for the same order
    statistics; the interpolation below is numpy's ``_lerp``, so the values are
    the same.
    """
    count = planes.shape[1]
    position = np.asarray(cuts, dtype=np.float64) / 100.0 * (count - 1)
    below = np.floor(position).astype(np.int64)
    above = np.minimum(below + 1, count - 1)
    ranks, where = np.unique(np.concatenate([below, above]), return_inverse=True)
    ordered = order_statistics(planes, ranks, rows)
    if ordered is None:
        return None
    t = (position - below)[:, None]
    a = ordered[:, where[: below.size]].T
    b = ordered[:, where[below.size :]].T
    diff = b - a  # in the values' precision, as numpy does
    return np.where(t >= 0.5, b - diff * (1.0 - t), a + diff * t)


def group_values(block: np.ndarray, group: ChannelGroup) -> np.ndarray:
    """``(..., k)`` values a curve reads: the channels, or ``(..., 1)`` magnitudes of a vector."""
    values = block[..., group.channels]
    if group.curve_mode == "vector":
        values = values.astype(np.float64)
        return np.sqrt((values**2 * group.quadrature).sum(axis=-1, keepdims=True))
    return values


def _plane_values(planes: np.ndarray, group: ChannelGroup) -> np.ndarray:
    """:func:`group_values` of a sample's planes, as planes ``(k, n)`` (the same bits)."""
    if group.curve_mode != "vector":
        first, count = int(group.channels[0]), len(group.channels)
        if np.array_equal(group.channels, np.arange(first, first + count)):
            return planes[first : first + count]  # a view: fancy indexing copied the planes
        return planes[group.channels]
    out = np.empty((1, planes.shape[1]))
    plane_magnitudes(
        planes,
        np.asarray(group.channels, dtype=np.int64),
        np.asarray(group.quadrature, dtype=np.float64),
        out[0],
    )
    return out


def tail_slope(remap: Remap) -> float:
    """How a curve continues beyond [0, 1]: slope 1 (data), the table's end segments (-1)."""
    return 1.0 if remap == "data" else -1.0


def _finite_values(planes: np.ndarray, group: ChannelGroup) -> np.ndarray:
    """The group's sampled values ``(k, n)`` at the texels where all of them are finite."""
    values = _plane_values(planes, group)
    finite = np.isfinite(values).all(axis=0)
    return values if finite.all() else values[:, finite]


def _group_percentiles(
    planes: np.ndarray, groups: list[ChannelGroup], cuts: list[float]
) -> list[np.ndarray | None]:
    """Each group's percentiles ``(len(cuts), k)`` over the sampled texels where all
    its channels are finite (None where there are none).

    All groups at once: the channels' own planes in one call, the vectors'
    magnitudes in another (:mod:`._order` takes a plane per thread). Finite or
    not comes out of the order statistics: only when a value is not finite is
    each group read again, for its finite texels.
    """
    if planes.shape[1] == 0:
        return [None] * len(groups)
    vectors = [g for g in groups if g.curve_mode == "vector"]
    channels = [g for g in groups if g.curve_mode != "vector"]
    none = np.empty((len(cuts), 0))
    rows = np.concatenate([g.channels for g in channels] or [[]]).astype(np.int64)
    by_channel = _plane_percentiles(planes, cuts, rows) if rows.size else none
    by_vector = (
        _plane_percentiles(np.concatenate([_plane_values(planes, g) for g in vectors]), cuts)
        if vectors
        else none
    )
    if by_channel is None or by_vector is None:
        return [_finite_group_percentiles(planes, g, cuts) for g in groups]
    found: list[np.ndarray | None] = []
    channel_at, vector_at = 0, 0
    for group in groups:
        if group.curve_mode == "vector":
            found.append(by_vector[:, vector_at : vector_at + 1])
            vector_at += 1
        else:
            count = len(group.channels)
            found.append(by_channel[:, channel_at : channel_at + count])
            channel_at += count
    return found


def _finite_group_percentiles(
    planes: np.ndarray, group: ChannelGroup, cuts: list[float]
) -> np.ndarray | None:
    """One group's percentiles over the sampled texels where its channels are all
    finite; None when there are none."""
    values = _finite_values(planes, group)
    return _plane_percentiles(values, cuts) if values.shape[1] else None


def tone_ranges(
    block: np.ndarray,
    groups: list[ChannelGroup],
    *,
    remap: Remap = "data",
    clip_percent: float = CLIP_PERCENT,
) -> list[ToneRange]:
    """One :class:`ToneRange` per group of the selected ``block`` ``(H, W, k)``."""
    if remap not in REMAPS:
        raise InvalidValue(f"unknown remap {remap!r} (use {' or '.join(REMAPS)})")
    found: list[np.ndarray | None] = [None] * len(groups)
    if remap == "data":
        planes = _sample(block)
        found = _group_percentiles(planes, groups, [clip_percent, 50.0, 100.0 - clip_percent])
    out = []
    for group, percentiles_found in zip(groups, found, strict=True):
        vector = group.curve_mode == "vector"
        count = 1 if vector else len(group.channels)
        space_lo, space_span = _space_range(group)
        lo = np.full(count, space_lo)
        span = np.full(count, space_span)
        source = ["space"] * count
        if percentiles_found is not None:
            low, median, high = percentiles_found
            for c in range(count):
                reach = max(median[c] - low[c], high[c] - median[c])
                if reach > 0.5 * _MIN_SPAN_FRACTION * space_span:
                    lo[c], span[c], source[c] = median[c] - reach, 2.0 * reach, "data"
        out.append(ToneRange(group.name, vector, lo, span, tuple(source)))
    return out
