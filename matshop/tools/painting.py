"""Brush, eraser, clone stamp and eyedropper: pointer events -> strokes on the document.

Each stroke is one :class:`~matshop.paint.StrokeSession` into the active
paint layer, or into the active layer's mask while its thumbnail is selected
(the brush hides, the eraser reveals): press starts it,
every move feeds it a sample, release ends it and hands the single edit to
the host's history, so a stroke is one undo step; a stroke that changes
nothing leaves no step. With symmetry on, a brush or eraser stroke (pixels or
mask) paints its mirror images in the same stroke. Every stroke takes the
brush's tip and dynamics, a fresh seed and the stencil (if one is over the
canvas); :attr:`StrokeTool.last_stroke` is the finished stroke as a stroke
file writes it (``matshop paint`` replays it byte-identically). :meth:`StrokeTool.action`
says beforehand what a press will do (the status bar shows it). Engine refusals become a status
message, never an exception in the event loop.
"""

from __future__ import annotations

import math

from ..errors import MatshopError
from ..layers import Layer, PaintLayer
from ..paint import StrokeSample, StrokeSession
from ..paint.painter import stroke_parameters
from ..paint.strokefile import stroke_json
from .base import Tool, ToolEvent, ToolHost
from .seamless_clone import SeamlessCloneTool

#: What the brush paints into a mask, as the mask reads: 0 hides the layer there, like
#: painting black in a paint program's layer mask (a new mask shows everything), also
#: after Invert; the eraser paints 1 - it (white: reveals).
MASK_HIDE = 0.0


def _labels(names: tuple[str, ...]) -> str:
    return ", ".join(name.replace("_", " ") for name in names)


def _sample(event: ToolEvent) -> StrokeSample:
    return StrokeSample(event.x, event.y, min(max(event.pressure, 0.0), 1.0))


class StrokeTool(Tool):
    """Base of the tools that paint with a :class:`StrokeSession`."""

    mode = "paint"
    creates_layer = True
    mirrors = True

    def __init__(self, host: ToolHost) -> None:
        super().__init__(host)
        self._session: StrokeSession | None = None
        self._used: dict = {}
        #: the last finished stroke in stroke-file form (None: none yet)
        self.last_stroke: dict | None = None

    @property
    def busy(self) -> bool:
        return self._session is not None

    def _options(self, event: ToolEvent) -> dict | None:
        """Extra StrokeSession options for this stroke (None: do not start one)."""
        return {}

    def press(self, event: ToolEvent) -> None:
        doc = self.host.doc
        if doc is None or self._session is not None:
            return
        if self.host.stroke_target() == "mask" and not event.pick:
            options = self._mask_options()
            layer_id = self.host.mask_layer()
        else:
            options = self._options(event)
            if options is None:
                return
            swatch = options.get("swatch")
            layer_id = self.host.stroke_layer(
                create=self.creates_layer, parameters=None if swatch is None else swatch.parameters
            )
        if options is None or layer_id is None:
            return
        if self.mirrors:
            options = {**options, "symmetry": self.host.symmetry()}
        options = {
            **options,
            "mode": self.mode,
            "seed": self.host.stroke_seed(),
            "stencil": self.host.stencil(),
        }
        try:
            self._session = StrokeSession(doc, layer_id, self.host.brush(), **options)
        except MatshopError as exc:  # the engine's sentence says what to change
            self.host.message(str(exc))
            return
        self._used = options
        if self._session.note:
            self.host.message(self._session.note[0].upper() + self._session.note[1:])
        self._session.add([_sample(event)])

    def _mask_options(self) -> dict | None:
        """A stroke on the mask: the brush hides (paints 0), the eraser reveals (paints 1)."""
        if self.mode == "clone":
            self.host.message("The clone stamp paints layer pixels: select the layer, not its mask")
            return None
        return {"target": "mask", "mask_value": MASK_HIDE}

    def move(self, event: ToolEvent) -> None:
        if self._session is not None:
            self._session.add([_sample(event)])

    def release(self, event: ToolEvent) -> None:
        session, self._session = self._session, None
        if session is None:
            return
        session.add([_sample(event)])
        edit = session.end()
        if edit is not None:
            layer = session.doc.layer(session.layer_id).name
            self.last_stroke = stroke_json(
                session.brush, session.samples, layer=layer, **self._used
            )
            self.host.push(edit)

    def cancel(self) -> None:
        session, self._session = self._session, None
        if session is not None:
            session.cancel()

    def cursor_radius(self) -> float | None:
        return self.host.brush().radius_px

    def action(self) -> str:
        text = self._action()
        symmetry = self.host.symmetry() if self.mirrors and text else None
        if symmetry:
            axes = {"x": "left/right", "y": "top/bottom", "xy": "both ways"}[symmetry.name]
            where = ""
            if symmetry.centre is not None:
                cx, cy = symmetry.centre
                where = " about " + ", ".join(
                    f"{axis} = {value:g}"
                    for axis, value, on in (("x", cx, symmetry.x), ("y", cy, symmetry.y))
                    if on
                )
            text += f" (mirrored {axes}{where})"
        if text and self.host.stencil() is not None:
            text += ", through the stencil"
        return text

    def _action(self) -> str:
        doc = self.host.doc
        if doc is None:
            return ""
        layer_id = self.host.active_layer()
        layer = None if layer_id is None else doc.layer(layer_id)
        if self.host.stroke_target() == "mask" and layer is not None and layer.mask is not None:
            if self.mode == "clone":
                return f"{self.label}: paints layer pixels; select the layer, not its mask"
            verb = "hides" if self.mode == "paint" else "reveals"
            return f"{self.label}: {verb} layer {layer.name!r} where it paints (its mask)"
        return self._pixels_action(layer)

    def _pixels_action(self, layer: Layer | None) -> str:
        verb = {"paint": "paints into", "erase": "erases paint from", "clone": "copies into"}
        if isinstance(layer, PaintLayer):
            return f"{self.label}: {verb[self.mode]} layer {layer.name!r}"
        if self.creates_layer:
            return f"{self.label}: {verb[self.mode]} a new paint layer"
        return f"{self.label}: select a paint layer (or a layer's mask)"


