"""Generated masks stay live: a layer's cavity / edge / AO mask is remade from the layers
below it whenever their normals change, and only then.

Truths: the generator run from scratch (``generate_mask``) on the material below as the
uncached whole-image flatten (``flatten_reference``) of a copy holding only the layers below;
the flattened colour is that mask's lerp, computed here; undo gives back the bytes before.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.errors import InvalidValue
from matshop.io.project import load_project, save_project
from matshop.layers import AddLayer, Document, History, SetProperty, flatten_reference
from matshop.material import EditMaterial, Material, Schema
from matshop.ops.generators import MaskGenerator, generate_mask
from matshop.paint import Brush, StrokeSample, Swatch, paint_stroke

SCHEMA = Schema.from_names(["base_color", "normal"])
SIZE = 64
RED = Swatch("red", {"base_color": (0.9, 0.05, 0.05)})
CAVITY = MaskGenerator("cavity", radius_px=4.0)


def make_doc() -> tuple[Document, History, int, int]:
    """Grey, flat material; an empty paint layer; a red fill masked by its cavity on top."""
    maps = {
        "base_color": np.full((SIZE, SIZE, 3), 0.5, np.float32),
        "normal": np.dstack([np.zeros((SIZE, SIZE, 2)), np.ones((SIZE, SIZE))]).astype(np.float32),
    }
    doc = Document.from_material(Material("flat", SCHEMA, maps), tile_size=16)
    history = History(doc)
    paint = doc.new_paint_layer("groove", parameters=["normal"])
    history.push(AddLayer(paint))
    value, _ = RED.edit_values(SCHEMA)
    dirt = doc.new_fill_layer(
        "dirt", value=value, parameters=["base_color"], mask_generator=CAVITY.to_json()
    )
    history.push(AddLayer(dirt))
    return doc, history, paint.id, dirt.id


def paint_wall(doc: Document, history: History, layer_id: int, x: float, tilt: float) -> None:
    """A vertical stroke (wrapping top to bottom) of normals tilted along x by ``tilt``."""
    swatch = Swatch("wall", {"normal": (tilt, 0.0, float(np.sqrt(1 - tilt * tilt)))})
    points = [StrokeSample(x, y) for y in np.linspace(-8, SIZE + 8, 12)]
    brush = Brush(radius_px=4, hardness=0.8)
    paint_stroke(doc, layer_id, points, brush, swatch=swatch, history=history)


def paint_groove(doc: Document, history: History, layer_id: int) -> None:
    """Two strokes of tilted normals: the left wall falls, the right one rises."""
    paint_wall(doc, history, layer_id, 28.0, 0.5)
    paint_wall(doc, history, layer_id, 36.0, -0.5)


def mask_from_scratch(doc: Document, layer_id: int, generator: MaskGenerator) -> np.ndarray:
    """The generator on the normals of an uncached flatten of the layers below ``layer_id``."""
    below = doc.snapshot()
    for layer in list(below.layers[below.index_of(layer_id) :]):
        below.remove_layer(layer.id)
    normals = EditMaterial("below", SCHEMA, flatten_reference(below)).to_physical().maps["normal"]
    settings = generator.to_json()
    return generate_mask(normals[..., :3], settings.pop("kind"), **settings)


def test_a_groove_painted_below_remakes_the_mask_as_the_generator_would_from_scratch() -> None:
    doc, history, paint, dirt = make_doc()
    assert not doc.generated_mask(dirt).any()  # a flat material has no cavity
    before = doc.flatten_edit()
    paint_groove(doc, history, paint)
    mask = doc.generated_mask(dirt)
    expected = mask_from_scratch(doc, dirt, CAVITY)
    np.testing.assert_allclose(mask, expected, atol=1e-5)
    # the groove's bottom is cavity, the flat far from it is not (the closed-form picture)
    assert mask[:, 31:34].mean() > 0.5 and mask[:, :12].max() < 0.05
    # the flatten shows red by exactly that mask, in edit space, and only in base colour
    flat = doc.flatten_edit()
    colour = SCHEMA.edit_slices["base_color"]
    red, _ = RED.edit_values(SCHEMA)
    grey = before[..., colour]
    lerp = grey + expected[..., None] * (red[colour] - grey)
    np.testing.assert_allclose(flat[..., colour], lerp, atol=1e-5)
    np.testing.assert_array_equal(flat, flatten_reference(doc))
    # undo takes the groove (two strokes) and the mask with it
    history.undo()
    history.undo()
    assert not doc.generated_mask(dirt).any()
    np.testing.assert_array_equal(doc.flatten_edit(), before)


def test_only_changes_to_the_normals_below_remake_the_mask() -> None:
    doc, history, paint, dirt = make_doc()
    paint_groove(doc, history, paint)
    mask = doc.generated_mask(dirt)
    doc.flatten_edit()
    dirty = []
    doc.events.dirty.connect(lambda region: dirty.append(region))
    # colour painted below: the normals are untouched, the mask is the same object
    colour = doc.new_paint_layer("colour", parameters=["base_color"])
    history.push(AddLayer(colour, doc.index_of(dirt)))
    dirty.clear()
    paint_stroke(doc, colour.id, [StrokeSample(8, 8)], Brush(radius_px=3), swatch=RED)
    assert doc.generated_mask(dirt) is mask
    assert dirty and not any(region.everything for region in dirty)  # just the dab's tiles
    # normals painted below, far from the groove: the whole mask is remade (its reach is global)
    dirty.clear()
    paint_wall(doc, history, paint, 8.0, 0.3)
    assert doc.generated_mask(dirt) is not mask
    assert any(region.everything for region in dirty)
    np.testing.assert_allclose(
        doc.generated_mask(dirt), mask_from_scratch(doc, dirt, CAVITY), atol=1e-5
    )
    np.testing.assert_array_equal(doc.flatten_edit(), flatten_reference(doc))


def test_generator_settings_are_one_undo_step_each() -> None:
    doc, history, paint, dirt = make_doc()
    paint_groove(doc, history, paint)
    cavity = doc.generated_mask(dirt).copy()
    edge = MaskGenerator("edge", radius_px=3.0, contrast=2.0)
    history.push(SetProperty(dirt, "mask_generator", edge), merge=False)
    np.testing.assert_allclose(
        doc.generated_mask(dirt), mask_from_scratch(doc, dirt, edge), atol=1e-5
    )
    history.push(SetProperty(dirt, "mask_generator", None), merge=False)
    assert doc.generated_mask(dirt) is None
    history.undo()
    assert doc.layer(dirt).mask_generator == edge
    history.undo()
    np.testing.assert_array_equal(doc.generated_mask(dirt), cavity)
    with pytest.raises(InvalidValue, match="unknown mask generator 'dirt'"):
        SetProperty(dirt, "mask_generator", {"kind": "dirt"}).apply(doc)
    plain = Document(Schema.from_names(["base_color"]), 8, 8)
    with pytest.raises(InvalidValue, match="this material has none"):
        plain.new_fill_layer("x", value=[0, 0, 0], mask_generator=CAVITY)


def test_projects_keep_the_generator_and_recompute_it_on_load(tmp_path: Path) -> None:
    doc, history, paint, dirt = make_doc()
    paint_groove(doc, history, paint)
    path = tmp_path / "live.matshop"
    save_project(doc, path)
    with zipfile.ZipFile(path) as archive:
        manifest = json.loads(archive.read("manifest.json"))
    entries = {entry["name"]: entry for entry in manifest["layers"]}
    assert entries["dirt"]["mask_generator"] == CAVITY.to_json()
    assert entries["dirt"]["mask"] is None  # the pixels are not stored: they are remade
    assert "mask_generator" not in entries["groove"]  # what older projects look like
    loaded = load_project(path).document
    np.testing.assert_array_equal(loaded.generated_mask(dirt), doc.generated_mask(dirt))
    np.testing.assert_array_equal(loaded.flatten_edit(), doc.flatten_edit())


def _groove_folder(tmp_path: Path) -> tuple[Path, Path]:
    """A flat grey texture set, and a 16-bit height image holding a Gaussian groove."""
    from matshop.io.images import write_image

    folder = tmp_path / "flat"
    folder.mkdir()
    flat = np.dstack([np.full((SIZE, SIZE, 2), 0.5), np.ones((SIZE, SIZE))])
    write_image(folder / "flat_normal_gl.png", flat.astype(np.float32), bit_depth="uint16")
    write_image(folder / "flat_basecolor.png", np.full((SIZE, SIZE, 3), 0.5, np.float32))
    x = np.arange(SIZE)
    height = 1.0 - np.exp(-((x - 32.0) ** 2) / (2 * 3.0**2))  # 0 at the bottom of the groove
    image = tmp_path / "groove_height.png"
    write_image(
        image, np.repeat(height[None, :], SIZE, 0)[..., None].astype(np.float32), bit_depth="uint16"
    )
    return folder, image


def test_the_command_line_keeps_the_mask_live(tmp_path: Path) -> None:
    folder, groove = _groove_folder(tmp_path)
    project = tmp_path / "g.matshop"
    assert main(["new", str(project), "--from", str(folder)]) == 0
    add = ["layer", "add", str(project)]
    assert (
        main(
            [
                *add,
                "fill",
                "--value",
                "base_color=0.9,0.05,0.05",
                "--name",
                "Dirt",
                "--mask-generator",
                "cavity",
                "radius_px=4",
            ]
        )
        == 0
    )
    doc = load_project(project).document
    dirt = doc.layers[-1]
    assert not doc.generated_mask(dirt.id).any()  # flat: no cavity yet
    # a groove added under the dirt (as a height image) remakes the mask on the way
    assert (
        main([*add, "image", str(groove), "--as-height", "--height-px", "6", "--index", "1"]) == 0
    )
    doc = load_project(project).document
    mask = doc.generated_mask(dirt.id)
    np.testing.assert_allclose(mask, mask_from_scratch(doc, dirt.id, CAVITY), atol=1e-5)
    assert mask[:, 32].min() > 0.9 and mask[:, :16].max() < 0.05  # bottom, not the flat
    # changed and removed with layer set; a bad setting is one line, exit 2, file unchanged
    assert main(["layer", "set", str(project), "Dirt", "mask_generator=edge radius_px=3"]) == 0
    edge = MaskGenerator("edge", radius_px=3.0)
    assert load_project(project).document.layers[-1].mask_generator == edge
    before = project.read_bytes()
    for bad in ("mask_generator=dirt", "mask_generator=ao radius_px=0", "mask_generator=ao x=1"):
        assert main(["layer", "set", str(project), "Dirt", bad]) == 2
    assert project.read_bytes() == before
    assert main(["layer", "set", str(project), "Dirt", "mask_generator=none"]) == 0
    assert load_project(project).document.layers[-1].mask_generator is None


@pytest.mark.parametrize(
    "stored",
    ["cavity", {"kind": "dirt"}, {"kind": "ao", "radius_px": "big"}, {"kind": "ao", "x": 1}],
)
def test_a_bad_stored_generator_is_refused_naming_the_layer(tmp_path: Path, stored) -> None:
    from matshop.errors import MatshopError

    doc, history, paint, dirt = make_doc()
    path = tmp_path / "bad.matshop"
    save_project(doc, path)
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    manifest = json.loads(members["manifest.json"])
    manifest["layers"][-1]["mask_generator"] = stored
    members["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    with pytest.raises(MatshopError, match="dirt.*mask_generator"):
        load_project(path)
