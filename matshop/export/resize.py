"""Resizing a material for export: power-of-two sizes, filtered in editing space.

Engines want power-of-two textures (mip chains, block compression). The
filter is a separable Lanczos-3 widened by the reduction factor (so a
downscale is properly low-passed, not aliased), applied with periodic
wrap-around because texture sets tile. It runs on the material's *edit-space*
channels, which is matshop's point: a linear filter there means the right
thing for every parameter (colors averaged in linear light, roughness in
its lobe coordinate, normals as rotations, sampled distributions as inverse CDFs),
and ``from_edit`` clamps whatever the filter's negative lobes overshoot.

With ``keep_variance`` a reduced texel stands for the micro-normals over its own
area, as a LEAN or Toksvig mip does: its normal, its lobe and the tilt variance
added to the lobe are all area means over that same footprint
(:func:`footprint_shading`), and only the other channels keep Lanczos-3.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse

from ..errors import MatshopError
from ..material import EditMaterial, Material
from ..memory import require_memory
from ..ops.variance import lobe_parameters, lost_slope_covariance, widen_lobes

_LOBES = 3

#: per-axis resampling weights ``(n_in, n_out) -> (n_out, n_in)`` sparse matrix
Weights = Callable[[int, int], scipy.sparse.csr_matrix]


def is_power_of_two(n: int) -> bool:
    return n > 0 and n & (n - 1) == 0


def target_size(size_hw: tuple[int, int], longest: int) -> tuple[int, int]:
    """(height, width) with the longer side ``longest`` (a power of two) and
    the other side the power of two nearest the original aspect ratio."""
    if not is_power_of_two(longest):
        raise MatshopError(f"--size must be a power of two (256, 512, 1024...), got {longest}")
    height, width = size_hw
    ratio = min(height, width) / max(height, width)
    short = 2 ** max(0, round(np.log2(max(longest * ratio, 1.0))))
    return (longest, short) if height >= width else (short, longest)


def resampling_matrix(n_in: int, n_out: int) -> scipy.sparse.csr_matrix:
    """Sparse ``(n_out, n_in)`` Lanczos-3 weights with periodic wrap; rows sum to 1.

    Texel centres are aligned (``x_in = (x_out + 0.5) * n_in / n_out - 0.5``);
    for a reduction the kernel is stretched by the factor, which is what
    makes it an anti-aliasing filter.
    """
    scale = n_in / n_out
    stretch = max(scale, 1.0)
    support = _LOBES * stretch
    centres = (np.arange(n_out) + 0.5) * scale - 0.5
    taps = int(np.ceil(2 * support)) + 1
    first = np.floor(centres - support).astype(np.int64) + 1
    index = first[:, None] + np.arange(taps)[None, :]
    x = (index - centres[:, None]) / stretch
    weights = np.sinc(x) * np.sinc(x / _LOBES) * (np.abs(x) < _LOBES)
    weights /= weights.sum(axis=1, keepdims=True)
    rows = np.repeat(np.arange(n_out), taps)
    # duplicate (row, col) pairs from wrapping are summed by the constructor
    return scipy.sparse.csr_matrix(
        (weights.ravel(), (rows, (index % n_in).ravel())), shape=(n_out, n_in)
    )


def area_matrix(n_in: int, n_out: int) -> scipy.sparse.csr_matrix:
    """Sparse ``(n_out, n_in)`` area weights: output texel ``j`` is the mean of the input
    over its own extent ``[j, j + 1) * n_in / n_out`` (texels weighted by their overlap).

    Non-negative, rows sum to 1, centres aligned as in :func:`resampling_matrix`.
    """
    scale = n_in / n_out
    start = np.arange(n_out) * scale
    first = np.floor(start).astype(np.int64)
    taps = int(np.ceil(scale)) + 1
    index = first[:, None] + np.arange(taps)[None, :]
    overlap = np.minimum(index + 1, start[:, None] + scale) - np.maximum(index, start[:, None])
    weights = np.clip(overlap, 0.0, None) / scale
    keep = (weights > 0) & (index < n_in)
    rows = np.broadcast_to(np.arange(n_out)[:, None], index.shape)
    return scipy.sparse.csr_matrix((weights[keep], (rows[keep], index[keep])), shape=(n_out, n_in))


def resize_array(
    array: np.ndarray, size_hw: tuple[int, int], *, weights: Weights | None = None
) -> np.ndarray:
    """Resample ``(H, W, C)`` float data to ``size_hw``: separable ``weights`` per axis
    (:func:`resampling_matrix`, periodic Lanczos-3, when None)."""
    weights = weights or resampling_matrix
    height, width, channels = array.shape
    new_h, new_w = size_hw
    data = np.asarray(array, dtype=np.float32)
    if new_h != height:
        rows = weights(height, new_h)
        data = (rows @ data.reshape(height, -1)).reshape(new_h, width, channels)
    if new_w != width:
        cols = weights(width, new_w)
        moved = np.ascontiguousarray(data.transpose(1, 0, 2)).reshape(width, -1)
        data = (cols @ moved).reshape(new_w, new_h, channels).transpose(1, 0, 2)
    return np.ascontiguousarray(data, dtype=np.float32)


def footprint_shading(edit: EditMaterial, data: np.ndarray, size_hw: tuple[int, int]) -> np.ndarray:
    """``data`` (``edit`` resampled to ``size_hw``) with the normal and every lobe
    parameter replaced by their area means over each small texel (:func:`area_matrix`);
    ``edit`` has a normal.

    The micro-normals of a small texel's area form one distribution: its mean normal,
    its lobe and the spread :func:`resize_material` adds must describe the same set of
    texels. Lanczos-3 reaches 3 small texels on each side with negative lobes, so next
    to a groove it rings: tilts and widths that no texel of the footprint has
    (docs/variance.md measures what each share buys).
    """
    out = data.copy()
    for name in ("normal", *lobe_parameters(edit.schema)):
        block = np.ascontiguousarray(edit.data[..., edit.schema.edit_slices[name]])
        out[..., edit.schema.edit_slices[name]] = resize_array(block, size_hw, weights=area_matrix)
    return out


def resize_material(
    material: Material, size_hw: tuple[int, int], *, keep_variance: bool = False
) -> Material:
    """``material`` resampled to ``size_hw``, filtered in editing space.

    ``keep_variance``: each small texel keeps the look of its own area from afar: the
    normal and the lobe are averaged over that area (:func:`footprint_shading`) and the
    lobe is widened by the slopes' covariance over it (:mod:`matshop.ops.variance`).
    Only reductions lose variance; without the option (or without a normal map) every
    channel is Lanczos-3.
    """
    if tuple(size_hw) == tuple(material.size):
        return material
    (out_h, out_w), (_, in_w) = size_hw, material.size
    channels = material.schema.edit_width
    # float64 passes (rows, then columns) and the float32 maps either side
    need = 8 * channels * (2 * out_h * out_w + out_h * in_w) + 8 * channels * out_h * out_w
    if keep_variance:  # float64 slopes and float32 moments at the input size, a few passes
        need += 64 * material.size[0] * in_w
    require_memory(need, f"resampling to {out_w}x{out_h}")
    edit = material.to_edit()
    data = resize_array(edit.data, size_hw)
    reduced = size_hw[0] < material.size[0] or size_hw[1] < material.size[1]
    if keep_variance and reduced and "normal" in material.maps:
        data = footprint_shading(edit, data, size_hw)
        # the lost tilt is the slopes' spread over the same areas: a variance also needs
        # non-negative weights (Lanczos' negative lobes are not a mixture)
        cov = lost_slope_covariance(
            material.maps["normal"][..., :3],
            lambda a: resize_array(a, size_hw, weights=area_matrix),
        )
        frame = edit.schema["normal"].space.from_edit(
            np.ascontiguousarray(data[..., edit.schema.edit_slices["normal"]])
        )
        tangent = frame[..., 3:6] if frame.shape[-1] >= 6 else None
        data = widen_lobes(data, edit.schema, cov, tangent=tangent, op="export --keep-variance")
    smaller = EditMaterial(edit.name, edit.schema, data, edit.sources)
    resized = smaller.to_physical()
    resized.sources = {k: dict(v) for k, v in material.sources.items()}
    return resized
