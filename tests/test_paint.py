"""The brush engine: dab shapes, spacing, stroke opacity, swatches, erase, masks, clone stamp."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from matshop.errors import MatshopError
from matshop.layers import AddLayer, Document, History, Rect, SetMask, SetProperty
from matshop.material import Material, Schema
from matshop.paint import (
    Brush,
    PressureCurve,
    Stroker,
    StrokeSample,
    StrokeSession,
    Swatch,
    dab_footprint,
    load_swatches,
    paint_stroke,
    save_swatches,
)

SCHEMA = Schema.from_names(["base_color", "roughness", "normal", "metallic"])
SIZE = 96
BRONZE = Swatch(
    "bronze",
    {
        "base_color": (0.45, 0.25, 0.08),
        "roughness": (0.3,),
        "normal": (0.0, 0.0, 1.0),
        "metallic": (1.0,),
    },
)


def base_material() -> Material:
    rng = np.random.default_rng(5)
    normal = rng.normal(size=(SIZE, SIZE, 3)) * [0.3, 0.3, 1] + [0, 0, 1]
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    maps = {
        "base_color": rng.uniform(0.05, 0.9, (SIZE, SIZE, 3)),
        "roughness": rng.uniform(0.1, 0.9, (SIZE, SIZE, 1)),
        "normal": normal,
        "metallic": np.zeros((SIZE, SIZE, 1)),
    }
    return Material("base", SCHEMA, {k: v.astype(np.float32) for k, v in maps.items()})


def make_doc(**layer_props) -> tuple[Document, History, int]:
    doc = Document.from_material(base_material(), tile_size=32)
    history = History(doc)
    layer = doc.new_paint_layer("paint", **layer_props)
    history.push(AddLayer(layer))
    return doc, history, layer.id


def line(x0: float, y0: float, x1: float, y1: float, n: int = 12, pressure: float = 1.0):
    return [
        StrokeSample(x0 + (x1 - x0) * t, y0 + (y1 - y0) * t, pressure) for t in np.linspace(0, 1, n)
    ]


# ---------------------------------------------------------------- dabs and spacing


@pytest.mark.parametrize("radius", [3.0, 10.5, 24.0])
def test_hard_dab_covers_the_area_of_its_disc(radius: float) -> None:
    x0, y0, alpha = dab_footprint(40.3, 37.8, radius, hardness=1.0)
    # a hard dab is anti-aliased over one texel around r + 0.5 - 0.5
    assert alpha.sum() == pytest.approx(math.pi * radius**2, rel=0.06)
    cols = np.arange(x0, x0 + alpha.shape[1]) + 0.5 - 40.3
    rows = np.arange(y0, y0 + alpha.shape[0]) + 0.5 - 37.8
    distance = np.hypot(rows[:, None], cols[None, :])
    assert np.all(alpha[distance <= radius - 0.5] == 1.0)
    assert np.all(alpha[distance >= radius + 0.5] == 0.0)


def test_soft_dab_falls_off_monotonically_from_the_centre() -> None:
    x0, y0, alpha = dab_footprint(20.5, 20.5, 10.0, hardness=0.0)
    row = alpha[20 - y0, 20 - x0 :]
    assert row[0] == pytest.approx(1.0, abs=0.02)
    assert np.all(np.diff(row) <= 1e-7) and row[-1] < 0.01


def test_dabs_are_spaced_evenly_and_do_not_depend_on_event_batching() -> None:
    brush = Brush(radius_px=10, spacing=0.25)  # a dab every 5 texels
    samples = line(0, 0, 60, 80, n=23)  # 100 texels long
    at_once = Stroker(brush).add(samples)
    one_by_one_stroker = Stroker(brush)
    one_by_one = [d for s in samples for d in one_by_one_stroker.add([s])]
    assert at_once == one_by_one
    assert len(at_once) == 21
    steps = [math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(at_once, at_once[1:], strict=False)]
    assert np.allclose(steps, 5.0)


def test_pressure_scales_size_opacity_and_flow_through_their_curves() -> None:
    brush = Brush(
        radius_px=20,
        flow=0.8,
        opacity=0.5,
        size_pressure=PressureCurve(((0, 0.25), (1, 1))),
        flow_pressure=PressureCurve(),
        opacity_pressure=PressureCurve(((0, 0.5), (1, 1))),
    )
    stroker = Stroker(brush)
    dabs = stroker.add([StrokeSample(0, 0, 0.0), StrokeSample(200, 0, 1.0)])
    assert dabs[0].radius_px == pytest.approx(5.0, abs=1e-3)
    assert dabs[0].flow == pytest.approx(0.0, abs=1e-6)
    assert dabs[0].opacity == pytest.approx(0.25, abs=1e-6)
    assert dabs[-1].radius_px > 19 and dabs[-1].flow > 0.75 and dabs[-1].opacity > 0.49
    # spacing follows the size: dabs are denser where the brush is small
    gaps = np.diff([d.x for d in dabs])
    assert gaps[0] < gaps[-1]


@pytest.mark.parametrize(
    "kwargs", [{"radius_px": 0.0}, {"hardness": 2.0}, {"opacity": float("nan")}, {"spacing": 0}]
)
def test_absurd_brush_settings_are_refused(kwargs) -> None:
    with pytest.raises(ValueError, match="brush"):
        Brush(**kwargs)


# ---------------------------------------------------------------- painting


def test_a_stroke_paints_every_parameter_of_the_swatch_and_nothing_outside() -> None:
    doc, history, layer_id = make_doc()
    before = doc.flatten_edit()
    edit = paint_stroke(
        doc, layer_id, line(30, 48, 66, 48), Brush(radius_px=8, hardness=1.0), swatch=BRONZE
    )
    assert edit is not None
    maps = doc.physical()
    for name, value in BRONZE.values.items():
        assert np.allclose(maps[name][48, 48], value, atol=2e-5), name
    after = doc.flatten_edit()
    # texels farther than radius + 1 from the stroke's segment are bit-identical
    rows, cols = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    distance = np.where(
        (cols >= 30) & (cols <= 66),
        np.abs(rows - 48),
        np.hypot(rows - 48, np.minimum(np.abs(cols - 30), np.abs(cols - 66))),
    )
    far = distance > 9.0
    assert np.array_equal(after[far], before[far])
    assert not np.array_equal(after[~far], before[~far])


def test_stroke_opacity_caps_the_buildup_and_flow_builds_towards_it() -> None:
    doc, history, layer_id = make_doc()
    samples = line(20, 20, 70, 20, n=30)
    brush = Brush(radius_px=10, hardness=1.0, spacing=0.05, opacity=0.5, flow=1.0)
    paint_stroke(doc, layer_id, samples, brush, swatch=BRONZE)
    coverage = doc.layer(layer_id).coverage(doc.layout.bounds)
    # dozens of overlapping dabs: still exactly the stroke opacity
    assert coverage.max() == pytest.approx(0.5, abs=1e-6)
    assert coverage[20, 45] == pytest.approx(0.5, abs=1e-6)
    doc2, _, layer2 = make_doc()
    soft = Brush(radius_px=10, hardness=1.0, spacing=0.5, opacity=0.5, flow=0.3)
    paint_stroke(doc2, layer2, [StrokeSample(45, 60)], soft, swatch=BRONZE)
    one = doc2.layer(layer2).coverage(doc2.layout.bounds)[60, 45]
    assert one == pytest.approx(0.5 * 0.3, abs=1e-6)  # one dab: flow x opacity
    paint_stroke(doc2, layer2, line(45, 60, 45.01, 60, n=8), soft, swatch=BRONZE)
    assert one < doc2.layer(layer2).coverage(doc2.layout.bounds)[60, 45] <= 0.5 + 1e-6


def test_a_soft_dab_on_an_empty_layer_paints_the_swatch_value_not_a_darker_one() -> None:
    doc, _, layer_id = make_doc()
    paint_stroke(
        doc, layer_id, [StrokeSample(48, 48)], Brush(radius_px=12, hardness=0.0), swatch=BRONZE
    )
    layer = doc.layer(layer_id)
    values, coverage = layer.values(doc.layout.bounds)
    vector, _ = BRONZE.edit_values(SCHEMA)
    painted = coverage > 0
    assert painted.sum() > 300 and coverage[painted].min() < 0.05
    assert np.allclose(values[painted], vector, atol=1e-6)


def test_one_stroke_is_one_undo_step_restoring_bit_identical_results() -> None:
    doc, history, layer_id = make_doc()
    before = doc.flatten_edit()
    session = StrokeSession(doc, layer_id, Brush(radius_px=6), swatch=BRONZE, history=history)
    for sample in line(10, 10, 80, 70, n=40):
        session.add([sample])  # one input event at a time, as a tablet sends them
    session.end()
    painted = doc.flatten_edit()
    assert session.dabs > 20
    assert history.undo_label == "Paint"
    history.undo()
    assert np.array_equal(doc.flatten_edit(), before)
    assert history.undo_label != "Paint"
    history.redo()
    assert np.array_equal(doc.flatten_edit(), painted)


def test_cancel_puts_every_texel_back() -> None:
    doc, history, layer_id = make_doc()
    before = doc.flatten_edit()
    session = StrokeSession(doc, layer_id, Brush(radius_px=9), swatch=BRONZE, history=history)
    session.add(line(5, 5, 90, 90))
    assert not np.array_equal(doc.flatten_edit(), before)
    session.cancel()
    assert np.array_equal(doc.flatten_edit(), before)


def test_a_partial_swatch_paints_a_layer_limited_to_its_parameters() -> None:
    doc, _, layer_id = make_doc(parameters=["roughness"])
    before = doc.physical()
    rough = Swatch("polish", {"roughness": (0.05,)})
    paint_stroke(doc, layer_id, line(20, 50, 70, 50), Brush(radius_px=10, hardness=1), swatch=rough)
    after = doc.physical()
    assert after["roughness"][50, 45, 0] == pytest.approx(0.05, abs=1e-5)
    for name in ("base_color", "normal", "metallic"):
        assert np.array_equal(after[name], before[name]), name


def _channels_of(doc: Document, names) -> list[int]:
    return [
        c
        for n in names
        for c in range(doc.schema.edit_slices[n].start, doc.schema.edit_slices[n].stop)
    ]


def test_a_partial_swatch_in_a_new_layer_paints_its_parameters_and_leaves_the_others() -> None:
    """A layer affecting everything, a swatch of roughness only: roughness is painted,
    every other edit channel stays bit-identical (the layer is limited to roughness, in
    the stroke's undo step)."""
    doc, history, layer_id = make_doc()
    before = doc.flatten_edit()
    polish = Swatch("polish", {"roughness": (0.05,)})
    session = StrokeSession(
        doc, layer_id, Brush(radius_px=10, hardness=1), swatch=polish, history=history
    )
    session.add(line(20, 50, 70, 50))
    session.end()
    after = doc.flatten_edit()
    others = _channels_of(doc, ["base_color", "normal", "metallic"])
    assert np.array_equal(after[..., others], before[..., others])
    assert doc.physical()["roughness"][50, 45, 0] == pytest.approx(0.05, abs=1e-5)
    assert doc.layer(layer_id).parameters == ("roughness",)
    assert session.layer_id == layer_id and "roughness" in session.note
    history.undo()  # one step: the pixels and the layer's parameters
    assert np.array_equal(doc.flatten_edit(), before)
    assert doc.layer(layer_id).parameters is None


def test_a_partial_swatch_on_a_painted_layer_goes_to_a_new_layer_above() -> None:
    doc, history, layer_id = make_doc()
    brush = Brush(radius_px=10, hardness=1)
    paint_stroke(doc, layer_id, line(10, 20, 80, 20), brush, swatch=BRONZE, history=history)
    before = doc.flatten_edit()
    polish = Swatch("polish", {"roughness": (0.05,)})
    # across the bronze stroke and onto unpainted texels
    session = StrokeSession(doc, layer_id, brush, swatch=polish, history=history)
    session.add(line(45, 5, 45, 90))
    session.end()
    after = doc.flatten_edit()
    others = _channels_of(doc, ["base_color", "normal", "metallic"])
    assert np.array_equal(after[..., others], before[..., others])
    rough = doc.physical()["roughness"]
    assert rough[20, 45, 0] == pytest.approx(0.05, abs=1e-5)  # over the bronze
    assert rough[70, 45, 0] == pytest.approx(0.05, abs=1e-5)  # over the base
    new = doc.layer(session.layer_id)
    assert session.layer_id != layer_id and new.parameters == ("roughness",)
    assert doc.index_of(new.id) == doc.index_of(layer_id) + 1
    assert doc.layer(layer_id).parameters is None  # the painted layer is left alone
    history.undo()
    assert np.array_equal(doc.flatten_edit(), before)
    assert [layer.id for layer in doc.layers].count(new.id) == 0


def test_a_swatch_of_none_of_the_layers_parameters_is_refused() -> None:
    doc, _, layer_id = make_doc(parameters=["base_color"])
    with pytest.raises(ValueError, match="affects only base_color: nothing to paint"):
        StrokeSession(doc, layer_id, Brush(), swatch=Swatch("polish", {"roughness": (0.05,)}))
    with pytest.raises(ValueError, match="does not have"):
        Swatch("odd", {"sheen": (1.0,)}).edit_values(SCHEMA)
    with pytest.raises(ValueError, match="needs 3 value"):
        Swatch("odd", {"base_color": (1.0,), "roughness": (1,)}).edit_values(SCHEMA)


def test_a_stroke_that_changes_nothing_leaves_no_undo_step() -> None:
    doc, history, layer_id = make_doc()
    steps = history.report().undo_steps
    # the eraser over an empty layer, and a mask painted with what it already shows
    assert (
        paint_stroke(doc, layer_id, line(10, 10, 80, 80), Brush(), mode="erase", history=history)
        is None
    )
    history.push(SetMask(layer_id, doc.new_mask(1.0)))
    assert (
        paint_stroke(
            doc,
            layer_id,
            line(10, 10, 80, 80),
            Brush(),
            target="mask",
            mask_value=1.0,
            history=history,
        )
        is None
    )
    assert history.report().undo_steps == steps + 1  # only the mask's own step


def test_after_invert_a_mask_still_shows_what_is_painted_white_reveals_black_hides() -> None:
    doc, history, layer_id = make_doc()
    below = doc.flatten_edit()[48, 48].copy()
    paint_stroke(doc, layer_id, [StrokeSample(48, 48)], Brush(radius_px=40), swatch=BRONZE)
    shown = doc.flatten_edit()[48, 48].copy()
    history.push(SetMask(layer_id, doc.new_mask(1.0)))
    history.push(SetProperty(layer_id, "mask_inverted", True))
    assert np.allclose(doc.flatten_edit()[48, 48], below, atol=1e-6)  # inverted: all hidden
    dot, hard = [StrokeSample(48.5, 48.5)], Brush(radius_px=4, hardness=1)
    paint_stroke(doc, layer_id, dot, hard, target="mask", mask_value=1.0)  # white
    assert np.allclose(doc.flatten_edit()[48, 48], shown, atol=1e-6)
    paint_stroke(doc, layer_id, dot, hard, target="mask", mask_value=0.0)  # black
    assert np.allclose(doc.flatten_edit()[48, 48], below, atol=1e-6)
    paint_stroke(doc, layer_id, dot, hard, target="mask", mode="erase", mask_value=0.0)
    assert np.allclose(doc.flatten_edit()[48, 48], shown, atol=1e-6)  # the eraser reveals


def test_erasing_the_same_path_removes_the_coverage() -> None:
    doc, history, layer_id = make_doc()
    before = doc.flatten_edit()
    path = line(20, 30, 70, 60)
    brush = Brush(radius_px=8, hardness=1.0)
    paint_stroke(doc, layer_id, path, brush, swatch=BRONZE, history=history)
    paint_stroke(doc, layer_id, path, Brush(radius_px=12, hardness=1.0), mode="erase")
    assert doc.layer(layer_id).coverage(doc.layout.bounds).max() == 0.0
    assert np.allclose(doc.flatten_edit(), before, atol=1e-6)


def test_painting_a_mask_hides_and_reveals_the_layer() -> None:
    doc, history, layer_id = make_doc()
    below = doc.flatten_edit()[48, 48].copy()
    paint_stroke(doc, layer_id, [StrokeSample(48, 48)], Brush(radius_px=40), swatch=BRONZE)
    history.push(SetMask(layer_id, doc.new_mask(1.0)))
    shown = doc.flatten_edit()[48, 48].copy()
    assert not np.allclose(shown, below)
    dot = [StrokeSample(48.5, 48.5)]
    hard = Brush(radius_px=4, hardness=1)
    paint_stroke(doc, layer_id, dot, hard, target="mask", mask_value=0.0)
    assert doc.layer(layer_id).mask.read(Rect(48, 48, 49, 49))[0, 0, 0] == 0.0
    assert np.allclose(doc.flatten_edit()[48, 48], below, atol=1e-6)
    # erasing a mask paints the opposite value: the layer shows again
    paint_stroke(doc, layer_id, dot, hard, target="mask", mode="erase", mask_value=0.0)
    assert np.allclose(doc.flatten_edit()[48, 48], shown, atol=1e-6)


def test_dabs_wrap_across_the_edges_of_a_tiling_texture() -> None:
    doc, _, layer_id = make_doc()
    paint_stroke(
        doc, layer_id, [StrokeSample(1.0, 1.0)], Brush(radius_px=6, hardness=1), swatch=BRONZE
    )
    coverage = doc.layer(layer_id).coverage(doc.layout.bounds)
    corners = [coverage[0, 0], coverage[0, -1], coverage[-1, 0], coverage[-1, -1]]
    assert all(c > 0.9 for c in corners)
    # the wrapped dab is the same shape as one painted in the middle
    assert coverage.sum() == pytest.approx(math.pi * 36, rel=0.08)
    doc2, _, layer2 = make_doc()
    paint_stroke(
        doc2,
        layer2,
        [StrokeSample(1.0, 1.0)],
        Brush(radius_px=6, hardness=1),
        swatch=BRONZE,
        wrap=False,
    )
    coverage2 = doc2.layer(layer2).coverage(doc2.layout.bounds)
    assert coverage2[0, 0] > 0.9 and coverage2[-1, -1] == 0.0 and coverage2[0, -1] == 0.0


def test_clone_stamp_copies_the_composite_from_the_source_offset() -> None:
    doc, history, layer_id = make_doc()
    before = doc.flatten_edit()
    offset = (-30, 17)
    paint_stroke(
        doc,
        layer_id,
        line(50, 30, 70, 40),
        Brush(radius_px=7, hardness=1),
        mode="clone",
        clone_offset=offset,
        history=history,
    )
    after = doc.flatten_edit()
    # in the middle of the stroke the texels are the ones 30 left, 17 down
    for x, y in [(50, 30), (60, 35), (70, 40)]:
        assert np.allclose(after[y, x], before[y + 17, x - 30], atol=1e-6)
    history.undo()
    assert np.array_equal(doc.flatten_edit(), before)


def test_clone_stamp_reads_across_the_edge_when_the_source_wraps() -> None:
    doc, _, layer_id = make_doc()
    before = doc.flatten_edit()
    paint_stroke(
        doc,
        layer_id,
        [StrokeSample(10.5, 10.5)],
        Brush(radius_px=3, hardness=1),
        mode="clone",
        clone_offset=(-20, -20),
    )
    assert np.allclose(doc.flatten_edit()[10, 10], before[SIZE - 10, SIZE - 10], atol=1e-6)


def test_bad_strokes_are_refused_before_anything_is_painted() -> None:
    doc, _, layer_id = make_doc()
    base_id = doc.layers[0].id
    with pytest.raises(ValueError, match="fill layer"):
        StrokeSession(doc, base_id, Brush(), swatch=BRONZE)
    with pytest.raises(ValueError, match="no mask"):
        StrokeSession(doc, layer_id, Brush(), target="mask")
    with pytest.raises(ValueError, match="needs a swatch"):
        StrokeSession(doc, layer_id, Brush())
    with pytest.raises(ValueError, match="pressure"):
        StrokeSample(1, 2, 1.5)
    with pytest.raises(ValueError, match="finite"):
        StrokeSample(float("nan"), 2)
    assert not list(doc.layer(layer_id).pixels.keys())


# ---------------------------------------------------------------- swatch libraries


def test_swatch_library_round_trip_and_eyedropper(tmp_path: Path) -> None:
    doc, _, _ = make_doc()
    picked = Swatch.from_physical("picked", doc.physical(), 12, 34)
    assert np.allclose(picked.values["roughness"], doc.physical()["roughness"][34, 12])
    path = tmp_path / "swatches.json"
    save_swatches(path, [BRONZE, picked])
    loaded = load_swatches(path)
    assert [s.name for s in loaded] == ["bronze", "picked"]
    assert loaded[0].values == BRONZE.values and loaded[1].values == picked.values


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"\x89PNG\r\n", "not a swatch library"),
        (b'{"format": "other"}', "not a swatch library"),
        (b'{"format": "matshop-swatches", "version": 99}', "reads up to 1"),
        (
            b'{"format": "matshop-swatches", "version": 1, "swatches": [{"values": {}}]}',
            "no values",
        ),
    ],
)
def test_bad_swatch_libraries_are_one_line_errors(
    tmp_path: Path, content: bytes, message: str
) -> None:
    path = tmp_path / "bad.json"
    path.write_bytes(content)
    with pytest.raises(MatshopError, match=message) as info:
        load_swatches(path)
    assert "bad.json" in str(info.value) and "\n" not in str(info.value)


def test_clone_stamp_samples_its_layer_and_below_not_the_filters_above() -> None:
    # cloning into a layer under a "scale x2" filter: the filter applies once to
    # the cloned texels, as to every other; sampling the full composite would
    # apply it twice (and feed back on every further stroke)
    doc, history, layer_id = make_doc()
    history.push(AddLayer(doc.new_filter_layer("scale", op_params={"factor": 2.0})))
    below = doc.composite_through(layer_id, doc.layout.bounds)
    brush = Brush(radius_px=3, hardness=1)
    for _ in range(3):  # repeated strokes stay put
        paint_stroke(
            doc, layer_id, [StrokeSample(60.5, 30.5)], brush, mode="clone", clone_offset=(-20, 9)
        )
    assert np.allclose(doc.flatten_edit()[30, 60], 2.0 * below[39, 40], atol=1e-5)
