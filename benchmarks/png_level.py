"""PNG writing: time and size per zlib level and row filter, as ratios to OpenCV's writer.

Writing PNGs dominated ``matshop apply`` on a 2K set. This prints, for the
real chessboard maps as read and blurred (sigma 4, what ``matshop apply --op
blur`` writes) -- 8-bit colour, 8-bit grey, the normal map as 8 and 16 bits --
the best single-thread CPU time (``time.process_time``; wall time in brackets)
of ``matshop.io.images.write_image`` at each level and row filter, as a ratio
to ``cv2.imwrite`` at the same level (measured in the same run), and the size
of all files relative to cv2's at that level, so :data:`PNG_LEVEL` and
:data:`PNG_FILTER` are chosen by measurement:

    python benchmarks/png_level.py [--repeat N]

Filters are libpng's: ``adaptive`` tries all five per row (libpng's default,
OpenImageIO's when no ``png:filter`` is given), the others use one for every row.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from _common import CHESSBOARD

from matshop.io.images import PNG_FILTERS, read_image, write_image

LEVELS = (1, 2, 3, 4, 6)


def cases() -> list[tuple[str, np.ndarray, str]]:
    if not CHESSBOARD.is_dir():
        raise SystemExit(f"{CHESSBOARD} not present: this benchmark needs real maps")
    color, _ = read_image(CHESSBOARD / "chessboard_base_color.jpg")
    gray, _ = read_image(CHESSBOARD / "chessboard_roughness.jpg")
    normal, _ = read_image(CHESSBOARD / "chessboard_normal.jpg")
    out = []
    for how, change in (("as read", lambda a: a), ("blurred", _blur)):
        out += [
            (f"base color 8-bit RGB, {how}", change(color), "uint8"),
            (f"roughness 8-bit grey, {how}", change(gray[..., :1]), "uint8"),
            (f"normal 8-bit RGB, {how}", change(normal), "uint8"),
            (f"normal 16-bit RGB, {how}", change(normal), "uint16"),
        ]
    return out


def _blur(image: np.ndarray) -> np.ndarray:
    pad = 16
    wide = cv2.copyMakeBorder(image, pad, pad, pad, pad, cv2.BORDER_WRAP)
    out = cv2.GaussianBlur(wide, (0, 0), 4.0)[pad:-pad, pad:-pad]
    return out.reshape(image.shape)


def cpu_time(fn, repeat: int) -> tuple[float, float]:
    """Best (CPU, wall) seconds of ``repeat`` runs after a warm-up."""
    fn()
    cpu = wall = float("inf")
    for _ in range(repeat):
        c, w = time.process_time(), time.perf_counter()
        fn()
        cpu, wall = min(cpu, time.process_time() - c), min(wall, time.perf_counter() - w)
    return cpu, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    maps = cases()
    print("per level: sum over the maps of CPU time (wall) / cv2's, size / cv2's at that level")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "x.png"
        for level in LEVELS:
            base_cpu = base_wall = base_size = 0.0
            cells = {name: [0.0, 0.0, 0] for name in PNG_FILTERS}
            for _, array, depth in maps:
                scale = 255 if depth == "uint8" else 65535
                codes = np.rint(np.clip(array, 0, 1) * scale).astype(depth)
                flags = [cv2.IMWRITE_PNG_COMPRESSION, level]
                cpu, wall = cpu_time(
                    lambda c=codes, f=flags: cv2.imwrite(str(path), c, f), args.repeat
                )
                base_cpu, base_wall = base_cpu + cpu, base_wall + wall
                base_size += path.stat().st_size
                for name in PNG_FILTERS:
                    cpu, wall = cpu_time(
                        lambda a=array, d=depth, f=name, lv=level: write_image(
                            path, a, bit_depth=d, png_level=lv, png_filter=f
                        ),
                        args.repeat,
                    )
                    cells[name][0] += cpu
                    cells[name][1] += wall
                    cells[name][2] += path.stat().st_size
            line = " | ".join(
                f"{name} {c / base_cpu:4.2f}x ({w / base_wall:4.2f}x) {s / base_size:4.2f}"
                for name, (c, w, s) in cells.items()
            )
            print(f"L{level} (cv2 {base_cpu * 1e3:4.0f} ms CPU): {line}", flush=True)


if __name__ == "__main__":
    main()
