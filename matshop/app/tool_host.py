"""The editor side of the tools: which layer strokes go into, the brush, the swatch."""

from __future__ import annotations

from collections.abc import Callable

from ..layers import Document, Edit, PaintLayer, Rect
from ..paint import Brush, Stencil, Swatch, Symmetry
from ..tools.settings import BrushSettings, SwatchModel
from .layer_commands import LayerCommands
from .session import DocumentSession


class EditorToolHost:
    """Implements :class:`matshop.tools.base.ToolHost` for the main window."""

    def __init__(
        self,
        session: DocumentSession,
        commands: LayerCommands,
        brush_settings: BrushSettings,
        swatch_model: SwatchModel,
        message: Callable[[str], None],
        flatten_ready: Callable[[], bool] = lambda: True,
        stencil: Callable[[], Stencil | None] = lambda: None,
    ) -> None:
        self.session = session
        self.commands = commands
        self.brush_settings = brush_settings
        self.swatch_model = swatch_model
        self.message = message
        self.flatten_ready = flatten_ready
        self.stencil = stencil

    @property
    def doc(self) -> Document | None:
        return self.session.doc

    def brush(self) -> Brush:
        return self.brush_settings.brush()

    def symmetry(self) -> Symmetry:
        return self.brush_settings.symmetry

    def stroke_seed(self) -> int:
        return self.brush_settings.tips.next_seed()

    def swatch(self) -> Swatch:
        return self.swatch_model.swatch()

    def pick_swatch(self, x: int, y: int) -> None:
        doc = self.session.doc
        if doc is None:
            return
        if not self.flatten_ready():
            self.message("The material is still being computed: pick again in a moment")
            return
        x = min(max(x, 0), doc.width - 1)
        y = min(max(y, 0), doc.height - 1)
        maps = doc.physical(Rect(x, y, x + 1, y + 1), copy=False)
        self.swatch_model.pick(Swatch.from_physical(f"Picked {x},{y}", maps, 0, 0))
        self.message(f"Swatch picked at texel {x}, {y}")

    def stroke_layer(self, create: bool, parameters: tuple[str, ...] | None) -> int | None:
        layer = self.session.active_layer
        if isinstance(layer, PaintLayer):
            return layer.id
        if not create:
            self.message("Select a paint layer to use this tool on")
            return None
        doc = self.session.doc
        if doc is not None and parameters is not None and len(parameters) == len(doc.schema):
            parameters = None
        # painting onto a fill or filter layer: start a paint layer above it, as
        # painting "on the material" is what the artist meant (its own undo step)
        layer_id = self.commands.add_paint_layer(parameters)
        if layer_id is not None:
            self.message("Added a paint layer for the stroke")
        return layer_id

    def active_layer(self) -> int | None:
        return self.session.active_layer_id

    def stroke_target(self) -> str:
        """``"mask"`` while the active layer's mask thumbnail is selected, else ``"pixels"``."""
        return "mask" if self.session.mask_target else "pixels"

    def mask_layer(self) -> int | None:
        layer = self.session.active_layer
        return None if layer is None or layer.mask is None else layer.id

    def push(self, edit: Edit) -> None:
        self.session.push(edit, applied=True)
