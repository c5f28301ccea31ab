"""Pass-through group layers: what they composite, hide and restrict, cached and not."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.layers import (
    AddLayer,
    Document,
    History,
    PaintTransaction,
    Rect,
    SetMask,
    SetProperty,
    flatten_reference,
)
from matshop.material import Schema

SCHEMA = Schema.from_names(["base_color", "roughness", "metallic"])  # 5 edit channels
C = SCHEMA.edit_width
H, W, TILE = 40, 56, 16


def base_values() -> np.ndarray:
    """The base layer's texels: what a document whose other layers all vanish shows."""
    return np.random.default_rng(1).uniform(0.1, 0.9, (H, W, C)).astype(np.float32)


def base_doc() -> tuple[Document, History]:
    doc = Document(SCHEMA, H, W, tile_size=TILE)
    history = History(doc)
    history.push(AddLayer(doc.new_fill_layer("base", source=base_values())))
    return doc, history


def add(doc: Document, history: History, layer, index=None) -> int:
    history.push(AddLayer(layer, index))
    return layer.id


def fill(doc: Document, value: float, **props):
    return doc.new_fill_layer(value=np.full(C, value, np.float32), **props)


def paint_rect(doc: Document, history: History, layer_id: int, rect: Rect, value: float) -> None:
    tx = PaintTransaction(doc, layer_id)
    tx.paint(
        rect, np.full(C, value, np.float32), np.full((rect.height, rect.width), 0.8, np.float32)
    )
    history.push(tx.commit(), applied=True)


def check(doc: Document) -> np.ndarray:
    cached = doc.flatten_edit()
    assert np.array_equal(cached, flatten_reference(doc))
    return cached


def test_a_group_mixes_its_members_result_with_its_input_by_its_opacity() -> None:
    doc, history = base_doc()
    below = doc.flatten_edit()
    group = doc.new_group_layer("group", opacity=0.25)
    add(doc, history, group)
    a = add(doc, history, fill(doc, 0.2, opacity=0.5, parent=group.id), 1)
    add(doc, history, fill(doc, 0.9, blend="add", opacity=0.5, parent=group.id), 2)
    assert [layer.id for layer in doc.layers][1] == a
    # the members alone, by the blend formulas: normal then add
    members = below + 0.5 * (0.2 - below)
    members = members + 0.5 * 0.9
    expected = below + np.float32(0.25) * (members - below)
    assert np.allclose(check(doc), expected, atol=1e-6)


def test_hiding_a_group_hides_its_members_and_only_them() -> None:
    doc, history = base_doc()
    below = doc.flatten_edit()
    group = doc.new_group_layer("group")
    add(doc, history, group)
    add(doc, history, fill(doc, 0.3, parent=group.id), 1)
    outside = add(doc, history, fill(doc, 0.7, opacity=0.5))
    shown = check(doc)
    history.push(SetProperty(group.id, "visible", False))
    hidden = check(doc)
    assert np.allclose(hidden, below + 0.5 * (0.7 - below), atol=1e-6)
    history.undo()
    assert np.array_equal(check(doc), shown)
    del outside


def test_a_group_limited_to_parameters_drops_its_members_other_changes() -> None:
    doc, history = base_doc()
    below = doc.flatten_edit()
    group = doc.new_group_layer("group", parameters=["roughness"])
    add(doc, history, group)
    add(doc, history, fill(doc, 0.05, parent=group.id), 1)
    out = check(doc)
    rough = SCHEMA.edit_slices["roughness"]
    assert np.allclose(out[..., rough], 0.05)
    others = np.setdiff1d(np.arange(C), np.arange(C)[rough])
    assert np.array_equal(out[..., others], below[..., others])


