"""Closed forms of the isotropic microfacet distributions used by the spaces.

Each ``*_d`` is the distribution ``d(theta)`` normalised so that
``2*pi * integral_0^{pi/2} d(theta) cos(theta) sin(theta) dtheta == 1``
(projected-area normalisation), and each ``*_cdf`` is
``c(theta) = 2*pi * integral_0^theta d cos sin``. These are the independent
truth the editing spaces and their tests are checked against; they work in
float64 and broadcast ``theta`` against the lobe parameter.
"""

from __future__ import annotations

import numpy as np

HALF_PI = 0.5 * np.pi


def phong_d(theta: np.ndarray, n: np.ndarray | float) -> np.ndarray:
    """Normalised Phong lobe ``(n + 2) / (2 pi) cos^n theta``."""
    cos_t = np.cos(np.asarray(theta, dtype=np.float64))
    n = np.asarray(n, dtype=np.float64)
    return (n + 2.0) / (2.0 * np.pi) * np.clip(cos_t, 0.0, None) ** n


def phong_cdf(theta: np.ndarray, n: np.ndarray | float) -> np.ndarray:
    """``1 - cos^(n+2) theta``."""
    cos_t = np.clip(np.cos(np.asarray(theta, dtype=np.float64)), 0.0, 1.0)
    return 1.0 - cos_t ** (np.asarray(n, dtype=np.float64) + 2.0)


def phong_cdf_inv(y: np.ndarray, n: np.ndarray | float) -> np.ndarray:
    """Angle below which a fraction ``y`` of the Phong lobe lies."""
    y = np.clip(np.asarray(y, dtype=np.float64), 0.0, 1.0)
    return np.arccos((1.0 - y) ** (1.0 / (np.asarray(n, dtype=np.float64) + 2.0)))


def beckmann_d(theta: np.ndarray, m: np.ndarray | float) -> np.ndarray:
    """Beckmann ``exp(-tan^2 theta / m^2) / (pi m^2 cos^4 theta)``."""
    theta = np.asarray(theta, dtype=np.float64)
    m2 = np.asarray(m, dtype=np.float64) ** 2
    cos_t = np.cos(theta)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        tan2 = np.tan(theta) ** 2
        d = np.exp(-tan2 / m2) / (np.pi * m2 * cos_t**4)
    return np.where(theta >= HALF_PI, 0.0, np.nan_to_num(d, nan=0.0, posinf=0.0))


def beckmann_cdf(theta: np.ndarray, m: np.ndarray | float) -> np.ndarray:
    """``1 - exp(-tan^2 theta / m^2)``."""
    theta = np.asarray(theta, dtype=np.float64)
    m2 = np.asarray(m, dtype=np.float64) ** 2
    with np.errstate(over="ignore"):
        tan2 = np.tan(np.clip(theta, 0.0, HALF_PI)) ** 2
        return np.where(theta >= HALF_PI, 1.0, 1.0 - np.exp(-tan2 / m2))


def beckmann_cdf_inv(y: np.ndarray, m: np.ndarray | float) -> np.ndarray:
    y = np.clip(np.asarray(y, dtype=np.float64), 0.0, 1.0)
    with np.errstate(divide="ignore"):
        return np.arctan(np.asarray(m, dtype=np.float64) * np.sqrt(-np.log1p(-y)))


def ggx_d(theta: np.ndarray, alpha: np.ndarray | float) -> np.ndarray:
    """GGX / Trowbridge-Reitz ``alpha^2 / (pi cos^4 theta (alpha^2 + tan^2 theta)^2)``.

    Written as ``alpha^2 / (pi (alpha^2 cos^2 + sin^2)^2)`` so it stays finite at 90 degrees.
    """
    theta = np.asarray(theta, dtype=np.float64)
    a2 = np.asarray(alpha, dtype=np.float64) ** 2
    cos2 = np.cos(theta) ** 2
    sin2 = np.sin(theta) ** 2
    return a2 / (np.pi * (a2 * cos2 + sin2) ** 2)


def ggx_cdf(theta: np.ndarray, alpha: np.ndarray | float) -> np.ndarray:
    """``tan^2 theta / (alpha^2 + tan^2 theta)``, written with sin/cos to stay finite."""
    theta = np.clip(np.asarray(theta, dtype=np.float64), 0.0, HALF_PI)
    a2 = np.asarray(alpha, dtype=np.float64) ** 2
    sin2 = np.sin(theta) ** 2
    cos2 = np.cos(theta) ** 2
    return sin2 / (a2 * cos2 + sin2)


def ggx_cdf_inv(y: np.ndarray, alpha: np.ndarray | float) -> np.ndarray:
    """``atan(alpha sqrt(y / (1 - y)))``."""
    y = np.clip(np.asarray(y, dtype=np.float64), 0.0, 1.0)
    with np.errstate(divide="ignore"):
        return np.arctan(np.asarray(alpha, dtype=np.float64) * np.sqrt(y / (1.0 - y)))
