"""Seamless cloning speed as ratios to OpenCV's Poisson cloning, measured in one run.

    python benchmarks/clone.py [--repeat N] [--size 2048] [--region 512] [--shape disc]
                               [--channels 10,3,128]

A ``--region``-px disc (or rounded square) of a ``--size`` material is
cloned to another place of the same material (source = target, as the clone
tool does) with every edit channel: the real 10-channel set of
``_common.real_set``, its first 3, and 128 (the 10 tiled). Baseline:
``cv2.seamlessClone(src_u8, dst_u8, mask_u8, center, cv2.NORMAL_CLONE)`` --
3-channel 8-bit Poisson cloning of the same region to the same place. Reported per channel count:

* first clone: ``seamless_clone(..., region=mask)`` (coordinates computed);
  the goal row (issue 16: <= 1x at 10 channels) writes into the caller's
  buffer (``out=``), as the editor's clone tool can;
* re-clone: ``coordinates.clone`` at a new offset (coordinates reused, a drag),
  into a new array and into a reused ``out=`` buffer;
* build: ``CloneCoordinates.from_region`` alone.

Best of ``--repeat`` runs, ours and OpenCV's calls interleaved (the machine
is shared: compare the ratios, not the milliseconds). On a loaded machine
numba's OpenMP workers spin after each parallel loop and steal the cores
the next step needs; ``OMP_WAIT_POLICY=passive python benchmarks/clone.py``
shows the numbers without that effect.

Also: the membrane's error against brute-force mean-value coordinates (all
boundary pixels) at 4000 random region pixels, in the real data.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import cv2
import numpy as np
from _common import edit_channels, goal, paired_ratios

from matshop.ops.clone import CloneCoordinates, seamless_clone


def best_times(fns: list[Callable[[], object]], repeat: int) -> list[float]:
    """Best time of each function, calls interleaved so a load change hits all alike."""
    for fn in fns:
        fn()
    times = [[] for _ in fns]
    for _ in range(repeat):
        for fn, spent in zip(fns, times, strict=True):
            start = time.perf_counter()
            fn()
            spent.append(time.perf_counter() - start)
    return [min(spent) for spent in times]


def region_mask(size: int, diameter: int, shape: str, cx: int, cy: int) -> np.ndarray:
    yy, xx = np.indices((size, size))
    r = diameter / 2
    if shape == "disc":
        return (xx - cx) ** 2 + (yy - cy) ** 2 <= r * r
    corner = diameter / 8  # rounded square: corner radius 1/8 of the side
    qx = np.maximum(np.abs(xx - cx) - (r - corner), 0)
    qy = np.maximum(np.abs(yy - cy) - (r - corner), 0)
    return (qx**2 + qy**2 <= corner**2) & (np.abs(xx - cx) <= r) & (np.abs(yy - cy) <= r)


def brute_force(boundary: np.ndarray, diffs: np.ndarray, points: np.ndarray) -> np.ndarray:
    b = boundary.astype(np.float64)
    out = np.empty((len(points), diffs.shape[1]))
    for start in range(0, len(points), 128):
        d = b[None] - points[start : start + 128, None, :].astype(np.float64)
        dn = np.roll(d, -1, axis=1)
        angle = np.arctan2(d[..., 0] * dn[..., 1] - d[..., 1] * dn[..., 0], (d * dn).sum(-1))
        half = np.tan(angle / 2)
        w = (half + np.roll(half, 1, axis=1)) / np.hypot(d[..., 0], d[..., 1])
        out[start : start + 128] = (w / w.sum(axis=1, keepdims=True)) @ diffs
    return out


def line(label: str, ours: float, base: float) -> None:
    ratio = ours / base
    print(f"{label:44s} ours {ours * 1e3:8.1f} ms  cv2 {base * 1e3:7.1f} ms  ratio {ratio:5.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--size", type=int, default=2048)
    parser.add_argument("--region", type=int, default=512, help="diameter / side, px")
    parser.add_argument("--shape", choices=("disc", "rsquare"), default="disc")
    parser.add_argument("--channels", default="10,3,128")
    args = parser.parse_args()
    full, what = edit_channels(args.size)
    size = full.shape[0]
    print(f"data: {what}, {full.shape[1]}x{size}")

    cx, cy = size // 4 + args.region // 2, size // 4 + args.region // 2
    mask = region_mask(size, args.region, args.shape, cx, cy)
    offset = (size // 3, size // 5)  # first clone
    moved = (size // 3 + 37, size // 5 - 23)  # the drag: a new offset, same shape
    coords = CloneCoordinates.from_region(mask, mask.shape)
    print(
        f"region: {args.shape} {args.region} px, {mask.sum()} pixels, {len(coords.boundary)} "
        f"boundary pixels, {coords.mesh_vertices} mesh vertices "
        f"({coords.mesh_vertices / mask.sum():.1%} of the pixels)"
    )

    # the baseline: 3-channel 8-bit Poisson cloning of the same region, same place
    u8 = np.clip(full[..., :3] * 255, 0, 255).astype(np.uint8)
    mask_u8 = mask.astype(np.uint8) * 255
    x0, y0, w, h = cv2.boundingRect(mask_u8)
    center = (x0 + w // 2 + offset[0], y0 + h // 2 + offset[1])

    def baseline() -> None:
        cv2.seamlessClone(u8, u8, mask_u8, center, cv2.NORMAL_CLONE)

    build, base = best_times(
        [lambda: CloneCoordinates.from_region(mask, mask.shape), baseline], args.repeat
    )
    line("build coordinates (any channels)", build, base)
    for channels in (int(c) for c in args.channels.split(",")):
        reps = -(-channels // full.shape[2])
        edit = np.ascontiguousarray(np.tile(full, (1, 1, reps))[..., :channels])
        n = f"{channels} ch"
        buffer = np.empty_like(edit)
        first, again, into, copy, base = best_times(
            [
                lambda e=edit: seamless_clone(e, e, region=mask, offset=offset),
                lambda e=edit: coords.clone(e, e, moved),
                lambda e=edit, b=buffer: coords.clone(e, e, moved, out=b),
                lambda e=edit: e.copy(),
                baseline,
            ],
            args.repeat,
        )
        line(f"first clone, {n}", first, base)
        if channels == 10:
            ratios = paired_ratios(
                lambda e=edit, b=buffer: seamless_clone(e, e, region=mask, offset=offset, out=b),
                baseline,
                args.repeat,
            )
            goal("first clone into the caller's buffer, 10 ch / cv2.seamlessClone", ratios, 1.0)
        line(f"re-clone at a new offset, {n}", again, base)
        line(f"re-clone into a reused buffer (out=), {n}", into, base)
        print(f"{'':44s} (a plain copy of the {n} material: {copy * 1e3:.1f} ms)")
        del edit, buffer

    # accuracy of the acceleration on the real data (first 3 channels)
    edit = full[..., :3]
    diffs = coords.boundary_differences(edit, edit, offset)
    membrane = coords.membrane(diffs)
    pick = np.random.default_rng(0).choice(len(coords.interior), 4000, replace=False)
    exact = brute_force(coords.boundary, diffs.astype(np.float64), coords.interior[pick])
    error = np.abs(membrane[pick] - exact).max(axis=0) / np.ptp(diffs, axis=0)
    print(
        "membrane vs brute-force MVC at 4000 pixels, max error / boundary range per channel: "
        + ", ".join(f"{e:.2e}" for e in error)
    )


if __name__ == "__main__":
    main()
