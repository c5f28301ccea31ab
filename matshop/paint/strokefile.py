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
                 "flow_pressure": [[0, 0.5], [1, 1]],
                 "tip": {"image": "tips/leaf.png"},   # or "noise" | "scratches" | "spots"
                                                      # | {"procedural": "noise", "seed": 3}
                 "rotation": "follow",                # fixed | follow | random
                 "angle_deg": 0, "size_jitter": 0.3, "angle_jitter_deg": 20,
                 "scatter_along": 0, "scatter_across": 0.5},
       "swatch": {"name": "bronze", "values": {"base_color": [0.45, 0.25, 0.08],
                                                "roughness": [0.3]}},
       "mask_value": 1.0, "clone_offset": [-30, 12], "wrap": true,
       "symmetry": "x",               # none | x | y | xy: mirror about the centre lines
       "symmetry_centre": [cx, cy],   # where they cross (texels); default the middle
       "seed": 7,                     # seeds jitter, scatter and random rotation
       "stencil": {"image": "stencils/grate.png", "centre": [256, 256],
                   "scale": 0.5, "angle_deg": 15},   # texels per stencil pixel
       "points": [[x, y, pressure], [x, y], ...]}
    ]}

A file may also be a single stroke object or a list of them. Coordinates are
texels from the top-left corner; pressure defaults to 1. Image paths are
relative to the stroke file's folder. :func:`stroke_json` writes a finished
stroke in this format (the editor's strokes replay byte-identically).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InvalidValue, MatshopError, naming
from ..io.jsonfile import read_json
from .brush import Brush
from .dynamics import Dynamics
from .pressure import PressureCurve
from .stencil import Stencil, load_stencil
from .stroke import StrokeSample
from .swatch import Swatch
from .symmetry import Symmetry
from .tip_shapes import SHAPES
from .tips import Tip, load_tip, procedural_tip

MAX_POINTS = 1_000_000
#: coordinates beyond 16x the largest document side mean nothing more
MAX_COORD_PX = float(1 << 20)
#: dabs one stroke file may place (path lengths over the brush's smallest step):
#: a stroke across a 65536-texel document at the finest spacing fits (~160 us a dab)
MAX_DABS = 250_000
_BRUSH_NUMBERS = ("radius_px", "hardness", "spacing", "opacity", "flow")
_PRESSURE_CURVES = ("size_pressure", "opacity_pressure", "flow_pressure")
_DYNAMICS_NUMBERS = (
    "angle_deg",
    "size_jitter",
    "angle_jitter_deg",
    "scatter_along",
    "scatter_across",
)
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
    "seed",
    "stencil",
    "points",
}


class _Images:
    """Tip and stencil images a stroke file names, read once each, relative to ``base``."""

    def __init__(self, base: Path | None) -> None:
        self.base = base
        self._tips: dict[Path, Tip] = {}
        self._stencils: dict[Path, Stencil] = {}

    def _path(self, value: Any, what: str) -> Path:
        if not isinstance(value, str) or not value:
            raise InvalidValue(f"{what} image must be a file path")
        path = Path(value)
        return path if path.is_absolute() or self.base is None else self.base / path

    def tip(self, path: Any) -> Tip:
        path = self._path(path, "tip")
        if path not in self._tips:
            self._tips[path] = load_tip(path)
        return self._tips[path]

    def stencil(self, path: Any) -> Stencil:
        path = self._path(path, "stencil")
        if path not in self._stencils:
            self._stencils[path] = load_stencil(path)
        return self._stencils[path]


@dataclass
class StrokeSpec:
    """One stroke read from a file, ready for :class:`~matshop.paint.StrokeSession`."""

    layer: str | int | None
    samples: list[StrokeSample]
    brush: Brush
    options: dict[str, Any] = field(default_factory=dict)
    #: at most this many dabs (bounds the time painting it takes)
    dabs: float = 0.0


def _brush(data: Any, images: _Images) -> Brush:
    if data is None:
        return Brush()
    if not isinstance(data, dict):
        raise InvalidValue("brush must be an object")
    unknown = set(data) - {*_BRUSH_NUMBERS, *_PRESSURE_CURVES, *_DYNAMICS_NUMBERS}
    unknown -= {"tip", "rotation"}
    if unknown:
        raise InvalidValue(f"brush has unknown setting(s) {', '.join(sorted(unknown))}")
    numbers = {}
    for key in _BRUSH_NUMBERS:
        if key in data:
            numbers[key] = _number(data[key], f"brush {key}")
    curves = {key: PressureCurve.from_points(data[key]) for key in _PRESSURE_CURVES if key in data}
    motion: dict[str, Any] = {
        key: _number(data[key], f"brush {key}") for key in _DYNAMICS_NUMBERS if key in data
    }
    if "rotation" in data:
        if not isinstance(data["rotation"], str):
            raise InvalidValue("brush rotation must be fixed, follow or random")
        motion["rotation"] = data["rotation"]
    tip = _tip(data.get("tip"), images)
    return Brush(**numbers, **curves, tip=tip, dynamics=Dynamics(**motion))


