"""The document: notifications, undo by tile swap, history budget, outputs."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.layers import (
    AddLayer,
    CompoundEdit,
    Document,
    History,
    MoveLayer,
    PaintTransaction,
    Rect,
    RemoveLayer,
    SetMask,
    SetProperty,
    flatten_reference,
)
from matshop.material import EditMaterial, Material, Schema
from matshop.ops import OpError

SCHEMA = Schema.from_names(["base_color", "roughness", "normal"])
C = SCHEMA.edit_width


def make_doc(height: int = 48, width: int = 64, tile: int = 16) -> tuple[Document, History]:
    doc = Document(SCHEMA, height, width, tile_size=tile)
    history = History(doc)
    rng = np.random.default_rng(3)
    base = rng.normal(0.3, 0.2, (height, width, C)).astype(np.float32)
    history.push(AddLayer(doc.new_fill_layer("base", source=base)))
    return doc, history


def add_paint(doc: Document, history: History, **props) -> int:
    layer = doc.new_paint_layer(**props)
    history.push(AddLayer(layer))
    return layer.id


def dab(doc: Document, history: History, layer_id: int, rect: Rect, target="pixels") -> None:
    tx = PaintTransaction(doc, layer_id, target)
    alpha = np.full((rect.height, rect.width), 0.75, np.float32)
    tx.paint(
        rect, np.linspace(-0.5, 1.0, C, dtype=np.float32) if target == "pixels" else 0.0, alpha
    )
    history.push(tx.commit(), applied=True)


class Recorder:
    def __init__(self, doc: Document) -> None:
        self.keys: set = set()
        self.calls = 0
        doc.events.dirty.connect(self)

    def __call__(self, region) -> None:
        self.keys |= region.keys
        self.calls += 1


def test_a_dab_reports_exactly_the_tiles_it_touches() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    doc.update()
    seen = Recorder(doc)
    rect = Rect(10, 5, 40, 20)
    dab(doc, history, layer_id, rect)
    assert (
        seen.keys
        == set(doc.layout.keys_in(rect))
        == {(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (1, 2)}
    )
    assert doc.update().sum() == len(seen.keys)  # only those are recomputed
    assert np.array_equal(doc.flatten_edit(), flatten_reference(doc))


def test_undo_reports_the_same_tiles_and_swaps_tile_objects_back() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    dab(doc, history, layer_id, Rect(0, 0, 20, 20))
    grid = doc.grid(layer_id, "pixels")
    before = {key: grid.get(key) for key in grid.keys()}
    image = doc.flatten_edit()
    rect = Rect(8, 8, 30, 30)
    dab(doc, history, layer_id, rect)
    seen = Recorder(doc)
    history.undo()
    assert seen.keys == set(doc.layout.keys_in(rect))
    assert {key: grid.get(key) for key in grid.keys()} == before
    assert all(grid.get(key) is tile for key, tile in before.items())  # the same objects
    assert np.array_equal(doc.flatten_edit(), image)


def test_undo_never_reruns_an_op(monkeypatch) -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    history.push(AddLayer(doc.new_filter_layer("blur", op_params={"sigma_px": 2.0})))
    dab(doc, history, layer_id, Rect(0, 0, 20, 20))
    filter_layer = doc.layers[-1]
    dirty_after_undo = Recorder(doc)

    import matshop.layers.layer as layer_module

    def refuse(*args, **kwargs):
        raise AssertionError("undo ran an op")

    monkeypatch.setattr(layer_module.FilterLayer, "run", refuse)
    history.undo()  # swapping tiles back needs no op; recompositing later does
    assert dirty_after_undo.keys
    monkeypatch.undo()
    assert filter_layer.op == "blur"
    assert np.array_equal(doc.flatten_edit(), flatten_reference(doc))


def test_hidden_layer_changes_report_nothing_dirty_but_content() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history, visible=False)
    seen = Recorder(doc)
    content = []
    doc.events.content.connect(lambda *args: content.append(args))
    dab(doc, history, layer_id, Rect(0, 0, 10, 10))
    assert seen.calls == 0 and len(content) == 1


def test_a_blur_above_widens_the_dirty_region_by_its_reach() -> None:
    doc, history = make_doc(64, 64, 16)
    layer_id = add_paint(doc, history)
    history.push(AddLayer(doc.new_filter_layer("blur", op_params={"sigma_px": 1.0})))  # reach 4
    doc.flatten_edit()
    seen = Recorder(doc)
    dab(doc, history, layer_id, Rect(20, 20, 28, 28))  # inside tile (1, 1)
    assert seen.keys == {(r, c) for r in range(3) for c in range(3)}
    assert np.array_equal(doc.flatten_edit(), flatten_reference(doc))


def test_detail_layer_reports_everything_it_covers() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history, blend="detail")
    dab(doc, history, layer_id, Rect(0, 0, 10, 10))
    seen = Recorder(doc)
    dab(doc, history, layer_id, Rect(40, 40, 50, 48))
    assert seen.keys == {(0, 0), (2, 2), (2, 3)}  # its mean moved
    assert np.array_equal(doc.flatten_edit(), flatten_reference(doc))


def test_mask_paint_reports_only_tiles_with_coverage() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    dab(doc, history, layer_id, Rect(0, 0, 16, 16))
    history.push(SetMask(layer_id, doc.new_mask(1.0)))
    seen = Recorder(doc)
    dab(doc, history, layer_id, Rect(0, 0, 40, 10), target="mask")
    assert seen.keys == {(0, 0)}
    assert np.array_equal(doc.flatten_edit(), flatten_reference(doc))


def test_structural_edits_undo_exactly() -> None:
    doc, history = make_doc()
    first = add_paint(doc, history)
    second = add_paint(doc, history, blend="add", opacity=0.5)
    dab(doc, history, first, Rect(0, 0, 30, 30))
    dab(doc, history, second, Rect(10, 10, 50, 40))
    image = doc.flatten_edit()
    removed = doc.layer(first)
    history.push(
        CompoundEdit(
            [
                MoveLayer(second, 1),
                SetProperty(second, "blend", "multiply"),
                SetProperty(second, "parameters", ["roughness"]),
                RemoveLayer(first),
            ],
            "several",
        )
    )
    assert len(doc) == 2
    assert not np.array_equal(doc.flatten_edit(), image)
    history.undo()
    assert doc.layer(first) is removed
    assert [layer.id for layer in doc.layers][1:] == [first, second]
    assert np.array_equal(doc.flatten_edit(), image)
    history.redo()
    history.undo()
    assert np.array_equal(doc.flatten_edit(), image)


def test_opacity_slider_moves_merge_until_sealed() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    for value in (0.9, 0.7, 0.5):
        history.push(SetProperty(layer_id, "opacity", value))
    assert history.report().undo_steps == 3  # two adds + one opacity step
    history.seal()
    history.push(SetProperty(layer_id, "opacity", 0.2))
    assert history.report().undo_steps == 4
    history.undo()
    assert doc.layer(layer_id).opacity == 0.5
    history.undo()
    assert doc.layer(layer_id).opacity == 1.0
    assert history.redo_label == "Layer opacity"


def test_history_budget_drops_oldest_steps_and_reports_bytes() -> None:
    doc = Document(SCHEMA, 64, 64, tile_size=16)
    tile_bytes = 16 * 16 * (C + 1) * 4
    history = History(doc, budget_bytes=10 * tile_bytes)
    layer = doc.new_paint_layer()
    history.push(AddLayer(layer))
    dab(doc, history, layer.id, Rect(0, 0, 16, 16))  # 1 tile: before None, after 1 tile
    assert history.nbytes == tile_bytes
    dab(doc, history, layer.id, Rect(0, 0, 16, 16))  # shares the previous "after" tile
    assert history.nbytes == 2 * tile_bytes
    for _ in range(6):
        dab(doc, history, layer.id, Rect(16, 16, 48, 32))  # 2 tiles each
    report = history.report()
    assert report.bytes <= report.budget_bytes
    assert report.dropped_steps > 0
    assert "MiB" in str(report)
    while history.undo() is not None:
        pass
    # what is left undoes cleanly, and the oldest steps are gone for good
    assert len(doc) == 1 and doc.layers[0].pixels is not None


def test_cancelled_transaction_leaves_no_trace() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    image = doc.flatten_edit()
    tx = PaintTransaction(doc, layer_id)
    tx.paint(Rect(0, 0, 30, 30), np.ones(C, np.float32), np.ones((30, 30), np.float32))
    assert not np.array_equal(doc.flatten_edit(), image)
    tx.cancel()
    assert len(doc.grid(layer_id, "pixels")) == 0
    assert np.array_equal(doc.flatten_edit(), image)
    with pytest.raises(RuntimeError):
        tx.paint(Rect(0, 0, 1, 1), np.ones(C, np.float32), np.ones((1, 1), np.float32))


def test_soft_dab_on_empty_texels_paints_the_dab_value() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    tx = PaintTransaction(doc, layer_id)
    value = np.arange(C, dtype=np.float32)
    tx.paint(Rect(0, 0, 4, 4), value, np.full((4, 4), 0.25, np.float32))
    values, coverage = doc.layer(layer_id).values(Rect(0, 0, 4, 4))
    assert np.allclose(values, value) and np.allclose(coverage, 0.25)
    tx.paint(Rect(0, 0, 4, 4), value, np.full((4, 4), 0.5, np.float32))
    _, coverage = doc.layer(layer_id).values(Rect(0, 0, 4, 4))
    assert np.allclose(coverage, 0.25 + 0.75 * 0.5)


def test_physical_flatten_is_from_edit_of_the_flatten() -> None:
    doc, history = make_doc(40, 36, 16)
    layer_id = add_paint(doc, history, parameters=["normal"])
    dab(doc, history, layer_id, Rect(5, 5, 30, 25))
    material = doc.flatten_physical()
    expected = EditMaterial("x", SCHEMA, flatten_reference(doc)).to_physical()
    for name in SCHEMA.names:
        assert np.array_equal(material.maps[name], expected.maps[name]), name
    view = doc.physical(Rect(0, 0, 8, 8), copy=False)["roughness"]
    assert not view.flags.writeable


def test_from_material_puts_the_set_in_a_fill_layer() -> None:
    schema = Schema.from_names(["base_color", "roughness"])
    rng = np.random.default_rng(0)
    maps = {
        "base_color": rng.random((20, 30, 3), np.float32),
        "roughness": rng.random((20, 30, 1), np.float32),
    }
    material = Material("steel", schema, maps)
    doc = Document.from_material(material, tile_size=8)
    assert doc.size == (20, 30) and doc.layers[0].kind == "fill"
    assert np.array_equal(doc.flatten_edit(), material.to_edit().data)


def test_tiled_filter_matches_the_whole_image_op_to_rounding() -> None:
    from matshop.ops.blur import gaussian_blur

    doc, history = make_doc(64, 64, 16)
    history.push(
        AddLayer(doc.new_filter_layer("blur", op_params={"sigma_px": 2.0, "border": "clamp"}))
    )
    whole = gaussian_blur(doc.layers[0].source, sigma_px=2.0, border="clamp")
    assert np.allclose(doc.flatten_edit(), whole, atol=1e-6, rtol=0)


def test_bad_layers_and_properties_fail_clearly() -> None:
    doc, history = make_doc()
    with pytest.raises(OpError, match="not a filter layer"):
        doc.new_filter_layer("composite")
    with pytest.raises(OpError):
        doc.new_filter_layer("blur", op_params={"sigma_px": -1})
    layer_id = add_paint(doc, history)
    with pytest.raises(ValueError, match="blend mode"):
        history.push(SetProperty(layer_id, "blend", "screen"))
    with pytest.raises(ValueError, match="no parameter"):
        history.push(SetProperty(layer_id, "parameters", ["sheen"]))
    with pytest.raises(ValueError, match="opacity"):
        history.push(SetProperty(layer_id, "opacity", 1.5))
    with pytest.raises(ValueError, match="no pixels"):
        PaintTransaction(doc, doc.layers[0].id)
    with pytest.raises(ValueError, match="no mask"):
        PaintTransaction(doc, layer_id, "mask")
    assert history.report().undo_steps == 2  # nothing half-applied was recorded


def test_a_failing_compound_edit_changes_nothing() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    with pytest.raises(ValueError):
        history.push(
            CompoundEdit(
                [SetProperty(layer_id, "opacity", 0.5), SetProperty(layer_id, "blend", "x")]
            )
        )
    assert doc.layer(layer_id).opacity == 1.0
    assert history.report().undo_steps == 2


def test_snapshot_flattens_on_its_own_and_its_caches_can_be_adopted() -> None:
    doc, history = make_doc()
    layer_id = add_paint(doc, history)
    dab(doc, history, layer_id, Rect(5, 6, 30, 20))
    history.push(AddLayer(doc.new_filter_layer("bilateral", op_params={"sigma_px": 2.0})))
    stale = doc.stale_global_layers()
    assert [layer.op for layer in stale] == ["bilateral"]
    twin = doc.snapshot()
    assert all(a is not b for a, b in zip(doc.layers, twin.layers, strict=True))
    live_tiles = doc.layer(layer_id).pixels
    twin_tiles = twin.layer(layer_id).pixels
    assert all(live_tiles.get(k) is twin_tiles.get(k) for k in live_tiles.keys())
    flat = twin.flatten_edit()  # as a worker would, without touching ``doc``
    assert doc.stale_global_layers() == stale
    doc.adopt_caches(twin)
    assert doc.stale_global_layers() == []
    assert np.array_equal(doc.flatten_edit(), flat)
    assert np.array_equal(flat, flatten_reference(doc))
    # the adopted caches keep working: an edit after adoption invalidates them
    dab(doc, history, layer_id, Rect(40, 30, 60, 45))
    assert np.array_equal(doc.flatten_edit(), flatten_reference(doc))
    with pytest.raises(ValueError, match="another document state"):
        doc.adopt_caches(Document(SCHEMA, 8, 8))
