"""Edge-aware filters in edit space: bilateral smoothing and detail enhancement.

The range distance is the Euclidean distance between edit vectors over the
selected parameters, each scaled by its edit range (and sampled functions by
their quadrature weights), so a roughness step and a color step of the same
relative size count the same. Detail enhancement is the unsharp mask with
the bilateral as the blur: ``p~' = p~ + k (p~ - bilateral(p~))``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..material import Schema
from .bilateral import bilateral_filter
from .selection import Selection
from .spec import BORDER, WHOLE_IMAGE, Check, OpError, OpSpec, OpTarget, ParamSpec, Reach

#: beyond this many guide channels the range guide is reduced by PCA (all
#: channels are still filtered); 128-sample distributions would otherwise
#: make the lattice too high-dimensional to be fast
MAX_GUIDE_DIMS = 12
REDUCED_GUIDE_DIMS = 6
#: ``guide="auto"``: the trailing principal axes of the guide whose variance sums
#: to at most this (in sigma_range^2) are dropped. Chosen by measurement on the
#: real 10-channel set (``benchmarks/bilateral.py --guide-table``): 4 of its 8
#: varying axes remain, at 45-46 dB against the exact filter (the full guide:
#: 41-42 dB, the lattice's own error dominating) for about half the time.
MAX_RESIDUAL = 0.01
GUIDES = ("auto", "full")


def _filtered(
    selection: Selection,
    block: np.ndarray,
    sigma_px: float,
    sigma_range: float,
    border: str,
    guide: str = "auto",
) -> np.ndarray:
    weights = selection.distance_weights()
    guide_dims = REDUCED_GUIDE_DIMS if np.count_nonzero(weights) > MAX_GUIDE_DIMS else None
    return bilateral_filter(
        np.ascontiguousarray(block),
        sigma_space_px=sigma_px,
        sigma_range=sigma_range,
        channel_weights=weights,
        guide_dims=guide_dims,
        border=border,
        max_residual=MAX_RESIDUAL if guide == "auto" else None,
    )


def bilateral(
    edit: np.ndarray,
    *,
    sigma_px: float = 4.0,
    sigma_range: float = 0.1,
    border: str = "wrap",
    guide: str = "auto",
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Bilateral filter of the selected parameters, guided by all of them jointly.

    ``sigma_range`` is a fraction of each parameter's edit range. ``guide``:
    ``"auto"`` leaves out the guide's principal axes that explain almost none
    of its variance (:data:`MAX_RESIDUAL`), ``"full"`` keeps every one.
    """
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="bilateral")
    block = selection.take(edit)
    filtered = _filtered(selection, block, sigma_px, sigma_range, border, guide)
    return selection.put(edit, filtered)


def detail(
    edit: np.ndarray,
    *,
    amount: float = 1.0,
    sigma_px: float = 4.0,
    sigma_range: float = 0.1,
    border: str = "wrap",
    guide: str = "auto",
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Detail enhancement: ``p~ + amount * (p~ - bilateral(p~))`` (negative amount smooths)."""
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="detail")
    block = selection.take(edit)
    base = _filtered(selection, block, sigma_px, sigma_range, border, guide)
    enhanced = block + np.float32(amount) * (block - base)
    return selection.put(edit, enhanced)


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

    The permutohedral lattice approximates the filter with an error whose
    pattern depends on where the lattice sits and on the guide's principal
    axes over the whole image, so no finite margin makes a tile equal the op
    run on the whole image (measured: tiles grown by 3 sigma differ by ~1 %
    rms of each channel's range, as much as either differs from the exact
    filter). A filter layer running it computes the whole image at once and
    equals ``matshop apply`` byte for byte.
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

SPECS = (
    OpSpec(
        name="bilateral",
        label="Bilateral filter",
        summary="edge-preserving smoothing guided by all selected parameters at once",
        function=bilateral,
        params=(_SIGMA_PX, _SIGMA_RANGE, BORDER, _GUIDE),
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
        ),
        linear=False,
        neighbourhood=True,
        checks=(sigma_fits("detail"),),
        reach=lattice_reach,
    ),
)
