"""GGX / Trowbridge-Reitz roughness as engines store it: perceptual ``r`` in [0, 1].

Engines (glTF, Unreal, Unity, Godot) store ``r`` with ``alpha = r^2``. With
``c(theta) = tan^2 theta / (alpha^2 + tan^2 theta)``, widening the lobe's
angles by ``s`` is approximately ``alpha -> s alpha`` (exact in
``tan theta``). Two coordinates, each a registry entry:

``ggx_alpha``
    ``e = alpha = r^2`` (MATH.md / DESIGN.md), back ``r = sqrt(clamp(e, 0, 1))``.
``ggx_median``
    The median angle ``e = atan(alpha)`` in radians, back
    ``r = sqrt(clamp(tan e, 0, 1))``; ``e`` is clamped to ``[0, 45 deg]``
    (``alpha <= 1``) before ``tan``, well below 90 degrees.

Choice of the default (the bare name ``ggx``), measured by
:func:`matshop.spaces.fit.scaling_fit` and decided by
:func:`matshop.spaces.fit.best_coordinate` (tests/test_analytic_spaces.py
reproduces both): the coordinate with the lowest worst CDF error over the
scaled lobes that still fit the hemisphere ("fits": 95% angle below 60
degrees), provided its worst error over all lobes is not worse than the
paper's (``alpha``). Measured (alpha in [0.02, 1], s in [0.25, 4]):
``alpha`` 0.29 all / 0.29 fits, ``median`` 0.29 all / 0.20 fits. So the
default is the median angle, not DESIGN.md's ``alpha = r^2`` (kept as
``ggx_alpha``). Both coordinates share their worst case overall
(alpha = 1, s = 4), where both are cut at ``alpha = 1``: the engines' range
``r <= 1`` is what keeps the median coordinate from diverging as Beckmann's
does (with ``alpha`` unbounded it reaches 0.98).

Both coordinates round-trip every 8-bit code ``r = k/255`` to itself.
"""

from __future__ import annotations

import math

import numpy as np

from ._kernels import ATAN_SQUARE, SQRT, SQRT_TAN, SQUARE, Step
from .base import EditRange, FusedSpace, Space

_QUARTER_PI = 0.25 * math.pi


# the kernel steps of the two coordinates (clamp, then the curve)
_ALPHA_TO = Step(False, SQUARE, 0.0, 1.0)
_ALPHA_FROM = Step(False, SQRT, 0.0, 1.0)
_MEDIAN_TO = Step(False, ATAN_SQUARE, 0.0, 1.0)
_MEDIAN_FROM = Step(False, SQRT_TAN, 0.0, _QUARTER_PI)


def _map(values: np.ndarray, out: np.ndarray | None, step: Step) -> np.ndarray:
    """One fused pass of ``step`` into ``out`` or a new array."""
    v = np.asarray(values, dtype=np.float32)
    if out is None:
        out = np.empty(v.shape, dtype=np.float32)
    return step.run(v, out)


def alpha_to_edit(r: np.ndarray, *, out: np.ndarray | None = None) -> np.ndarray:
    """``alpha = r^2`` with ``r`` clamped to ``[0, 1]``."""
    return _map(r, out, _ALPHA_TO)


def alpha_from_edit(e: np.ndarray, *, out: np.ndarray | None = None) -> np.ndarray:
    """``r = sqrt(clamp(alpha, 0, 1))``."""
    return _map(e, out, _ALPHA_FROM)


def median_to_edit(r: np.ndarray, *, out: np.ndarray | None = None) -> np.ndarray:
    """Median lobe angle ``atan(r^2)`` in radians, in ``[0, pi/4]`` (``r`` clamped to [0, 1])."""
    return _map(r, out, _MEDIAN_TO)


def median_from_edit(e: np.ndarray, *, out: np.ndarray | None = None) -> np.ndarray:
    """``r = sqrt(clamp(tan e, 0, 1))`` with ``e`` clamped to ``[0, pi/4]`` first."""
    return _map(e, out, _MEDIAN_FROM)


#: per coordinate: description, the two kernel steps (what the functions above run), range
_COORDINATES = {
    "alpha": (
        "alpha = r^2 (MATH.md)",
        _ALPHA_TO,
        _ALPHA_FROM,
        (0.0, 1.0),
    ),
    "median": (
        "median lobe angle atan(r^2) in radians",
        _MEDIAN_TO,
        _MEDIAN_FROM,
        (0.0, 0.25 * np.pi),
    ),
}

#: the best-fitting coordinate by the rule in the module docstring
DEFAULT_COORDINATE = "median"


class GGXSpace(FusedSpace):
    """GGX perceptual roughness ``r`` <-> ``alpha`` or ``median`` coordinate."""

    family = "ggx"
    phys_channels = 1
    edit_channels = 1
    curve_mode = "channels"

    def __init__(self, coordinate: str, *, name: str | None = None) -> None:
        description, self._to_step, self._from_step, (lo, hi) = _COORDINATES[coordinate]
        self.coordinate = coordinate
        self.name = name or f"ggx_{coordinate}"
        self.description = f"GGX perceptual roughness r (alpha = r^2): {description}"
        self.edit_range = EditRange(lo, hi)

    def to_edit_step(self) -> Step:
        return self._to_step

    def from_edit_step(self) -> Step:
        return self._from_step


SPACES: dict[str, Space] = {
    "ggx": GGXSpace(DEFAULT_COORDINATE, name="ggx"),
    **{f"ggx_{key}": GGXSpace(key) for key in _COORDINATES},
}
