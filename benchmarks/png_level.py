"""PNG writing: time and size per zlib level, as ratios to OpenCV's PNG writer.

Writing PNGs dominated ``matshop apply`` on a 2K set (1.5 s of 2.1 s at
OpenImageIO's default level 6). This prints, for the real chessboard maps (8-bit
colour, 8-bit grey, and the normal map as 16-bit), the best time of
``matshop.io.images.write_image`` at each level, its ratio to
``cv2.imwrite`` at OpenCV's default (measured in the same run) and the file
size relative to level 6, so the default level is chosen by measurement:

    python benchmarks/png_level.py [--repeat N]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import cv2
import numpy as np
from _common import CHESSBOARD, best_time

from matshop.io.images import read_image, write_image

LEVELS = (1, 2, 3, 4, 6)


def cases() -> list[tuple[str, np.ndarray, str]]:
    if not CHESSBOARD.is_dir():
        raise SystemExit(f"{CHESSBOARD} not present: this benchmark needs real maps")
    color, _ = read_image(CHESSBOARD / "chessboard_base_color.jpg")
    gray, _ = read_image(CHESSBOARD / "chessboard_roughness.jpg")
    normal, _ = read_image(CHESSBOARD / "chessboard_normal.jpg")
    return [
        ("base color 8-bit RGB", color, "uint8"),
        ("roughness 8-bit grey", gray[..., :1], "uint8"),
        ("normal 16-bit RGB", normal, "uint16"),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "x.png"
        for label, array, depth in cases():
            scale = 255 if depth == "uint8" else 65535
            codes = np.rint(array * scale).astype(np.uint8 if depth == "uint8" else np.uint16)
            baseline = best_time(lambda c=codes: cv2.imwrite(str(path), c), args.repeat)
            sizes, times = {}, {}
            for level in LEVELS:
                times[level] = best_time(
                    lambda a=array, d=depth, lv=level: write_image(
                        path, a, bit_depth=d, png_level=lv
                    ),
                    args.repeat,
                )
                sizes[level] = path.stat().st_size
            cells = [
                f"L{lv} {times[lv] / baseline:4.2f}x cv2, {sizes[lv] / sizes[6]:4.2f} size"
                for lv in LEVELS
            ]
            print(f"{label:22s} (cv2 {baseline * 1000:5.0f} ms): " + " | ".join(cells))


if __name__ == "__main__":
    main()
