"""What every benchmark script shares: timing, the real sets to time on, goal rows.

Goal rows: a script measures a ratio to a baseline it runs in the same
process, several times, and calls :func:`goal`; that prints one line starting
with ``GOAL`` (median, spread, limit, verdict) that ``benchmarks/table.py``
(``make bench``) collects from every script into one table.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

CHESSBOARD = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"
#: the goal-line marker ``table.py`` parses (tab-separated fields follow)
GOAL = "GOAL"


def best_time(fn: Callable[[], object], repeat: int) -> float:
    """Fastest of ``repeat`` runs after one warm-up (numba compilation, page faults)."""
    fn()
    return _fastest(fn, repeat)


def _fastest(fn: Callable[[], object], runs: int) -> float:
    """Seconds of the fastest of ``runs`` calls of ``fn``."""
    best = float("inf")
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def paired_ratios(
    ours: Callable[[], object], base: Callable[[], object], repeat: int, inner: int = 1
) -> list[float]:
    """``repeat`` ratios ours/base, each from back-to-back runs (best of ``inner`` each).

    Pairing keeps a load change on the shared machine from landing on one
    side only; the spread of the ratios says how much the load moved them.
    """
    return interleaved_ratios([(ours, base)], repeat, inner)[0]


def interleaved_ratios(
    pairs: Sequence[tuple[Callable[[], object], Callable[[], object]]],
    rounds: int,
    inner: int = 1,
) -> list[list[float]]:
    """Per (ours, base) pair, ``rounds`` ratios ours/base: each round times every pair
    once, base first (best of ``inner`` runs each).

    :func:`paired_ratios` takes one goal's ratios back to back, a window of a few
    tenths of a second for a fast op, which one slow stretch of a shared machine
    can cover whole (a 2K levels' seven pairs took 0.1 s). Taken in rounds, every
    goal's ratios come from the whole run, so a slow stretch moves a few ratios
    of each goal rather than all of one.
    """
    for ours, base in pairs:
        ours()
        base()
    ratios: list[list[float]] = [[] for _ in pairs]
    for _ in range(rounds):
        for (ours, base), found in zip(pairs, ratios, strict=True):
            base_time = _fastest(base, inner)
            found.append(_fastest(ours, inner) / base_time)
    return ratios


def goal(name: str, ratios: list[float], limit: float, strict: bool = False) -> bool:
    """Print the goal row for ``ratios`` (median against ``limit``); True when met.

    ``strict``: the goal is ``< limit`` rather than ``<= limit``.
    """
    median = statistics.median(ratios)
    met = median < limit if strict else median <= limit
    print(
        f"{GOAL}\t{name}\t{median:.3f}\t{min(ratios):.3f}\t{max(ratios):.3f}"
        f"\t{'<' if strict else '<='} {limit:g}\t{'met' if met else 'NOT met'}",
        flush=True,
    )
    return met


def chessboard_material():
    """The shared 2K chessboard set as loaded (base color, metallic, roughness, normal)."""
    from matshop.io.material_io import load_material

    material, _ = load_material(CHESSBOARD)
    return material


def real_set(size: int | None = None):
    """A 10-channel PBR set made from the chessboard's own maps by the engine's conversions.

    Parameters: base_color (sRGB, 3), metallic (1), roughness (GGX, 1), normal
    (frame, 3) as loaded, plus anisotropic_exponents (Ashikhmin-Shirley, 2)
    derived from them: each texel's GGX median lobe angle ``theta`` (the ggx
    space's edit value of its roughness) becomes ``theta * (0.5 + L)`` along u
    and ``theta * (1.5 - L)`` along v, ``L`` the base colour's Rec. 709 luma of
    its sRGB codes (light squares brushed one way, dark ones the other), and
    the ashikhmin_shirley space (the same median-angle coordinate) converts
    those angles to exponents (nu, nv). Every channel is real texture content
    and none a linear copy of another. ``size`` crops (top-left).
    Returns ``(Material, description)``; a synthetic set when the chessboard is absent.
    """
    from matshop.material import Material, Parameter, Schema
    from matshop.spaces import get_space

    if CHESSBOARD.is_dir():
        base = chessboard_material()
        maps = {k: v[:size, :size] for k, v in base.maps.items()}
        what = "chessboard"
    else:
        rng = np.random.default_rng(0)
        n = size or 2048
        normal = rng.normal(size=(n, n, 3)).astype(np.float32) * [0.2, 0.2, 1] + [0, 0, 1]
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        maps = {
            "base_color": rng.random((n, n, 3), dtype=np.float32),
            "metallic": rng.random((n, n, 1), dtype=np.float32),
            "roughness": rng.random((n, n, 1), dtype=np.float32),
            "normal": normal.astype(np.float32),
        }
        what = "synthetic (chessboard absent)"
    theta = get_space("ggx").to_edit(maps["roughness"])
    luma = maps["base_color"] @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
    luma = luma[..., None]
    angles = np.concatenate([theta * (0.5 + luma), theta * (1.5 - luma)], axis=-1)
    anisotropic = get_space("ashikhmin_shirley")
    maps["anisotropic_exponents"] = anisotropic.from_edit(angles.astype(np.float32))
    names = ["base_color", "metallic", "roughness", "normal"]
    params = [Parameter(n, Schema.from_names([n]).parameters[0].space) for n in names]
    params.append(Parameter("anisotropic_exponents", anisotropic))
    material = Material("chessboard_10ch", Schema(params), maps)
    height, width = material.size
    return material, (
        f"{what} {width}x{height} as a 10-channel set "
        f"({', '.join(material.schema.names)}; anisotropic exponents from roughness and luma)"
    )


def edit_channels(size: int) -> tuple[np.ndarray, str]:
    """(size, size, 10) float32 edit values of the real 10-channel set (:func:`real_set`)."""
    material, what = real_set(size)
    return np.ascontiguousarray(material.to_edit().data), what
