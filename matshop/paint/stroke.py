"""Placing dabs along a stroke by spacing."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from ..errors import InvalidValue
from .brush import Brush


@dataclass(frozen=True)
class StrokeSample:
    """One input event: position in continuous texel coordinates, pen pressure in [0, 1]."""

    x: float
    y: float
    pressure: float = 1.0

    def __post_init__(self) -> None:
        if not all(math.isfinite(v) for v in (self.x, self.y, self.pressure)):
            raise InvalidValue(f"stroke sample must be finite, got {self}")
        if not 0.0 <= self.pressure <= 1.0:
            raise InvalidValue(f"pressure must lie in [0, 1], got {self.pressure:g}")


@dataclass(frozen=True)
class Dab:
    """One stamp of the brush."""

    x: float
    y: float
    radius_px: float
    flow: float
    #: the most the stroke may cover where this dab lands (the brush's opacity x pressure)
    opacity: float = 1.0


class Stroker:
    """Turns samples into dabs, one at the first sample, then every ``brush.step_at`` texels.

    Feed samples as they arrive (:meth:`add` may be called per input event);
    the distance walked since the last dab carries over between calls, so
    the dabs do not depend on how the samples were batched. Pressure is
    interpolated linearly along each segment.
    """

    def __init__(self, brush: Brush) -> None:
        self.brush = brush
        self._last: StrokeSample | None = None
        self._to_next = 0.0  # distance left to walk before the next dab

    def _dab(self, x: float, y: float, pressure: float) -> Dab:
        brush = self.brush
        return Dab(
            x, y, brush.radius_at(pressure), brush.flow_at(pressure), brush.opacity_at(pressure)
        )

    def add(self, samples: Iterable[StrokeSample]) -> list[Dab]:
        dabs: list[Dab] = []
        for sample in samples:
            last = self._last
            self._last = sample
            if last is None:
                dabs.append(self._dab(sample.x, sample.y, sample.pressure))
                self._to_next = self.brush.step_at(sample.pressure)
                continue
            length = math.hypot(sample.x - last.x, sample.y - last.y)
            walked = 0.0
            while length - walked >= self._to_next:
                walked += self._to_next
                t = walked / length
                pressure = last.pressure + t * (sample.pressure - last.pressure)
                x = last.x + t * (sample.x - last.x)
                y = last.y + t * (sample.y - last.y)
                dabs.append(self._dab(x, y, pressure))
                self._to_next = self.brush.step_at(pressure)
            self._to_next -= length - walked
        return dabs
