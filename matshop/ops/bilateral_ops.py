"""Edge-aware filters in edit space: bilateral smoothing and detail enhancement.

The range distance is the Euclidean distance between edit vectors over the
selected parameters, each scaled by its edit range (and sampled functions by
their quadrature weights), so a roughness step and a color step of the same
relative size count the same. Detail enhancement is the unsharp mask with
the bilateral as the blur: ``p~' = p~ + k (p~ - bilateral(p~))``.

``keep_variance``: when the normals are smoothed (by ``bilateral``, or by
``detail`` with a negative amount), the slope moments of the normals are
filtered in the same lattice pass as zero-weight channels, so they get the op's
own per-texel normalised weights ``W`` without changing the guide; the lost
covariance ``W(s s^T) - W(s) W(s)^T`` widens the lobe (:mod:`.variance`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..material import Schema
from .bilateral import bilateral_filter
from .selection import Selection
from .spec import BORDER, WHOLE_IMAGE, Check, OpError, OpSpec, OpTarget, ParamSpec, Reach
from .variance import (
    moments_covariance,
    normal_moments,
    smooths_normals,
    widen_smoothed,
)

#: beyond this many guide channels the range guide is reduced by PCA (all
#: channels are still filtered); 128-sample distributions would otherwise
#: make the lattice too high-dimensional to be fast
MAX_GUIDE_DIMS = 12
REDUCED_GUIDE_DIMS = 6
#: ``guide="auto"``: the trailing principal axes of the guide whose variance sums
#: to at most this (in sigma_range^2) are dropped. Chosen by measurement on the
#: real 10-channel set (``benchmarks/bilateral.py --guide-table``): its axes
#: carry 1.73, 0.43, 0.19, then 0.0045 and less; the 5 weak ones together 0.013
#: (a typical range weight moved by ~1 %). Dropping them keeps 3 of 8 varying
#: axes, and the worst of three crops is 44.8 / 41.7 dB against the exact filter
#: at sigma 4 / 8 (4 axes: 44.8 / 41.2, full guide: 43.4 / 39.8: the lattice's
#: own error dominates, and it grows with the dimension) for about a quarter
#: less time than 4 axes (one thread: 1.25 s against 1.65 s at sigma 4).
MAX_RESIDUAL = 0.02
GUIDES = ("auto", "full")


def _filtered(
    selection: Selection,
    block: np.ndarray,
    sigma_px: float,
    sigma_range: float,
    border: str,
    guide: str = "auto",
    moments: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """The bilateral of ``block``, and of ``moments`` with the same weights (None if none).

    The moments ride along as channels of distance weight 0: they are left out of
    the guide, so every texel's weights are the ones ``block`` gets.
    """
    weights = selection.distance_weights()
    guide_dims = REDUCED_GUIDE_DIMS if np.count_nonzero(weights) > MAX_GUIDE_DIMS else None
    image = np.ascontiguousarray(block)
    if moments is not None:
        image = np.concatenate([image, moments], axis=2)
        weights = np.concatenate([weights, np.zeros(moments.shape[2], weights.dtype)])
    out = bilateral_filter(
        image,
        sigma_space_px=sigma_px,
        sigma_range=sigma_range,
        channel_weights=weights,
        guide_dims=guide_dims,
        border=border,
        max_residual=MAX_RESIDUAL if guide == "auto" else None,
    )
    width = block.shape[2]
    return out[..., :width], (None if moments is None else out[..., width:])


def _moments_to_keep(
    edit: np.ndarray, schema: Schema | None, selection: Selection, op: str
) -> np.ndarray | None:
    """The normals' slope moments when ``keep_variance`` has tilt to keep, else None."""
    if schema is None:
        raise OpError(f"{op}: needs the material's schema (which channels are normals)")
    if not smooths_normals(schema, (g.name for g in selection.groups)):
        return None  # the normals are not filtered: no tilt is lost
    return normal_moments(edit, schema)


