"""Brush settings and the footprint of one dab."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InvalidValue
from .dynamics import Dynamics
from .pressure import CONSTANT, PressureCurve
from .tips import Tip, tip_footprint


@dataclass(frozen=True)
class Brush:
    """What a brush does, in the units artists set it in.

    Attributes
    ----------
    radius_px : float
        Dab radius at full pressure, in texels.
    hardness : float
        Fraction of the radius painted at full strength; the rest falls off
        smoothly (0: all falloff, 1: a hard edge, still anti-aliased).
    spacing : float
        Distance between dabs as a fraction of the dab's diameter.
    opacity : float
        The most one stroke can cover: overlapping dabs of a stroke never
        build up past it (Krita's and Photoshop's stroke opacity).
    flow : float
        Strength of each dab within the stroke; low flow builds up.
    size_pressure, opacity_pressure, flow_pressure : PressureCurve
        Pressure -> factor on the radius, on the opacity a dab builds the
        stroke up to, and on each dab's flow. ``CONSTANT`` switches a target off.
    tip : Tip, optional
        A grayscale tip image stamped instead of the round dab (hardness then
        does not apply); None: the round dab.
    dynamics : Dynamics
        Tip angle, size and angle jitter, scatter (any tip, round included).
    """

    radius_px: float = 16.0
    hardness: float = 0.5
    spacing: float = 0.15
    opacity: float = 1.0
    flow: float = 1.0
    size_pressure: PressureCurve = field(default_factory=PressureCurve)
    opacity_pressure: PressureCurve = field(default_factory=lambda: PressureCurve(CONSTANT))
    flow_pressure: PressureCurve = field(default_factory=lambda: PressureCurve(CONSTANT))
    tip: Tip | None = None
    dynamics: Dynamics = field(default_factory=Dynamics)

    def __post_init__(self) -> None:
        checks = {
            "radius_px": (self.radius_px, 0.5, 4096.0),
            "hardness": (self.hardness, 0.0, 1.0),
            "spacing": (self.spacing, 0.01, 10.0),
            "opacity": (self.opacity, 0.0, 1.0),
            "flow": (self.flow, 0.0, 1.0),
        }
        for name, (value, lo, hi) in checks.items():
            if not (math.isfinite(value) and lo <= value <= hi):
                raise InvalidValue(f"brush {name} must lie in [{lo:g}, {hi:g}], got {value!r}")

    def radius_at(self, pressure: float) -> float:
        # a dab never shrinks below half a texel: a light touch still paints
        return max(self.radius_px * self.size_pressure(pressure), 0.5)

    def flow_at(self, pressure: float) -> float:
        return self.flow * self.flow_pressure(pressure)

    def opacity_at(self, pressure: float) -> float:
        """The most the stroke covers where a dab at this pressure lands."""
        return self.opacity * self.opacity_pressure(pressure)

    @property
    def opacity_follows_pressure(self) -> bool:
        return self.opacity_pressure.points != CONSTANT

    def step_at(self, pressure: float) -> float:
        """Distance to the next dab, in texels."""
        return max(self.spacing * 2.0 * self.radius_at(pressure), 0.5)

    def footprint(
        self, x: float, y: float, radius_px: float, angle_deg: float
    ) -> tuple[int, int, np.ndarray]:
        """One dab's alpha ``(x0, y0, alpha)``: the tip image, or the round dab."""
        if self.tip is None:
            return dab_footprint(x, y, radius_px, self.hardness)  # round: the angle is moot
        return tip_footprint(x, y, radius_px, angle_deg, self.tip)


def dab_footprint(
    x: float, y: float, radius_px: float, hardness: float
) -> tuple[int, int, np.ndarray]:
    """The alpha of one dab centred at (x, y): ``(x0, y0, alpha (h, w))``.

    Coordinates are continuous texel coordinates (texel (i, j) spans
    [i, i + 1) x [j, j + 1), its centre at +0.5). The result is unclipped:
    ``x0, y0`` may be negative or reach past the image, for the caller to
    clip or wrap. Alpha is 1 within ``hardness * radius`` and falls to 0 at
    ``radius + 0.5`` along a smoothstep; the falloff is at least one texel
    wide, centred on the radius for a hard dab, so a hard dab is anti-aliased
    and covers the area of its disc.
    """
    outer = radius_px + 0.5
    inner = max(min(hardness * radius_px, radius_px - 0.5), 0.0)
    x0 = math.floor(x - outer)
    y0 = math.floor(y - outer)
    x1 = math.ceil(x + outer)
    y1 = math.ceil(y + outer)
    cols = np.arange(x0, x1, dtype=np.float32) + np.float32(0.5 - x)
    rows = np.arange(y0, y1, dtype=np.float32) + np.float32(0.5 - y)
    distance = np.sqrt(rows[:, None] ** 2 + cols[None, :] ** 2)
    t = np.clip((np.float32(outer) - distance) / np.float32(outer - inner), 0.0, 1.0)
    alpha = t * t * (np.float32(3.0) - np.float32(2.0) * t)
    return x0, y0, alpha.astype(np.float32)
