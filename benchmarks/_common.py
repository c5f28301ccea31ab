"""What every benchmark script shares: timing, and the real edit channels to time on."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

CHESSBOARD = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"


def best_time(fn: Callable[[], object], repeat: int) -> float:
    """Fastest of ``repeat`` runs after one warm-up (numba compilation, page faults)."""
    fn()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def edit_channels(size: int) -> tuple[np.ndarray, str]:
    """(size, size, 10) float32 edit values of a real set when available."""
    if CHESSBOARD.is_dir():
        from matshop.io.material_io import load_material

        material, _ = load_material(CHESSBOARD)
        edit = material.to_edit().data
        what = f"chessboard edit channels ({', '.join(material.schema.names)})"
    else:
        edit = np.random.default_rng(0).random((2048, 2048, 8), dtype=np.float32)
        what = "synthetic (chessboard absent)"
    edit = np.concatenate([edit, edit[..., 3:5]], axis=2)[:size, :size]
    return np.ascontiguousarray(edit), what
