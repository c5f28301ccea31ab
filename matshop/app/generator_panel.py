"""The active layer's generated mask: which generator, and its controls.

A layer's mask can be generated from the material below it (cavity, edge, ambient
occlusion: :class:`~matshop.ops.generators.MaskGenerator`); the document keeps it up to
date as the layers below change, and the background flatten computes it off the GUI
thread. Every change here is one ``SetProperty(mask_generator)`` edit: choosing a
generator or flipping invert is one undo step, a slider drag merges its ticks into one.
"""

from __future__ import annotations

import dataclasses

from PySide6.QtWidgets import QCheckBox, QComboBox, QFormLayout, QGroupBox, QWidget

from ..ops.generators import BOUNDS, GENERATORS, MaskGenerator
from ..tools.widgets import FloatSlider
from .layer_commands import LayerCommands
from .session import DocumentSession

LABELS = {"cavity": "Cavity", "edge": "Edge (convexity)", "ao": "Ambient occlusion"}
#: (label, UI range, log scale, unit, tip) of each slider; the hard ranges are the engine's
SLIDERS: dict[str, tuple[str, float, float, bool, str, str]] = {
    "radius_px": ("Radius", 0.5, 64.0, True, "px", "Scale of the features it finds, in texels"),
    "level": ("Level", 0.0, 1.0, False, "", "The raw value that maps to mid grey"),
    "contrast": ("Contrast", 0.1, 16.0, True, "", "Slope of the mask around the level"),
    "blur_px": ("Blur", 0.0, 32.0, False, "px", "Softens the mask (Gaussian sigma, texels)"),
}


class GeneratorPanel(QGroupBox):
    """Generated mask of the active layer: none, cavity, edge or AO, and their controls."""

    def __init__(
        self, session: DocumentSession, commands: LayerCommands, parent: QWidget | None = None
    ) -> None:
        super().__init__("Generated mask", parent)
        self.session = session
        self.commands = commands
        self.setToolTip("A mask made of the material below this layer, remade whenever it changes")
        form = QFormLayout(self)
        form.setVerticalSpacing(4)
        self.kind = QComboBox()
        self.kind.addItem("None", None)
        for name in GENERATORS:
            self.kind.addItem(LABELS[name], name)
        self.kind.activated.connect(self._choose)
        form.addRow("Mask", self.kind)
        self.sliders: dict[str, FloatSlider] = {}
        defaults = MaskGenerator()
        for name, (label, lo, hi, log, unit, tip) in SLIDERS.items():
            assert BOUNDS[name][0] <= lo and hi <= BOUNDS[name][1]
            slider = FloatSlider("", lo, hi, getattr(defaults, name), log=log, unit=unit, tip=tip)
            slider.label.hide()
            slider.started.connect(session.seal)
            slider.edited.connect(lambda v, n=name: self._change(n, v, merge=True))
            slider.finished.connect(session.seal)
            form.addRow(label, slider)
            self.sliders[name] = slider
        self.invert = QCheckBox("Invert")
        self.invert.toggled.connect(lambda on: self._change("invert", on))
        form.addRow("", self.invert)
        self.refresh()

    # -- showing ---------------------------------------------------------------

    def refresh(self) -> None:
        """Show the active layer's generator (or hide when the material has no normals)."""
        doc, layer = self.session.doc, self.session.active_layer
        usable = doc is not None and layer is not None and "normal" in doc.schema.names
        self.setVisible(usable)
        generator = None if not usable else layer.mask_generator
        self.kind.setCurrentIndex(self.kind.findData(None if generator is None else generator.kind))
        shown = generator or MaskGenerator()
        for name, slider in self.sliders.items():
            slider.set_value(getattr(shown, name))
            slider.setEnabled(generator is not None)
        self.invert.blockSignals(True)
        self.invert.setChecked(shown.invert)
        self.invert.blockSignals(False)
        self.invert.setEnabled(generator is not None)

    # -- changing --------------------------------------------------------------

    def _choose(self, index: int) -> None:
        layer = self.session.active_layer
        if layer is None:
            return
        kind = self.kind.itemData(index)
        current = layer.mask_generator
        if kind is None:
            generator = None
        elif current is None:
            generator = MaskGenerator(kind)
        else:  # another generator keeps the controls the artist set
            generator = dataclasses.replace(current, kind=kind)
        self._push(generator)

    def _change(self, name: str, value: float | bool, *, merge: bool = False) -> None:
        layer = self.session.active_layer
        if layer is None or layer.mask_generator is None:
            return
        self._push(dataclasses.replace(layer.mask_generator, **{name: value}), merge=merge)

    def _push(self, generator: MaskGenerator | None, *, merge: bool = False) -> None:
        layer = self.session.active_layer
        if layer is None:
            return
        if not merge:
            self.session.seal()
        self.commands.set_property(layer.id, "mask_generator", generator, merge=merge)
        if not merge:
            self.session.seal()
