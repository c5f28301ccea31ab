"""Strokes into a document: paint a swatch, erase, or clone-stamp, one undo step each.

A stroke keeps its own buffer of accumulated dab alpha ``S`` (and, for the
clone stamp, of the values it picked up), Krita's "wash" mode: each dab adds
``flow`` to ``S`` by alpha-over, and the layer shows the stroke composited
over the layer *as it was before the stroke* with weight ``opacity * S``. So
overlapping dabs build up towards ``opacity`` and never past it, low flow
builds up softly, and a stroke is an ordinary alpha composite in edit space:
one stroke paints every parameter of the swatch at once, predictably.

Dabs that cross the image edge wrap to the other side (tiling textures) unless
``wrap=False``. Samples and dab centres are continuous texel coordinates.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from typing import Literal

import numpy as np

from ..layers.document import Document
from ..layers.edits import PaintEdit
from ..layers.geometry import Rect, periodic_runs
from ..layers.history import History
from ..layers.layer import PaintLayer
from ..layers.tiles import TileGrid
from ..layers.transaction import PaintTransaction
from ..ops.spec import MAX_OFFSET_PX
from .brush import Brush, dab_footprint
from .stroke import Dab, Stroker, StrokeSample
from .swatch import Swatch

Mode = Literal["paint", "erase", "clone"]
Target = Literal["pixels", "mask"]


def _spans(start: int, length: int, size: int, wrap: bool) -> list[tuple[int, int, int]]:
    """Pieces of ``[start, start + length)`` on an axis of ``size``: (offset, document start, n)."""
    if wrap:
        return periodic_runs(start, start + length, size)
    lo, hi = max(start, 0), min(start + length, size)
    return [(lo - start, lo, hi - lo)] if hi > lo else []


def footprint_pieces(
    x0: int, y0: int, height: int, width: int, doc: Document, wrap: bool
) -> Iterator[tuple[Rect, tuple[slice, slice]]]:
    """The document rectangles a ``height x width`` block at (x0, y0) lands on, with its slices."""
    for off_y, doc_y, n_y in _spans(y0, height, doc.height, wrap):
        for off_x, doc_x, n_x in _spans(x0, width, doc.width, wrap):
            yield (
                Rect(doc_x, doc_y, doc_x + n_x, doc_y + n_y),
                (slice(off_y, off_y + n_y), slice(off_x, off_x + n_x)),
            )


class StrokeSession:
    """One stroke in progress on one layer: feed samples, then :meth:`end` it.

    Parameters
    ----------
    doc : Document
    layer_id : int
        A paint layer (``target="pixels"``) or any layer with a mask (``"mask"``).
    brush : Brush
    mode : {"paint", "erase", "clone"}
        ``paint`` composites ``swatch`` (pixels) or ``mask_value`` (mask);
        ``erase`` removes coverage (pixels) or paints ``1 - mask_value``
        (mask: hides what painting reveals); ``clone`` stamps the composite of
        this layer and those below it ("current and below", so layers above,
        filters among them, are not applied twice) from ``clone_offset``
        texels away (dx, dy) into the pixels.
    swatch : Swatch, optional
        Needed to paint pixels. It must set every parameter the layer affects
        (other channels of the layer keep their values).
    history : History, optional
        Where :meth:`end` pushes the stroke as one step.
    """

    def __init__(
        self,
        doc: Document,
        layer_id: int,
        brush: Brush,
        *,
        mode: Mode = "paint",
        target: Target = "pixels",
        swatch: Swatch | None = None,
        mask_value: float = 1.0,
        clone_offset: tuple[float, float] = (0.0, 0.0),
        wrap: bool = True,
        history: History | None = None,
        label: str | None = None,
    ) -> None:
        if mode not in ("paint", "erase", "clone"):
            raise ValueError(f"unknown brush mode {mode!r} (paint, erase or clone)")
        if target not in ("pixels", "mask"):
            raise ValueError(f"unknown stroke target {target!r} (pixels or mask)")
        if not all(math.isfinite(v) and abs(v) <= MAX_OFFSET_PX for v in clone_offset):
            raise ValueError(
                f"clone offset must be finite, within +-{MAX_OFFSET_PX} px, got {clone_offset}"
            )
        layer = doc.layer(layer_id)
        if target == "pixels" and not isinstance(layer, PaintLayer):
            raise ValueError(f"layer {layer.name!r} is a {layer.kind} layer: paint into its mask")
        if target == "mask" and layer.mask is None:
            raise ValueError(f"layer {layer.name!r} has no mask to paint")
        if target == "mask" and mode == "clone":
            raise ValueError("the clone stamp paints layer pixels, not masks")
        if not 0.0 <= mask_value <= 1.0:
            raise ValueError(f"mask value must lie in [0, 1], got {mask_value:g}")
        self.doc = doc
        self._layer_id = layer_id
        self.brush = brush
        self.mode = mode
        self.target = target
        self.wrap = wrap
        self.history = history
        self._values: np.ndarray | float = 0.0
        self._channels: np.ndarray | None = None
        if target == "mask":
            self._values = mask_value if mode == "paint" else 1.0 - mask_value
        elif mode == "paint":
            self._values, self._channels = self._swatch_values(layer, swatch)
        self._offset = (int(round(clone_offset[0])), int(round(clone_offset[1])))
        # the stroke's own accumulation: picked-up values (clone) and alpha S
        carried = doc.channels if mode == "clone" else 0
        self._buffer = TileGrid(doc.layout, carried + 1, 0.0)
        self._stroker = Stroker(brush)
        default = {"paint": "Paint", "erase": "Erase", "clone": "Clone stamp"}[mode]
        if target == "mask":
            default += " mask"
        self._transaction = PaintTransaction(doc, layer_id, target, label or default)
        self.dabs = 0

    def _swatch_values(
        self, layer: PaintLayer, swatch: Swatch | None
    ) -> tuple[np.ndarray, np.ndarray]:
        if swatch is None:
            raise ValueError("painting pixels needs a swatch (the material to paint)")
        schema = self.doc.schema
        vector, channels = swatch.edit_values(schema)
        affected = layer.parameters or schema.names
        missing = [p for p in affected if p not in swatch.values]
        if missing:
            raise ValueError(
                f"layer {layer.name!r} affects {', '.join(missing)}, which swatch "
                f"{swatch.name!r} does not set: pick a swatch that does or limit the "
                f"layer's parameters"
            )
        return vector, channels

    def add(self, samples: Iterable[StrokeSample]) -> list[Dab]:
        """Feed input samples; paints the dabs they place and returns them."""
        dabs = self._stroker.add(samples)
        for dab in dabs:
            self._stamp(dab)
        return dabs

    def _stamp(self, dab: Dab) -> None:
        x0, y0, footprint = dab_footprint(dab.x, dab.y, dab.radius_px, self.brush.hardness)
        height, width = footprint.shape
        for rect, where in footprint_pieces(x0, y0, height, width, self.doc, self.wrap):
            self.stamp_alpha(rect, np.float32(dab.flow) * footprint[where])
        self.dabs += 1

    def stamp_alpha(self, rect: Rect, alpha: np.ndarray) -> None:
        """Add one dab's alpha ``(h, w)`` over ``rect`` (inside the image) to the stroke.

        :meth:`add` places round dabs in texture space; painting on a mesh
        computes its own footprints (a ball on the surface) and stamps them here.
        """
        block = self._buffer.read(rect)
        stroke_alpha = block[..., -1]
        new_alpha = alpha + stroke_alpha * (np.float32(1.0) - alpha)
        if self.mode == "clone":
            source = self.doc.composite_through(self._layer_id, rect.translate(*self._offset))
            share = np.divide(alpha, new_alpha, out=np.zeros_like(alpha), where=new_alpha > 0)
            values = block[..., :-1]
            values += share[..., None] * (source - values)
        block[..., -1] = new_alpha
        self._buffer.write(rect, block)
        weight = np.float32(self.brush.opacity) * new_alpha
        tx = self._transaction
        if self.mode == "erase" and self.target == "pixels":
            tx.erase(rect, weight, over_original=True)
        elif self.mode == "clone":
            tx.paint(rect, block[..., :-1], weight, over_original=True)
        else:
            tx.paint(rect, self._values, weight, channels=self._channels, over_original=True)

    def end(self) -> PaintEdit | None:
        """Finish the stroke: one (applied) edit, pushed to the history if there is one.

        Returns None when the stroke painted nothing.
        """
        if not self._transaction.keys:
            self._transaction.cancel()
            return None
        edit = self._transaction.commit()
        if self.history is not None:
            self.history.push(edit, applied=True)
        return edit

    def cancel(self) -> None:
        """Abandon the stroke: every texel it touched goes back."""
        self._transaction.cancel()


def paint_stroke(
    doc: Document,
    layer_id: int,
    samples: Iterable[StrokeSample],
    brush: Brush,
    **options,
) -> PaintEdit | None:
    """A whole stroke at once (scripts, the CLI, tests): see :class:`StrokeSession`."""
    session = StrokeSession(doc, layer_id, brush, **options)
    session.add(samples)
    return session.end()
