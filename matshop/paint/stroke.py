"""Placing dabs along a stroke by spacing."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace

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
    """One stamp of the brush, before dynamics (jitter, scatter, tip angle).

    ``direction``: the stroke's heading where the dab lies, ``atan2(dy, dx)``
    in texel space (y down); None for a stroke that never moved.
    """

    x: float
    y: float
    radius_px: float
    flow: float
    #: the most the stroke may cover where this dab lands (the brush's opacity x pressure)
    opacity: float = 1.0
    direction: float | None = None


class Stroker:
    """Turns samples into dabs, one at the first sample, then every ``brush.step_at`` texels.

    Feed samples as they arrive (:meth:`add` may be called per input event);
    the distance walked since the last dab carries over between calls, so
    the dabs do not depend on how the samples were batched. Pressure is
    interpolated linearly along each segment; each dab carries the heading
    of its segment. When the brush's dynamics need that heading, the first
    dab waits until the stroke moves (or :meth:`finish`, for a click).
    """

    def __init__(self, brush: Brush) -> None:
        self.brush = brush
        self._last: StrokeSample | None = None
        self._to_next = 0.0  # distance left to walk before the next dab
        self._pending: Dab | None = None  # the first dab, waiting for a direction

    def _dab(self, x: float, y: float, pressure: float, direction: float | None) -> Dab:
        brush = self.brush
        return Dab(
            x,
            y,
            brush.radius_at(pressure),
            brush.flow_at(pressure),
            brush.opacity_at(pressure),
            direction,
        )

    def add(self, samples: Iterable[StrokeSample]) -> list[Dab]:
        dabs: list[Dab] = []
        for sample in samples:
            last = self._last
            self._last = sample
            if last is None:
                first = self._dab(sample.x, sample.y, sample.pressure, None)
                if self.brush.dynamics.needs_direction:
                    self._pending = first
                else:
                    dabs.append(first)
                self._to_next = self.brush.step_at(sample.pressure)
                continue
            length = math.hypot(sample.x - last.x, sample.y - last.y)
            if length == 0.0:
                continue
            direction = math.atan2(sample.y - last.y, sample.x - last.x)
            if self._pending is not None:
                dabs.append(replace(self._pending, direction=direction))
                self._pending = None
            walked = 0.0
            while length - walked >= self._to_next:
                walked += self._to_next
                t = walked / length
                pressure = last.pressure + t * (sample.pressure - last.pressure)
                x = last.x + t * (sample.x - last.x)
                y = last.y + t * (sample.y - last.y)
                dabs.append(self._dab(x, y, pressure, direction))
                self._to_next = self.brush.step_at(pressure)
            self._to_next -= length - walked
        return dabs

    def finish(self) -> list[Dab]:
        """The dabs still held at the end of the stroke (the first, if it never moved)."""
        pending, self._pending = self._pending, None
        return [] if pending is None else [pending]
