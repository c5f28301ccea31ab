"""Built-in procedural brush tips: noise, scratches, spots, each made from a seed.

Each is a ``(SIZE, SIZE)`` float32 image in [0, 1] (white paints) made with
NumPy's PCG64 generator and plain array arithmetic only, so a seed gives the
same tip, bit for bit, in the editor, the command line and every replay.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.ndimage import gaussian_filter

SIZE = 128


def _grid() -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre coordinates in [-1, 1] (x across, y down)."""
    t = (np.arange(SIZE, dtype=np.float64) + 0.5) / SIZE * 2.0 - 1.0
    return t[None, :], t[:, None]


def _round_edge(inner: float = 0.55) -> np.ndarray:
    """A soft disc: 1 inside ``inner`` of the radius, smoothstep to 0 at the tip's edge."""
    x, y = _grid()
    t = np.clip((1.0 - np.hypot(x, y)) / (1.0 - inner), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def noise(seed: int) -> np.ndarray:
    """Cloudy value noise (blurred white noise, stretched to [0, 1]) in a soft disc."""
    rng = np.random.default_rng(seed)
    field = gaussian_filter(rng.random((SIZE, SIZE)), sigma=2.5, mode="wrap")
    field = (field - field.min()) / max(field.max() - field.min(), 1e-12)
    return (np.clip(1.6 * field - 0.3, 0.0, 1.0) * _round_edge()).astype(np.float32)


def _segment_distance(
    x: np.ndarray, y: np.ndarray, a: tuple[float, float], b: tuple[float, float]
) -> np.ndarray:
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    t = np.clip(((x - ax) * dx + (y - ay) * dy) / max(dx * dx + dy * dy, 1e-12), 0.0, 1.0)
    return np.hypot(x - (ax + t * dx), y - (ay + t * dy))


def scratches(seed: int) -> np.ndarray:
    """Thin strokes of varying strength along the tip's x axis (so "follow stroke" drags them
    along the stroke), as wear leaves them."""
    rng = np.random.default_rng(seed)
    x, y = _grid()
    pixel = 2.0 / SIZE
    image = np.zeros((SIZE, SIZE))
    for _ in range(18):
        angle = rng.normal(0.0, 0.2)
        length = rng.uniform(0.4, 1.4)
        cx, cy = rng.uniform(-0.6, 0.6, 2)
        half = 0.5 * length * np.array([np.cos(angle), np.sin(angle)])
        width = rng.uniform(0.6, 2.2) * pixel
        strength = rng.uniform(0.45, 1.0)
        distance = _segment_distance(
            x, y, (cx - half[0], cy - half[1]), (cx + half[0], cy + half[1])
        )
        # anti-aliased line: full within half the width, one pixel of falloff
        line = np.clip((width / 2 + pixel / 2 - distance) / pixel, 0.0, 1.0) * strength
        image = np.maximum(image, line)
    return (image * _round_edge(0.7)).astype(np.float32)


def spots(seed: int) -> np.ndarray:
    """Soft round spots of many sizes (drips, dirt, speckle)."""
    rng = np.random.default_rng(seed)
    x, y = _grid()
    image = np.zeros((SIZE, SIZE))
    for _ in range(26):
        radius = rng.uniform(0.03, 0.2)
        r = np.sqrt(rng.uniform(0.0, 1.0)) * (0.85 - radius)  # inside the tip's circle
        phi = rng.uniform(0.0, 2.0 * np.pi)
        cx, cy = r * np.cos(phi), r * np.sin(phi)
        t = np.clip((radius - np.hypot(x - cx, y - cy)) / (0.5 * radius), 0.0, 1.0)
        image = np.maximum(image, t * t * (3.0 - 2.0 * t) * rng.uniform(0.5, 1.0))
    return image.astype(np.float32)


SHAPES: dict[str, Callable[[int], np.ndarray]] = {
    "noise": noise,
    "scratches": scratches,
    "spots": spots,
}