def _tip(data: Any, images: _Images) -> Tip | None:
    """``"round"`` / absent: the round dab; a built-in's name; ``{"procedural": name, "seed": n}``;
    ``{"image": path}``."""
    if data is None or data == "round":
        return None
    if isinstance(data, str):
        return procedural_tip(data, 0)
    if isinstance(data, dict) and set(data) == {"image"}:
        return images.tip(data["image"])
    if isinstance(data, dict) and "procedural" in data and set(data) <= {"procedural", "seed"}:
        return procedural_tip(data["procedural"], data.get("seed", 0))
    raise InvalidValue(
        f'brush tip must be round, {", ".join(SHAPES)}, {{"procedural": name, "seed": n}} '
        'or {"image": path}'
    )


def _stencil(data: Any, images: _Images) -> Stencil:
    keys = {"image", "centre", "scale", "angle_deg"}
    if not isinstance(data, dict) or "image" not in data or not set(data) <= keys:
        raise InvalidValue(
            'stencil must be {"image": path, "centre": [x, y], "scale": s, "angle_deg": a}'
        )
    centre = data.get("centre", [0, 0])
    if not (isinstance(centre, list) and len(centre) == 2):
        raise InvalidValue("stencil centre must be [x, y] in texels")
    image = images.stencil(data["image"])
    return image.placed(
        tuple(_number(v, "stencil centre") for v in centre),  # type: ignore[arg-type]
        _number(data.get("scale", 1.0), "stencil scale"),
        _number(data.get("angle_deg", 0.0), "stencil angle_deg"),
    )


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


def parse_stroke(data: Any, base: Path | None = None, images: _Images | None = None) -> StrokeSpec:
    """One stroke object; image paths are relative to ``base`` (the stroke file's folder)."""
    images = images or _Images(base)
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
    if "seed" in data:
        seed = data["seed"]
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
            raise InvalidValue(f"seed must be an integer in [0, 2^63), got {seed!r}")
        options["seed"] = seed
    if "stencil" in data:
        options["stencil"] = _stencil(data["stencil"], images)
    layer = data.get("layer")
    if layer is not None and (isinstance(layer, bool) or not isinstance(layer, str | int)):
        raise InvalidValue("layer must be a layer name or id")
    samples, brush = _samples(data.get("points")), _brush(data.get("brush"), images)
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
    images = _Images(path.parent)
    for number, item in enumerate(items, 1):
        with naming(path, what=f"stroke {number}"):
            strokes.append(parse_stroke(item, images=images))
    if not strokes:
        raise MatshopError("no strokes in the file", path)
    total = sum(stroke.dabs for stroke in strokes)
    if total > MAX_DABS:
        raise MatshopError(_too_many_dabs(total, f"the file's {len(strokes)} strokes"), path)
    return strokes


def brush_json(brush: Brush) -> dict[str, Any]:
    """``brush`` as a stroke file's ``"brush"`` object."""
    data: dict[str, Any] = {key: getattr(brush, key) for key in _BRUSH_NUMBERS}
    for key in _PRESSURE_CURVES:
        data[key] = [list(point) for point in getattr(brush, key).points]
    data["tip"] = "round" if brush.tip is None else dict(brush.tip.source)
    data["rotation"] = brush.dynamics.rotation
    data.update({key: getattr(brush.dynamics, key) for key in _DYNAMICS_NUMBERS})
    return data


def stroke_json(
    brush: Brush,
    samples: list[StrokeSample],
    *,
    layer: str | int | None = None,
    **options: Any,
) -> dict[str, Any]:
    """One stroke as a stroke file writes it: ``options`` as given to a
    :class:`~matshop.paint.StrokeSession` (floats are written exactly: a replay paints
    the same bytes)."""
    data: dict[str, Any] = {} if layer is None else {"layer": layer}
    data["brush"] = brush_json(brush)
    for key, value in options.items():
        if value is None:
            continue
        if key == "swatch":
            value = value.to_json()
        elif key == "symmetry":
            symmetry = Symmetry.parse(value) if isinstance(value, str) else value
            if symmetry.centre is not None:
                data["symmetry_centre"] = list(symmetry.centre)
            value = symmetry.name
        elif key == "clone_offset":
            value = list(value)
        elif key == "stencil":
            value = {
                "image": value.source,
                "centre": list(value.centre),
                "scale": value.scale,
                "angle_deg": value.angle_deg,
            }
        elif key not in _STROKE_KEYS:
            raise InvalidValue(f"stroke files have no {key!r}")
        data[key] = value
    data["points"] = [[s.x, s.y, s.pressure] for s in samples]
    return data
