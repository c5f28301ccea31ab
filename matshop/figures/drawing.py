"""Tiny raster plotting and labelling for the figures (OpenCV drawing, no plotting library).

Everything works on ``(H, W, 3)`` uint8 RGB images.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

FONT = cv2.FONT_HERSHEY_SIMPLEX
WHITE = (255, 255, 255)
BLACK = (0, 0, 0)
PALETTE = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
]


def text(
    image: np.ndarray, s: str, xy: tuple[int, int], *, scale: float = 0.4, color=BLACK
) -> None:
    """Draw ``s`` with its baseline starting at ``xy`` (in place)."""
    cv2.putText(image, s, xy, FONT, scale, color, 1, cv2.LINE_AA)


def caption(
    image: np.ndarray, lines: Sequence[str], *, height: int = 16, scale: float = 0.4
) -> np.ndarray:
    """``image`` with a white band of text lines above it."""
    band = np.full((height * len(lines) + 4, image.shape[1], 3), 255, np.uint8)
    for k, line in enumerate(lines):
        text(band, line, (4, height * (k + 1) - 3), scale=scale)
    return np.concatenate([band, image], axis=0)


def side_label(
    image: np.ndarray, lines: Sequence[str], *, width: int = 170, scale: float = 0.4
) -> np.ndarray:
    """``image`` with a white column of text lines on its left."""
    band = np.full((image.shape[0], width, 3), 255, np.uint8)
    top = max(14, (image.shape[0] - 15 * len(lines)) // 2 + 11)
    for k, line in enumerate(lines):
        text(band, line, (4, top + 15 * k), scale=scale)
    return np.concatenate([band, image], axis=1)


def grid(tiles: Sequence[Sequence[np.ndarray]], *, gap: int = 2) -> np.ndarray:
    """Rows of equally tall tiles, separated by white gaps."""
    rows = []
    for row in tiles:
        parts = []
        for k, tile in enumerate(row):
            if k:
                parts.append(np.full((tile.shape[0], gap, 3), 255, np.uint8))
            parts.append(tile)
        rows.append(np.concatenate(parts, axis=1))
    width = max(r.shape[1] for r in rows)
    out = []
    for k, r in enumerate(rows):
        if k:
            out.append(np.full((gap, width, 3), 255, np.uint8))
        pad = np.full((r.shape[0], width - r.shape[1], 3), 255, np.uint8)
        out.append(np.concatenate([r, pad], axis=1))
    return np.concatenate(out, axis=0)


def line_plot(
    series: Sequence[tuple[np.ndarray, np.ndarray, str]],
    *,
    size: tuple[int, int] = (320, 240),
    xlim: tuple[float, float] | None = None,
    ylim: tuple[float, float] | None = None,
    title: str = "",
    xlabel: str = "",
    dashed: Sequence[bool] | None = None,
) -> np.ndarray:
    """A line chart of ``(x, y, label)`` series with axes, ticks and a legend."""
    w, h = size
    img = np.full((h, w, 3), 255, np.uint8)
    left, right, top, bottom = 44, 8, 22, 30
    xs = np.concatenate([np.asarray(s[0], float) for s in series])
    ys = np.concatenate([np.asarray(s[1], float) for s in series])
    x0, x1 = xlim or (float(xs.min()), float(xs.max()))
    y0, y1 = ylim or (float(ys.min()), float(ys.max()))
    if y1 <= y0:
        y1 = y0 + 1.0

    def px(x, y):
        u = left + (np.asarray(x) - x0) / (x1 - x0) * (w - left - right)
        v = h - bottom - (np.asarray(y) - y0) / (y1 - y0) * (h - top - bottom)
        return u, v

    cv2.rectangle(img, (left, top), (w - right, h - bottom), (90, 90, 90), 1)
    for k in range(5):
        fx, fy = x0 + (x1 - x0) * k / 4, y0 + (y1 - y0) * k / 4
        u, _ = px(fx, y0)
        _, v = px(x0, fy)
        text(img, f"{fx:.3g}", (int(u) - 10, h - bottom + 12), scale=0.32)
        text(img, f"{fy:.3g}", (2, int(v) + 4), scale=0.32)
    if title:
        text(img, title, (left, 14), scale=0.4)
    if xlabel:
        text(img, xlabel, (w // 2 - 4 * len(xlabel) // 2, h - 4), scale=0.35)
    colour_index = -1
    for k, (x, y, label) in enumerate(series):
        # a dashed series is the companion of the solid one before it: same colour
        if dashed is None or not dashed[k]:
            colour_index += 1
        color = PALETTE[max(colour_index, 0) % len(PALETTE)]
        u, v = px(x, y)
        pts = np.stack([u, v], axis=1).round().astype(np.int32)
        if dashed is not None and dashed[k]:
            for a in range(0, len(pts) - 1, 2):
                cv2.line(img, tuple(pts[a]), tuple(pts[a + 1]), color, 1, cv2.LINE_AA)
        else:
            cv2.polylines(img, [pts], False, color, 1, cv2.LINE_AA)
        if label:
            text(
                img, label, (w - right - 118, top + 12 + 12 * colour_index), scale=0.32, color=color
            )
    return img
