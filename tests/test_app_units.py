"""Editor building blocks on their own: display conversion, view math, tile refresh,
the session's history bookkeeping and the slider gesture."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import AddLayer, Document, SetProperty  # noqa: E402
from matshop.material import Schema  # noqa: E402
from matshop.paint import Brush, StrokeSample, StrokeSession, Swatch  # noqa: E402
from matshop.viewport.display import display_mode, to_display  # noqa: E402
from matshop.viewport.display_cache import DisplayCache  # noqa: E402
from matshop.viewport.view import ViewTransform  # noqa: E402

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


@pytest.fixture(scope="module")
def sample_material():
    material, _ = load_material(SAMPLE)
    return material


def test_every_code_a_file_can_hold_is_shown_as_that_code() -> None:
    """Colors are the file's codes already; normals are shown as their file encodes them."""
    schema = Schema.from_names(["base_color", "normal", "roughness", "phong_exponent"])
    codes = np.arange(256, dtype=np.float32)
    phys = np.stack([codes, codes[::-1], codes], axis=-1)[None] / np.float32(255.0)
    shown = to_display(schema["base_color"], phys)[0]
    np.testing.assert_array_equal(shown[:, :3], np.stack([codes, codes[::-1], codes], -1))
    assert (shown[:, 3] == 255).all()
    gray = to_display(schema["roughness"], codes.reshape(1, 256, 1) / np.float32(255.0))[0]
    np.testing.assert_array_equal(gray[:, :3], np.repeat(codes[:, None], 3, axis=1))
    # a normal tilted towards +Y (OpenGL): the OpenGL file stores green 0.5 + 0.5 * 0.6,
    # a DirectX file 0.5 - 0.5 * 0.6
    tilted = np.array([[[0.0, 0.6, 0.8]]], np.float32)
    assert to_display(schema["normal"], tilted)[0, 0].tolist() == [128, 204, 230, 255]
    directx = to_display(schema["normal"], tilted, normal_convention="directx")[0, 0]
    assert directx.tolist() == [128, 51, 230, 255]
    assert display_mode(schema["normal"]).kind == "vector"
    # a Phong exponent n is shown as the equivalent roughness sqrt(2 / (n + 2))
    exponents = np.array([[[0.0], [2.0], [98.0], [10000.0]]], np.float32)
    expected = np.round(255.0 * np.sqrt(2.0 / (exponents[0, :, 0] + 2.0)))
    shown = to_display(schema["phong_exponent"], exponents)[0, :, 0]
    np.testing.assert_array_equal(shown, expected)


def test_zoom_keeps_the_texel_under_the_cursor_fixed() -> None:
    view = ViewTransform(zoom=1.5, offset_x=30.0, offset_y=-12.0)
    before = view.to_texel(200.0, 150.0)
    view.zoom_at(1.7, 200.0, 150.0)
    assert view.zoom == pytest.approx(2.55)
    assert view.to_texel(200.0, 150.0) == pytest.approx(before)
    view.fit(512, 256, 1000, 600)
    assert view.to_widget(256, 128) == pytest.approx((500, 300), abs=1)
    view.actual_size(512, 256, 1000, 600)
    assert view.zoom == 1.0


def test_display_cache_refreshes_only_dirty_tiles_and_matches_a_full_conversion(
    sample_material,
) -> None:
    doc = Document.from_material(sample_material)
    cache = DisplayCache(doc, "base_color")
    doc.events.dirty.connect(cache.mark)
    cache.refresh(budget_s=None)
    assert not cache.busy
    layer = doc.new_paint_layer()
    AddLayer(layer).apply(doc)  # an empty layer changes no tile
    assert not cache.busy
    session = StrokeSession(
        doc,
        layer.id,
        Brush(radius_px=6, hardness=1.0),
        swatch=Swatch("red", {p.name: _value(p) for p in doc.schema.parameters}),
    )
    session.add([StrokeSample(100, 100), StrokeSample(120, 100)])
    session.end()
    stale = int(cache.pending.sum())
    assert 1 <= stale <= 4  # a short stroke touches a few 64x64 tiles, not 64 of them
    done = cache.refresh(budget_s=None)
    assert sum(rect.area for rect in done) == stale * 64 * 64
    full = to_display(doc.schema["base_color"], doc.physical()["base_color"])
    np.testing.assert_array_equal(cache.buffer, full)


def _value(param) -> tuple[float, ...]:
    if param.name == "normal":
        return (0.0, 0.0, 1.0)
    return (0.9,) * param.phys_channels


def test_session_tracks_modified_across_undo_merge_and_save(qtbot, sample_material) -> None:
    from matshop.app.session import DocumentSession

    session = DocumentSession()
    doc = Document.from_material(sample_material)
    session.set_document(doc)
    base = doc.layers[0].id
    assert not session.modified
    session.seal()
    for value in (0.9, 0.8, 0.7):  # one slider drag
        session.push(SetProperty(base, "opacity", value), merge=True)
    session.seal()
    assert session.steps == 1 and session.modified
    session.undo()
    assert not session.modified and doc.layers[0].opacity == 1.0
    session.redo()
    session.mark_saved(Path("x.matshop"))
    assert not session.modified
    session.undo()
    assert session.modified  # the saved state had the opacity change
    session.jump_to(1)
    assert not session.modified and doc.layers[0].opacity == pytest.approx(0.7)


def test_float_slider_reports_a_drag_as_one_gesture(qtbot) -> None:
    from matshop.app.testing import drag
    from matshop.tools.widgets import FloatSlider

    slider = FloatSlider("Size", 1.0, 100.0, 50.0)
    qtbot.addWidget(slider)
    slider.resize(300, 30)
    slider.show()
    events: list[str] = []
    slider.started.connect(lambda: events.append("start"))
    slider.edited.connect(lambda v: events.append("edit"))
    slider.finished.connect(lambda: events.append("finish"))
    groove = slider.slider
    middle = groove.rect().center()
    drag(
        groove, [(middle.x(), middle.y()), *[(middle.x() + 10 * i, middle.y()) for i in (1, 2, 3)]]
    )
    assert events[0] == "start" and events[-1] == "finish"
    assert events.count("start") == 1 and events.count("edit") >= 2
    assert slider.value() > 50.0
    events.clear()
    slider.box.setValue(12.0)  # typing a value: one complete gesture
    assert events == ["start", "edit", "finish"]
