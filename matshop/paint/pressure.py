"""Pressure curves: how pen pressure scales a brush's size or opacity."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidValue
from ..ops.curves import curve_lut

LINEAR = ((0.0, 0.0), (1.0, 1.0))
CONSTANT = ((0.0, 1.0), (1.0, 1.0))


@dataclass(frozen=True)
class PressureCurve:
    """A monotone curve through control points (pressure, factor), both in [0, 1].

    The same PCHIP curve as the curves op, so a pressure curve drawn in the
    UI behaves like a tone curve. ``PressureCurve()`` is the identity;
    ``PressureCurve(CONSTANT)`` ignores pressure.
    """

    points: tuple[tuple[float, float], ...] = LINEAR

    def __post_init__(self) -> None:
        points = tuple((float(x), float(y)) for x, y in self.points)
        if len(points) < 2:
            raise InvalidValue("a pressure curve needs at least two points")
        for x, y in points:
            if not (0.0 <= x <= 1.0 and 0.0 <= y <= 1.0):
                raise InvalidValue(
                    f"pressure curve points must lie in [0, 1]^2, got ({x:g}, {y:g})"
                )
        if any(b[0] <= a[0] for a, b in zip(points, points[1:], strict=False)):
            raise InvalidValue("pressure curve points need strictly increasing pressures")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "_lut", curve_lut(points))

    @classmethod
    def from_points(cls, points: Sequence[Sequence[float]] | None) -> PressureCurve:
        return cls() if points is None else cls(tuple(tuple(p) for p in points))  # type: ignore[arg-type]

    def __call__(self, pressure: float) -> float:
        lut = self._lut  # type: ignore[attr-defined]
        position = min(max(float(pressure), 0.0), 1.0) * (lut.size - 1)
        # the curve's straight continuation past its end points may leave [0, 1]
        return min(max(float(np.interp(position, np.arange(lut.size), lut)), 0.0), 1.0)
