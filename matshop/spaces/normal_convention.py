"""Guessing a normal map's green-channel convention (OpenGL +Y or DirectX -Y) from its pixels.

A normal map baked from a surface is the gradient of a height field, so it is
curl-free: reading ``p = dh/du``, ``q = dh/dv`` from the map, the mixed
derivative computed two ways agrees, ``a = dq/du`` equals ``b = dp/dv``.
Reading the green channel with the wrong sign negates ``q``, so then
``a = -b``. The guess measures, around every 2x2 texel loop, how ``a`` and
``b`` agree in sign, and asks whether the map agrees consistently.

What it measures, and why each choice (the numbers are from the calibration
corpus, ``benchmarks/normal_convention.py``; notes in H-convention.md):

* Per loop, the bounded evidence ``e = 2ab / (a^2 + b^2 + sigma^2)`` in
  [-1, 1]: ``+1`` for ``a = b`` (OpenGL), ``-1`` for ``a = -b`` (DirectX),
  about 0 where one of them is large and the other not (a UV island seam, a
  height discontinuity, edge padding) or both are at the noise floor
  ``sigma`` (8-bit steps, JPEG noise). A seam therefore cannot outvote the
  interior, which a sum of squared curls lets it do.
* Per tile of ``_TILE x _TILE`` loops the evidence is summed, and a level's
  statistic is the self-normalised sum ``t = sum S / sqrt(sum S^2 + n c^2)``
  over its ``n`` tiles. For tiles whose evidence is symmetric about zero (a
  map that cannot tell) ``t`` has sub-Gaussian tails whatever the tiles'
  magnitudes (Hoeffding), so it measures *consistency* across the map, not
  the strength of a few tiles; the floor ``c`` (:data:`_TILE_FLOOR`) keeps
  tiles with next to no evidence from counting as consistent.
* Levels: the full resolution and one 2x2 box-averaged level (the average
  of gradients is the gradient of the averaged height, so the right
  hypothesis stays curl-free while noise averages out), combined as
  ``(t0 + t1) / sqrt(2)``. Fine detail holds most of the evidence; on real
  baked atlases (MaterialX's chess set) the coarser levels are dominated by
  island seams and edge padding and often point the wrong way.
* Heights of the form ``f(u) + g(v)`` (axis-aligned grooves: bricks, tiles,
  planks without surface detail) have no mixed derivative: both readings are
  curl-free (the flipped map is the gradient of ``f(u) - g(v)``), nothing in
  the pixels can tell, and ``t`` stays near zero. That is the physics, not a
  weakness of the statistic: a low confidence is the right answer there.

``confidence = t^2 / (t^2 + T^2)`` maps ``|t|`` to [0, 1) with ``T`` =
:data:`_T_SCALE`; :data:`CONFIDENT_GUESS` is the confidence above which the
corpus holds no wrong guess (see its comment).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit, prange

Convention = Literal["opengl", "directx"]

#: loops per tile side; a tile's evidence is one term of the self-normalised sum
_TILE = 16
#: noise floor of the per-loop evidence, in slope units (about 2 steps of an 8-bit map)
_SIGMA = 0.016
#: evidence floor of a tile, in loops of full agreement: tiles below it count as
#: noise however consistent their sign (the second-order traces of supersampled
#: bakes of f(u) + g(v) grooves, which 16-bit files keep, reached |t| = 8 without it)
_TILE_FLOOR = 4.0
#: levels of the box pyramid (full resolution first); a level needs 2 x 2 tiles
_LEVELS = 2
#: n_z clamp for grazing texels (slopes stay below ~20)
_MIN_NZ = 0.05
#: |t| at which the confidence is 1/2
_T_SCALE = 8.0

#: Use a guess only at or above this confidence, else read OpenGL and say so.
#: On the calibration corpus (1474 maps, 256-4096 texels, PNG 8/16 and JPEG
#: q50-95; benchmarks/normal_convention.py) no guess at or above it is wrong,
#: the most confident wrong one is at 0.217 (|t| = 4.2, pure grooves), and
#: 85% of the maps (none of the pure grooves) reach it.
CONFIDENT_GUESS = 0.5

_JIT = {
    "parallel": True,
    "cache": True,
    "error_model": "numpy",
    "fastmath": {"contract"},
    "nogil": True,
}


@njit(**_JIT)
def _slopes(rgb: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """``(p, q) = (dh/du, dh/dv)`` read in the OpenGL convention, float32 planes.

    ``n = 2 rgb scale - 1`` and ``p = -n_x / n_z``, which needs no
    normalisation; ``n_z`` is clamped to :data:`_MIN_NZ` (|n| is about 1 in a
    normal map), so grazing or broken texels give a slope of at most ~20.
    """
    rows, cols = rgb.shape[0], rgb.shape[1]
    p = np.empty((rows, cols), np.float32)
    q = np.empty((rows, cols), np.float32)
    two = np.float32(2.0 * scale)
    one = np.float32(1.0)
    for i in prange(rows):
        for j in range(cols):
            minus_inv_z = -one / max(two * rgb[i, j, 2] - one, np.float32(_MIN_NZ))
            p[i, j] = (two * rgb[i, j, 0] - one) * minus_inv_z
            q[i, j] = (two * rgb[i, j, 1] - one) * minus_inv_z
    return p, q


@njit(**_JIT)
def _tile_evidence(p: np.ndarray, q: np.ndarray, tile: int, sigma2: float) -> np.ndarray:
    """Per tile, the sum over its 2x2 loops of ``2ab / (a^2 + b^2 + sigma^2)``.

    The loop through texel centres ``(i, j) (i, j+1) (i+1, j+1) (i+1, j)``
    (rows go down, ``v`` up) splits into ``a`` (``dq/du``) and ``b``
    (``dp/dv``), each by the trapezoid rule.
    """
    n_ty = (p.shape[0] - 1) // tile
    n_tx = (p.shape[1] - 1) // tile
    out = np.zeros((n_ty, n_tx), np.float64)
    for ty in prange(n_ty):
        for tx in range(n_tx):
            total = 0.0
            for i in range(ty * tile, ty * tile + tile):
                for j in range(tx * tile, tx * tile + tile):
                    a = 0.5 * ((q[i, j + 1] + q[i + 1, j + 1]) - (q[i, j] + q[i + 1, j]))
                    b = 0.5 * ((p[i, j] + p[i, j + 1]) - (p[i + 1, j] + p[i + 1, j + 1]))
                    total += 2.0 * a * b / (a * a + b * b + sigma2)
            out[ty, tx] = total
    return out


@njit(**_JIT)
def _box_down(x: np.ndarray) -> np.ndarray:
    rows, cols = x.shape[0] // 2, x.shape[1] // 2
    out = np.empty((rows, cols), np.float32)
    for i in prange(rows):
        for j in range(cols):
            top = x[2 * i, 2 * j] + x[2 * i, 2 * j + 1]
            out[i, j] = 0.25 * (top + x[2 * i + 1, 2 * j] + x[2 * i + 1, 2 * j + 1])
    return out


def guess_normal_convention(rgb: np.ndarray) -> tuple[Convention, float]:
    """Guess whether a tangent-space normal map is OpenGL (+Y) or DirectX (-Y).

    ``rgb`` is one image ``(H, W, 3)``, float in [0, 1] or integer codes.
    Returns the convention whose reading is consistently curl-free and a
    confidence in [0, 1) (module docstring). Contract for a loader: act on the
    guess only when ``confidence >= CONFIDENT_GUESS``; below it the pixels do
    not tell (flat maps, ``f(u) + g(v)`` grooves, little detail), so read
    OpenGL and say so. Ties, flat and tiny maps give ``("opengl", 0.0)``.
    """
    arr = np.asarray(rgb)
    if arr.ndim != 3 or arr.shape[-1] != 3:
        raise ValueError(f"guess_normal_convention: expected an (H, W, 3) image, got {arr.shape}")
    if arr.shape[0] < 2 or arr.shape[1] < 2:
        return "opengl", 0.0  # no 2x2 loop, no evidence: a tie (a 1x1 set loads)
    if np.issubdtype(arr.dtype, np.integer):
        scale = 1.0 / np.iinfo(arr.dtype).max
    else:
        arr, scale = arr.astype(np.float32, copy=False), 1.0
    p, q = _slopes(arr, scale)
    tile = max(1, min(_TILE, (min(p.shape) - 1) // 2))
    t_levels = []
    for _ in range(_LEVELS):
        if (min(p.shape) - 1) // tile < 2:
            break
        evidence = _tile_evidence(p, q, tile, _SIGMA * _SIGMA)
        norm = math.sqrt(float(np.sum(evidence * evidence)) + evidence.size * _TILE_FLOOR**2)
        t_levels.append(float(np.sum(evidence)) / norm)
        p, q = _box_down(p), _box_down(q)
    t = sum(t_levels) / math.sqrt(len(t_levels)) if t_levels else 0.0
    return ("opengl" if t >= 0.0 else "directx"), t * t / (t * t + _T_SCALE * _T_SCALE)
