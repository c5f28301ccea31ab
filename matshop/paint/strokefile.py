"""Stroke files: brush strokes as JSON, for pipelines and replayable tests.

::

    {"strokes": [
      {"layer": "Paint 2",            # layer name or id; default: the top paint layer
       "mode": "paint",               # paint | erase | clone
       "target": "pixels",            # pixels | mask
       "brush": {"radius_px": 24, "hardness": 0.8, "spacing": 0.1,
                 "opacity": 1, "flow": 1,
                 "size_pressure": [[0, 0.2], [1, 1]],    # pen pressure -> factor (PCHIP)
                 "opacity_pressure": [[0, 0], [1, 1]],   # each one switched on by giving it
                 "flow_pressure": [[0, 0.5], [1, 1]]},
       "swatch": {"name": "bronze", "values": {"base_color": [0.45, 0.25, 0.08],
                                                "roughness": [0.3]}},
       "mask_value": 1.0, "clone_offset": [-30, 12], "wrap": true,
       "symmetry": "x",               # none | x | y | xy: mirror about the centre lines
       "symmetry_centre": [cx, cy],   # where they cross (texels); default the middle
       "points": [[x, y, pressure], [x, y], ...]}
    ]}

A file may also be a single stroke object or a list of them. Coordinates are
texels from the top-left corner; pressure defaults to 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InvalidValue, MatshopError, naming
from ..io.jsonfile import read_json
from .brush import Brush
from .pressure import PressureCurve
from .stroke import StrokeSample
from .swatch import Swatch
from .symmetry import Symmetry

MAX_POINTS = 1_000_000
#: coordinates beyond 16x the largest document side mean nothing more
MAX_COORD_PX = float(1 << 20)
#: dabs one stroke file may place (path lengths over the brush's smallest step):
#: a stroke across a 65536-texel document at the finest spacing fits (~160 us a dab)
MAX_DABS = 250_000
_BRUSH_NUMBERS = ("radius_px", "hardness", "spacing", "opacity", "flow")
_PRESSURE_CURVES = ("size_pressure", "opacity_pressure", "flow_pressure")
_STROKE_KEYS = {
    "layer",
    "mode",
    "target",
    "brush",
    "swatch",
    "mask_value",
    "clone_offset",
    "wrap",
    "symmetry",
    "symmetry_centre",
    "points",
}


@dataclass
class StrokeSpec:
    """One stroke read from a file, ready for :class:`~matshop.paint.StrokeSession`."""

    layer: str | int | None
    samples: list[StrokeSample]
    brush: Brush
    options: dict[str, Any] = field(default_factory=dict)
    #: at most this many dabs (bounds the time painting it takes)
    dabs: float = 0.0


def _brush(data: Any) -> Brush:
    if data is None:
        return Brush()
    if not isinstance(data, dict):
        raise InvalidValue("brush must be an object")
    unknown = set(data) - {*_BRUSH_NUMBERS, *_PRESSURE_CURVES}
    if unknown:
        raise InvalidValue(f"brush has unknown setting(s) {', '.join(sorted(unknown))}")
    numbers = {}
    for key in _BRUSH_NUMBERS:
        if key in data:
            numbers[key] = _number(data[key], f"brush {key}")
    curves = {key: PressureCurve.from_points(data[key]) for key in _PRESSURE_CURVES if key in data}
    return Brush(**numbers, **curves)


def _number(value: Any, what: str) -> float:
    """A JSON number (not a boolean, not text) as a float (read_json bounds the digits)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidValue(f"{what} must be a number")
    return float(value)


