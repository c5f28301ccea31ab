"""Gaussian blur: ``p~' = sum_i w_i p~_i`` with spatial Gaussian weights.

Blurring frame edit values blurs orientation (the frames stay orthonormal
after from_edit) instead of flattening a height field; blurring a lobe's
inverse CDF averages the distributions (Read's construction). OpenCV's
separable filter does the work on all selected channels at once; tiling
textures wrap around by padding with the opposite edge.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import cv2
import numpy as np

from ..material import Schema
from .selection import Selection
from .spec import BORDER, OpError, OpSpec, OpTarget, ParamSpec, Reach
from .variance import (
    moments_covariance,
    normal_moments,
    smooths_normals,
    widen_smoothed,
)

#: OpenCV's kernel for float images spans +-4 sigma
_TRUNCATE = 4.0


#: From this kernel radius on, wrapping fixes each separable pass instead of
#: bands of the 2D result (measured crossover, benchmarks/ops.py: sigma ~6 px)
SEPARATE_PASSES_FROM_RADIUS = 24


def kernel_radius_px(sigma_px: float) -> int:
    """Half-width of the kernel OpenCV uses for ``sigma_px`` on float images."""
    size = int(round(sigma_px * _TRUNCATE * 2 + 1)) | 1
    return size // 2


def pad(image: np.ndarray, radius: int, border: str) -> np.ndarray:
    """Pad height and width by ``radius`` with wrapped or repeated edge texels."""
    if border == "wrap" and radius <= min(image.shape[:2]):
        return cv2.copyMakeBorder(image, radius, radius, radius, radius, cv2.BORDER_WRAP)
    mode = "wrap" if border == "wrap" else "edge"
    return np.pad(image, ((radius, radius), (radius, radius), (0, 0)), mode=mode)


def _as_cv(image: np.ndarray) -> np.ndarray:
    # OpenCV drops a trailing axis of length 1; keep the (H, W, C) contract
    return image[..., None] if image.ndim == 2 else image


def _blur(image: np.ndarray, sigma_px: float, cv_border: int) -> np.ndarray:
    return _as_cv(cv2.GaussianBlur(image, (0, 0), sigma_px, borderType=cv_border))


def _wrapped_band(image: np.ndarray, sigma_px: float, radius: int, axis: int) -> np.ndarray:
    """Blur of the 2*radius rows (axis 0) or columns (axis 1) that straddle the wrap seam.

    Returns the band ordered [last radius, first radius] along ``axis``.
    """
    n = image.shape[axis]
    take = np.r_[n - 2 * radius : n, 0 : 2 * radius]
    strip = np.take(image, take, axis=axis)
    # the other axis wraps too, so the corners come out right
    pads = (0, 0, radius, radius) if axis == 0 else (radius, radius, 0, 0)
    strip = _as_cv(cv2.copyMakeBorder(strip, *pads, cv2.BORDER_WRAP))
    blurred = _blur(strip, sigma_px, cv2.BORDER_REFLECT_101)
    inner = (slice(radius, 3 * radius), slice(radius, -radius))
    return blurred[inner if axis == 0 else inner[::-1]]


def _wrapped_pass(image: np.ndarray, kernel: np.ndarray, radius: int, axis: int) -> np.ndarray:
    """One separable pass along ``axis`` (1: horizontal, 0: vertical) that wraps at the seam.

    The whole image is filtered with any border (its interior is then
    exact); only the ``radius`` texels on each side of the seam are redone,
    from a thin strip of the ``2 * radius`` texels either side of it.
    """
    one = np.ones(1, dtype=np.float32)
    kx, ky = (kernel, one) if axis == 1 else (one, kernel)
    out = _as_cv(cv2.sepFilter2D(image, -1, kx, ky, borderType=cv2.BORDER_REFLECT_101))
    n = image.shape[axis]
    strip = np.take(image, np.r_[n - 2 * radius : n, 0 : 2 * radius], axis=axis)
    fixed = _as_cv(cv2.sepFilter2D(strip, -1, kx, ky, borderType=cv2.BORDER_REFLECT_101))
    if axis == 1:
        out[:, -radius:], out[:, :radius] = (
            fixed[:, radius : 2 * radius],
            fixed[:, 2 * radius : 3 * radius],
        )
    else:
        out[-radius:], out[:radius] = fixed[radius : 2 * radius], fixed[2 * radius : 3 * radius]
    return out


#: how errors about the variance option name it
_KEEP = "blur keep_variance=true"

#: OpenCV 5's filters take at most this many channels (a 128-bin sampled lobe
#: next to a few colours is more): wider arrays are blurred in blocks
MAX_CV_CHANNELS = 128


def gaussian(image: np.ndarray, sigma_px: float, border: str) -> np.ndarray:
    """Blur an (H, W, C) float32 array; ``border`` is ``"wrap"`` or ``"clamp"``."""
    if sigma_px == 0:
        return image.copy()
    if image.ndim == 3 and image.shape[2] > MAX_CV_CHANNELS:
        blocks = range(0, image.shape[2], MAX_CV_CHANNELS)
        return np.concatenate(
            [gaussian(image[..., k : k + MAX_CV_CHANNELS], sigma_px, border) for k in blocks],
            axis=2,
        )
    image = np.ascontiguousarray(image)
    radius = kernel_radius_px(sigma_px)
    if radius == 0:  # a one-tap kernel (sigma below ~0.07 px) is the identity
        return image.copy()
    if border == "clamp":
        return _blur(image, sigma_px, cv2.BORDER_REPLICATE)
    if 4 * radius > min(image.shape[:2]):
        padded = pad(image, radius, border)
        blurred = _blur(padded, sigma_px, cv2.BORDER_ISOLATED)
        return np.ascontiguousarray(blurred[radius:-radius, radius:-radius])
    # Wrap without padding the whole image: filter it with any border (the
    # interior is then exact) and redo only what is within reach of the seams.
    if radius < SEPARATE_PASSES_FROM_RADIUS:
        # small kernels: OpenCV's 2D Gaussian is fastest; redo bands of its result
        out = _blur(image, sigma_px, cv2.BORDER_REFLECT_101)
        rows = _wrapped_band(image, sigma_px, radius, axis=0)
        out[-radius:], out[:radius] = rows[:radius], rows[radius:]
        cols = _wrapped_band(image, sigma_px, radius, axis=1)
        out[:, -radius:], out[:, :radius] = cols[:, :radius], cols[:, radius:]
        return out
    # wide kernels: the bands would cost ~20 %; fix each 1D pass from a thin strip
    kernel = cv2.getGaussianKernel(2 * radius + 1, sigma_px).astype(np.float32)
    horizontal = _wrapped_pass(image, kernel, radius, axis=1)
    return _wrapped_pass(horizontal, kernel, radius, axis=0)


def gaussian_blur(
    edit: np.ndarray,
    *,
    sigma_px: float = 2.0,
    border: str = "wrap",
    keep_variance: bool = False,
    schema: Schema | None = None,
    params: Sequence[str] | str | None = None,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """Gaussian blur of the selected edit channels.

    Parameters
    ----------
    edit : (H, W, C) float32 ndarray
    sigma_px : float
        Standard deviation in texels (0 is a no-op).
    border : {"wrap", "clamp"}
        Wrap for tiling textures; clamp repeats the edge texels.
    keep_variance : bool
        When the normal is among the blurred parameters, widen every lobe
        parameter (selected or not) by the slope variance the blur removed
        from the normals (:mod:`matshop.ops.variance`); colours are untouched.
    schema, params, mask : selection and blending, see :mod:`matshop.ops.selection`.
    """
    selection = Selection(edit, schema=schema, params=params, mask=mask, op="blur")
    values = {"sigma_px": sigma_px, "keep_variance": keep_variance}
    check_blur(values, OpTarget(schema, params, edit.shape[:2]))  # before the costly part
    out = selection.put(edit, gaussian(selection.take(edit), sigma_px, border))
    if keep_variance:
        out = _keep_variance(edit, out, schema, selection, sigma_px, border)
    return out


def _keep_variance(
    before: np.ndarray,
    after: np.ndarray,
    schema: Schema | None,
    selection: Selection,
    sigma_px: float,
    border: str,
) -> np.ndarray:
    """``after`` with its lobes widened by the tilt the blur took out of the normals."""
    if schema is None:
        raise OpError(f"{_KEEP}: needs the material's schema (which channels are normals)")
    if not smooths_normals(schema, (g.name for g in selection.groups)):
        return after  # the normals were not blurred: no tilt was lost
    moments = normal_moments(before, schema)
    cov = moments_covariance(gaussian(moments, sigma_px, border))
    return widen_smoothed(after, schema, cov, mask=selection.mask, op=_KEEP)


def check_blur(values: Mapping[str, Any], target: OpTarget) -> None:
    """A sigma far beyond the image means nothing."""
    sigma_px = values["sigma_px"]
    if target.size is not None and sigma_px > 4 * max(target.size):
        height, width = target.size
        raise OpError(f"blur: sigma_px={sigma_px:g} is far larger than the {width}x{height} image")


def blur_reach(values: Mapping[str, Any], target: OpTarget) -> Reach:
    """The kernel's half-width: OpenCV truncates the Gaussian at 4 sigma."""
    sigma_px = float(values["sigma_px"])
    return 0 if sigma_px == 0 else kernel_radius_px(sigma_px)


SPECS = (
    OpSpec(
        name="blur",
        label="Gaussian blur",
        summary="spatial Gaussian average of edit values",
        function=gaussian_blur,
        params=(
            ParamSpec(
                "sigma_px",
                "float",
                2.0,
                "standard deviation of the Gaussian",
                unit="px",
                hard_range=(0.0, 4096.0),
                ui_range=(0.0, 64.0),
            ),
            BORDER,
            ParamSpec(
                "keep_variance",
                "bool",
                False,
                "widen the lobe (roughness, Beckmann m, Phong/Ashikhmin-Shirley exponents) by "
                "the normal tilt variance the blur removes; acts whenever normal is blurred, "
                "even if the lobe parameter is not selected",
            ),
        ),
        linear=True,
        neighbourhood=True,
        checks=(check_blur,),
        reach=blur_reach,
    ),
)
