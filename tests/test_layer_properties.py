"""One table of layer properties: the layer model, project loading, ``matshop layer set``
and edit labels all read it, so a value is refused (or accepted) alike everywhere."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from matshop.cli import main
from matshop.errors import InvalidValue, MatshopError
from matshop.io.project import load_project, save_project
from matshop.layers import AddLayer, Document, History, SetProperty
from matshop.layers.properties import PROPERTIES
from matshop.material import Schema

SCHEMA = Schema.from_names(["base_color", "roughness", "metallic"])

#: stored-form values each property refuses (JSON-representable, so a manifest can hold them)
BAD: dict[str, list[Any]] = {
    "name": [7, None],
    "visible": [1, "yes", None],
    "opacity": [1.5, -0.1, "0.5", True, None],
    "blend": ["glow", 3],
    "parameters": [["sheen"], [], ["roughness", "roughness"], 0],
    "mask_inverted": [0, "false"],
}


def _doc() -> tuple[Document, History, int]:
    doc = Document(SCHEMA, 24, 20, tile_size=16)
    history = History(doc)
    base = np.random.default_rng(1).uniform(0, 1, (24, 20, SCHEMA.edit_width))
    history.push(AddLayer(doc.new_fill_layer("base", source=base.astype(np.float32))))
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    return doc, history, layer.id


def _tampered(doc: Document, tmp_path: Path, name: str, value: Any) -> Path:
    path = tmp_path / "p.matshop"
    save_project(doc, path)
    with zipfile.ZipFile(path) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    manifest = json.loads(members["manifest.json"])
    manifest["layers"][1][name] = value
    members["manifest.json"] = json.dumps(manifest).encode()
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for member, data in members.items():
            archive.writestr(member, data)
    path.write_bytes(buffer.getvalue())
    return path


@pytest.mark.parametrize(
    ("name", "value"), [(name, value) for name, values in BAD.items() for value in values]
)
def test_the_model_and_project_loading_refuse_a_value_with_one_message(
    tmp_path: Path, name: str, value: Any
) -> None:
    doc, history, layer_id = _doc()
    with pytest.raises(InvalidValue) as refused:
        history.push(SetProperty(layer_id, name, value))
    assert history.report().undo_steps == 2
    path = _tampered(doc, tmp_path, name, value)
    with pytest.raises(MatshopError) as not_loaded:
        load_project(path)
    assert refused.value.problem in not_loaded.value.problem


def test_every_property_of_every_kind_is_in_the_table_with_a_label() -> None:
    from matshop.layers.layer import FillLayer, FilterLayer, GroupLayer, PaintLayer

    for cls in (PaintLayer, FillLayer, FilterLayer, GroupLayer):
        assert cls.PROPERTIES and set(cls.PROPERTIES) <= set(PROPERTIES)
    for prop in PROPERTIES.values():
        assert SetProperty(1, prop.name, None).label == prop.label
        assert SetProperty(1, prop.name, None).mergeable == prop.mergeable


@pytest.mark.parametrize(
    ("text", "visible"), [("off", False), ("no", False), ("0", False), ("On", True), ("yes", True)]
)
def test_layer_set_reads_booleans_as_op_settings_do(tmp_path: Path, text: str, visible: bool):
    from matshop.ops.spec import ParamSpec

    assert ParamSpec("b", "bool", False, "").parse(text, "op") is visible  # the op's spelling
    doc, _, layer_id = _doc()
    path = tmp_path / "p.matshop"
    save_project(doc, path)
    main(["layer", "set", str(path), str(layer_id), "visible=false"])
    assert main(["layer", "set", str(path), str(layer_id), f"visible={text}"]) == 0
    assert load_project(path).document.layer(layer_id).visible is visible


@pytest.mark.parametrize(
    ("setting", "problem"),
    [
        ("visible=maybe", "visible must be true or false, got 'maybe'"),
        ("opacity=half", "opacity must be a number in [0, 1], got 'half'"),
        ("opacity=2", "opacity=2 is outside [0, 1]"),
        ("parameters=sheen", "no parameter(s) ['sheen']"),
        ("parent=x", "parent must be a group layer id, or none, got 'x'"),
    ],
)
def test_layer_set_refuses_bad_text_and_leaves_the_file(
    tmp_path: Path, capsys, setting: str, problem: str
) -> None:
    doc, _, layer_id = _doc()
    path = tmp_path / "p.matshop"
    save_project(doc, path)
    before = path.read_bytes()
    assert main(["layer", "set", str(path), str(layer_id), setting]) == 2
    assert problem in capsys.readouterr().err
    assert path.read_bytes() == before


def test_layer_set_moves_a_layer_into_a_group_by_id(tmp_path: Path) -> None:
    doc, history, layer_id = _doc()
    group = doc.new_group_layer("g")
    history.push(AddLayer(group))
    path = tmp_path / "p.matshop"
    save_project(doc, path)
    assert main(["layer", "set", str(path), str(layer_id), f"parent={group.id}"]) == 0
    assert load_project(path).document.layer(layer_id).parent == group.id
    assert main(["layer", "set", str(path), str(layer_id), "parent=none"]) == 0
    assert load_project(path).document.layer(layer_id).parent is None
