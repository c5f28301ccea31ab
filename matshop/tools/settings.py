"""The brush settings and the swatch being painted, as observable Qt objects.

Panels edit them, tools read them when a stroke starts, the project stores
them (``to_json``). The swatch keeps *physical* values for every parameter
of the document plus which parameters the brush paints, so switching a
parameter off and on again keeps its value.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Signal

from ..errors import InvalidValue
from ..layers import Document, Rect
from ..material import PARAMETER_KINDS
from ..paint import Brush, PressureCurve, Swatch, Symmetry
from ..paint.pressure import CONSTANT, LINEAR
from .tip_settings import StencilSettings, TipSettings


def short_label(parameter: str) -> str:
    """A parameter's name that fits a narrow panel (the schema's labels are descriptive)."""
    kind = PARAMETER_KINDS.get(parameter)
    return kind.short if kind else parameter.replace("_", " ").capitalize()


@dataclass(frozen=True)
class Setting:
    """One brush setting as a panel shows it."""

    name: str
    label: str
    lo: float
    hi: float
    default: float
    log: bool = False
    unit: str = ""
    tip: str = ""


BRUSH_SETTINGS: tuple[Setting, ...] = (
    Setting("radius_px", "Size", 0.5, 512.0, 16.0, log=True, unit="px", tip="Radius in texels"),
    Setting("hardness", "Hardness", 0.0, 1.0, 0.6, tip="Fraction painted at full strength"),
    Setting("spacing", "Spacing", 0.01, 2.0, 0.12, log=True, tip="Dab distance / diameter"),
    Setting("opacity", "Opacity", 0.0, 1.0, 1.0, tip="Most one stroke can cover"),
    Setting("flow", "Flow", 0.01, 1.0, 1.0, tip="Strength of each dab (low flow builds up)"),
)

#: what pen pressure may drive, the brush's curve for each, and whether it does by default
PRESSURE_TARGETS: dict[str, tuple[str, bool]] = {
    "size": ("size_pressure", True),
    "opacity": ("opacity_pressure", False),
    "flow": ("flow_pressure", False),
}


class BrushSettings(QObject):
    """Size, hardness, spacing, opacity and flow of the painting tools, and their symmetry."""

    changed = Signal()

    def __init__(self) -> None:
        super().__init__()
        self.values = {s.name: s.default for s in BRUSH_SETTINGS}
        #: mirror strokes of the brush and eraser about the texture's centre lines
        self.symmetry = Symmetry()
        #: the pen's pressure curve, and which of size, opacity and flow it drives
        self.pressure_curve = PressureCurve(LINEAR)
        self.pressure_targets = {name: on for name, (_, on) in PRESSURE_TARGETS.items()}
        #: the tip and its dynamics (part of the brush: changes are brush changes)
        self.tips = TipSettings()
        self.tips.changed.connect(self.changed)
        #: the stencil over the canvas (not saved: an image placed on this screen)
        self.stencil = StencilSettings()

    def set_pressure_curve(self, points) -> None:
        """A new pressure curve through ``points`` (checked like any :class:`PressureCurve`)."""
        curve = PressureCurve.from_points(points)
        if curve != self.pressure_curve:
            self.pressure_curve = curve
            self.changed.emit()

    def set_pressure_target(self, target: str, on: bool) -> None:
        """Pen pressure drives ``target`` (size, opacity or flow) through the curve, or not."""
        if self.pressure_targets[target] != bool(on):
            self.pressure_targets[target] = bool(on)
            self.changed.emit()

    def set_mirror(self, axis: str, on: bool) -> None:
        """Mirror across ``axis`` (``"x"``: left/right, ``"y"``: top/bottom) or not."""
        x, y, centre = self.symmetry.x, self.symmetry.y, self.symmetry.centre
        self._set_symmetry(Symmetry(on, y, centre) if axis == "x" else Symmetry(x, on, centre))

    def set_mirror_centre(self, centre: tuple[float, float] | None) -> None:
        """Where the mirror lines cross, in texels (snapped to half texels); None: the middle."""
        self._set_symmetry(Symmetry(self.symmetry.x, self.symmetry.y, centre))

    def _set_symmetry(self, symmetry: Symmetry) -> None:
        if symmetry != self.symmetry:
            self.symmetry = symmetry
            self.changed.emit()

    def brush(self) -> Brush:
        constant = PressureCurve(CONSTANT)
        curves = {
            field: self.pressure_curve if self.pressure_targets[target] else constant
            for target, (field, _) in PRESSURE_TARGETS.items()
        }
        return Brush(**self.values, **curves, tip=self.tips.tip(), dynamics=self.tips.dynamics())

    def set(self, name: str, value: float) -> None:
        spec = next(s for s in BRUSH_SETTINGS if s.name == name)
        value = min(max(float(value), spec.lo), spec.hi)
        if value != self.values[name]:
            self.values[name] = value
            self.changed.emit()

    def scale_radius(self, factor: float) -> None:
        """``[`` and ``]``: size steps proportional to the size, like every paint program."""
        self.set("radius_px", self.values["radius_px"] * factor)

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {**self.values, "symmetry": self.symmetry.name}
        if self.symmetry.centre is not None:
            data["symmetry_centre"] = list(self.symmetry.centre)
        data["pressure"] = {
            "curve": [list(p) for p in self.pressure_curve.points],
            **self.pressure_targets,
        }
        data["tip"] = self.tips.to_json()
        return data

    def load_json(self, data: Any) -> None:
        if isinstance(data, dict):
            for spec in BRUSH_SETTINGS:
                if isinstance(data.get(spec.name), int | float):
                    self.set(spec.name, data[spec.name])
            centre = data.get("symmetry_centre")
            try:
                symmetry = Symmetry.parse(data.get("symmetry", "none"), centre)
            except (InvalidValue, TypeError, ValueError):  # older or hand-edited: no mirror
                symmetry = Symmetry()
            self._set_symmetry(symmetry)
            pressure = data.get("pressure")
            if isinstance(pressure, dict):  # older projects: the defaults stay
                try:
                    self.set_pressure_curve(pressure.get("curve", LINEAR))
                except (InvalidValue, TypeError, ValueError):
                    pass  # a hand-edited curve that does not read: keep the one there is
                for target in PRESSURE_TARGETS:
                    if isinstance(pressure.get(target), bool):
                        self.set_pressure_target(target, pressure[target])
            self.tips.load_json(data.get("tip"))


#: Physical defaults of a fresh swatch: a rusty iron a user can see on any material.
#: Colors are file codes (sRGB-encoded): linear rust (0.42, 0.12, 0.035) and a
#: dielectric's linear F0 of 0.04, encoded.
_DEFAULTS: dict[str, tuple[float, ...]] = {
    "base_color": (0.68, 0.38, 0.2),
    "diffuse": (0.68, 0.38, 0.2),
    "specular": (0.22, 0.22, 0.22),
    "emissive": (0.0, 0.0, 0.0),
    "metallic": (0.0,),
    "roughness": (0.75,),
    "ao": (1.0,),
    "opacity": (1.0,),
    "transmission": (0.0,),
    "height": (0.5,),
    "normal": (0.0, 0.0, 1.0),
}


class SwatchModel(QObject):
    """Physical values for each parameter and which ones the brush paints."""

    changed = Signal()

    def __init__(self) -> None:
        super().__init__()
        self.values: dict[str, tuple[float, ...]] = {}
        self.enabled: list[str] = []
        self.name = "Swatch"

    def reset(self, doc: Document) -> None:
        """Defaults for ``doc``'s parameters; ones without a default come from the centre texel."""
        centre = doc.physical(_centre_rect(doc), copy=False)
        values: dict[str, tuple[float, ...]] = {}
        for param in doc.schema.parameters:
            default = _DEFAULTS.get(param.name)
            if default is not None and len(default) == param.phys_channels:
                values[param.name] = default
            else:  # wide parameters, frames with tangents: what the material has
                values[param.name] = tuple(np.asarray(centre[param.name]).ravel().tolist())
        self.values = values
        self.enabled = list(doc.schema.names)
        self.changed.emit()

    def swatch(self) -> Swatch:
        """The swatch strokes paint: only the enabled parameters."""
        chosen = {p: self.values[p] for p in self.enabled if p in self.values}
        if not chosen:
            raise InvalidValue("the swatch paints no parameter: enable one in the swatch panel")
        return Swatch(self.name, chosen)

    def set_value(self, parameter: str, value: tuple[float, ...]) -> None:
        self.values[parameter] = tuple(float(v) for v in value)
        self.changed.emit()

    def set_enabled(self, parameter: str, on: bool) -> None:
        names = [p for p in self.values if (p in self.enabled or p == parameter)]
        self.enabled = [p for p in names if on or p != parameter]
        self.changed.emit()

    def pick(self, swatch: Swatch) -> None:
        """Take every value of ``swatch`` (the eyedropper); enabled parameters stay."""
        for parameter, value in swatch.values.items():
            if parameter in self.values:
                self.values[parameter] = tuple(value)
        self.changed.emit()

    def apply(self, swatch: Swatch) -> None:
        """Paint ``swatch`` (from the library): its values and only its parameters.

        Parameters the document lacks are skipped; a swatch of none of them changes nothing.
        """
        fitting = {
            p: v
            for p, v in swatch.values.items()
            if p in self.values and len(v) == len(self.values[p])
        }
        if not fitting:
            return
        self.values.update({p: tuple(v) for p, v in fitting.items()})
        self.enabled = [p for p in self.values if p in fitting]
        self.name = swatch.name
        self.changed.emit()

    def to_json(self) -> dict[str, Any]:
        return {"values": {k: list(v) for k, v in self.values.items()}, "enabled": self.enabled}

    def load_json(self, data: Any) -> None:
        """Restore saved values where they still fit the document's parameters."""
        if not isinstance(data, dict):
            return
        saved = data.get("values", {})
        if isinstance(saved, dict):
            for name, value in saved.items():
                old = self.values.get(name)
                if old is not None and isinstance(value, list) and len(value) == len(old):
                    self.values[name] = tuple(float(v) for v in value)
        enabled = data.get("enabled")
        if isinstance(enabled, list):
            self.enabled = [p for p in self.values if p in enabled]
        self.changed.emit()


def _centre_rect(doc: Document) -> Rect:
    x, y = doc.width // 2, doc.height // 2
    return Rect(x, y, x + 1, y + 1)
