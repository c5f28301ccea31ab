"""Random edit sequences on a document (hypothesis stateful testing).

After every step:

- the cached, tiled flatten equals the uncached whole-image flatten exactly;
- every texel whose flattened value changed lies in a tile that was reported
  dirty (notifications are sound);
- after undo or redo, the document (layers, properties, tiles, masks) is
  bit-identical to replaying the remaining steps on a fresh document.

Commands are plain tuples naming layers by stack position, so the same list
replays on another document.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule

from matshop.layers import (
    AddLayer,
    Document,
    FillLayer,
    FilterLayer,
    GroupLayer,
    History,
    MoveLayer,
    PaintLayer,
    PaintTransaction,
    Rect,
    RemoveLayer,
    SetMask,
    SetProperty,
    flatten_reference,
)
from matshop.material import Schema
from matshop.paint import Brush, StrokeSample, StrokeSession, Swatch

SCHEMA = Schema.from_names(["base_color", "roughness", "metallic"])  # 5 edit channels
C = SCHEMA.edit_width

FILTERS = st.one_of(
    st.builds(
        lambda s, b: ("blur", {"sigma_px": s, "border": b}),
        st.sampled_from([0.0, 0.6, 1.5, 3.0, 7.0]),
        st.sampled_from(["wrap", "clamp"]),
    ),
    st.builds(lambda f: ("scale", {"factor": f}), st.sampled_from([0.5, -1.0, 2.0])),
    st.builds(lambda g: ("levels", {"gamma": g, "in_white": 0.8}), st.sampled_from([0.5, 2.0])),
    st.just(("curves", {"points": ((0.0, 0.1), (0.5, 0.7), (1.0, 0.9))})),
)
PARAMETERS = st.sampled_from([None, ("roughness",), ("base_color", "metallic"), ("base_color",)])
BLENDS = st.sampled_from(["normal", "add", "subtract", "multiply", "detail"])


def _dab(seed: int, rect: Rect, blob: bool) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    values = rng.normal(0.4, 0.6, C).astype(np.float32)
    if not blob:
        alpha = np.full((rect.height, rect.width), rng.choice([0.3, 1.0]), np.float32)
        return values, alpha
    ys, xs = np.mgrid[0 : rect.height, 0 : rect.width]
    cy, cx = (rect.height - 1) / 2, (rect.width - 1) / 2
    r = np.hypot((ys - cy) / max(cy, 1), (xs - cx) / max(cx, 1))
    alpha = np.clip(1.0 - r, 0.0, 1.0).astype(np.float32) ** rng.choice([0.5, 2.0])
    return values, alpha.astype(np.float32)


def execute(doc: Document, history: History, command: tuple) -> bool | None:
    """Apply one command as one edit; returns whether history merged it into the last step
    (None: nothing was pushed, a stroke that changed no texel)."""
    kind, *args = command
    if kind == "add":
        index, name, layer_kind, payload, props = args
        if layer_kind == "paint":
            layer = doc.new_paint_layer(name, **props)
        elif layer_kind == "fill":
            seed = payload
            if seed % 2:
                value = np.random.default_rng(seed).normal(0.5, 0.3, C)
                layer = doc.new_fill_layer(name, value=value, **props)
            else:
                texture = np.random.default_rng(seed).normal(0.5, 0.3, (doc.height, doc.width, C))
                layer = doc.new_fill_layer(name, source=texture.astype(np.float32), **props)
        elif layer_kind == "group":
            layer = doc.new_group_layer(name, **{**props, "blend": "normal"})
        else:
            op, op_params = payload
            layer = doc.new_filter_layer(op, name, op_params=op_params, **props)
        return history.push(AddLayer(layer, index))
    layer_id = doc.layers[args[0]].id
    if kind == "remove":
        return history.push(RemoveLayer(layer_id))
    if kind == "move":
        return history.push(MoveLayer(layer_id, args[1]))
    if kind == "prop":
        return history.push(SetProperty(layer_id, args[1], args[2]))
    if kind == "join":  # args: layer index, group index or None
        parent = None if args[1] is None else doc.layers[args[1]].id
        return history.push(SetProperty(layer_id, "parent", parent))
    if kind == "mask":
        mask = None if args[1] is None else doc.new_mask(args[1])
        return history.push(SetMask(layer_id, mask))
    if kind in ("paint", "erase"):
        _, target, rect, seed, blob = args
        tx = PaintTransaction(doc, layer_id, target)
        values, alpha = _dab(seed, rect, blob)
        if kind == "erase":
            tx.erase(rect, alpha)
        elif target == "mask":
            tx.paint(rect, float(values[0] > 0.4), alpha)
        else:
            tx.paint(rect, values, alpha)
            if seed % 3 == 0:  # a second dab in the same stroke
                tx.paint(rect.translate(seed % 7 - 3, 2), values[::-1].copy(), alpha)
        return history.push(tx.commit(), applied=True)
    if kind == "stroke":
        _, mode, points, radius, hardness, opacity, seed = args
        rng = np.random.default_rng(seed)
        swatch = Swatch(
            "random",
            {"base_color": rng.random(3), "roughness": rng.random(1), "metallic": rng.random(1)},
        )
        session = StrokeSession(
            doc,
            layer_id,
            Brush(radius_px=radius, hardness=hardness, opacity=opacity, flow=0.7),
            mode=mode,
            swatch=swatch if mode == "paint" else None,
            clone_offset=(seed % 11 - 5, seed % 7 - 3),
        )
        session.add([StrokeSample(x, y, p) for x, y, p in points])
        edit = session.end()
        # a stroke that changed no texel (an eraser over nothing) is no step at all
        return None if edit is None else history.push(edit, applied=True)
    raise AssertionError(kind)


def snapshot(doc: Document) -> list[Any]:
    """Everything that defines a document's content, ids aside."""
    state: list[Any] = [doc.size]
    index_of = {layer.id: index for index, layer in enumerate(doc.layers)}
    for layer in doc.layers:
        info = layer.describe()
        # ids differ between a document and its replay: name the group by position
        info["parent"] = index_of.get(info["parent"], "gone" if info["parent"] else None)
        state.append(repr(sorted(info.items())))
        if layer.mask is not None:
            state.append(layer.mask.to_array().tobytes())
        if isinstance(layer, PaintLayer) and layer.pixels is not None:
            state.append(layer.pixels.to_array().tobytes())
        if isinstance(layer, FillLayer) and layer.source is not None:
            state.append(layer.source.tobytes())
    return state


