"""Phong exponent ``n >= 0``: three approximate editing coordinates.

Scaling an edit value by ``s`` should widen the lobe's angles by ``s``
(``c_s(theta) = c(theta / s)``, MATH.md "Analytic distributions"). With
``c(theta) = 1 - cos^(n+2) theta`` no coordinate does this exactly; three are
offered, each a registry entry of its own:

``phong_paper``
    The seed paper's ``e = 1/sqrt(n)``, back ``n = 1/e^2`` (``e >= eps``).
    From ``cos^n theta ~ exp(-n theta^2 / 2)``, which ignores the ``+2`` of the
    CDF, so it is poor for small exponents.
``phong_small_angle``
    ``e = 1/sqrt(n + 2)``, back ``n = 1/e^2 - 2``: the same small-angle
    argument applied to the CDF exponent ``n + 2``.
``phong_median``
    The median angle ``e = acos(2^(-1/(n+2)))``, back
    ``n = -ln 2 / ln(cos e) - 2``. The median of a Phong lobe never exceeds
    45 degrees (``n = 0``), so ``e`` is clamped to ``(0, 45 deg]`` before
    inverting, comfortably below 90 degrees where ``ln cos`` blows up.

Choice of the default (the bare name ``phong``), measured by
:func:`matshop.spaces.fit.scaling_fit` and decided by
:func:`matshop.spaces.fit.best_coordinate` (tests/test_analytic_spaces.py
reproduces both): the coordinate with the lowest worst CDF error over the
scaled lobes that still fit the hemisphere ("fits": 95% angle below 60
degrees), provided its worst error over all lobes is not worse than the
paper's. Measured (n in [1, 1e4], s in [0.25, 4]):

====================  =====  =====
coordinate            all    fits
====================  =====  =====
paper ``1/sqrt(n)``   0.41   0.41
small angle           0.28   0.066
median angle          0.28   0.047
====================  =====  =====

so the default is ``median``; ``phong_paper`` keeps the seed's behaviour.

Physical exponents are clamped to ``[0, N_MAX]`` on the way back. ``N_MAX =
1e6`` is a median lobe angle of about 1.2 mrad (0.07 degrees): a mirror for any
texture or environment resolution, yet still resolvable in float32, where
``cos theta`` rounds to 1 below about 0.35 mrad (so larger exponents stop
meaning anything in a float32 renderer). It also gives every coordinate a
positive minimum edit value (about 1e-3), so a mirror (``e = 0`` or ``n =
inf``) maps to a finite exponent instead of ``inf``.

The coordinate functions below are pure float32 maps on arrays of any shape;
Ashikhmin-Shirley (two exponents) reuses them per channel.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ._kernels import PHONG_MEDIAN_FROM_EDIT, PHONG_MEDIAN_TO_EDIT, Step
from .base import EditRange, Space, as_channels

#: largest physical exponent produced by ``from_edit`` (see module docstring)
N_MAX = 1.0e6
#: the paper coordinate's floor on ``n`` in ``to_edit``: ``1/sqrt(0)`` is
#: infinite, so ``n = 0`` maps to ``e = 1000`` (and back to ``n = 1e-6``)
N_FLOOR_PAPER = 1.0e-6

_F32 = np.float32
_N_MAX = _F32(N_MAX)


def _exponent(n: np.ndarray) -> np.ndarray:
    """Physical exponents as float32, negatives (invalid) raised to 0."""
    return np.maximum(np.asarray(n, dtype=_F32), _F32(0.0))


def _finish_exponent(n: np.ndarray) -> np.ndarray:
    return np.clip(n, _F32(0.0), _N_MAX).astype(_F32, copy=False)


# --- paper: e = 1/sqrt(n) ------------------------------------------------------------

_PAPER_E_MIN = _F32(1.0 / np.sqrt(N_MAX))


def paper_to_edit(n: np.ndarray) -> np.ndarray:
    """``1/sqrt(n)``, with ``n`` floored at :data:`N_FLOOR_PAPER`."""
    n = np.maximum(_exponent(n), _F32(N_FLOOR_PAPER))
    return (_F32(1.0) / np.sqrt(n)).astype(_F32, copy=False)


def paper_from_edit(e: np.ndarray) -> np.ndarray:
    """``1/e^2`` with ``e >= 1/sqrt(N_MAX)``."""
    # the upper clip only keeps e*e finite: any e above it already means n == 0
    e = np.clip(np.asarray(e, dtype=_F32), _PAPER_E_MIN, _F32(1e15))
    return _finish_exponent(_F32(1.0) / (e * e))


# --- small angle: e = 1/sqrt(n + 2) --------------------------------------------------

_SMALL_E_MIN = _F32(1.0 / np.sqrt(N_MAX + 2.0))
_SMALL_E_MAX = _F32(1.0 / np.sqrt(2.0))


def small_angle_to_edit(n: np.ndarray) -> np.ndarray:
    """``1/sqrt(n + 2)``: in ``(0, 1/sqrt(2)]``."""
    return (_F32(1.0) / np.sqrt(_exponent(n) + _F32(2.0))).astype(_F32, copy=False)


def small_angle_from_edit(e: np.ndarray) -> np.ndarray:
    """``1/e^2 - 2`` with ``e`` clamped to the image of ``[0, N_MAX]``."""
    e = np.clip(np.asarray(e, dtype=_F32), _SMALL_E_MIN, _SMALL_E_MAX)
    return _finish_exponent(_F32(1.0) / (e * e) - _F32(2.0))


# --- median angle: e = acos(2^(-1/(n+2))) --------------------------------------------


def median_to_edit(n: np.ndarray) -> np.ndarray:
    """Median angle ``acos(2^(-1/(n+2)))`` in radians, in ``(0, pi/4]``.

    Evaluated as ``sqrt(x) G(x)``, ``x = 1/(n + 2)`` and ``G`` a fitted
    polynomial, so that large exponents (tiny angles) keep full precision: one
    fused kernel pass in float64 (``_kernels``), within an ulp of the float32
    rounding of the exact value and equal to it nearly everywhere
    (tests/test_kernels.py).
    """
    return _MEDIAN_TO.run(*_in_out(n))


def median_from_edit(e: np.ndarray) -> np.ndarray:
    """``-ln 2 / ln(cos e) - 2`` with ``e`` clamped to ``[median(N_MAX), pi/4]``.

    Evaluated in float64 (one fused kernel pass) as ``S(e) (pi/4 - e) / e^2``,
    ``S`` a fitted polynomial: float32 arithmetic of the closed form lost up to
    3e-4 relative near ``N_MAX``, and the difference ``... - 2`` loses digits
    near ``n = 0``, where the factor ``pi/4 - e`` keeps them.
    """
    return _MEDIAN_FROM.run(*_in_out(e))


def _in_out(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(values, dtype=_F32)
    return v, np.empty(v.shape, dtype=_F32)


# the same formula in numpy float64 (no kernel call at import time)
_MEDIAN_E_MIN = _F32(2.0 * np.arcsin(np.sqrt(-0.5 * np.expm1(-np.log(2.0) / (N_MAX + 2.0)))))
_MEDIAN_E_MAX = _F32(0.25 * np.pi)
_MEDIAN_TO = Step(False, PHONG_MEDIAN_TO_EDIT, lo=0.0)
_MEDIAN_FROM = Step(
    False, PHONG_MEDIAN_FROM_EDIT, float(_MEDIAN_E_MIN), float(_MEDIAN_E_MAX), N_MAX
)


# --- the space -------------------------------------------------------------------------


@dataclass(frozen=True)
class ExponentCoordinate:
    """One edit coordinate for a Phong-like exponent: a pair of float32 maps."""

    key: str
    description: str
    to_edit: Callable[[np.ndarray], np.ndarray]
    from_edit: Callable[[np.ndarray], np.ndarray]
    edit_range: EditRange


COORDINATES: dict[str, ExponentCoordinate] = {
    "paper": ExponentCoordinate(
        "paper", "1/sqrt(n) (the seed paper)", paper_to_edit, paper_from_edit, EditRange(0.0, 1.0)
    ),
    "small_angle": ExponentCoordinate(
        "small_angle",
        "1/sqrt(n + 2) (small-angle exact)",
        small_angle_to_edit,
        small_angle_from_edit,
        EditRange(0.0, float(_SMALL_E_MAX)),
    ),
    "median": ExponentCoordinate(
        "median",
        "median lobe angle acos(2^(-1/(n+2))) in radians",
        median_to_edit,
        median_from_edit,
        EditRange(0.0, float(_MEDIAN_E_MAX)),
    ),
}

#: the best-fitting coordinate by the rule in the module docstring
DEFAULT_COORDINATE = "median"


class PhongSpace(Space):
    """Phong exponent(s) ``n >= 0`` <-> one of :data:`COORDINATES`, per channel."""

    family = "phong"
    curve_mode = "channels"

    def __init__(self, coordinate: str, *, name: str | None = None, channels: int = 1) -> None:
        self.coordinate = coordinate
        self._maps = COORDINATES[coordinate]
        self.name = name or f"{self.family}_{coordinate}"
        self.description = f"{self._what()}: {self._maps.description}"
        self.phys_channels = channels
        self.edit_channels = channels
        self.edit_range = self._maps.edit_range

    def _what(self) -> str:
        return "Phong exponent n"

    def to_edit_step(self) -> Step | None:
        # the median coordinate (the default) is a fused kernel step; the others numpy
        return _MEDIAN_TO if self.coordinate == "median" else None

    def from_edit_step(self) -> Step | None:
        return _MEDIAN_FROM if self.coordinate == "median" else None

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        return self._maps.to_edit(as_channels(phys, self.phys_channels, self.name))

    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        return self._maps.from_edit(as_channels(edit, self.edit_channels, self.name))


SPACES: dict[str, Space] = {
    "phong": PhongSpace(DEFAULT_COORDINATE, name="phong"),
    **{f"phong_{key}": PhongSpace(key) for key in COORDINATES},
}
