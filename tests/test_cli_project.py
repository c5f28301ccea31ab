"""The headless project verbs: new, layer add/list/set/remove, paint --stroke, flatten."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.material_io import load_material, save_material
from matshop.io.project import load_project
from matshop.layers import AddLayer, Document, History, SetProperty
from matshop.paint import Brush, StrokeSample, Swatch, paint_stroke

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
BRONZE = {
    "name": "bronze",
    "values": {
        "base_color": [0.45, 0.25, 0.08],
        "roughness": [0.3],
        "metallic": [1.0],
        "normal": [0.0, 0.0, 1.0],
        "ao": [1.0],
    },
}
POINTS = [[50, 50, 0.5], [300, 200, 1.0], [450, 450]]


def run(*argv: str) -> int:
    return main([str(a) for a in argv])


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.fixture
def project(tmp_path: Path) -> Path:
    path = tmp_path / "p.matshop"
    assert run("new", path, "--from", SAMPLE) == 0
    return path


def test_a_scripted_project_flattens_to_what_the_engine_computes(
    project: Path, tmp_path: Path
) -> None:
    strokes = tmp_path / "s.json"
    brush = {"radius_px": 20, "hardness": 0.7}
    strokes.write_text(
        json.dumps({"strokes": [{"brush": brush, "swatch": BRONZE, "points": POINTS}]})
    )
    assert run("layer", "add", project, "paint", "--name", "Bronze") == 0
    assert run("paint", project, "--stroke", strokes) == 0
    assert run("layer", "add", project, "fill", "--value", "roughness=0.9", "--name", "Rough") == 0
    assert (
        run("layer", "add", project, "filter", "--op", "blur", "sigma_px=3", "--params", "normal")
        == 0
    )
    assert run("layer", "set", project, "Rough", "opacity=0.5", "blend=multiply") == 0
    assert run("flatten", project, tmp_path / "cli") == 0

    # the same edits through the Python engine
    material, _ = load_material(SAMPLE)
    doc = Document.from_material(material)
    history = History(doc)
    paint = doc.new_paint_layer("Bronze")
    history.push(AddLayer(paint))
    paint_stroke(
        doc,
        paint.id,
        [StrokeSample(*p) for p in POINTS],
        Brush(radius_px=20, hardness=0.7),
        swatch=Swatch.from_json(BRONZE),
    )
    value, _ = Swatch("v", {"roughness": [0.9]}).edit_values(doc.schema)
    rough = doc.new_fill_layer("Rough", value=value, parameters=["roughness"])
    history.push(AddLayer(rough))
    history.push(
        AddLayer(doc.new_filter_layer("blur", op_params={"sigma_px": 3.0}, parameters=["normal"]))
    )
    history.push(SetProperty(rough.id, "opacity", 0.5))
    history.push(SetProperty(rough.id, "blend", "multiply"))
    save_material(doc.flatten_physical(), tmp_path / "api")
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")

    layers = load_project(project).document.layers
    assert [layer.name for layer in layers] == ["Base", "Bronze", "Rough", "Gaussian blur"]
    assert layers[2].blend == "multiply" and layers[2].parameters == ("roughness",)


def test_layer_list_remove_and_hidden(project: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        run(
            "layer",
            "add",
            project,
            "paint",
            "--name",
            "Scratch",
            "--hidden",
            "--params",
            "roughness",
        )
        == 0
    )
    capsys.readouterr()
    assert run("layer", "list", project) == 0
    listing = capsys.readouterr().out
    assert "'Scratch': paint" in listing and "hidden" in listing and "affects roughness" in listing
    assert run("layer", "remove", project, "Scratch") == 0
    assert [layer.name for layer in load_project(project).document.layers] == ["Base"]


def test_fill_from_another_set_with_a_mask(project: Path, tmp_path: Path) -> None:
    from matshop.io.images import read_image, write_image

    rust = tmp_path / "rust"
    rust.mkdir()
    write_image(rust / "rust_basecolor.png", np.tile([[[0.6, 0.25, 0.1]]], (512, 512, 1)))
    ramp = np.linspace(0, 1, 512, dtype=np.float32)[None, :].repeat(512, axis=0)
    write_image(tmp_path / "ramp.png", ramp[..., None], bit_depth="uint16")
    assert (
        run("layer", "add", project, "fill", "--from", rust, "--mask", tmp_path / "ramp.png") == 0
    )
    doc = load_project(project).document
    assert doc.layers[1].parameters == ("base_color",)
    maps = doc.physical()
    base = load_material(SAMPLE)[0].maps
    assert np.allclose(maps["base_color"][:, 0], base["base_color"][:, 0], atol=1e-5)
    assert np.allclose(maps["base_color"][:, -1], [0.6, 0.25, 0.1], atol=2e-3)
    # the fill affects base color only: roughness is the source file's, code for code
    rough_file, _ = read_image(SAMPLE / "tiles_roughness.png")
    assert np.abs(maps["roughness"][..., 0] - rough_file[..., 0]).max() <= 0.5 / 255


def test_an_empty_project_of_a_given_size(tmp_path: Path) -> None:
    path = tmp_path / "e.matshop"
    assert run("new", path, "--size", "300x200", "--params", "base_color,roughness") == 0
    doc = load_project(path).document
    assert doc.size == (200, 300) and list(doc.schema.names) == ["base_color", "roughness"]


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["new", "PROJECT", "--from", "SAMPLE"], "already exists"),
        (["new", "NEW", "--size", "10x10"], "--size and --params"),
        (["new", "NEW", "--size", "0x10", "--params", "roughness"], "1 to 65536"),
        (["layer", "add", "PROJECT", "fill"], "needs --value"),
        (["layer", "add", "PROJECT", "fill", "--value", "sheen=1"], "does not have"),
        (["layer", "add", "PROJECT", "paint", "--op", "blur"], "does not apply"),
        (["layer", "add", "PROJECT", "filter", "--op", "sharpen"], "unknown op"),
        (["layer", "add", "PROJECT", "paint", "--blend", "overlay"], "overlay"),
        (["layer", "set", "PROJECT", "Base", "opacity=2"], "opacity"),
        (["layer", "set", "PROJECT", "Nope", "opacity=1"], "no layer named 'Nope'"),
        (["layer", "remove", "PROJECT", "99"], "no layer with id 99"),
        (["paint", "PROJECT", "--stroke", "STROKE"], "no paint layer"),
        (["flatten", "MISSING", "OUT"], "missing.matshop: file not found"),
    ],
)
def test_bad_requests_are_one_line_and_leave_the_project_alone(
    argv: list[str], expected: str, project: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    stroke = tmp_path / "s.json"
    stroke.write_text(json.dumps({"swatch": BRONZE, "points": POINTS}))
    before = project.read_bytes()
    names = {
        "PROJECT": project,
        "SAMPLE": SAMPLE,
        "NEW": tmp_path / "new.matshop",
        "STROKE": stroke,
        "MISSING": tmp_path / "missing.matshop",
        "OUT": tmp_path / "out",
    }
    capfd.readouterr()
    assert run(*[names.get(a, a) for a in argv]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0], err
    assert project.read_bytes() == before
    assert not (tmp_path / "new.matshop").exists() and not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("{", "not a stroke file"),
        ('{"points": []}', "non-empty"),
        ('{"points": [[1, 2, 3, 4]]}', "bad point"),
        ('{"points": [[1, 2, 7]]}', "pressure"),
        ('{"points": [[1, 2]], "colour": 1}', "unknown key"),
        ('{"points": [[1, 2]], "brush": {"radius_px": -3}}', "radius_px"),
        ('{"points": [[1, 2]], "swatch": {"values": {"roughness": [1e999]}}}', "finite"),
        (
            '{"points": [[1, 2]], "layer": "Base", "swatch": ' + json.dumps(BRONZE) + "}",
            "fill layer",
        ),
    ],
)
def test_bad_stroke_files_name_the_file_and_paint_nothing(
    content: str, expected: str, project: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    assert run("layer", "add", project, "paint") == 0
    before = project.read_bytes()
    stroke = tmp_path / "bad.json"
    stroke.write_text(content)
    capfd.readouterr()
    assert run("paint", project, "--stroke", stroke) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0] and "bad.json" in err[0], err
    assert project.read_bytes() == before


def test_a_group_made_on_the_command_line_mixes_its_members(project: Path) -> None:
    below = load_project(project).document.physical()["roughness"]
    assert run("layer", "add", project, "group", "--name", "G", "--opacity", "0.5") == 0
    assert run("layer", "add", project, "fill", "--value", "roughness=0.1", "--group", "G") == 0
    doc = load_project(project).document
    assert [layer.kind for layer in doc.layers] == ["fill", "fill", "group"]
    assert doc.layers[1].parent == doc.layers[2].id
    # half of the way from the original roughness to 0.1, in the GGX edit space
    roughness = doc.schema["roughness"].space
    expected = roughness.from_edit(
        0.5 * (roughness.to_edit(below) + roughness.to_edit(np.full_like(below, 0.1)))
    )
    assert np.allclose(doc.physical()["roughness"], expected, atol=1e-5)
    assert run("layer", "set", project, "G", "visible=false") == 0
    assert np.array_equal(load_project(project).document.physical()["roughness"], below)


def test_recover_restores_a_newer_autosave_and_the_verbs_mention_it(
    project: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    from matshop.io.project import find_recovery, write_recovery

    doc = load_project(project).document
    doc.insert_layer(doc.new_paint_layer("unsaved work"))
    write_recovery(doc, project)
    capfd.readouterr()
    assert run("layer", "list", project) == 0
    assert "matshop recover" in capfd.readouterr().err
    assert run("recover", project) == 0
    assert [layer.name for layer in load_project(project).document.layers][-1] == "unsaved work"
    assert find_recovery(project) is None
    capfd.readouterr()
    assert run("recover", project) == 2
    assert "no autosave" in capfd.readouterr().err


def test_info_describes_a_project(project: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert run("layer", "add", project, "paint", "--name", "Scratches") == 0
    capsys.readouterr()
    assert run("info", project) == 0
    out = capsys.readouterr().out
    assert "512x512" in out and "'Base': fill" in out and "'Scratches': paint" in out