class DocumentMachine(RuleBasedStateMachine):
    @initialize(
        height=st.integers(12, 40),
        width=st.integers(12, 48),
        tile=st.sampled_from([8, 16]),
        seed=st.integers(0, 100),
        sigma=st.sampled_from([0.6, 1.5]),
        border=st.sampled_from(["wrap", "clamp"]),
        blends=st.tuples(BLENDS, BLENDS),
    )
    def start(self, height, width, tile, seed, sigma, border, blends) -> None:
        self.shape = (height, width, tile)
        self.doc = self._new_doc()
        self.history = History(self.doc)
        self.steps: list[list[tuple]] = []
        self.redo_steps: list[list[tuple]] = []
        self.dirty = self.doc.layout.no_tiles()
        self.doc.events.dirty.connect(self._on_dirty)
        self.previous = flatten_reference(self.doc)
        self.names = 0
        # a stack worth editing from the first step: a textured base, paint
        # under and over a neighbourhood filter (the hard case for caching)
        self._run(("add", 0, "base", "fill", 2 * seed, {}))
        self._run(("add", 1, "under", "paint", None, {"blend": blends[0]}))
        self._run(
            ("add", 2, "filter", "filter", ("blur", {"sigma_px": sigma, "border": border}), {})
        )
        self._run(("add", 3, "over", "paint", None, {"blend": blends[1]}))
        self.doc.flatten_edit()  # fill the caches, so later steps test invalidation

    def _new_doc(self) -> Document:
        height, width, tile = self.shape
        return Document(SCHEMA, height, width, tile_size=tile, background=np.full(C, 0.25))

    def _on_dirty(self, region) -> None:
        self.dirty |= region.tiles

    def _run(self, command: tuple) -> None:
        merged = execute(self.doc, self.history, command)
        if merged is None:  # nothing pushed: the history and its redo stack are as they were
            return
        if merged:
            self.steps[-1].append(command)
        else:
            self.steps.append([command])
        self.redo_steps.clear()

    def _rect(self, data) -> Rect:
        height, width, _ = self.shape
        x0 = data.draw(st.integers(-6, width - 1), "x0")
        y0 = data.draw(st.integers(-6, height - 1), "y0")
        w = data.draw(st.integers(1, 20), "w")
        h = data.draw(st.integers(1, 20), "h")
        return Rect(x0, y0, x0 + w, y0 + h)

    def _index(self, data, kinds: tuple[type, ...] | None = None, masked: bool = False) -> int:
        candidates = [
            i
            for i, layer in enumerate(self.doc.layers)
            if (kinds is None or isinstance(layer, kinds))
            and (not masked or layer.mask is not None)
        ]
        return data.draw(st.sampled_from(candidates), "layer")

    # -- rules -----------------------------------------------------------------

    @rule(
        data=st.data(),
        layer_kind=st.sampled_from(["paint", "paint", "fill", "filter"]),
        blend=BLENDS,
        opacity=st.sampled_from([1.0, 0.5]),
        parameters=PARAMETERS,
    )
    def add_layer(self, data, layer_kind, blend, opacity, parameters) -> None:
        index = data.draw(st.integers(0, len(self.doc.layers)), "index")
        if layer_kind == "fill":
            payload: Any = data.draw(st.integers(0, 1000), "seed")
        elif layer_kind == "filter":
            payload = data.draw(FILTERS, "filter")
        else:
            payload = None
        self.names += 1
        props = {"blend": blend, "opacity": opacity, "parameters": parameters}
        self._run(("add", index, f"L{self.names}", layer_kind, payload, props))

    @precondition(lambda self: self.doc.layers)
    @rule(data=st.data())
    def remove_layer(self, data) -> None:
        self._run(("remove", self._index(data)))

    @precondition(lambda self: len(self.doc.layers) > 1)
    @rule(data=st.data())
    def move_layer(self, data) -> None:
        index = self._index(data)
        self._run(("move", index, data.draw(st.integers(0, len(self.doc.layers) - 1), "to")))

    @precondition(lambda self: any(isinstance(la, PaintLayer) for la in self.doc.layers))
    @rule(data=st.data(), seed=st.integers(0, 10_000), blob=st.booleans(), erase=st.booleans())
    def paint(self, data, seed, blob, erase) -> None:
        index = self._index(data, (PaintLayer,))
        self._run(("erase" if erase else "paint", index, "pixels", self._rect(data), seed, blob))

    @precondition(lambda self: any(isinstance(la, PaintLayer) for la in self.doc.layers))
    @rule(data=st.data(), seed=st.integers(0, 10_000))
    def dab(self, data, seed) -> None:
        """Brush-like blobs are what users do most: a second, more likely paint rule."""
        index = self._index(data, (PaintLayer,))
        self._run(("paint", index, "pixels", self._rect(data), seed, True))

    @precondition(lambda self: any(isinstance(la, PaintLayer) for la in self.doc.layers))
    @rule(
        data=st.data(),
        mode=st.sampled_from(["paint", "paint", "erase", "clone"]),
        radius=st.sampled_from([0.5, 2.0, 5.5]),
        hardness=st.sampled_from([0.0, 0.6, 1.0]),
        opacity=st.sampled_from([1.0, 0.4]),
        seed=st.integers(0, 10_000),
    )
    def brush_stroke(self, data, mode, radius, hardness, opacity, seed) -> None:
        """A stroke of the real brush engine (spacing, wash mode, wrap, clone stamp)."""
        index = self._index(data, (PaintLayer,))
        height, width = self.doc.size
        coordinate = st.tuples(st.floats(-3, width + 3), st.floats(-3, height + 3), st.floats(0, 1))
        points = data.draw(st.lists(coordinate, min_size=1, max_size=4))
        self._run(("stroke", index, mode, points, radius, hardness, opacity, seed))

    @precondition(lambda self: any(la.mask is not None for la in self.doc.layers))
    @rule(data=st.data(), seed=st.integers(0, 10_000), blob=st.booleans())
    def paint_mask(self, data, seed, blob) -> None:
        index = self._index(data, masked=True)
        self._run(("paint", index, "mask", self._rect(data), seed, blob))

    @precondition(lambda self: self.doc.layers)
    @rule(data=st.data(), fill=st.sampled_from([None, 0.0, 1.0, 0.5]))
    def set_mask(self, data, fill) -> None:
        self._run(("mask", self._index(data), fill))

    @precondition(lambda self: self.doc.layers)
    @rule(
        data=st.data(),
        change=st.one_of(
            st.tuples(st.just("opacity"), st.sampled_from([0.0, 0.3, 0.8, 1.0])),
            st.tuples(st.just("visible"), st.booleans()),
            st.tuples(st.just("blend"), BLENDS),
            st.tuples(st.just("parameters"), PARAMETERS),
            st.tuples(st.just("mask_inverted"), st.booleans()),
            st.tuples(st.just("name"), st.sampled_from(["a", "b"])),
        ),
    )
    def set_property(self, data, change) -> None:
        index = self._index(data)
        if change[0] == "blend" and isinstance(self.doc.layers[index], GroupLayer):
            change = ("blend", "normal")  # groups only pass through
        self._run(("prop", index, *change))

    @rule(data=st.data(), opacity=st.sampled_from([1.0, 0.5, 0.0]), parameters=PARAMETERS)
    def add_group(self, data, opacity, parameters) -> None:
        index = data.draw(st.integers(0, len(self.doc.layers)), "index")
        self.names += 1
        props = {"opacity": opacity, "parameters": parameters}
        self._run(("add", index, f"G{self.names}", "group", None, props))

    @precondition(lambda self: any(isinstance(la, GroupLayer) for la in self.doc.layers))
    @rule(data=st.data(), leave=st.booleans())
    def join_group(self, data, leave) -> None:
        """Put a layer into a group above it (or take it out of its group)."""
        layers = self.doc.layers
        members = [i for i, layer in enumerate(layers) if layer.parent is not None]
        if leave and members:
            self._run(("join", data.draw(st.sampled_from(members), "member"), None))
            return
        groups = [g for g, layer in enumerate(layers) if isinstance(layer, GroupLayer)]
        group = data.draw(st.sampled_from(groups), "group")
        candidates = [i for i in range(group) if not self.doc.in_group(layers[group], layers[i].id)]
        if candidates:
            self._run(("join", data.draw(st.sampled_from(candidates), "layer"), group))

    @precondition(lambda self: any(isinstance(la, FilterLayer) for la in self.doc.layers))
    @rule(data=st.data(), new_filter=FILTERS)
    def set_filter(self, data, new_filter) -> None:
        index = self._index(data, (FilterLayer,))
        layer = self.doc.layers[index]
        assert isinstance(layer, FilterLayer)
        op, params = new_filter
        if op == layer.op:
            self._run(("prop", index, "op_params", params))
        else:
            self._run(("prop", index, "filter", (op, params)))

    @precondition(lambda self: self.history.can_undo)
    @rule()
    def undo(self) -> None:
        self.history.undo()
        self.redo_steps.append(self.steps.pop())
        self._check_replay()

    @precondition(lambda self: self.history.can_redo)
    @rule()
    def redo(self) -> None:
        self.history.redo()
        self.steps.append(self.redo_steps.pop())
        self._check_replay()

    @rule()
    def seal(self) -> None:
        self.history.seal()

    # -- checks ----------------------------------------------------------------

    def _check_replay(self) -> None:
        fresh = self._new_doc()
        history = History(fresh)
        for step in self.steps:
            for command in step:
                execute(fresh, history, command)
        assert snapshot(self.doc) == snapshot(fresh)
        assert np.array_equal(self.doc.flatten_edit(), flatten_reference(fresh))

    @invariant()
    def cached_flatten_equals_full_flatten(self) -> None:
        if not hasattr(self, "doc"):
            return
        reference = flatten_reference(self.doc)
        cached = self.doc.flatten_edit()
        assert np.array_equal(cached, reference), np.abs(cached - reference).max()
        # every changed texel was reported dirty
        changed = (reference != self.previous).any(axis=2)
        layout = self.doc.layout
        for key in layout.keys_in(layout.bounds):
            if changed[layout.tile_rect(key).slices].any():
                assert self.dirty[key], f"tile {key} changed but was not reported"
        self.previous = reference
        self.dirty = layout.no_tiles()


DocumentMachine.TestCase.settings = settings(
    max_examples=int(os.environ.get("MATSHOP_STATEFUL_EXAMPLES", "60")),
    stateful_step_count=30,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
TestDocumentMachine = DocumentMachine.TestCase
