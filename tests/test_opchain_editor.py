"""The editor runs a batch recipe's op chain as filter layers, and they flatten to
the same bytes `matshop apply` writes for the same ops.

Truth: the files `matshop apply` writes (its own command line, run here) for the
bundled sample; the editor's document, flattened and saved as raw maps, must be
byte-identical. `test_batch.py` holds batch to `apply` the same way.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from matshop.batch import load_recipe
from matshop.cli import main
from matshop.errors import MatshopError
from matshop.io.images import write_image
from matshop.io.material_io import load_material, save_material
from matshop.layers import Document, FilterLayer
from matshop.opchain import Step, filter_layers

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SIZE = 512  # the bundled sample's size
PARAMS = ["normal", "roughness", "base_color"]

RECIPE = f"""
[[ops]]
op = "blur"
sigma_px = 2.5
params = {json.dumps(PARAMS)}
mask = "ramp.png"

[[ops]]
op = "bilateral"
sigma_px = 4
sigma_range = 0.2
params = {json.dumps(PARAMS)}
mask = "ramp.png"

[[ops]]
op = "curves"
points = "0,0;0.5,0.6;1,1"
params = {json.dumps(PARAMS)}
mask = "ramp.png"
"""
#: the same chain in `matshop apply`'s words
APPLY_WORDS = [
    "--op", "blur", "sigma_px=2.5",
    "--op", "bilateral", "sigma_px=4", "sigma_range=0.2",
    "--op", "curves", "points=0,0;0.5,0.6;1,1",
    "--params", ",".join(PARAMS),
]  # fmt: skip


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture(scope="module")
def recipe(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("recipe")
    ramp = np.linspace(0, 1, SIZE, dtype=np.float32)[None, :].repeat(SIZE, axis=0)
    write_image(folder / "ramp.png", ramp[..., None], bit_depth="uint16")
    (folder / "recipe.toml").write_text(RECIPE)
    return folder / "recipe.toml"


@pytest.fixture(scope="module")
def applied(recipe: Path) -> dict[str, bytes]:
    """What `matshop apply` writes for the sample with the recipe's ops."""
    out = recipe.parent / "applied"
    assert (
        main(
            [
                "apply",
                str(SAMPLE),
                str(out),
                *APPLY_WORDS,
                "--mask",
                str(recipe.parent / "ramp.png"),
            ]
        )
        == 0
    )
    files = _files(out)
    plain = recipe.parent / "plain"
    save_material(load_material(SAMPLE)[0], plain)
    changed = [name for name, data in _files(plain).items() if files.get(name) != data]
    assert {"tiles_basecolor.png", "tiles_roughness.png", "tiles_normal_gl.png"} <= set(changed)
    return files


def _saved(doc: Document, folder: Path) -> dict[str, bytes]:
    save_material(doc.flatten_physical(), folder)
    return _files(folder)


def test_recipe_layers_flatten_to_the_bytes_apply_writes(recipe, applied, tmp_path) -> None:
    doc = Document.from_material(load_material(SAMPLE)[0])
    layers = filter_layers(doc, load_recipe(recipe).steps)
    assert [layer.op for layer in layers] == ["blur", "bilateral", "curves"]
    for layer in layers:
        doc.insert_layer(layer)
    assert _saved(doc, tmp_path / "editor") == applied


def test_a_step_needing_another_set_is_not_a_filter_layer() -> None:
    doc = Document.from_material(load_material(SAMPLE)[0])
    with pytest.raises(MatshopError, match="step 1 \\(composite\\) needs another texture set"):
        filter_layers(doc, [Step("composite", {"over": SAMPLE})])


def test_the_editor_adds_a_recipe_as_one_undo_step(qtbot, recipe, applied, tmp_path) -> None:
    pytest.importorskip("pytestqt")
    from matshop.app.testing import shown_window

    window = shown_window(qtbot, tmp_path)
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    before = doc.flatten_edit()
    window.prompts.recipe_path = recipe
    window.actions_by_name["add_recipe"].trigger()

    filters = [layer for layer in doc.layers if isinstance(layer, FilterLayer)]
    assert [layer.op for layer in filters] == ["blur", "bilateral", "curves"]
    assert all(layer.mask is not None for layer in filters)
    assert "Added 3 filter layer(s) from recipe.toml" in window.statusBar().currentMessage()
    assert _saved(doc, tmp_path / "editor") == applied

    window.actions_by_name["undo"].trigger()  # the whole recipe is one step
    assert not any(isinstance(layer, FilterLayer) for layer in doc.layers)
    assert np.array_equal(doc.flatten_edit(), before)
    window.prompts.save_answer = "discard"


def test_a_bad_recipe_is_one_line_in_the_status_bar_and_adds_nothing(qtbot, tmp_path) -> None:
    pytest.importorskip("pytestqt")
    from matshop.app.testing import shown_window

    bad = tmp_path / "bad.toml"
    bad.write_text('[[ops]]\nop = "blur"\nsigma_px = -3\n')
    window = shown_window(qtbot, tmp_path)
    assert window.open_path(SAMPLE)
    count, steps = len(window.session.doc.layers), window.session.history.report().undo_steps
    window.prompts.recipe_path = bad
    window.actions_by_name["add_recipe"].trigger()
    message = window.statusBar().currentMessage()
    assert message.startswith(str(bad)) and "sigma_px" in message and "\n" not in message
    assert len(window.session.doc.layers) == count
    assert window.session.history.report().undo_steps == steps
    window.prompts.save_answer = "discard"
