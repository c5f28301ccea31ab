"""Blend modes in edit space.

A layer contributes edit values ``L`` with per-texel weight ``a`` (opacity x
mask x coverage) onto the composite ``B`` below it. All arithmetic is float32
in the order written, so every mode is exact at ``a = 0`` (gives ``B``) and
the document's tiled flatten equals a whole-image flatten bit for bit:

=========  ======================================  =======
mode       result                                  linear
=========  ======================================  =======
normal     ``(1 - a) B + a L``  (alpha-over)        yes
add        ``B + a L``                              yes
subtract   ``B - a L``                              yes
multiply   ``(1 - a) B + a (B L)``                  no
detail     ``B + a (L - mean(L))``                  yes
=========  ======================================  =======

"Linear" means the result is linear in the edit values of ``B`` and ``L``
together (for fixed ``a``): the principled modes of editing spaces, flagged
so the UI can say so. ``mean(L)`` is the layer's coverage-weighted mean over
the whole document (:func:`weighted_mean`), so "detail" adds only the layer's
deviation, e.g. the grain of an imported texture without its overall tone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from ..errors import InvalidValue

_NORMAL, _ADD, _SUBTRACT, _MULTIPLY, _DETAIL = range(5)


@dataclass(frozen=True)
class BlendMode:
    """One blend mode: what the UI shows and what the compositor needs to know."""

    name: str
    label: str
    formula: str
    linear: bool
    #: needs the layer's mean over the document (so a change anywhere in the
    #: layer changes its contribution everywhere it covers)
    uses_mean: bool
    code: int


#: The blend modes by name, in menu order.
BLEND_MODES: dict[str, BlendMode] = {
    mode.name: mode
    for mode in (
        BlendMode("normal", "Normal", "(1 - a) B + a L", True, False, _NORMAL),
        BlendMode("add", "Add", "B + a L", True, False, _ADD),
        BlendMode("subtract", "Subtract", "B - a L", True, False, _SUBTRACT),
        BlendMode("multiply", "Multiply", "(1 - a) B + a B L", False, False, _MULTIPLY),
        BlendMode("detail", "Detail", "B + a (L - mean L)", True, True, _DETAIL),
    )
}


def get_blend_mode(name: str) -> BlendMode:
    """The mode called ``name``, or a clear error listing the known ones."""
    try:
        return BLEND_MODES[name]
    except KeyError:
        raise InvalidValue(
            f"unknown blend mode {name!r} (known: {', '.join(BLEND_MODES)})"
        ) from None


@njit(cache=True, nogil=True, inline="always")
def _blend_row(below, layer, alpha, mean, code, out, row):  # pragma: no cover - compiled
    width, channels = below.shape[1], below.shape[2]
    one = np.float32(1.0)
    for col in range(width):
        a = alpha[row, col]
        keep = one - a
        for c in range(channels):
            b = below[row, col, c]
            v = layer[row, col, c]
            if code == 0:
                out[row, col, c] = keep * b + a * v
            elif code == 1:
                out[row, col, c] = b + a * v
            elif code == 2:
                out[row, col, c] = b - a * v
            elif code == 3:
                out[row, col, c] = keep * b + a * (b * v)
            else:
                out[row, col, c] = b + a * (v - mean[c])


@njit(cache=True, nogil=True)
def _blend_serial(below, layer, alpha, mean, code, out):  # pragma: no cover - compiled
    for row in range(below.shape[0]):
        _blend_row(below, layer, alpha, mean, code, out, row)


@njit(cache=True, parallel=True, nogil=True)
def _blend_parallel(below, layer, alpha, mean, code, out):  # pragma: no cover - compiled
    for row in prange(below.shape[0]):
        _blend_row(below, layer, alpha, mean, code, out, row)


#: Values from which threads pay off. Below it, waking threads costs more
#: than the work, and far more when the cores are busy with other processes
#: (measured ~200 us per 64x64 call on a loaded 2-core machine, ~10 us serial).
_PARALLEL_FROM = 1 << 18


def blend(
    mode: str | BlendMode,
    below: np.ndarray,
    layer: np.ndarray,
    alpha: np.ndarray,
    *,
    mean: np.ndarray | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Blend ``layer`` onto ``below`` with per-texel weight ``alpha``.

    Parameters
    ----------
    mode : str or BlendMode
        One of :data:`BLEND_MODES`.
    below, layer : (H, W, C) float32 ndarray
        Edit values; ``layer`` may be a broadcast view (a constant fill).
    alpha : (H, W) float32 ndarray
        Opacity x mask x coverage, normally in [0, 1].
    mean : (C,) float32 ndarray, optional
        The layer's mean; required by "detail".
    out : (H, W, C) float32 ndarray, optional
        Where to write; may be ``below`` itself (in place).

    Returns
    -------
    (H, W, C) float32 ndarray

    Examples
    --------
    >>> import numpy as np
    >>> b = np.full((1, 1, 1), 0.2, np.float32); v = np.full((1, 1, 1), 0.6, np.float32)
    >>> float(blend("normal", b, v, np.full((1, 1), 0.5, np.float32))[0, 0, 0])
    0.4000000059604645
    """
    spec = mode if isinstance(mode, BlendMode) else get_blend_mode(mode)
    if below.shape != layer.shape or alpha.shape != below.shape[:2]:
        raise ValueError(
            f"blend: below {below.shape}, layer {layer.shape}, alpha {alpha.shape} disagree"
        )
    if spec.uses_mean:
        if mean is None:
            raise ValueError(f"blend mode {spec.name!r} needs the layer's mean")
        mean = np.ascontiguousarray(mean, dtype=np.float32)
    else:
        mean = np.zeros(below.shape[2], dtype=np.float32)
    if out is None:
        out = np.empty(below.shape, dtype=np.float32)
    kernel = _blend_parallel if below.size >= _PARALLEL_FROM else _blend_serial
    kernel(below, layer, alpha.astype(np.float32, copy=False), mean, spec.code, out)
    return out


def weighted_mean(
    values: np.ndarray, weights: np.ndarray | None = None
) -> tuple[np.ndarray, float]:
    """Per-channel sums ``(sum w v, sum w)`` of an ``(H, W, C)`` block, in float64.

    Returned as sums, not a mean, so a layer can add them up tile by tile;
    :func:`mean_of` finishes. Deterministic for a given block.
    """
    values = np.asarray(values, dtype=np.float32)
    if weights is None:
        total = values.sum(axis=(0, 1), dtype=np.float64)
        return total, float(values.shape[0] * values.shape[1])
    weights = np.asarray(weights, dtype=np.float32)
    total = np.einsum("hw,hwc->c", weights.astype(np.float64), values.astype(np.float64))
    return total, float(weights.sum(dtype=np.float64))


def mean_of(total: np.ndarray, weight: float) -> np.ndarray:
    """Finish :func:`weighted_mean`: the mean as float32 (zeros when nothing is covered)."""
    if weight <= 0.0:
        return np.zeros(total.shape, dtype=np.float32)
    return (total / weight).astype(np.float32)
