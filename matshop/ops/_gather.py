"""The texels a tone range is measured on, gathered channel by channel.

:mod:`.tone_range` reads a fixed random draw of texels (sorted flat indices)
and then sorts each channel's values. numpy's ``np.take`` gives the texels
interleaved, ``(n, k)``, so every channel's sort and the magnitudes of a
frame then ran over strided columns (a third of the ranges' time on 10
channels); this gather writes each channel as its own contiguous plane, on all
threads (each drawn texel is a cache miss: the threads wait on memory side by
side). A vector's magnitudes are then one pass over its planes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

#: samples per parallel chunk: gathered whole into a small buffer, then written
#: out plane by plane from cache (writing the planes directly, k scattered store
#: streams, measured 1.6x slower at 10 channels)
_CHUNK = 1024


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def gather_planes(texels, index, planes):
    """``planes[c, i] = texels[index[i], c]`` for ``texels`` (N, k) of any strides."""
    count = index.shape[0]
    channels = texels.shape[1]
    for chunk in prange((count + _CHUNK - 1) // _CHUNK):
        start = chunk * _CHUNK
        stop = min(count, start + _CHUNK)
        buffer = np.empty((_CHUNK, channels), dtype=planes.dtype)
        for i in range(start, stop):
            texel = np.uint64(index[i])  # unsigned: no wraparound fix-up
            for c in range(channels):
                buffer[i - start, c] = texels[texel, c]
        for c in range(channels):
            for i in range(start, stop):
                planes[c, i] = buffer[i - start, c]


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def plane_magnitudes(planes, channels, quadrature, out):
    """``out[i] = sqrt(sum_j q[j] planes[channels[j], i]^2)`` in float64, one pass.

    Summed channel by channel in order, each term ``(v * v) * q``, and without
    fused multiply-adds: the bits of numpy's ``sqrt((v**2 * q).sum(-1))`` over
    ``block[..., channels]`` (whose fancy indexing puts the channels outermost,
    so numpy adds them in order).
    """
    count = out.shape[0]
    for chunk in prange((count + _CHUNK - 1) // _CHUNK):
        start = chunk * _CHUNK
        size = min(count, start + _CHUNK) - start
        # channel by channel over a chunk: each loop runs over contiguous values and
        # vectorises (texel by texel, the indirect channel index kept it scalar)
        total = np.zeros(size)
        terms = np.empty(size)
        for j in range(channels.shape[0]):
            plane = planes[channels[j]]
            weight = quadrature[j]
            for i in range(size):
                v = np.float64(plane[start + i])
                terms[i] = total[i] + (v * v) * weight
            total, terms = terms, total
        for i in range(size):
            out[start + i] = np.sqrt(total[i])
