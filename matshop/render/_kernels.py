"""numba kernel for the one hot spot numpy cannot do fast: trilinear environment reads.

Filtered importance sampling reads the environment once per (pixel, sample)
at a fractional mip level: eight gathers and their weights per read. In
numpy that is eight fancy-index passes over millions of rows and half of a
thumbnail's time; this kernel does it in one parallel pass with no
temporaries. ``Environment.lookup`` keeps the numpy version as the
specification (``tests/test_render.py`` holds the two together).

Kept in its own module so numba's on-disk cache (``cache=True``) sees every
edit to the code it compiles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

_OPTIONS = {"parallel": True, "cache": True, "error_model": "numpy"}


@njit(inline="always", error_model="numpy")
def _bilinear_add(flat, offset, h, w, u, v, weight, out, k):
    x = u * w - 0.5
    y = min(max(v * h - 0.5, 0.0), h - 1.0)
    fx0 = math.floor(x)
    fy0 = min(math.floor(y), h - 2.0)
    fx = x - fx0
    fy = y - fy0
    x0 = int(fx0) % w
    x1 = (x0 + 1) % w
    y0 = int(fy0)
    r0 = offset + y0 * w
    r1 = r0 + w
    w00 = (1.0 - fx) * (1.0 - fy) * weight
    w01 = fx * (1.0 - fy) * weight
    w10 = (1.0 - fx) * fy * weight
    w11 = fx * fy * weight
    for c in range(3):
        out[k, c] += (
            w00 * flat[r0 + x0, c]
            + w01 * flat[r0 + x1, c]
            + w10 * flat[r1 + x0, c]
            + w11 * flat[r1 + x1, c]
        )


@njit(**_OPTIONS)
def environment_lookup(flat, offsets, heights, widths, x, y, z, lod, out):
    """``out[k] = trilinear radiance along (x, y, z)[k] at mip level lod[k]`` (all 1-D inputs)."""
    top = offsets.size - 1
    two_pi = 2.0 * math.pi
    for k in prange(x.size):
        u = 0.5 + math.atan2(x[k], -z[k]) / two_pi
        v = math.acos(min(max(y[k], -1.0), 1.0)) / math.pi
        level = min(max(lod[k], 0.0), float(top))
        l0 = min(int(level), max(top - 1, 0))
        frac = level - l0 if top > 0 else 0.0
        for c in range(3):
            out[k, c] = 0.0
        _bilinear_add(flat, offsets[l0], heights[l0], widths[l0], u, v, 1.0 - frac, out, k)
        if frac > 0.0:
            l1 = l0 + 1
            _bilinear_add(flat, offsets[l1], heights[l1], widths[l1], u, v, frac, out, k)


def lookup(flat, offsets, heights, widths, x, y, z, lod) -> np.ndarray:
    """Broadcast and flatten the inputs, run :func:`environment_lookup`, restore the shape."""
    x, y, z, lod = np.broadcast_arrays(x, y, z, lod)
    shape = x.shape
    args = [np.ascontiguousarray(a, dtype=np.float64).reshape(-1) for a in (x, y, z, lod)]
    out = np.empty((args[0].size, 3), dtype=np.float32)
    environment_lookup(flat, offsets, heights, widths, *args, out)
    return out.reshape(*shape, 3)
