"""The curves dialog: points added, dragged and removed with real mouse events on the
pyqtgraph plot; each gesture one undo step; the result is the engine's curves op."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")
pytest.importorskip("pyqtgraph")

from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.histogram import edit_histogram  # noqa: E402
from matshop.app.testing import click, drag, shown_window  # noqa: E402
from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import AddLayer, Document, FilterLayer, History  # noqa: E402
from matshop.ops.curves import curve_lut  # noqa: E402
from matshop.tools.curve_points import CurvePoints  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def _reference(points, parameters=None) -> np.ndarray:
    material, _ = load_material(SAMPLE)
    doc = Document.from_material(material)
    layer = doc.new_filter_layer("curves", op_params={"points": points}, parameters=parameters)
    History(doc).push(AddLayer(layer))
    return doc.flatten_edit()


def test_curve_points_stay_valid_for_the_engine() -> None:
    model = CurvePoints()
    assert model.add(0.5, 0.7) == 1
    assert model.add(0.5 + 1e-4, 0.2) is None  # too close: x must increase strictly
    model.begin_drag(1)
    model.drag_to(1.5, -3.0)  # clamped below the right end point, y into [0, 1]
    model.end_drag()
    x, y = model.points[1]
    assert x < 1.0 and y == 0.0
    x_curve, y_curve = model.curve()
    assert np.array_equal(y_curve, curve_lut(model.points, x_curve.size))
    assert model.remove(1) and not model.remove(0)  # two points always remain


def test_histogram_maps_values_like_the_curves_op() -> None:
    material, _ = load_material(SAMPLE)
    edit = material.to_edit().data
    counts = edit_histogram(edit, material.schema, ["metallic"], bins=4, remap="space")
    # metallic is 0 or 1 in the sample: only the end bins are filled
    assert counts[0] > 0 and counts[-1] > 0 and counts[1:-1].sum() == 0 and counts.max() == 1.0
    # remap="data": the median at 0.5, the range median -/+ its larger reach to the
    # 0.5th / 99.5th percentile (computed here), so 0 and 1 land in those bins
    values = edit[..., material.schema.edit_slices["metallic"]].reshape(-1).astype(np.float64)
    low, median, high = np.percentile(values, [0.5, 50, 99.5])
    reach = max(median - low, high - median)
    want = np.zeros(4)
    for v in (0.0, 1.0):
        t = (v - (median - reach)) / (2 * reach)
        want[min(int(t * 4), 3)] += np.count_nonzero(values == v)
    counts = edit_histogram(edit, material.schema, ["metallic"], bins=4)
    np.testing.assert_allclose(counts, want / want.max())


def test_curves_dialog_adds_a_layer_one_step_per_drag_and_cancels_exactly(window, qtbot) -> None:
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    before = doc.flatten_edit()
    steps = window.session.steps
    dialog = window.open_curves()
    assert dialog is not None and dialog.isVisible()
    qtbot.waitExposed(dialog)
    layer = window.session.active_layer
    assert isinstance(layer, FilterLayer) and layer.op == "curves"
    assert window.session.steps == steps + 1  # the added layer is one step
    # the dialog says what [0, 1] stands for: the values' own range by default
    assert dialog.range_label.text().startswith("0 → 1 spans (data): ")
    assert "normal |v| [" in dialog.range_label.text()
    # ... and offers the space's fixed range: one undo step, shown at once
    dialog.remap.activated.emit(dialog.remap.findData("space"))
    assert layer.op_params["remap"] == "space" and window.session.steps == steps + 2
    assert dialog.range_label.text().startswith("0 → 1 spans (space): ")
    assert "normal |v| [0, 1.571] (space)" in dialog.range_label.text()
    window.session.undo()
    assert layer.op_params["remap"] == "data" and window.session.steps == steps + 1
    assert dialog.remap.currentData() == "data"
    assert dialog.range_label.text().startswith("0 → 1 spans (data): ")
    editor, model = dialog.editor, dialog.model
    viewport = editor.viewport()

    click(viewport, editor.to_widget(0.25, 0.1))  # a click adds a point
    assert len(model) == 3 and window.session.steps == steps + 2
    # a press on empty plot and a drag: a new point, dragged, one undo step
    path = [editor.to_widget(0.6, 0.6 + 0.04 * i) for i in range(6)]
    drag(viewport, path, pause_ms=15)
    assert len(model) == 4 and window.session.steps == steps + 3
    assert window.history_panel.labels()[-1] == "Filter settings"
    x, y = model.points[2]
    assert x == pytest.approx(0.6, abs=0.02) and y == pytest.approx(0.8, abs=0.02)
    # dragging a point off the plot removes it, in one step too
    path = [editor.to_widget(0.25, 0.1 - 0.1 * i) for i in range(5)]
    drag(viewport, path, pause_ms=15)
    assert len(model) == 3 and window.session.steps == steps + 4
    model.add(0.85, 0.95)  # the model API is the same gesture
    assert tuple(layer.op_params["points"]) == model.points

    dialog.parameter.setCurrentIndex(dialog.parameter.findData("roughness"))
    dialog.parameter.activated.emit(dialog.parameter.currentIndex())
    assert layer.parameters == ("roughness",)
    QApplication.processEvents()
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert dialog.grab().save(str(SHOTS / "10_curves_dialog.png"))
    window.canvas.flush()
    assert window.grab().save(str(SHOTS / "11_curves_layer_window.png"))

    # the layer is the engine's curves op on the same points
    assert np.array_equal(doc.flatten_edit(), _reference(model.points, ("roughness",)))
    dialog.reject()  # Cancel: back to the step the dialog opened at
    assert window.session.steps == steps and len(doc) == 1
    assert np.array_equal(doc.flatten_edit(), before)  # bit-identical


def test_ok_keeps_the_layer_and_reopening_edits_it(window, qtbot) -> None:
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    before = doc.flatten_edit()
    dialog = window.open_curves()
    dialog.model.add(0.5, 0.8)
    dialog.buttons.accepted.emit()
    assert not dialog.isVisible() and len(doc) == 2
    points = dialog.model.points
    assert np.array_equal(doc.flatten_edit(), _reference(points))
    again = window.open_curves()  # the curves layer is active: edited, not added
    assert len(doc) == 2 and again.model.points == points
    again.model.begin_drag(1)
    for y in (0.7, 0.6, 0.5):
        again.model.drag_to(0.5, y)
    again.model.end_drag()
    again.accept()
    window.session.undo()  # the whole drag is one step
    assert doc.layers[-1].op_params["points"] == points
    window.session.undo()
    window.session.undo()
    assert len(doc) == 1 and np.array_equal(doc.flatten_edit(), before)


def test_the_axes_and_readout_show_physical_roughness_and_the_histogram_spans_the_data(
    window, qtbot
) -> None:
    """Roughness chosen: the ticks are the GGX roughness at lo + t * span of the op's own
    data range, computed here from the space's closed form (edit = atan(r^2), MATH.md);
    the readout of a dragged point says the physical values; the histogram's mass lies
    inside [0, 1] (the data's robust range, not a corner of the space's range)."""
    import OpenImageIO as oiio

    from matshop.ops.curves import curve_ranges

    assert window.open_path(SAMPLE)
    dialog = window.open_curves()
    assert dialog is not None
    qtbot.waitExposed(dialog)
    dialog.parameter.setCurrentIndex(dialog.parameter.findData("roughness"))
    dialog.parameter.activated.emit(dialog.parameter.currentIndex())
    doc = window.session.doc
    (tone,) = curve_ranges(dialog._sample, schema=doc.schema, params=["roughness"])
    axis = dialog.editor.getPlotItem().getAxis("bottom")
    ticks = axis._tickLevels[0]  # what setTicks was given: (t, label)

    def roughness(t: float) -> float:
        # edit values outside the space's range [0, pi/4] are clamped going back (DESIGN 3)
        edit = np.clip(tone.lo[0] + t * tone.span[0], 0.0, np.pi / 4)
        return float(np.sqrt(np.tan(edit)))

    assert len(ticks) >= 3
    for t, label in ticks:  # round roughness values, each where the axis holds it
        assert abs(roughness(t) - float(label)) < 0.006, (t, label, roughness(t))
    assert "roughness" in dialog.editor.getPlotItem().getAxis("left").labelText.lower()
    # the file's roughness range (read independently) lies within the axis' ends
    buf = oiio.ImageBuf(str(next(SAMPLE.glob("*_roughness.*"))))
    file_r = np.asarray(buf.get_pixels(oiio.FLOAT))[..., 0]
    lo_r, hi_r = roughness(0.0), roughness(1.0)
    inside = np.mean((file_r >= lo_r - 0.01) & (file_r <= hi_r + 0.01))
    assert inside > 0.98  # the axis spans the data (0.5-99.5th percentiles inside)
    # a dragged point reads out in roughness
    editor, viewport = dialog.editor, dialog.editor.viewport()
    path = [editor.to_widget(0.5, 0.5 + 0.05 * i) for i in range(5)]
    seen = []
    dialog.model.changed.connect(lambda: seen.append(dialog.readout.text()))
    drag(viewport, path, pause_ms=15)
    x, _ = min(dialog.model.points, key=lambda point: abs(point[0] - 0.5))
    expected = f"Input {roughness(x):.2f}"
    assert any(text.startswith(expected) and "Roughness" in text for text in seen), seen
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert dialog.grab().save(str(SHOTS / "10b_curves_roughness_physical.png"))
    dialog.reject()