class BrushTool(StrokeTool):
    """Paints the swatch (every enabled parameter at once); Alt/Ctrl-click picks it."""

    name = "brush"
    label = "Brush"
    shortcut = "B"
    tip = "Paint the swatch into the active paint layer (Alt-click picks the swatch)"

    def _options(self, event: ToolEvent) -> dict | None:
        if event.pick:
            self.host.pick_swatch(int(math.floor(event.x)), int(math.floor(event.y)))
            return None
        try:
            return {"swatch": self.host.swatch()}
        except MatshopError as exc:
            self.host.message(str(exc))
            return None

    def _pixels_action(self, layer: Layer | None) -> str:
        try:
            swatch = self.host.swatch()
        except MatshopError as exc:
            return f"Brush: {exc}"
        doc = self.host.doc
        assert doc is not None
        if not isinstance(layer, PaintLayer):
            return f"Brush: paints {_labels(swatch.parameters)} into a new paint layer"
        painted, skipped = stroke_parameters(doc, layer, swatch)
        if not painted:
            return f"Brush: layer {layer.name!r} affects none of the swatch's parameters"
        text = f"Brush: paints {_labels(painted)} into layer {layer.name!r}"
        if skipped and len(layer.pixels or ()) > 0:
            return (
                f"Brush: paints {_labels(painted)} into a new layer above {layer.name!r} "
                f"(it also affects {_labels(skipped)}, which the swatch leaves as they are)"
            )
        return text


class EraserTool(StrokeTool):
    """Removes paint (coverage) from the active paint layer."""

    name = "eraser"
    label = "Eraser"
    shortcut = "E"
    tip = "Erase paint from the active paint layer"
    mode = "erase"
    creates_layer = False


class CloneTool(StrokeTool):
    """Clone stamp: Alt/Ctrl-click sets the source; the first stroke fixes the offset.

    The offset (source minus destination) is kept for later strokes, like
    Photoshop's aligned mode, until a new source is set.
    """

    name = "clone"
    label = "Clone stamp"
    shortcut = "S"
    tip = "Alt-click sets the source, then paint to copy from it (offset is kept)"
    mode = "clone"
    mirrors = False  # a mirrored stamp would copy unmirrored content from beside the source

    def __init__(self, host: ToolHost) -> None:
        super().__init__(host)
        self.source: tuple[float, float] | None = None
        self.offset: tuple[float, float] | None = None

    def _pixels_action(self, layer: Layer | None) -> str:
        if self.offset is None and self.source is None:
            return "Clone stamp: Alt-click (or Ctrl-click) to set the source first"
        return super()._pixels_action(layer)

    def _options(self, event: ToolEvent) -> dict | None:
        if event.pick:
            self.source = (event.x, event.y)
            self.offset = None
            self.host.message(f"Clone source set at {int(event.x)}, {int(event.y)}")
            return None
        if not self.host.flatten_ready():  # the stamp reads the flattened material
            self.host.message("The material is still being computed: clone in a moment")
            return None
        if self.offset is None:
            if self.source is None:
                self.host.message("Alt-click (or Ctrl-click) to set the clone source first")
                return None
            self.offset = (self.source[0] - event.x, self.source[1] - event.y)
        return {"clone_offset": self.offset}

    def markers(self, x: float, y: float) -> list[tuple[float, float]]:
        if self.offset is not None:
            return [(x + self.offset[0], y + self.offset[1])]
        return [self.source] if self.source is not None else []


class EyedropperTool(Tool):
    """Sets the swatch from the flattened physical values under the cursor."""

    name = "eyedropper"
    label = "Eyedropper"
    shortcut = "I"
    tip = "Pick the swatch (all parameters) from the flattened material"
    uses_brush = False

    def __init__(self, host: ToolHost) -> None:
        super().__init__(host)
        self._down = False

    def _pick(self, event: ToolEvent) -> None:
        self.host.pick_swatch(int(math.floor(event.x)), int(math.floor(event.y)))

    def press(self, event: ToolEvent) -> None:
        self._down = True
        self._pick(event)

    def move(self, event: ToolEvent) -> None:
        if self._down:
            self._pick(event)

    def release(self, event: ToolEvent) -> None:
        self._down = False


TOOL_CLASSES: tuple[type[Tool], ...] = (
    BrushTool,
    EraserTool,
    CloneTool,
    SeamlessCloneTool,
    EyedropperTool,
)
