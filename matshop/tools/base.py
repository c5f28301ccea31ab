"""What every canvas tool is and what it may ask of the editor.

Tools turn pointer input in texel coordinates into document edits. They are
kept free of widgets: the canvas maps mouse and tablet events to
:class:`ToolEvent` (continuous texel coordinates, pressure 1.0 for a mouse)
and the editor implements :class:`ToolHost`, so a tool can be driven by a
test or a script exactly as by a pen.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from ..layers import Document, Edit
    from ..paint import Brush, Stencil, Swatch, Symmetry


@dataclass(frozen=True)
class ToolEvent:
    """One pointer event: texel position (continuous, (0, 0) top-left), pressure, modifiers."""

    x: float
    y: float
    pressure: float = 1.0
    alt: bool = False
    ctrl: bool = False
    shift: bool = False

    @property
    def pick(self) -> bool:
        """Alt or Ctrl held: the "pick a source / a color" gesture of paint programs."""
        return self.alt or self.ctrl


class ToolHost(Protocol):
    """The editor as a tool sees it."""

    @property
    def doc(self) -> Document | None: ...

    def brush(self) -> Brush: ...

    def symmetry(self) -> Symmetry:
        """Which centre lines the brush and eraser mirror their strokes across."""
        ...

    def stroke_seed(self) -> int:
        """The seed of a stroke starting now (its jitter and scatter); each stroke gets another."""
        ...

    def stencil(self) -> Stencil | None:
        """The stencil over the canvas, placed in texel space for the current view."""
        ...

    def swatch(self) -> Swatch:
        """The material to paint (raises ValueError when no parameter is enabled)."""
        ...

    def pick_swatch(self, x: int, y: int) -> None:
        """Eyedropper: set the swatch from the flattened physical values at texel (x, y)."""
        ...

    def stroke_layer(self, create: bool, parameters: tuple[str, ...] | None) -> int | None:
        """Id of the paint layer strokes go into; with ``create``, add one affecting
        ``parameters`` (None: all) if the active layer cannot take paint. None (after
        telling the user) if there is none."""
        ...

    def active_layer(self) -> int | None:
        """Id of the active layer (None: none)."""
        ...

    def stroke_target(self) -> str:
        """``"pixels"`` (a paint layer's values) or ``"mask"`` (the active layer's mask)."""
        ...

    def mask_layer(self) -> int | None:
        """Id of the active layer when it has a mask (strokes on ``"mask"`` go there)."""
        ...

    def push(self, edit: Edit) -> None:
        """Record an already applied edit as one undo step."""
        ...

    def message(self, text: str) -> None:
        """Tell the user something short (status bar)."""
        ...

    def flatten_ready(self) -> bool:
        """Reading the flattened document is cheap now (no slow filter is being computed)."""
        ...


class Tool:
    """A canvas tool: press starts, move continues, release finishes."""

    name = "tool"
    label = "Tool"
    shortcut = ""
    tip = ""
    #: the brush sliders apply to this tool (the tool panel greys them out otherwise)
    uses_brush = True
    #: strokes follow the brush's symmetry (the canvas shows where their mirror images land)
    mirrors = False

    def __init__(self, host: ToolHost) -> None:
        self.host = host

    @property
    def busy(self) -> bool:
        """A stroke is in progress."""
        return False

    def press(self, event: ToolEvent) -> None:
        pass

    def move(self, event: ToolEvent) -> None:
        pass

    def release(self, event: ToolEvent) -> None:
        pass

    def cancel(self) -> None:
        """Abandon what is in progress (Escape, a document change)."""

    def action(self) -> str:
        """What pressing on the canvas will do now, in a sentence (the status bar's)."""
        return f"{self.label}: {self.tip}"

    def cursor_radius(self) -> float | None:
        """Radius in texels of the outline to draw around the cursor (None: none)."""
        return None

    def markers(self, x: float, y: float) -> list[tuple[float, float]]:
        """Texel points to mark while the cursor is at (x, y) (a clone source)."""
        return []

    def outlines(self) -> list[tuple[list[tuple[float, float]], bool]]:
        """Polylines in texels to draw over the canvas, each with "closed" (a selection)."""
        return []
