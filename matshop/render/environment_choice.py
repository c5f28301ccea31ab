"""The artist's lighting choice: which environment, turned how far, at what exposure.

One description read the same way by ``matshop render`` (``--env``,
``--env-rotation``, ``--exposure``), the editor's 3D view and its lit display
(the View > Lighting menu and the Lighting toolbar), and saved with the
editor's settings and projects (:meth:`EnvironmentChoice.to_json`).

- ``source``: ``"studio"``, ``"sky"``, ``"uniform"`` (radiance 1), ``"uniform:L"``,
  or the path of an equirectangular .hdr/.exr
  (:func:`matshop.render.environment.load_environment`);
- ``rotation_deg``: the environment turned about world up (+y) by this many
  degrees; what was at azimuth ``phi`` (measured from the view direction -z
  towards +x) moves to ``phi + rotation_deg``: a positive turn carries the
  environment to the camera's right. Whole texels of the map
  (:meth:`~matshop.render.environment.Environment.rotated`);
- ``exposure_stops``: the picture's linear radiance is multiplied by
  ``2 ** exposure_stops`` before the tone map (+1 stop doubles it).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from .environment import PROCEDURAL, Environment, load_environment, uniform_radiance

#: the preset names, in the order the editor offers them
PRESETS = ("studio", "sky", "uniform")
#: file types an environment may be
SUFFIXES = (".hdr", ".exr")
EXPOSURE_RANGE_STOPS = (-16.0, 16.0)


def _number(value: Any, what: str, lo: float, hi: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise MatshopError(f"{what} must be a number, got {value!r}") from None
    if not (math.isfinite(number) and lo <= number <= hi):
        raise MatshopError(f"{what} must be a number from {lo:g} to {hi:g}, got {value!r}")
    return number


@dataclass(frozen=True)
class EnvironmentChoice:
    """See the module doc. Build it with :meth:`parse`, which checks every field."""

    source: str = "studio"
    rotation_deg: float = 0.0
    exposure_stops: float = 0.0

    @classmethod
    def parse(
        cls,
        source: str | os.PathLike[str] | None = "studio",
        rotation_deg: Any = 0.0,
        exposure_stops: Any = 0.0,
    ) -> EnvironmentChoice:
        """A checked choice; a bad field raises a one-line :class:`MatshopError`.

        A file source must exist and end in .hdr or .exr (its pixels are only
        read by :meth:`load`); the rotation is kept in [0, 360).
        """
        text = "studio" if source is None else os.fspath(source)
        if text not in PROCEDURAL and uniform_radiance(text) is None:
            path = Path(text)
            if path.suffix.lower() not in SUFFIXES:
                raise MatshopError(
                    "an environment is studio, sky, uniform, uniform:L or an equirectangular "
                    ".hdr/.exr file",
                    text,
                )
            if not path.is_file():
                raise MatshopError("no such environment file", text)
            text = os.path.abspath(text)  # settings and projects outlive the working folder
        rotation = _number(rotation_deg, "the environment rotation (degrees)", -1e6, 1e6) % 360.0
        exposure = _number(exposure_stops, "the exposure (stops)", *EXPOSURE_RANGE_STOPS)
        return cls(text, rotation, exposure)

    @property
    def is_file(self) -> bool:
        return self.source not in PROCEDURAL and uniform_radiance(self.source) is None

    @property
    def label(self) -> str:
        """What the editor calls it: "Studio", "Uniform 0.5", a file's name."""
        if self.is_file:
            return Path(self.source).name
        radiance = uniform_radiance(self.source)
        if radiance is not None and radiance != 1.0:
            return f"Uniform {radiance:g}"
        return self.source.split(":")[0].capitalize()

    def changed(self, **changes: Any) -> EnvironmentChoice:
        """A copy with some fields changed, checked as :meth:`parse` checks."""
        fields = {
            "source": self.source,
            "rotation_deg": self.rotation_deg,
            "exposure_stops": self.exposure_stops,
        }
        fields.update(changes)
        return EnvironmentChoice.parse(**fields)

    def load_base(self, progress: Callable[[int, int], None] | None = None) -> Environment:
        """The environment as its source gives it, not yet turned (slow for a big file)."""
        return load_environment(self.source, progress=progress)

    def turn(self, base: Environment) -> Environment:
        """``base`` (this choice's :meth:`load_base`) turned by :attr:`rotation_deg`."""
        return base.rotated(self.rotation_deg) if self.rotation_deg else base

    def load(self, progress: Callable[[int, int], None] | None = None) -> Environment:
        """The environment to light with: read (or generated), then turned."""
        return self.turn(self.load_base(progress))

    # -- settings and projects ------------------------------------------------

    def to_json(self) -> dict[str, Any]:
        return {
            "environment": self.source,
            "rotation_deg": self.rotation_deg,
            "exposure_stops": self.exposure_stops,
        }

    @classmethod
    def from_json(cls, data: Any) -> EnvironmentChoice:
        """A choice saved by :meth:`to_json`; anything else raises a one-line error."""
        if not isinstance(data, dict) or not isinstance(data.get("environment"), str):
            raise MatshopError(f"a lighting choice is an object with an environment, got {data!r}")
        return cls.parse(
            data["environment"], data.get("rotation_deg", 0.0), data.get("exposure_stops", 0.0)
        )
