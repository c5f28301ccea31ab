"""How far the sampled tone range is from all texels' range, and what the sample costs.

    python benchmarks/tone_range_sample.py [--draws 12]

Curves and levels (``remap="data"``) map ``[m - r, m + r]`` to [0, 1], ``m``
the median and ``r`` the larger distance to the 0.5th / 99.5th percentiles
(:mod:`matshop.ops.tone_range`), read from a random draw of texels. This
prints, for each way of drawing, the error of the drawn range's two ends
against the range of every texel, in units of that exact span (per channel or
vector magnitude; mean, 90th percentile and worst over several seeds), and
the time to gather the draw and take its percentiles. Ways: the draw in use
(:data:`MAX_SAMPLES` single texels) and the one before it (2^18 texels in
runs of 16 neighbours, 2^14 places).

Data: the real 10-channel set of ``_common.real_set`` in edit space (the
chessboard's flat normal magnitudes, three quarters zero, are left out of the
summary: their range is the space's fallback), and scikit-image's bundled
photographs and textures, scaled to 2048^2 with cubic interpolation.
"""

from __future__ import annotations

import argparse
import time

import cv2
import numpy as np
import skimage.data
from _common import real_set

from matshop.ops import tone_range
from matshop.ops._gather import gather_planes
from matshop.ops.selection import Selection

CUTS = [tone_range.CLIP_PERCENT, 50.0, 100.0 - tone_range.CLIP_PERCENT]
PHOTOS = ("grass", "gravel", "brick", "astronaut", "coffee", "chelsea", "camera", "moon")
#: (places, texels per place): the draw in use, the draw before it
DRAWS = {
    "in use": (tone_range.MAX_SAMPLES, 1),
    "before (2^18 in runs of 16)": (1 << 14, 16),
}


def _ends(planes: np.ndarray, groups: list) -> np.ndarray:
    """``(2, k)``: each channel's (or vector's) ``m - r`` and ``m + r``."""
    found = tone_range._group_percentiles(planes, groups, CUTS)
    low, median, high = np.concatenate(found, axis=1)
    reach = np.maximum(median - low, high - median)
    return np.stack([median - reach, median + reach])


def _draw(block: np.ndarray, places: int, run: int, seed: int) -> np.ndarray:
    height, width, channels = block.shape
    starts = np.random.default_rng(seed).integers(0, height * width - run + 1, places)
    starts.sort()
    index = (starts[:, None] + np.arange(run)).reshape(-1)
    planes = np.empty((channels, index.size), dtype=block.dtype)
    gather_planes(block.reshape(-1, channels), index, planes)
    return planes


def _sets() -> list[tuple[str, np.ndarray, list, list[int]]]:
    """``(name, block, groups, columns to summarise)``."""
    material, what = real_set(2048)
    edit = material.to_edit().data
    selection = Selection(edit, schema=material.schema, params=None, mask=None, op="curves")
    block = selection.take(edit)
    columns, at = [], 0
    for group in selection.groups:
        count = 1 if group.curve_mode == "vector" else len(group.channels)
        if group.name != "normal":
            columns += range(at, at + count)
        at += count
    sets = [(f"{what.split()[0]} set (10 ch)", block, selection.groups, columns)]
    for name in PHOTOS:
        image = getattr(skimage.data, name)().astype(np.float32) / 255.0
        image = cv2.resize(image, (2048, 2048), interpolation=cv2.INTER_CUBIC)
        image = np.ascontiguousarray(image.reshape(2048, 2048, -1))
        grey = Selection(image, schema=None, params=None, mask=None, op="curves")
        sets.append((name, image, grey.groups, list(range(image.shape[2]))))
    return sets


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=12)
    args = parser.parse_args()
    sets = _sets()
    exact = []
    for _, block, groups, _ in sets:
        all_texels = np.ascontiguousarray(block.reshape(-1, block.shape[2]).T)
        exact.append(_ends(all_texels, groups))
    for label, (places, run) in DRAWS.items():
        print(f"{label}: {places} places x {run} texels")
        for (name, block, groups, columns), ends in zip(sets, exact, strict=True):
            span = ends[1] - ends[0]
            errors, gather_ms, percentile_ms = [], [], []
            for seed in range(args.draws):
                start = time.perf_counter()
                planes = _draw(block, places, run, seed + 1)
                middle = time.perf_counter()
                drawn = _ends(planes, groups)
                gather_ms.append((middle - start) * 1e3)
                percentile_ms.append((time.perf_counter() - middle) * 1e3)
                errors.append((np.abs(drawn - ends).max(axis=0) / span)[columns])
            errors = np.concatenate(errors)
            print(
                f"  {name:32s} error of the span: mean {errors.mean():.4f}"
                f" p90 {np.percentile(errors, 90):.4f} worst {errors.max():.4f};"
                f" gather {np.median(gather_ms[1:]):.2f} ms,"
                f" percentiles {np.median(percentile_ms[1:]):.2f} ms"
            )


if __name__ == "__main__":
    main()