def bilateral(
    edit: np.ndarray,
    *,
    sigma_px: float = 4.0,
    sigma_range: float = 0.1,
    border: str = "wrap",
    guide: str = "auto",
    keep_variance: bool = False,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Bilateral filter of the selected parameters, guided by all of them jointly.

    ``sigma_range`` is a fraction of each parameter's edit range. ``guide``:
    ``"auto"`` leaves out the guide's principal axes that explain almost none
    of its variance (:data:`MAX_RESIDUAL`), ``"full"`` keeps every one.
    ``keep_variance``: widen the lobe by the normal tilt variance the filter
    removes (module doc).
    """
    op = "bilateral keep_variance=true"
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="bilateral")
    moments = _moments_to_keep(edit, schema, selection, op) if keep_variance else None
    block = selection.take(edit)
    base, averaged = _filtered(selection, block, sigma_px, sigma_range, border, guide, moments)
    out = selection.put(edit, base)
    if averaged is None:
        return out
    cov = moments_covariance(averaged)
    return widen_smoothed(out, schema, cov, mask=selection.mask, op=op)


def detail(
    edit: np.ndarray,
    *,
    amount: float = 1.0,
    sigma_px: float = 4.0,
    sigma_range: float = 0.1,
    border: str = "wrap",
    guide: str = "auto",
    keep_variance: bool = False,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Detail enhancement: ``p~ + amount * (p~ - bilateral(p~))`` (negative amount smooths).

    ``keep_variance`` with a negative amount: the result is the average
    ``(1 - t) p~ + t bilateral(p~)``, ``t = -amount``; the lobe is widened by the
    tilt variance that average removes. A positive amount adds detail: nothing lost.
    """
    op = "detail keep_variance=true"
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="detail")
    moments = _moments_to_keep(edit, schema, selection, op) if keep_variance else None
    if amount >= 0:
        moments = None
    block = selection.take(edit)
    base, averaged = _filtered(selection, block, sigma_px, sigma_range, border, guide, moments)
    k = np.float32(amount)
    out = selection.put(edit, block + k * (block - base))
    if averaged is None:
        return out
    cov = moments_covariance(moments + k * (moments - averaged))  # the same unsharp mix
    return widen_smoothed(out, schema, cov, mask=selection.mask, op=op)


def sigma_fits(op: str) -> Check:
    """A check that the spatial sigma fits in the image (the lattice filter refuses more)."""

    def check(values: Mapping[str, Any], target: OpTarget) -> None:
        if target.size is not None and values["sigma_px"] > min(target.size):
            height, width = target.size
            raise OpError(
                f"{op}: sigma_px={values['sigma_px']:g} is larger than the {width}x{height} image"
            )

    return check


def lattice_reach(values: Mapping[str, Any], target: OpTarget) -> Reach:
    """The whole image, although the spatial Gaussian is negligible past ~3 sigma.

    The guide's principal axes (and which are dropped) come from the whole
    image, and the permutohedral lattice (wide sigmas) approximates the filter
    with an error whose pattern depends on where the lattice sits, so no finite
    margin makes a tile equal the op run on the whole image (measured with the
    lattice: tiles grown by 3 sigma differ by ~1 % rms of each channel's range,
    as much as either differs from the exact filter). A filter layer running it
    computes the whole image at once and equals ``matshop apply`` byte for byte.
    """
    return WHOLE_IMAGE


_SIGMA_PX = ParamSpec(
    "sigma_px",
    "float",
    4.0,
    "spatial standard deviation",
    unit="px",
    hard_range=(0.5, 1024.0),
    ui_range=(1.0, 32.0),
)
_SIGMA_RANGE = ParamSpec(
    "sigma_range",
    "float",
    0.1,
    "range standard deviation, as a fraction of each parameter's edit range",
    hard_range=(1e-3, 100.0),
    ui_range=(0.01, 1.0),
)

_GUIDE = ParamSpec(
    "guide",
    "choice",
    "auto",
    "range guide: auto = leave out the principal axes that explain almost none of its "
    "variance (faster, as accurate), full = every axis",
    choices=GUIDES,
    missing="full",
)


def _keep_param(when: str) -> ParamSpec:
    return ParamSpec(
        "keep_variance",
        "bool",
        False,
        "widen the lobe (roughness, Beckmann m, Phong/Ashikhmin-Shirley exponents) by "
        f"the normal tilt variance the op smooths away; acts {when}, even if the lobe "
        "parameter is not selected",
    )


SPECS = (
    OpSpec(
        name="bilateral",
        label="Bilateral filter",
        summary="edge-preserving smoothing guided by all selected parameters at once",
        function=bilateral,
        params=(
            _SIGMA_PX,
            _SIGMA_RANGE,
            BORDER,
            _GUIDE,
            _keep_param("whenever normal is filtered"),
        ),
        linear=False,
        neighbourhood=True,
        checks=(sigma_fits("bilateral"),),
        reach=lattice_reach,
    ),
    OpSpec(
        name="detail",
        label="Detail enhancement",
        summary="unsharp mask with the bilateral as the blur (local contrast)",
        function=detail,
        params=(
            ParamSpec(
                "amount",
                "float",
                1.0,
                "how much detail to add (negative smooths)",
                hard_range=(-1.0, 20.0),
                ui_range=(0.0, 4.0),
            ),
            _SIGMA_PX,
            _SIGMA_RANGE,
            BORDER,
            _GUIDE,
            _keep_param("when normal is filtered with a negative amount"),
        ),
        linear=False,
        neighbourhood=True,
        checks=(sigma_fits("detail"),),
        reach=lattice_reach,
    ),
)
