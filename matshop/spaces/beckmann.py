"""Beckmann roughness ``m > 0``: two approximate editing coordinates.

With ``c(theta) = 1 - exp(-tan^2 theta / m^2)``, widening the lobe's angles by
``s`` is approximately ``m -> s m`` (exact in ``tan theta``, not in
``theta``). Two coordinates, each a registry entry:

``beckmann_identity``
    ``e = m`` (the seed paper).
``beckmann_median``
    The median angle ``e = atan(m sqrt(ln 2))`` in radians, back
    ``m = tan(e) / sqrt(ln 2)`` with ``e`` clamped to the image of
    ``[M_MIN, M_MAX]``, i.e. below 90 degrees.

Choice of the default (the bare name ``beckmann``), measured by
:func:`matshop.spaces.fit.scaling_fit` and decided by
:func:`matshop.spaces.fit.best_coordinate` (tests/test_analytic_spaces.py
reproduces both): the coordinate with the lowest worst CDF error over the
scaled lobes that still fit the hemisphere ("fits": 95% angle below 60
degrees), provided its worst error over all lobes is not worse than the
paper's (``identity``). Measured (m in [0.02, 1], s in [0.25, 4]):
identity 0.28 all / 0.27 fits; median 0.91 all / 0.15 fits. The median angle
fits better but diverges once ``s`` times the median passes 90 degrees: the
clamp then returns ``M_MAX``, a lobe lying flat on the horizon (0.91 with the
cap at 89.3 degrees, tending to 1 as the cap approaches 90). So by the rule
the default stays the identity; ``beckmann_median`` is there for edits that
keep lobes inside the hemisphere.

Physical ``m`` is clamped to ``[M_MIN, M_MAX] = [1e-3, 100]`` on the way back.
``M_MIN`` matches Phong's ``N_MAX`` (``n ~ 2/m^2 - 2`` gives 2e6: a mirror);
at ``M_MAX`` about 99% of the microfacet mass lies beyond 85 degrees and the
median angle is 89.3 degrees, so larger values render the same.
"""

from __future__ import annotations

import numpy as np

from .base import EditRange, Space, as_channels

M_MIN = 1.0e-3
M_MAX = 100.0

_F32 = np.float32
_SQRT_LN2 = _F32(np.sqrt(np.log(2.0)))
_M_MIN = _F32(M_MIN)
_M_MAX = _F32(M_MAX)


def _roughness(m: np.ndarray) -> np.ndarray:
    """Physical roughness as float32, negatives (invalid) raised to 0."""
    return np.maximum(np.asarray(m, dtype=_F32), _F32(0.0))


def identity_to_edit(m: np.ndarray) -> np.ndarray:
    return _roughness(m).copy()


def identity_from_edit(e: np.ndarray) -> np.ndarray:
    return np.clip(np.asarray(e, dtype=_F32), _M_MIN, _M_MAX)


def median_to_edit(m: np.ndarray) -> np.ndarray:
    """Median lobe angle ``atan(m sqrt(ln 2))`` in radians, in ``[0, pi/2)``."""
    return np.arctan(_roughness(m) * _SQRT_LN2).astype(_F32, copy=False)


_MEDIAN_E_MIN = median_to_edit(_M_MIN)
_MEDIAN_E_MAX = median_to_edit(_M_MAX)


def median_from_edit(e: np.ndarray) -> np.ndarray:
    """``tan(e) / sqrt(ln 2)``, ``e`` clamped to ``[median(M_MIN), median(M_MAX)]``."""
    e = np.clip(np.asarray(e, dtype=_F32), _MEDIAN_E_MIN, _MEDIAN_E_MAX)
    return np.clip(np.tan(e) / _SQRT_LN2, _M_MIN, _M_MAX).astype(_F32, copy=False)


_COORDINATES = {
    "identity": ("m itself (the seed paper)", identity_to_edit, identity_from_edit, (0.0, 1.0)),
    "median": (
        "median lobe angle atan(m sqrt(ln 2)) in radians",
        median_to_edit,
        median_from_edit,
        (0.0, 0.5 * np.pi),
    ),
}

#: the best-fitting coordinate by the rule in the module docstring
DEFAULT_COORDINATE = "identity"


class BeckmannSpace(Space):
    """Beckmann roughness ``m`` <-> ``identity`` or ``median`` coordinate."""

    family = "beckmann"
    phys_channels = 1
    edit_channels = 1
    curve_mode = "channels"

    def __init__(self, coordinate: str, *, name: str | None = None) -> None:
        description, self._to_edit, self._from_edit, (lo, hi) = _COORDINATES[coordinate]
        self.coordinate = coordinate
        self.name = name or f"beckmann_{coordinate}"
        self.description = f"Beckmann roughness m: {description}"
        self.edit_range = EditRange(lo, hi)

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        return self._to_edit(as_channels(phys, 1, self.name))

    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        return self._from_edit(as_channels(edit, 1, self.name))


SPACES: dict[str, Space] = {
    "beckmann": BeckmannSpace(DEFAULT_COORDINATE, name="beckmann"),
    **{f"beckmann_{key}": BeckmannSpace(key) for key in _COORDINATES},
}
