"""Strokes into a document: paint a swatch, erase, or clone-stamp, one undo step each.

A stroke keeps its own buffer of accumulated dab alpha ``S`` (and, for the
clone stamp, of the values it picked up), Krita's "wash" mode: each dab adds
``flow`` to ``S`` by alpha-over, and the layer shows the stroke composited
over the layer *as it was before the stroke* with weight ``opacity * S``. So
overlapping dabs build up towards ``opacity`` and never past it, low flow
builds up softly, and a stroke is an ordinary alpha composite in edit space:
one stroke paints every parameter of the swatch at once, predictably. When pen
pressure drives the opacity, each dab has its own: the stroke keeps its weight
``W`` too and a dab of opacity ``o`` moves it toward ``o`` by the dab's alpha,
never down (Krita's "alpha darken"): a light touch after a firm one leaves the
firm one's paint, and with one opacity ``W`` is ``opacity * S`` again.

Dabs that cross the image edge wrap to the other side (tiling textures) unless
``wrap=False``. Samples and dab centres are continuous texel coordinates.
With a :class:`~.symmetry.Symmetry`, every dab is stamped with its mirror
images too, into the same stroke buffer: one stroke, one undo step.

Each dab goes through the brush's :class:`~.dynamics.Dynamics` (jitter,
scatter, tip angle; seeded by the stroke's ``seed``), is stamped with the
brush's tip, and, with a :class:`~.stencil.Stencil`, is multiplied by what
the stencil lets through there.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from typing import Literal

import numpy as np

from ..errors import InvalidValue
from ..layers.document import Document
from ..layers.edits import AddLayer, CompoundEdit, Edit, SetProperty
from ..layers.geometry import Rect, periodic_runs
from ..layers.history import History
from ..layers.layer import Layer, PaintLayer
from ..layers.tiles import TileGrid
from ..layers.transaction import PaintTransaction
from ..ops.spec import MAX_OFFSET_PX
from .brush import Brush
from .dynamics import DabShaper
from .stencil import Stencil
from .stroke import Dab, Stroker, StrokeSample
from .swatch import Swatch
from .symmetry import NONE, Symmetry, mirrored_footprints

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
        Needed to paint pixels. The stroke paints exactly the parameters the
        swatch sets (those the layer affects) and leaves every other parameter
        of the material as it is (see :func:`fit_layer`; :attr:`layer_id` is
        the layer actually painted, :attr:`note` says why when it differs).
    mask_value : float
        What painting shows in a mask, as the mask reads: 1 reveals the layer,
        0 hides it, also after the mask was inverted (Photoshop's white and black).
    symmetry : Symmetry or str, optional
        Mirror each dab about the mirror lines (``"x"``: left/right, ``"y"``:
        top/bottom, ``"xy"``: both), through the texture's middle or the
        symmetry's own centre; a mirror image reaching past the border wraps or
        is clipped as ``wrap`` says (:mod:`.symmetry`); paint and erase strokes only.
    seed : int
        Seeds the brush's random dynamics: the same seed, the same stroke.
    stencil : Stencil, optional
        Masks every dab (in texel space; the editor places it from the screen).
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
        symmetry: Symmetry | str = NONE,
        seed: int = 0,
        stencil: Stencil | None = None,
        history: History | None = None,
        label: str | None = None,
    ) -> None:
        if isinstance(symmetry, str):
            symmetry = Symmetry.parse(symmetry)
        if symmetry and mode == "clone":
            raise InvalidValue("the clone stamp does not mirror: turn symmetry off to clone")
        if mode not in ("paint", "erase", "clone"):
            raise InvalidValue(f"unknown brush mode {mode!r} (paint, erase or clone)")
        if target not in ("pixels", "mask"):
            raise InvalidValue(f"unknown stroke target {target!r} (pixels or mask)")
        if not all(math.isfinite(v) and abs(v) <= MAX_OFFSET_PX for v in clone_offset):
            raise InvalidValue(
                f"clone offset must be finite, within +-{MAX_OFFSET_PX} px, got {clone_offset}"
            )
        layer = doc.layer(layer_id)
        if target == "pixels" and not isinstance(layer, PaintLayer):
            raise InvalidValue(f"layer {layer.name!r} is a {layer.kind} layer: paint into its mask")
        if target == "mask" and layer.mask is None:
            raise InvalidValue(f"layer {layer.name!r} has no mask to paint")
        if target == "mask" and mode == "clone":
            raise InvalidValue("the clone stamp paints layer pixels, not masks")
        if not 0.0 <= mask_value <= 1.0:
            raise InvalidValue(f"mask value must lie in [0, 1], got {mask_value:g}")
        self.doc = doc
        self.brush = brush
        self.mode = mode
        self.target = target
        self.wrap = wrap
        self.symmetry = symmetry
        self.stencil = stencil
        self._shaper = DabShaper(brush.dynamics, seed)
        self.history = history
        #: every sample fed, in order (what a stroke file of this stroke lists)
        self.samples: list[StrokeSample] = []
        self._values: np.ndarray | float = 0.0
        self._channels: np.ndarray | None = None
        #: the edit (already applied) that made the layer fit the swatch, undone with the stroke
        self._prepare: Edit | None = None
        #: why the stroke paints another layer or changed the layer's parameters ("" if not)
        self.note = ""
        if target == "mask":
            shown = mask_value if mode == "paint" else 1.0 - mask_value
            # the mask stores what shows before the inversion: paint what shows after it
            self._values = 1.0 - shown if layer.mask_inverted else shown
        elif mode == "paint":
            if swatch is None:
                raise InvalidValue("painting pixels needs a swatch (the material to paint)")
            layer, self._prepare, self.note = fit_layer(doc, layer, swatch)
            if self._prepare is not None:
                self._prepare.apply(doc)
            self._values, self._channels = swatch.edit_values(doc.schema)
        self._layer_id = layer_id = layer.id
        self._offset = (int(round(clone_offset[0])), int(round(clone_offset[1])))
        # the stroke's own accumulation: picked-up values (clone), weight W (when the
        # opacity follows pressure) and alpha S, in that order
        self._carried = carried = doc.channels if mode == "clone" else 0
        self._darken = brush.opacity_follows_pressure
        self._buffer = TileGrid(doc.layout, carried + 1 + self._darken, 0.0)
        self._stroker = Stroker(brush)
        default = {"paint": "Paint", "erase": "Erase", "clone": "Clone stamp"}[mode]
        if target == "mask":
            default += " mask"
        self._transaction = PaintTransaction(doc, layer_id, target, label or default)
        self.dabs = 0

    @property
    def layer_id(self) -> int:
        """The layer this stroke paints (a new one when :func:`fit_layer` made one)."""
        return self._layer_id

    def add(self, samples: Iterable[StrokeSample]) -> list[Dab]:
        """Feed input samples; paints the dabs they place and returns them."""
        samples = list(samples)
        self.samples += samples
        dabs = self._stroker.add(samples)
        for dab in dabs:
            self._stamp(dab)
        return dabs

    def _stamp(self, dab: Dab) -> None:
        placed = self._shaper.place(dab.x, dab.y, dab.radius_px, dab.direction)
        x0, y0, footprint = self.brush.footprint(
            placed.x, placed.y, placed.radius_px, placed.angle_deg
        )
        if self.stencil is not None:
            footprint = footprint * self.stencil.mask(x0, y0, *footprint.shape)
        doc = self.doc
        images = mirrored_footprints(x0, y0, footprint, doc.width, doc.height, self.symmetry)
        for x, y, alpha in images:
            height, width = alpha.shape
            for rect, where in footprint_pieces(x, y, height, width, doc, self.wrap):
                self.stamp_alpha(rect, np.float32(dab.flow) * alpha[where], dab.opacity)
        self.dabs += 1

    def stamp_alpha(self, rect: Rect, alpha: np.ndarray, opacity: float | None = None) -> None:
        """Add one dab's alpha ``(h, w)`` over ``rect`` (inside the image) to the stroke.

        ``opacity`` is the dab's (default: the brush's). :meth:`add` places round
        dabs in texture space; painting on a mesh computes its own footprints (a
        ball on the surface) and stamps them here.
        """
        block = self._buffer.read(rect)
        stroke_alpha = block[..., -1]
        new_alpha = alpha + stroke_alpha * (np.float32(1.0) - alpha)
        if self.mode == "clone":
            source = self.doc.composite_through(self._layer_id, rect.translate(*self._offset))
            share = np.divide(alpha, new_alpha, out=np.zeros_like(alpha), where=new_alpha > 0)
            values = block[..., : self._carried]
            values += share[..., None] * (source - values)
        block[..., -1] = new_alpha
        if self._darken:
            held = block[..., -2]
            dab_opacity = np.float32(self.brush.opacity if opacity is None else opacity)
            weight = held + alpha * np.maximum(dab_opacity - held, np.float32(0.0))
            block[..., -2] = weight
        else:
            weight = np.float32(self.brush.opacity) * new_alpha
        self._buffer.write(rect, block)
        tx = self._transaction
        if self.mode == "erase" and self.target == "pixels":
            tx.erase(rect, weight, over_original=True)
        elif self.mode == "clone":
            tx.paint(rect, block[..., : self._carried], weight, over_original=True)
        else:
            tx.paint(rect, self._values, weight, channels=self._channels, over_original=True)

    def end(self) -> Edit | None:
        """Finish the stroke: one (applied) edit, pushed to the history if there is one.

        Returns None, and leaves no trace, when the stroke changed no texel (an
        eraser over nothing, a mask painted with the value it already has).
        """
        for dab in self._stroker.finish():  # a click with a brush that waited for a direction
            self._stamp(dab)
        if not self._transaction.changed:
            self.cancel()
            return None
        edit: Edit = self._transaction.commit()
        if self._prepare is not None:
            edit = CompoundEdit([self._prepare, edit], label=edit.label)
        if self.history is not None:
            self.history.push(edit, applied=True)
        return edit

    def cancel(self) -> None:
        """Abandon the stroke: every texel it touched goes back, and the layer as it was."""
        self._transaction.cancel()
        if self._prepare is not None:
            self._prepare.revert(self.doc)
            self._prepare = None


def fit_layer(doc: Document, layer: PaintLayer, swatch: Swatch) -> tuple[Layer, Edit | None, str]:
    """Where a stroke of ``swatch`` goes so it paints its parameters and leaves the others.

    A paint layer holds one coverage for all its parameters, so a stroke
    raising coverage also shows the layer's values of parameters the swatch
    does not set. To leave those as they are, the painted layer must affect
    only parameters the swatch sets:

    - the layer does (or the swatch sets all it affects): paint it as it is;
    - it affects more but holds no paint yet: the stroke limits it to the
      swatch's parameters (nothing shown changes; undone with the stroke);
    - it affects more and holds paint: the stroke goes into a new paint layer
      just above, affecting the swatch's parameters (one undo step with it).

    Parameters the swatch sets that the layer does not affect stay unpainted:
    a layer's parameter limit is the artist's choice. Returns ``(layer to
    paint, the edit making it so or None, a sentence saying what changed)``.

    Raises ValueError when the swatch sets none of the parameters the layer affects.
    """
    painted, skipped = stroke_parameters(doc, layer, swatch)
    if not painted:
        raise InvalidValue(
            f"swatch {swatch.name!r} sets {', '.join(swatch.parameters)}; layer "
            f"{layer.name!r} affects only {', '.join(skipped)}: nothing to paint"
        )
    if not skipped:
        return layer, None, ""
    limit = None if len(painted) == len(doc.schema.names) else painted
    names = ", ".join(painted)
    if layer.pixels is None or len(layer.pixels) == 0:
        edit = SetProperty(layer.id, "parameters", limit)
        return layer, edit, f"layer {layer.name!r} now affects what the swatch sets: {names}"
    fresh = doc.new_paint_layer(parameters=limit, parent=layer.parent)  # in the same group
    edit = AddLayer(fresh, doc.index_of(layer.id) + 1)
    return (
        fresh,
        edit,
        f"painted into new layer {fresh.name!r} ({names}): {layer.name!r} also affects "
        f"{', '.join(skipped)}, which the swatch does not set",
    )


def stroke_parameters(
    doc: Document, layer: Layer, swatch: Swatch
) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """``(parameters a stroke of swatch paints in layer, those the layer affects but it does
    not set)``, in schema order."""
    affected = layer.parameters or doc.schema.names
    painted = tuple(p for p in affected if p in swatch.values)
    return painted, tuple(p for p in affected if p not in swatch.values)


def paint_stroke(
    doc: Document,
    layer_id: int,
    samples: Iterable[StrokeSample],
    brush: Brush,
    **options,
) -> Edit | None:
    """A whole stroke at once (scripts, the CLI, tests): see :class:`StrokeSession`."""
    session = StrokeSession(doc, layer_id, brush, **options)
    session.add(samples)
    return session.end()
