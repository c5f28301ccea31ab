"""The Lighting toolbar and the View > Lighting menu: the artist's environment, its turn and
exposure, for the 3D view and the lit display at once (:mod:`.lighting`).

Toolbar: an environment list (Studio, Sky, Uniform, the files opened this session,
"Open HDR/EXR…"), the turn in degrees about up and the exposure in stops. Menu:
the same presets and files as checkable actions, and "Open HDR/EXR…". Both only
ask the :class:`~.lighting.LightingController`; they show what it reports, so a
file that fails to load leaves them on the lighting still in use.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import QComboBox, QDoubleSpinBox, QLabel, QMenu, QToolBar, QWidget

from ..render.environment_choice import EXPOSURE_RANGE_STOPS, PRESETS, EnvironmentChoice
from .lighting import LightingController
from .prompts import Prompts

OPEN_LABEL = "Open HDR/EXR…"
TIP = (
    "Lighting of the 3D view and the lit display (as matshop render --env, --env-rotation, "
    "--exposure)"
)


class LightingBar(QToolBar):
    """The Lighting toolbar (see the module doc); ``menu`` is View > Lighting."""

    def __init__(self, controller: LightingController, prompts: Prompts, parent: QWidget):
        super().__init__("Lighting", parent)
        self.setObjectName("lighting_toolbar")
        self.controller, self.prompts = controller, prompts
        self._syncing = False
        #: the files offered (opened this session, or restored), in the order opened
        self.files: list[str] = []

        self.addWidget(QLabel(" Lighting "))
        self.combo = QComboBox()
        self.combo.setObjectName("lighting_environment")
        self.combo.setToolTip(TIP)
        self.combo.setMinimumWidth(120)
        self.combo.activated.connect(self._combo_activated)
        self.addWidget(self.combo)

        self.rotation = QDoubleSpinBox()
        self.rotation.setObjectName("lighting_rotation")
        self.rotation.setRange(0.0, 360.0)
        self.rotation.setWrapping(True)
        self.rotation.setDecimals(1)
        self.rotation.setSingleStep(15.0)
        self.rotation.setSuffix("°")
        self.rotation.setKeyboardTracking(False)  # one load per value, not per key
        self.rotation.setToolTip("Turn the environment about up; + carries it to the right")
        self.rotation.valueChanged.connect(self._rotation_changed)
        self.addWidget(QLabel("  Turn "))
        self.addWidget(self.rotation)

        self.exposure = QDoubleSpinBox()
        self.exposure.setObjectName("lighting_exposure")
        self.exposure.setRange(*EXPOSURE_RANGE_STOPS)
        self.exposure.setDecimals(1)
        self.exposure.setSingleStep(0.5)
        self.exposure.setSuffix(" stops")
        self.exposure.setKeyboardTracking(False)
        self.exposure.setToolTip("Exposure: +1 stop doubles the light before the tone map")
        self.exposure.valueChanged.connect(self._exposure_changed)
        self.addWidget(QLabel("  Exposure "))
        self.addWidget(self.exposure)

        self.menu = QMenu("&Lighting", parent)
        self.menu.setToolTip(TIP)
        self._group = QActionGroup(self)
        self._group.setExclusive(True)
        self.open_action = QAction(OPEN_LABEL, self)
        self.open_action.setToolTip("Light with your own equirectangular HDR (.hdr or .exr)")
        self.open_action.triggered.connect(lambda _=False: self.open_file())

        controller.changed.connect(self._shown)
        controller.failed.connect(lambda _text: self._sync())
        self._sync()

    # -- what the user does ------------------------------------------------------

    def open_file(self) -> bool:
        """Ask for an .hdr/.exr and light with it (False: cancelled or refused)."""
        start = self.controller.target().source if self.controller.target().is_file else ""
        path = self.prompts.open_environment(str(Path(start).parent) if start else "")
        if path is None:
            self._sync()
            return False
        return self.controller.choose_source(path)

    def _combo_activated(self, index: int) -> None:
        source = self.combo.itemData(index)
        if source is None:
            self.open_file()
        else:
            self.controller.choose_source(source)

    def _rotation_changed(self, value: float) -> None:
        if not self._syncing:
            self.controller.set_rotation(value)

    def _exposure_changed(self, value: float) -> None:
        if not self._syncing:
            self.controller.set_exposure(value)

    # -- what it shows -------------------------------------------------------------

    def _shown(self, choice: EnvironmentChoice, _environment) -> None:
        if choice.is_file and choice.source not in self.files:
            self.files.append(choice.source)
        self._sync()

    def _sync(self) -> None:
        """Widgets and menu show the controller's target (the current or loading choice)."""
        choice = self.controller.target()
        if choice.is_file and choice.source not in self.files:
            self.files.append(choice.source)
        sources = [*PRESETS, *self.files]
        if choice.source not in sources:  # uniform:L, restored from a project
            sources.append(choice.source)
        self._syncing = True
        try:
            self.combo.clear()
            for menu_action in self._group.actions():
                self._group.removeAction(menu_action)
            self.menu.clear()
            for source in sources:
                label = EnvironmentChoice(source).label
                self.combo.addItem(label, source)
                action = self.menu.addAction(label)
                action.setCheckable(True)
                action.setChecked(source == choice.source)
                action.setData(source)
                action.triggered.connect(lambda _=False, s=source: self.controller.choose_source(s))
                self._group.addAction(action)
            self.combo.addItem(OPEN_LABEL, None)
            self.menu.addSeparator()
            self.menu.addAction(self.open_action)
            self.combo.setCurrentIndex(sources.index(choice.source))
            self.rotation.setValue(choice.rotation_deg)
            self.exposure.setValue(choice.exposure_stops)
        finally:
            self._syncing = False

    def menu_action(self, label: str) -> QAction:
        """The View > Lighting entry called ``label`` (tests trigger it as a click would)."""
        for action in self.menu.actions():
            if action.text() == label:
                return action
        raise KeyError(label)
