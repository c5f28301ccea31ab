"""Op speed as ratios to the baseline a user has today, measured in one run.

    python benchmarks/ops.py [--repeat N] [--size 2048]

Data: the edit channels of the real 10-channel set of ``_common.real_set``
(the shared chessboard plus anisotropic exponents derived from it) at 2K,
and its first 3 channels; curves here treat every channel alone
(``benchmarks/curves.py`` has the goals, with the schema). Baselines:
``cv2.GaussianBlur`` on the same channels for blur; ``np.copyto`` of the same
bytes (the bandwidth limit) for scale, curves and compositing.
Bilateral and cloning have their own scripts: ``benchmarks/bilateral.py``
and ``benchmarks/clone.py``.
"""

from __future__ import annotations

import argparse

import cv2
import numpy as np
from _common import best_time, edit_channels

from matshop.ops.blur import gaussian_blur
from matshop.ops.composite import composite
from matshop.ops.curves import curves
from matshop.ops.scale import scale


def line(label: str, ours: float, base: float, base_name: str) -> None:
    print(
        f"{label:40s} ours {ours * 1e3:8.1f} ms  {base_name} {base * 1e3:8.1f} ms"
        f"  ratio {ours / base:5.2f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--size", type=int, default=2048)
    args = parser.parse_args()
    full, what = edit_channels(args.size)
    print(f"data: {what}, {full.shape[1]}x{full.shape[0]}")
    rng = np.random.default_rng(1)
    for channels in (full.shape[2], 3):
        edit = np.ascontiguousarray(full[..., :channels])
        other = np.ascontiguousarray(edit[::-1])
        mask = rng.random(edit.shape[:2], dtype=np.float32)
        dst = np.empty_like(edit)
        copy = best_time(lambda e=edit, d=dst: np.copyto(d, e), args.repeat)
        n = f"{channels} ch"
        for sigma in (2.0, 8.0):
            ours = best_time(lambda e=edit, s=sigma: gaussian_blur(e, sigma_px=s), args.repeat)
            base = best_time(lambda e=edit, s=sigma: cv2.GaussianBlur(e, (0, 0), s), args.repeat)
            line(f"blur sigma {sigma:g}, {n} (wrap)", ours, base, "cv2.GaussianBlur")
        line(
            f"scale, {n}", best_time(lambda e=edit: scale(e, factor=0.7), args.repeat), copy, "copy"
        )
        line(
            f"scale with mask, {n}",
            best_time(lambda e=edit, m=mask: scale(e, factor=0.7, mask=m), args.repeat),
            copy,
            "copy",
        )
        points = [(0, 0), (0.3, 0.5), (1, 1)]
        line(
            f"curves, {n}",
            best_time(lambda e=edit, p=points: curves(e, points=p), args.repeat),
            copy,
            "copy",
        )
        # the default remap=data reads each channel's percentiles first; remap=space not
        line(
            f"curves remap=space, {n}",
            best_time(lambda e=edit, p=points: curves(e, points=p, remap="space"), args.repeat),
            copy,
            "copy",
        )
        line(
            f"composite with mask, {n}",
            best_time(lambda e=edit, o=other, m=mask: composite(e, o, mask=m), args.repeat),
            copy,
            "copy",
        )


if __name__ == "__main__":
    main()
