"""High-dimensional bilateral filter: separable at small spatial sigma, else a lattice.

``output(x) = sum_y w(x, y) image(y) / sum_y w(x, y)`` with
``w = exp(-|p_x - p_y|^2 / (2 sigma_s^2)) * exp(-|g(x) - g(y)|^2 / (2 sigma_r^2))``,
``p`` the pixel position and ``g = image * channel_weights`` the range guide
(optionally reduced to its leading principal components). Every channel is
filtered with the same weights, so the filter treats the edit vector as one
point and stays meaningful in every editing space. Before filtering, the guide
is rotated onto its principal axes (which changes no distance) so that
constant or linearly dependent channels add no dimension.

Two evaluations (``method``; ``"auto"`` picks by ``sigma_s``, see
:data:`SEPARABLE_MAX_SIGMA`):

* ``"separable"`` (:mod:`matshop.ops._separable`, Pham and van Vliet 2005): a
  1-D bilateral along the rows, then along the columns, both weighted by the
  original guide, each cut at ``ceil(3 sigma_s)`` texels like the exact
  reference below. Its cost grows with ``sigma_s`` (the taps) and the channels,
  barely with the guide's dimension. Exact where the guide varies along one
  axis only; on oblique edges it counts some neighbours the 2-D kernel would
  weigh by a path of their own.
* ``"lattice"``: the Gaussian in the ``d = 2 + guide`` dimensional feature
  space on the permutohedral lattice of Adams, Baek and Davis (2010), see
  :mod:`matshop.ops._permutohedral`. Its cost grows with the number of texels,
  with ``d`` and with the number of lattice points the texels occupy: larger
  spatial and range sigmas are *faster* (a sparser lattice), small sigmas and
  noisy, high-dimensional guides slower. Its kernel is Gaussian only
  approximately (its variance is calibrated, its shape is piecewise linear).

Accuracy against the exact filter with a window truncated at 3 sigma:
``tests/test_bilateral.py`` measures 40-50 dB PSNR on real material edit values
and 50-60 dB on smoother synthetic sets, for both. It is lowest when the range
noise of the guide exceeds ``sigma_range``, so that hardly any neighbour falls
inside the range kernel (down to ~35 dB).

Borders: both read through the border (wrapped for tiling textures, clamped
otherwise). The lattice processes the image in tiles, each read with a margin
of 2.5 sigma; positions are global, so all tiles build pieces of one lattice
and do not show (the margin truncation is ~85 dB below the signal).
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numba
import numpy as np

from ..finite import all_finite
from ._permutohedral import filter_tiles, key_primes, locate
from ._separable import run_separable
from .spec import OpError

__all__ = [
    "BORDERS",
    "METHODS",
    "SEPARABLE_MAX_SIGMA",
    "Guide",
    "bilateral_filter",
    "prepare_guide",
    "run_lattice",
    "run_separable_guided",
]

BORDERS = ("wrap", "clamp")
METHODS = ("auto", "separable", "lattice")
#: ``method="auto"`` filters separably up to this spatial sigma (texels), with the
#: lattice beyond: the separable filter's cost grows with sigma (its taps), the
#: lattice's falls (fewer points). Measured on the real 10-channel set, guide
#: "auto" (3 axes), single-thread CPU time over cv2's (``benchmarks/bilateral.py
#: --methods``, loaded machine): separable / lattice 2.7 / 11.7 at sigma 2,
#: 1.1 / 1.8 at 4, 0.59 / 0.73 at 6, 0.55 / 0.55 at 7, 0.43 / 0.42 at 8; worst
#: crop 50.5 / 46.1 dB at 4, 46.7 / 46.5 at 7, 45.7 / 45.2 at 8. Since each pair
#: is weighed once and the sums take four taps per sweep, the separable filter's
#: CPU ratio is 1.6 / 0.65 / 0.35 at sigma 2 / 4 / 8 (loaded machine): faster
#: than the lattice at 8 as well; the limit stays until a quiet measurement.
SEPARABLE_MAX_SIGMA = 7.0

_NOT_FINITE = "bilateral: the image has non-finite values"
#: the neighbourhood read around each tile, in spatial sigmas
_MARGIN_SIGMAS = 2.5
#: a principal component of the guide whose extent (max - min) over the whole
#: image is below this, in range sigmas, is dropped: no weight changes by more
#: than a factor exp(0.01^2 / 2)
_NEGLIGIBLE_EXTENT = 0.01
#: texels sampled to find the principal axes of the guide (at most, at least,
#: and the budget of samples x guide width^2)
_PCA_SAMPLES = 1 << 16
_PCA_SAMPLES_MIN = 1 << 12
_PCA_BUDGET = 1 << 26
#: texels per block when projecting the whole guide
_CHUNK = 1 << 16
#: lattice points per tile (cache-sized) and bounds of the tile side in texels
_TILE_POINTS = 60_000
_TILE_MIN = 64
_TILE_MAX = 512
#: side of the tile probed for the lattice density
_PROBE = 96
#: reduced guides at least this wide (before reduction) are projected once
#: (BLAS) instead of per texel in the kernel
_PROJECT_FIRST = 16


def _lattice_scale(d: int) -> float:
    """Position scale of the lattice so its blur has unit variance in feature space.

    The paper's ``sqrt(2/3) (d + 1)`` leaves the kernel's variance a few
    percent too large once the splat and slice interpolation are included;
    the correction was measured from impulse responses for d = 2..14.
    """
    excess = 1.068 - 0.068 * math.exp(-(d - 2) / 1.5)
    return math.sqrt(2.0 / 3.0) * (d + 1) * math.sqrt(excess)


def _check_sigma(name: str, value: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise OpError(f"bilateral: {name} must be a number, got {value!r}") from None
    if not math.isfinite(value):
        raise OpError(f"bilateral: {name} must be finite, got {value}")
    if value <= 0:
        raise OpError(f"bilateral: {name} must be positive, got {value}")
    return value


def _validate(
    image: np.ndarray,
    sigma_space_px: float,
    sigma_range: float,
    channel_weights: np.ndarray | None,
    guide_dims: int | None,
    border: str,
    method: str,
) -> tuple[np.ndarray, float, float, np.ndarray, int | None]:
    arr = np.asarray(image)
    if arr.ndim != 3 or arr.shape[0] == 0 or arr.shape[1] == 0 or arr.shape[2] == 0:
        raise OpError(f"bilateral: expected an (H, W, C) image, got shape {arr.shape}")
    if arr.dtype.kind not in "fiub":
        raise OpError(f"bilateral: expected a numeric image, got dtype {arr.dtype}")
    height, width, channels = arr.shape
    sigma_s = _check_sigma("sigma_space_px", sigma_space_px)
    sigma_r = _check_sigma("sigma_range", sigma_range)
    if sigma_s > min(height, width):
        raise OpError(
            f"bilateral: sigma_space_px={sigma_s:g} is larger than the {width}x{height} image"
        )
    if border not in BORDERS:
        raise OpError(f"bilateral: border must be one of {BORDERS}, got {border!r}")
    if method not in METHODS:
        raise OpError(f"bilateral: method must be one of {METHODS}, got {method!r}")
    if channel_weights is None:
        weights = np.ones(channels, dtype=np.float64)
    else:
        weights = np.asarray(channel_weights, dtype=np.float64)
        if weights.shape != (channels,):
            raise OpError(
                f"bilateral: channel_weights must have shape ({channels},), got {weights.shape}"
            )
        if not np.all(np.isfinite(weights)) or np.any(weights < 0):
            raise OpError("bilateral: channel_weights must be finite and non-negative")
    if guide_dims is not None:
        if isinstance(guide_dims, bool) or not isinstance(guide_dims, int | np.integer):
            raise OpError(f"bilateral: guide_dims must be an integer, got {guide_dims!r}")
        if guide_dims < 1:
            raise OpError(f"bilateral: guide_dims must be at least 1, got {guide_dims}")
        guide_dims = int(guide_dims)
    return arr, sigma_s, sigma_r, weights, guide_dims


@dataclass(frozen=True)
class Guide:
    """How the kernel computes the range features from a texel's channels.

    ``g = image[..., used] * scales`` (the weighted guide over the range
    sigma), then ``g @ basis - offset`` when ``rotate`` (principal axes, some
    dropped), else ``g - offset``; the offset centres the features (which
    changes no distance but keeps lattice coordinates small). ``dims`` is the
    number of range features.
    """

    used: np.ndarray
    scales: np.ndarray
    basis: np.ndarray
    offset: np.ndarray
    rotate: bool

    @property
    def dims(self) -> int:
        return self.basis.shape[1] if self.rotate else self.used.size


def _extent(
    flat: np.ndarray, used: np.ndarray, scales: np.ndarray, basis: np.ndarray
) -> np.ndarray:
    """Per column of ``basis``: extent (max - min) of ``(flat[:, used] * scales) @ basis``."""
    weighted = (scales[:, None] * basis).astype(np.float32)
    lo = np.full(basis.shape[1], np.inf)
    hi = np.full(basis.shape[1], -np.inf)
    for start in range(0, flat.shape[0], _CHUNK):
        block = flat[start : start + _CHUNK]
        if used.size < flat.shape[1]:
            block = block[:, used]
        proj = weighted.T @ block.T  # (components, texels): contiguous rows reduce fast
        lo = np.minimum(lo, proj.min(axis=1))
        hi = np.maximum(hi, proj.max(axis=1))
    return hi - lo


def prepare_guide(
    image: np.ndarray,
    weights: np.ndarray,
    sigma_range: float,
    guide_dims: int | None,
    max_residual: float | None = None,
) -> Guide:
    """The range guide of a validated float32 image: channels, scales and PCA basis.

    Rotating the guide onto its principal axes preserves every distance, so
    the basis is only a change of coordinates; components are dropped when
    ``guide_dims`` asks for fewer, when their extent over the whole image is
    negligible (constant or linearly dependent channels cost nothing), and,
    with ``max_residual``, the trailing ones whose variance sums to at most
    that (per texel, in units of ``sigma_range**2``: the mean squared guide
    distance they would have added, over two, so 0.01 moves a typical range
    weight by about 1 %). The axes come from a subsample; the extents are
    checked on every texel.
    """
    used = np.flatnonzero(weights > 0).astype(np.int64)
    scales = weights[used] / sigma_range
    if used.size == 0:
        return Guide(used, scales, np.eye(0), np.zeros(0), rotate=False)
    flat = image.reshape(-1, image.shape[2])
    # enough samples for the leading axes; fewer for wide guides (cost ~ U^2)
    samples = max(_PCA_SAMPLES_MIN, min(_PCA_SAMPLES, _PCA_BUDGET // used.size**2))
    if flat.shape[0] > samples:
        # random texels (fixed seed): a stride through rows of a power-of-two width
        # lands on a few columns only (every 64th texel of a 2K map: 32 columns)
        index = np.random.default_rng(0).integers(0, flat.shape[0], samples)
        index.sort()
        flat_sample = np.take(flat, index, axis=0)
    else:
        flat_sample = flat
    sample = flat_sample[:, used].astype(np.float64) * scales
    _check_finite(sample)  # the eigensolver fails on non-finite values
    mean = sample.mean(axis=0)
    centred = sample - mean
    eigval, eigvec = np.linalg.eigh(centred.T @ centred)
    order = np.argsort(eigval)[::-1]
    eigvec = eigvec[:, order]
    keep = used.size if guide_dims is None else min(guide_dims, used.size)
    if max_residual is not None:
        variance = np.clip(eigval[order], 0.0, None) / len(centred)
        residual = np.cumsum(variance[::-1])[::-1]  # residual[k]: variance of axes k, k + 1, ...
        keep = min(keep, max(1, int(np.count_nonzero(residual > max_residual))))
    proj = centred @ eigvec[:, :keep]
    sample_extent = proj.max(axis=0) - proj.min(axis=0)
    doubtful = np.flatnonzero(sample_extent < _NEGLIGIBLE_EXTENT)
    kept = np.ones(keep, dtype=bool)
    if doubtful.size:
        basis = np.ascontiguousarray(eigvec[:, doubtful])
        extent = _extent(flat, used, scales, basis)
        kept[doubtful[extent < _NEGLIGIBLE_EXTENT]] = False
    if keep == used.size and kept.all():
        return Guide(used, scales, np.eye(used.size), mean, rotate=False)
    basis = np.ascontiguousarray(eigvec[:, :keep][:, kept])
    return Guide(used, scales, basis, mean @ basis, rotate=True)


def _tile_size(
    feat: np.ndarray,
    used: np.ndarray,
    lifts: tuple[np.ndarray, ...],
    primes: np.ndarray,
    margin: int,
    wrap: bool,
) -> int:
    """Core side of the square tiles, from the lattice density of a probe tile.

    A tile's lattice should stay cache-sized (``_TILE_POINTS`` points), and
    the density (points per texel) grows as the sigmas shrink and the guide
    gets noisier, so it is measured on a small tile at the image centre.
    """
    height, width, _ = feat.shape
    d1 = lifts[0].shape[0]
    probe = min(_PROBE, height, width)
    side = probe + 2 * margin
    idx = np.empty((side * side, d1), dtype=np.int32)
    bw = np.empty((side * side, d1), dtype=np.float32)
    table = np.empty(1 << 14, dtype=np.int64)
    keys = np.empty(1 << 13, dtype=np.int64)
    top = (height - probe) // 2 - margin
    left = (width - probe) // 2 - margin
    count, _, _ = locate(
        feat, used, top, left, side, side, wrap, *lifts, primes, idx, bw, table, keys
    )
    density = max(count / (side * side), 1e-3)
    tile = int(math.sqrt(_TILE_POINTS / density)) - 2 * margin
    tile = max(tile, 4 * margin, _TILE_MIN)
    return min(tile, _TILE_MAX, max(height, width))


def bilateral_filter(
    image: np.ndarray,
    *,
    sigma_space_px: float,
    sigma_range: float,
    channel_weights: np.ndarray | None = None,
    guide_dims: int | None = None,
    border: str = "wrap",
    max_residual: float | None = None,
    method: str = "auto",
) -> np.ndarray:
    """Bilateral filter of an ``(H, W, C)`` image guided jointly by its (weighted) channels.

    Parameters
    ----------
    image : (H, W, C) float32 ndarray
        Edit-space values; never modified.
    sigma_space_px : float
        Spatial standard deviation in texels (> 0, at most the image size).
    sigma_range : float
        Range standard deviation, in units of the weighted guide distance.
    channel_weights : (C,) ndarray, optional
        Per-channel scale of the range distance (0 leaves the channel out of
        the guide; it is still filtered). Default: all ones.
    guide_dims : int, optional
        Reduce the range guide to this many principal components when it is
        wider (distances then ignore the discarded minor components).
    border : {"wrap", "clamp"}
        ``"wrap"`` for tiling textures, ``"clamp"`` repeats the edge texels.
    max_residual : float, optional
        Also drop the trailing principal components of the guide whose
        variance sums to at most this, in units of ``sigma_range**2``
        (:func:`prepare_guide`); default: keep every component that varies.
    method : {"auto", "separable", "lattice"}
        How the filter is evaluated (module doc); ``"auto"``: separable up to
        :data:`SEPARABLE_MAX_SIGMA`, the lattice beyond.

    Returns
    -------
    (H, W, C) float32 ndarray, a new array.
    """
    arr, sigma_s, sigma_r, weights, guide_dims = _validate(
        image, sigma_space_px, sigma_range, channel_weights, guide_dims, border, method
    )
    src = np.ascontiguousarray(arr, dtype=np.float32)
    if max_residual is not None:
        max_residual = _check_sigma("max_residual", max_residual)
    if method == "separable" or (method == "auto" and sigma_s <= SEPARABLE_MAX_SIGMA):
        # the kernel checks finiteness on its one read of the image (a serial sum
        # here was ~20 of ~300 ms); the guide's sample before its PCA. The output
        # is not pre-touched on a thread: with the touch, calls took 0.8-1.3 s
        # instead of 0.2 s now and then (system time: page-fault stalls)
        guide = prepare_guide(src, weights, sigma_r, guide_dims, max_residual)
        return run_separable_guided(src, guide, sigma_s, border)
    _check_finite(src)
    guide = prepare_guide(src, weights, sigma_r, guide_dims, max_residual)
    return run_lattice(src, guide, sigma_s, border)


def _check_finite(values: np.ndarray) -> None:
    if not all_finite(values):
        raise OpError(_NOT_FINITE)


def run_separable_guided(
    src: np.ndarray, guide: Guide, sigma_s: float, border: str, out: np.ndarray | None = None
) -> np.ndarray:
    """The separable filter on validated inputs (``src`` float32, C-contiguous).

    Writes into ``out`` (float32, like ``src``) when given. Raises
    :class:`OpError` when ``src`` has a non-finite value.
    """
    mix = guide.scales[:, None] * guide.basis  # the basis is the identity when not rotated
    out, finite = run_separable(
        src, guide.used, mix, guide.offset, sigma_s, border == "wrap", _threads(), out
    )
    if not finite:
        raise OpError(_NOT_FINITE)
    return out


def _elevation(d: int, scale: float) -> np.ndarray:
    """``(d + 1, d)`` matrix lifting features onto ``H_d``: orthonormal columns times ``scale``.

    Column m is ``scale / sqrt((m + 1)(m + 2))`` on rows ``0..m`` and
    ``-(m + 1)`` times that on row ``m + 1`` (the paper's elevation).
    """
    lift = np.zeros((d + 1, d))
    for m in range(d):
        step = scale / math.sqrt((m + 1) * (m + 2))
        lift[: m + 1, m] = step
        lift[m + 1, m] = -(m + 1) * step
    return lift


def run_lattice(
    src: np.ndarray,
    guide: Guide,
    sigma_s: float,
    border: str,
    *,
    tile: int | None = None,
    scale: float = 1.0,
    passes: int = 1,
) -> np.ndarray:
    """The lattice filter proper, on validated inputs (``src`` float32, C-contiguous).

    ``tile`` (core side in texels; default from the lattice density),
    ``scale`` (of the lattice) and ``passes`` (of the blur) are for tests and
    tuning; the defaults give the calibrated Gaussian.
    """
    height, width, channels = src.shape
    d = 2 + guide.dims
    elevation = _elevation(d, _lattice_scale(d) * scale)
    lift_r = elevation[:, 0] / sigma_s
    lift_c = elevation[:, 1] / sigma_s
    to_h = elevation[:, 2:].T  # (guide dims, d + 1)
    if not guide.rotate:
        feat, used = src, guide.used
        lift_g = guide.scales[:, None] * to_h
        lift0 = -guide.offset @ to_h
    elif guide.used.size >= _PROJECT_FIRST:
        weighted = (guide.scales[:, None] * guide.basis).astype(np.float32)
        flat = src.reshape(-1, channels)
        if guide.used.size < channels:
            flat = flat[:, guide.used]
        flat = flat @ weighted
        flat -= guide.offset.astype(np.float32)
        feat = np.ascontiguousarray(flat.reshape(height, width, guide.dims))
        used = np.arange(guide.dims)
        lift_g, lift0 = to_h, np.zeros(d + 1)
    else:
        feat, used = src, guide.used
        lift_g = (guide.scales[:, None] * guide.basis) @ to_h
        lift0 = -guide.offset @ to_h
    margin = int(math.ceil(_MARGIN_SIGMAS * sigma_s))
    used = used.astype(np.int64)
    lifts = tuple(
        np.ascontiguousarray(a, dtype=np.float64) for a in (lift0, lift_r, lift_c, lift_g)
    )
    primes = key_primes(d)
    wrap = border == "wrap"
    if tile is None:
        tile = _tile_size(feat, used, lifts, primes, margin, wrap)
    tiles = ((height + tile - 1) // tile) * ((width + tile - 1) // tile)
    workers = max(1, min(_threads(), tiles))
    out = np.empty_like(src)
    counts = np.zeros(tiles, dtype=np.int64)
    args = (src, feat, used, *lifts, out, tile, margin, wrap, passes, primes)
    if workers == 1:
        filter_tiles(*args, 0, 1, counts)
    else:
        # the kernel releases the GIL: one thread per worker, tiles dealt round-robin
        with ThreadPoolExecutor(max_workers=workers) as pool:
            jobs = [pool.submit(filter_tiles, *args, w, workers, counts) for w in range(workers)]
            for job in jobs:
                job.result()
    return out


def _threads() -> int:
    """Worker threads: numba's setting (NUMBA_NUM_THREADS, ``numba.set_num_threads``)."""
    return numba.get_num_threads()