def test_nested_groups_and_a_group_mask() -> None:
    doc, history = base_doc()
    below = doc.flatten_edit()
    outer = doc.new_group_layer("outer", opacity=0.5)
    add(doc, history, outer)
    inner = doc.new_group_layer("inner", opacity=0.5, parent=outer.id)
    add(doc, history, inner, 1)
    add(doc, history, fill(doc, 1.0, parent=inner.id), 1)
    # members: 1.0; inner: below + .5 (1 - below); outer: below + .5 (inner - below)
    expected = below + 0.25 * (1.0 - below)
    assert np.allclose(check(doc), expected, atol=1e-6)
    mask = np.zeros((H, W), np.float32)
    mask[:, : W // 2] = 1.0
    history.push(SetMask(outer.id, doc.new_mask(array=mask)))
    out = check(doc)
    assert np.allclose(out[:, : W // 2], expected[:, : W // 2], atol=1e-6)
    assert np.array_equal(out[:, W // 2 :], below[:, W // 2 :])
    history.push(SetProperty(inner.id, "visible", False))
    assert np.array_equal(check(doc), below)


def test_painting_inside_a_group_reports_only_the_dab_tiles() -> None:
    doc, history = base_doc()
    group = doc.new_group_layer("group", opacity=0.6)
    add(doc, history, group)
    layer = doc.new_paint_layer("paint", parent=group.id)
    add(doc, history, layer, 1)
    check(doc)
    seen = []
    doc.events.dirty.connect(lambda region: seen.append(set(region.keys)))
    paint_rect(doc, history, layer.id, Rect(3, 4, 12, 10), 0.9)
    assert set().union(*seen) == {(0, 0)}
    check(doc)
    history.undo()
    check(doc)


def test_membership_changes_are_undoable_and_validated() -> None:
    doc, history = base_doc()
    group = doc.new_group_layer("group", opacity=0.0)
    add(doc, history, group)
    member = fill(doc, 0.5)
    add(doc, history, member, 1)
    alone = check(doc)
    history.push(SetProperty(member.id, "parent", group.id))
    assert np.array_equal(check(doc), base_values())  # opacity 0 group: the member vanishes
    assert not np.array_equal(alone, base_values())  # (it showed before)
    history.undo()
    assert np.array_equal(check(doc), alone)
    with pytest.raises(ValueError, match="not a group"):
        history.push(SetProperty(group.id, "parent", member.id))
    with pytest.raises(ValueError, match="itself"):
        history.push(SetProperty(group.id, "parent", group.id))
    with pytest.raises(ValueError, match="blend mode is normal"):
        history.push(SetProperty(group.id, "blend", "add"))
    assert np.array_equal(check(doc), alone)


def test_removing_a_hidden_group_releases_its_members() -> None:
    doc, history = base_doc()
    group = doc.new_group_layer("group", visible=False)
    add(doc, history, group)
    add(doc, history, fill(doc, 0.5), 1)
    history.push(SetProperty(doc.layers[1].id, "parent", group.id))
    hidden = check(doc)
    base = doc.layers[0].source
    assert np.array_equal(hidden, base)  # a hidden group hides its members
    from matshop.layers import RemoveLayer

    history.push(RemoveLayer(group.id))
    # released, the opaque fill shows in every parameter: exactly its value
    assert np.array_equal(check(doc), np.full_like(base, 0.5))
    history.undo()
    assert np.array_equal(check(doc), hidden)


def test_undo_can_restore_membership_of_a_removed_group() -> None:
    # found by the stateful test: join G1, remove G1, join G2, undo
    from matshop.layers import RemoveLayer

    doc, history = base_doc()
    first = doc.new_group_layer("G1")
    add(doc, history, first)
    member = fill(doc, 0.5)
    add(doc, history, member, 1)
    history.push(SetProperty(member.id, "parent", first.id))
    history.push(RemoveLayer(first.id))
    alone = check(doc)
    second = doc.new_group_layer("G2", opacity=0.0)
    add(doc, history, second)
    history.push(SetProperty(member.id, "parent", second.id))
    assert np.array_equal(check(doc), base_values())  # in an opacity 0 group it vanishes
    assert not np.array_equal(alone, base_values())
    history.undo()  # back to the id of the removed G1: no group
    assert member.parent == first.id
    history.undo()
    assert np.array_equal(check(doc), alone)
    history.undo()  # G1 comes back, and with it the membership
    assert doc.layers[-1].id == first.id and doc.in_group(member, first.id)
    check(doc)


def test_a_removed_groups_id_is_never_reused_after_a_reload(tmp_path) -> None:
    from matshop.io.project import load_project, save_project
    from matshop.layers import RemoveLayer

    doc, history = base_doc()
    member = fill(doc, 0.5)
    add(doc, history, member)
    group = doc.new_group_layer("G")
    add(doc, history, group)
    history.push(SetProperty(member.id, "parent", group.id))
    history.push(RemoveLayer(group.id))
    save_project(doc, tmp_path / "p.matshop")
    loaded = load_project(tmp_path / "p.matshop").document
    fresh = loaded.new_group_layer("new")
    assert fresh.id > group.id  # else the new group would adopt the orphaned member
