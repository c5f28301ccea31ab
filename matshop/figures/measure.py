"""Measurements the figures report, taken on material arrays or on linear renders.

- :func:`tilt_deg`, :func:`steep_fraction`: how tilted a normal map is;
- :func:`highlight_shape`: the shape of a specular highlight in an image --
  elongation and direction of its half-maximum region;
- :func:`median_lobe_deg`: highlight size of a Phong exponent (its lobe's
  median half-vector angle).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


def tilt_deg(normal: np.ndarray) -> np.ndarray:
    """Angle (degrees) between each unit normal ``(..., 3)`` and ``+z``."""
    return np.degrees(np.arccos(np.clip(normal[..., 2], -1.0, 1.0)))


def steep_fraction(normal: np.ndarray, threshold_deg: float = 30.0) -> float:
    """Fraction of texels tilted more than ``threshold_deg``."""
    return float(np.mean(tilt_deg(normal) > threshold_deg))


def median_lobe_deg(exponent: np.ndarray) -> np.ndarray:
    """Median half-vector angle (degrees) of Phong lobes ``cos^n``: ``acos(2^(-1/(n+2)))``."""
    n = np.maximum(np.asarray(exponent, dtype=np.float64), 0.0)
    return np.degrees(np.arccos(2.0 ** (-1.0 / (n + 2.0))))


@dataclass(frozen=True)
class HighlightShape:
    """The half-maximum region of a highlight, summarised by its second moments.

    ``major_px`` / ``minor_px`` are the standard deviations of the region's
    pixel positions along its principal axes; ``angle_deg`` is the direction
    of the major axis, counter-clockwise from the image's +x with +y *up*, in
    ``[0, 180)``; ``aspect = major_px / minor_px`` (1 for a round highlight).
    """

    aspect: float
    angle_deg: float
    major_px: float
    minor_px: float
    pixels: int

    def extent_along(self, angle_deg: float) -> float:
        """Standard deviation (pixels) of the region along the direction ``angle_deg``."""
        d = np.radians(angle_deg - self.angle_deg)
        return float(np.hypot(self.major_px * np.cos(d), self.minor_px * np.sin(d)))


def highlight_shape(
    energy: np.ndarray, *, level: float = 0.5, smooth_px: float = 1.0
) -> HighlightShape:
    """Shape of the brightest highlight in ``energy`` ``(H, W)`` (linear, e.g. summed RGB).

    The image is smoothed by a Gaussian of ``smooth_px`` (texture detail
    would otherwise break the region up), thresholded at ``level`` times its
    peak, and the connected region containing the peak is measured by the
    covariance of its pixel coordinates. For an elliptical lobe the
    half-maximum region is an ellipse, whose covariance axes are in the ratio
    of its semi-axes.
    """
    e = np.asarray(energy, dtype=np.float32)
    if smooth_px > 0:
        e = cv2.GaussianBlur(e, (0, 0), smooth_px)
    peak = np.unravel_index(int(np.argmax(e)), e.shape)
    region = (e >= level * e[peak]).astype(np.uint8)
    _, labels = cv2.connectedComponents(region, connectivity=8)
    rows, cols = np.nonzero(labels == labels[peak])
    # +y up: image rows grow downwards
    xy = np.stack([cols.astype(np.float64), -rows.astype(np.float64)])
    cov = np.cov(xy) if xy.shape[1] > 1 else np.zeros((2, 2))
    values, vectors = np.linalg.eigh(cov)
    minor, major = np.sqrt(np.maximum(values, 0.0))
    vx, vy = vectors[:, 1]
    angle = float(np.degrees(np.arctan2(vy, vx)) % 180.0)
    aspect = float(major / minor) if minor > 0 else float("inf")
    return HighlightShape(aspect, angle, float(major), float(minor), int(rows.size))


def axis_difference_deg(a: float, b: float) -> float:
    """Smallest angle between two undirected axes given in degrees (in ``[0, 90]``)."""
    d = abs(a - b) % 180.0
    return min(d, 180.0 - d)
