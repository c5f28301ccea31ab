"""Where and how each dab lands: tip angle (fixed, following the stroke, random), size and
angle jitter, scatter along and across the stroke.

Random choices come from a stroke's own seeded generator (NumPy's PCG64),
five numbers a dab whatever the settings, so a stroke replays identically
from its seed, and turning one setting does not reshuffle the others.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidValue

ROTATIONS = ("fixed", "follow", "random")
#: scatter beyond this many dab diameters is no longer a stroke
MAX_SCATTER = 10.0


@dataclass(frozen=True)
class Dynamics:
    """How dabs vary along a stroke.

    Attributes
    ----------
    rotation : {"fixed", "follow", "random"}
        The tip's angle: ``angle_deg``; ``angle_deg`` plus the stroke's
        direction (the tip's right edge points where the stroke goes); or
        ``angle_deg`` plus a uniform random turn.
    angle_deg : float
        Counter-clockwise on screen, in degrees.
    size_jitter : float in [0, 1]
        Each dab's radius is scaled by ``1 - size_jitter * u``, u uniform in
        [0, 1) (never larger than the brush: the cursor ring is the bound).
    angle_jitter_deg : float in [0, 180]
        Each dab turns by up to this much either way, uniformly.
    scatter_along, scatter_across : float in [0, MAX_SCATTER]
        Each dab moves by up to this many dab diameters either way along /
        across the stroke's direction, uniformly.
    """

    rotation: str = "fixed"
    angle_deg: float = 0.0
    size_jitter: float = 0.0
    angle_jitter_deg: float = 0.0
    scatter_along: float = 0.0
    scatter_across: float = 0.0

    def __post_init__(self) -> None:
        if self.rotation not in ROTATIONS:
            raise InvalidValue(
                f"tip rotation must be {', '.join(ROTATIONS)}, got {self.rotation!r}"
            )
        checks = {
            "angle_deg": (self.angle_deg, -360.0, 360.0),
            "size_jitter": (self.size_jitter, 0.0, 1.0),
            "angle_jitter_deg": (self.angle_jitter_deg, 0.0, 180.0),
            "scatter_along": (self.scatter_along, 0.0, MAX_SCATTER),
            "scatter_across": (self.scatter_across, 0.0, MAX_SCATTER),
        }
        for name, (value, lo, hi) in checks.items():
            if not (math.isfinite(value) and lo <= value <= hi):
                raise InvalidValue(f"brush {name} must lie in [{lo:g}, {hi:g}], got {value!r}")

    @property
    def needs_direction(self) -> bool:
        """The stroke's direction matters for the first dab (so it waits for the stroke to move)."""
        return self.rotation == "follow" or self.scatter_along > 0 or self.scatter_across > 0

    @property
    def random(self) -> bool:
        return (
            self.rotation == "random"
            or self.size_jitter > 0
            or self.angle_jitter_deg > 0
            or self.scatter_along > 0
            or self.scatter_across > 0
        )


@dataclass(frozen=True)
class Placed:
    """A dab after dynamics: centre, radius and tip angle (degrees, counter-clockwise)."""

    x: float
    y: float
    radius_px: float
    angle_deg: float


class DabShaper:
    """Applies :class:`Dynamics` to the dabs of one stroke, in order, from ``seed``."""

    def __init__(self, dynamics: Dynamics, seed: int) -> None:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
            raise InvalidValue(f"stroke seed must be an integer in [0, 2^63), got {seed!r}")
        self.dynamics = dynamics
        self._rng = np.random.default_rng(seed)

    def place(self, x: float, y: float, radius_px: float, direction: float | None) -> Placed:
        """``direction``: the stroke's heading in texel space (``atan2(dy, dx)``, y down)."""
        d = self.dynamics
        size_u, angle_u, turn_u, along_u, across_u = self._rng.random(5).tolist()
        heading = 0.0 if direction is None else direction
        angle = d.angle_deg
        if d.rotation == "follow":
            angle += -math.degrees(heading)  # y points down: on screen, counter-clockwise is -y
        elif d.rotation == "random":
            angle += 360.0 * turn_u
        angle += d.angle_jitter_deg * (2.0 * angle_u - 1.0)
        radius = max(radius_px * (1.0 - d.size_jitter * size_u), 0.5)
        diameter = 2.0 * radius_px
        along = d.scatter_along * diameter * (2.0 * along_u - 1.0)
        across = d.scatter_across * diameter * (2.0 * across_u - 1.0)
        cos, sin = math.cos(heading), math.sin(heading)
        return Placed(x + along * cos - across * sin, y + along * sin + across * cos, radius, angle)
