"""History's events: a hand-written sequence for push, merge, undo, redo, drops and saves,
and the saved marker judged against the document's own state."""

from __future__ import annotations

import numpy as np

from matshop.layers import AddLayer, Document, History, PaintTransaction, Rect, SetProperty
from matshop.material import Schema

SCHEMA = Schema.from_names(["base_color", "roughness"])


def make() -> tuple[Document, History, int, list[tuple]]:
    doc = Document(SCHEMA, 32, 32, tile_size=16)
    layer = doc.new_fill_layer("base", value=np.full(SCHEMA.edit_width, 0.5, np.float32))
    doc.insert_layer(layer)
    history = History(doc)
    seen: list[tuple] = []
    events = history.events
    events.pushed.connect(lambda step, merged: seen.append(("pushed", step, merged)))
    events.undone.connect(lambda step: seen.append(("undone", step)))
    events.redone.connect(lambda step: seen.append(("redone", step)))
    events.dropped.connect(lambda steps, why: seen.append(("dropped", steps, why)))
    events.saved.connect(lambda: seen.append(("saved",)))
    return doc, history, layer.id, seen


def test_events_of_push_merge_undo_redo_drop_save_and_clear() -> None:
    doc, history, base, seen = make()
    fade = SetProperty(base, "opacity", 0.5)
    fade_more = SetProperty(base, "opacity", 0.4)  # the same drag: merges into ``fade``
    hide = SetProperty(base, "visible", False)
    rename = SetProperty(base, "name", "ground")
    blend = SetProperty(base, "blend", "add")

    history.push(fade)
    history.push(fade_more)
    history.seal()
    history.push(hide)
    history.mark_saved()
    history.undo()
    history.redo()
    history.undo()
    history.push(rename)  # after an undo: the undone ``hide`` is dropped
    history.max_steps = 2
    history.push(blend)  # three steps: the oldest (``fade``) goes
    history.clear()

    assert seen == [
        ("pushed", fade, False),
        ("pushed", fade, True),
        ("pushed", hide, False),
        ("saved",),
        ("undone", hide),
        ("redone", hide),
        ("undone", hide),
        ("dropped", (hide,), "redo"),
        ("pushed", rename, False),
        ("pushed", blend, False),
        ("dropped", (fade,), "limit"),
        ("dropped", (rename, blend), "clear"),
    ]
    assert doc.layer(base).opacity == 0.4 and doc.layer(base).name == "ground"


def test_a_push_drops_redo_steps_next_first_then_limits_after_it() -> None:
    _, history, base, seen = make()
    steps = [SetProperty(base, "opacity", v) for v in (0.9, 0.8, 0.7)]
    for step in steps:
        history.seal()
        history.push(step)
    for _ in steps:
        history.undo()
    history.max_steps = 0  # keep nothing: the new step itself is dropped after it is pushed
    last = SetProperty(base, "blend", "add")
    history.push(last)
    assert seen[-3:] == [
        ("dropped", (steps[0], steps[1], steps[2]), "redo"),
        ("pushed", last, False),
        ("dropped", (last,), "limit"),
    ]
    assert not history.can_undo and not history.can_redo


def test_the_byte_budget_drops_the_oldest_steps_as_events() -> None:
    doc, history, _, seen = make()
    tile_bytes = 16 * 16 * (SCHEMA.edit_width + 1) * 4
    history.budget_bytes = 3 * tile_bytes
    layer = doc.new_paint_layer()
    history.push(AddLayer(layer))
    for x0 in (0, 16, 0, 16, 0):
        tx = PaintTransaction(doc, layer.id, "pixels")
        rect = Rect(x0, 0, x0 + 16, 16)
        tx.paint(rect, np.full(SCHEMA.edit_width, 0.2, np.float32), np.ones((16, 16), np.float32))
        history.push(tx.commit(), applied=True)
    dropped = [step for event in seen if event[0] == "dropped" for step in event[1]]
    assert all(event[2] == "limit" for event in seen if event[0] == "dropped")
    report = history.report()
    assert len(dropped) == report.dropped_steps > 0
    assert report.bytes <= report.budget_bytes
    pushed = [event[1] for event in seen if event[0] == "pushed"]
    kept = [step for step in pushed if not any(step is d for d in dropped)]
    assert [step.label for step in kept] == list(report.undo_labels)


def test_saved_marker_follows_the_documents_real_state() -> None:
    """``at_saved`` is true exactly when the document equals what was marked saved."""
    doc, history, base, _ = make()
    opened = (doc.layer(base).opacity, doc.layer(base).visible)

    def state() -> tuple:
        return (doc.layer(base).opacity, doc.layer(base).visible)

    assert history.at_saved
    history.push(SetProperty(base, "opacity", 0.5))
    history.push(SetProperty(base, "opacity", 0.3))  # merged: a new state, not the first push's
    assert not history.at_saved
    history.undo()
    assert state() == opened and history.at_saved
    history.redo()
    history.mark_saved()
    saved = state()
    history.seal()
    history.push(SetProperty(base, "visible", False))
    assert not history.at_saved
    history.undo()
    assert state() == saved and history.at_saved


def test_undoing_past_dropped_steps_is_not_the_opened_state() -> None:
    doc, history, base, _ = make()
    opened = doc.layer(base).opacity
    history.max_steps = 1
    history.push(SetProperty(base, "opacity", 0.5))
    history.seal()
    history.push(SetProperty(base, "visible", False))  # drops the opacity step
    history.undo()
    assert not history.can_undo and doc.layer(base).opacity != opened
    assert not history.at_saved  # the opened state cannot be reached: still modified
