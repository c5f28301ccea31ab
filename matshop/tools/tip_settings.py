"""The brush's tip and dynamics, and the stencil over the canvas, as observable Qt objects.

:class:`TipSettings` is part of the brush settings (saved with the project's
editor state); it hands strokes a :class:`~matshop.paint.Tip`, a
:class:`~matshop.paint.Dynamics` and a fresh seed per stroke (the seed a
stroke file records, so the stroke replays). :class:`StencilSettings` holds
the stencil's image and its place *on the screen* (widget pixels: the
texture pans and zooms under it); :meth:`StencilSettings.in_texels` converts
that place for a stroke.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, Signal

from ..errors import MatshopError
from ..paint import Dynamics, Stencil, Tip, load_tip, procedural_tip
from ..paint.dynamics import MAX_SCATTER, ROTATIONS
from ..paint.stencil import MAX_SCALE, MIN_SCALE
from ..paint.tip_shapes import SHAPES

#: the tips offered: the round dab, the built-in procedural ones, an image file
TIP_KINDS = ("round", *SHAPES, "image")


@dataclass(frozen=True)
class Range:
    """One dynamics setting as a panel shows it."""

    name: str
    label: str
    lo: float
    hi: float
    unit: str = ""
    tip: str = ""


DYNAMICS_SETTINGS: tuple[Range, ...] = (
    Range("angle_deg", "Angle", -180.0, 180.0, "°", "Tip angle, counter-clockwise"),
    Range("size_jitter", "Size jitter", 0.0, 1.0, "", "Each dab up to this much smaller"),
    Range("angle_jitter_deg", "Angle jitter", 0.0, 180.0, "°", "Each dab turned up to this"),
    Range(
        "scatter_along",
        "Scatter along",
        0.0,
        4.0,
        "",
        "Random shift along the stroke, in dab diameters",
    ),
    Range(
        "scatter_across",
        "Scatter across",
        0.0,
        4.0,
        "",
        "Random shift across the stroke, in dab diameters",
    ),
)
assert all(r.hi <= MAX_SCATTER for r in DYNAMICS_SETTINGS if r.name.startswith("scatter"))


class TipSettings(QObject):
    """Which tip the brush stamps (round, a built-in with its seed, an image) and how dabs vary."""

    changed = Signal()

    def __init__(self) -> None:
        super().__init__()
        self.kind = "round"
        self.tip_seed = 1
        self.image: Tip | None = None  # the tip read from a file, kept while another is chosen
        self.rotation = "fixed"
        self.values = {r.name: (0.0) for r in DYNAMICS_SETTINGS}
        #: the seed of the next stroke (each stroke takes one and moves it on)
        self.stroke_seed = 1
        self._procedural: dict[tuple[str, int], Tip] = {}

    def tip(self) -> Tip | None:
        if self.kind == "round" or (self.kind == "image" and self.image is None):
            return None
        if self.kind == "image":
            return self.image
        key = (self.kind, self.tip_seed)
        if key not in self._procedural:
            self._procedural = {key: procedural_tip(*key)}  # one kept: each is 64 KB
        return self._procedural[key]

    def dynamics(self) -> Dynamics:
        return Dynamics(rotation=self.rotation, **self.values)

    def next_seed(self) -> int:
        """The seed for a stroke starting now; the next stroke gets another."""
        seed = self.stroke_seed
        self.stroke_seed = (seed + 1) % 2**63
        return seed

    def set_kind(self, kind: str) -> None:
        if kind not in TIP_KINDS:
            raise ValueError(f"unknown tip kind {kind!r}")
        if kind != self.kind:
            self.kind = kind
            self.changed.emit()

    def set_image(self, tip: Tip) -> None:
        """Stamp ``tip`` (read from a file) from now on."""
        self.image = tip
        self.kind = "image"
        self.changed.emit()

    def set_tip_seed(self, seed: int) -> None:
        seed = min(max(int(seed), 0), 2**31 - 1)
        if seed != self.tip_seed:
            self.tip_seed = seed
            self.changed.emit()

    def set_rotation(self, rotation: str) -> None:
        if rotation not in ROTATIONS:
            raise ValueError(f"unknown rotation {rotation!r}")
        if rotation != self.rotation:
            self.rotation = rotation
            self.changed.emit()

    def set(self, name: str, value: float) -> None:
        spec = next(r for r in DYNAMICS_SETTINGS if r.name == name)
        value = min(max(float(value), spec.lo), spec.hi)
        if value != self.values[name]:
            self.values[name] = value
            self.changed.emit()

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {
            "kind": self.kind,
            "tip_seed": self.tip_seed,
            "rotation": self.rotation,
            "stroke_seed": self.stroke_seed,
            **self.values,
        }
        if self.image is not None:
            data["image"] = self.image.source.get("image")
        return data

    def load_json(self, data: Any) -> None:
        """Restore saved settings; a tip file that went missing falls back to the round dab."""
        if not isinstance(data, dict):
            return
        for spec in DYNAMICS_SETTINGS:
            if isinstance(data.get(spec.name), int | float):
                self.values[spec.name] = min(max(float(data[spec.name]), spec.lo), spec.hi)
        if data.get("rotation") in ROTATIONS:
            self.rotation = data["rotation"]
        for key in ("tip_seed", "stroke_seed"):
            if isinstance(data.get(key), int) and 0 <= data[key] < 2**31:
                setattr(self, key, data[key])
        self.image = None
        if isinstance(data.get("image"), str):
            try:
                self.image = load_tip(data["image"])
            except MatshopError:  # moved or deleted since: the round dab, said by the panel
                self.image = None
        kind = data.get("kind")
        self.kind = kind if kind in TIP_KINDS else "round"
        self.changed.emit()


class StencilSettings(QObject):
    """The stencil image and its place on the canvas widget: centre, scale, angle.

    ``scale`` is widget pixels per stencil pixel; ``angle_deg`` counter-clockwise.
    ``placing``: pointer drags on the canvas move the stencil (the wheel scales
    it, Shift+wheel turns it) instead of painting.
    """

    changed = Signal()

    def __init__(self) -> None:
        super().__init__()
        self.stencil: Stencil | None = None
        self.centre = (0.0, 0.0)
        self.scale = 1.0
        self.angle_deg = 0.0
        self.placing = False

    def set_image(self, stencil: Stencil, centre: tuple[float, float], scale: float) -> None:
        self.stencil = stencil
        self.centre = (float(centre[0]), float(centre[1]))
        self.scale = float(scale)
        self.angle_deg = 0.0
        self.changed.emit()

    def clear(self) -> None:
        if self.stencil is not None or self.placing:
            self.stencil = None
            self.placing = False
            self.changed.emit()

    def move_by(self, dx: float, dy: float) -> None:
        self.centre = (self.centre[0] + dx, self.centre[1] + dy)
        self.changed.emit()

    def set_scale(self, scale: float) -> None:
        scale = min(max(float(scale), 0.01), 100.0)
        if scale != self.scale:
            self.scale = scale
            self.changed.emit()

    def set_angle(self, angle_deg: float) -> None:
        angle = math.remainder(float(angle_deg), 360.0)  # in [-180, 180]
        if angle != self.angle_deg:
            self.angle_deg = angle
            self.changed.emit()

    def set_placing(self, on: bool) -> None:
        on = bool(on) and self.stencil is not None
        if on != self.placing:
            self.placing = on
            self.changed.emit()

    def in_texels(self, to_texel: Any, zoom: float) -> Stencil | None:
        """The stencil placed in texel space for the current view (None: no stencil).

        ``to_texel(x, y)`` maps widget pixels to texels; ``zoom`` is widget
        pixels per texel (the canvas neither turns nor shears the texture).
        """
        if self.stencil is None:
            return None
        scale = min(max(self.scale / zoom, MIN_SCALE), MAX_SCALE)
        return self.stencil.placed(to_texel(*self.centre), scale, self.angle_deg)