def _centre(value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    if not (isinstance(value, list) and len(value) == 2):
        raise InvalidValue("symmetry_centre must be [x, y] in texels")
    cx, cy = (_number(v, "symmetry_centre") for v in value)
    if max(abs(cx), abs(cy)) > MAX_COORD_PX:
        raise InvalidValue(f"symmetry_centre {value!r} lies beyond +-{MAX_COORD_PX:g} texels")
    return cx, cy


def _samples(points: Any) -> list[StrokeSample]:
    if not isinstance(points, list) or not points:
        raise InvalidValue("points must be a non-empty list of [x, y] or [x, y, pressure]")
    if len(points) > MAX_POINTS:
        raise InvalidValue(f"a stroke has at most {MAX_POINTS} points, got {len(points)}")
    samples = []
    for point in points:
        ok = isinstance(point, list) and len(point) in (2, 3)
        if not ok or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in point):
            raise InvalidValue(f"bad point {point!r}: expected [x, y] or [x, y, pressure]")
        sample = StrokeSample(*(float(v) for v in point))
        if max(abs(sample.x), abs(sample.y)) > MAX_COORD_PX:
            raise InvalidValue(f"point {point!r} lies beyond +-{MAX_COORD_PX:g} texels")
        samples.append(sample)
    return samples


def _dab_estimate(samples: list[StrokeSample], brush: Brush) -> float:
    """How many dabs a stroke places at most: its path over the brush's smallest step."""
    # the curves are monotone, so the smallest step is at one end of the pressure range
    step = min(brush.step_at(0.0), brush.step_at(1.0))
    pairs = zip(samples, samples[1:], strict=False)
    return 1 + sum(math.dist((a.x, a.y), (b.x, b.y)) for a, b in pairs) / step


def _too_many_dabs(dabs: float, what: str) -> str:
    return f"{what} would place about {dabs:.3g} dabs at its brush spacing, more than {MAX_DABS}"


def parse_stroke(data: Any) -> StrokeSpec:
    if not isinstance(data, dict):
        raise InvalidValue("a stroke must be an object")
    unknown = set(data) - _STROKE_KEYS
    if unknown:
        raise InvalidValue(f"stroke has unknown key(s) {', '.join(sorted(unknown))}")
    options: dict[str, Any] = {}
    for key in ("mode", "target"):
        if key in data:
            options[key] = str(data[key])
    if "swatch" in data:
        options["swatch"] = Swatch.from_json(data["swatch"])
    if "mask_value" in data:
        options["mask_value"] = _number(data["mask_value"], "mask_value")
    if "clone_offset" in data:
        offset = data["clone_offset"]
        if not (isinstance(offset, list) and len(offset) == 2):
            raise InvalidValue("clone_offset must be [dx, dy]")
        # checked when painted
        options["clone_offset"] = tuple(_number(v, "clone_offset") for v in offset)
    if "wrap" in data:
        if not isinstance(data["wrap"], bool):
            raise InvalidValue("wrap must be true or false")
        options["wrap"] = data["wrap"]
    if "symmetry" in data or "symmetry_centre" in data:
        if not isinstance(data.get("symmetry", "none"), str):
            raise InvalidValue("symmetry must be none, x, y or xy")
        options["symmetry"] = Symmetry.parse(
            data.get("symmetry", "none"), _centre(data.get("symmetry_centre"))
        )
    layer = data.get("layer")
    if layer is not None and (isinstance(layer, bool) or not isinstance(layer, str | int)):
        raise InvalidValue("layer must be a layer name or id")
    samples, brush = _samples(data.get("points")), _brush(data.get("brush"))
    mirror = options.get("symmetry", Symmetry())
    dabs = _dab_estimate(samples, brush) * (1 + mirror.x) * (1 + mirror.y)  # mirror images too
    if dabs > MAX_DABS:  # points far apart: refused before painting, not after minutes
        raise InvalidValue(_too_many_dabs(dabs, "the stroke"))
    return StrokeSpec(layer, samples, brush, options, dabs)


def load_strokes(path: str | Path) -> list[StrokeSpec]:
    """Read a stroke file; anything wrong is one :class:`MatshopError` naming the file."""
    path = Path(path)
    data = read_json(path, "stroke file")
    if isinstance(data, dict) and "strokes" in data:
        data = data["strokes"]
    items = data if isinstance(data, list) else [data]
    strokes = []
    for number, item in enumerate(items, 1):
        with naming(path, what=f"stroke {number}"):
            strokes.append(parse_stroke(item))
    if not strokes:
        raise MatshopError("no strokes in the file", path)
    total = sum(stroke.dabs for stroke in strokes)
    if total > MAX_DABS:
        raise MatshopError(_too_many_dabs(total, f"the file's {len(strokes)} strokes"), path)
    return strokes
