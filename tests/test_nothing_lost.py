"""Nothing lost: headless verbs keep a newer autosave, and whatever is saved loads again."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pytest
from fuzz_settings import fuzz_examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from matshop.cli import main
from matshop.errors import MatshopError
from matshop.io.project import autosave_path, load_project, save_project, write_recovery
from matshop.layers import Document
from matshop.material import Schema

BRONZE = {"name": "b", "values": {"base_color": [0.5, 0.3, 0.1], "roughness": [0.3]}}


def run(*argv: object) -> int:
    return main([str(a) for a in argv])


@pytest.fixture
def project(tmp_path: Path) -> Path:
    path = tmp_path / "p.matshop"
    doc = Document(Schema.from_names(["base_color", "roughness"]), 32, 32, name="p")
    doc.insert_layer(doc.new_paint_layer("Paint"))
    save_project(doc, path)
    return path


def _one_line_error(capfd: pytest.CaptureFixture[str], *names: object) -> str:
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for name in names:
        assert str(name) in err, err
    return err


VERBS = [
    ("layer", "add", "{p}", "paint", "--name", "x"),
    ("layer", "set", "{p}", "Paint", "opacity=0.5"),
    ("layer", "remove", "{p}", "Paint"),
    ("paint", "{p}", "--stroke", "{s}"),
    ("new", "{p}", "--size", "8x8", "--params", "roughness", "--force"),
]


@pytest.mark.parametrize("verb", VERBS, ids=[" ".join(v[:2]) for v in VERBS])
def test_a_headless_verb_never_deletes_a_newer_autosave(
    verb: tuple[str, ...], project: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    strokes = tmp_path / "s.json"
    strokes.write_text(json.dumps({"strokes": [{"swatch": BRONZE, "points": [[1, 1], [9, 9]]}]}))
    doc = load_project(project).document
    doc.insert_layer(doc.new_paint_layer("unsaved work"))
    recovery = write_recovery(doc, project)
    saved, autosaved = project.read_bytes(), recovery.read_bytes()
    capfd.readouterr()
    argv = [a.format(p=project, s=strokes) for a in verb]
    assert run(*argv) == 2
    err = _one_line_error(capfd, project, "matshop recover", recovery.name)
    assert "newer autosave" in err
    assert project.read_bytes() == saved and recovery.read_bytes() == autosaved
    # the hint works: recover restores it, then the verb runs
    assert run("recover", project) == 0
    assert load_project(project).document.layers[-1].name == "unsaved work"
    assert run(*argv) == 0
    assert not autosave_path(project).exists()


def test_reading_verbs_only_mention_a_newer_autosave(
    project: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    recovery = write_recovery(load_project(project).document, project)
    autosaved = recovery.read_bytes()
    for argv in (("layer", "list", project), ("flatten", project, tmp_path / "out")):
        assert run(*argv) == 0
        assert "matshop recover" in capfd.readouterr().err
    assert recovery.read_bytes() == autosaved


def test_a_layer_name_too_long_to_load_is_refused_before_saving(
    project: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    saved = project.read_bytes()
    assert run("layer", "add", project, "paint", "--name", "n" * 5000) == 2
    _one_line_error(capfd, project, "longer than")
    assert project.read_bytes() == saved
    assert run("layer", "set", project, "Paint", "name=" + "n" * 5000) == 2
    _one_line_error(capfd, project)
    assert project.read_bytes() == saved
    load_project(project)


def _retamper(path: Path, change) -> None:
    with zipfile.ZipFile(path) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    manifest = json.loads(members["manifest.json"])
    change(manifest)
    members["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)


def test_a_huge_layer_id_never_becomes_an_unloadable_save(
    project: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    _retamper(project, lambda m: m["layers"][0].update(id=2**62))
    tampered = project.read_bytes()
    load_project(project)  # accepted on read ...
    capfd.readouterr()
    assert run("layer", "add", project, "paint") == 2  # ... but a save past the limit is refused
    _one_line_error(capfd, project, "id")
    assert project.read_bytes() == tampered
    load_project(project)


def test_the_api_refuses_to_save_what_it_could_not_load(tmp_path: Path) -> None:
    doc = Document(Schema.from_names(["roughness"]), 8, 8, name="d" * 5000)
    with pytest.raises(MatshopError, match="cannot save"):
        save_project(doc, tmp_path / "x.matshop")
    assert list(tmp_path.iterdir()) == []


_TEXT = st.text(st.characters(codec=None), max_size=5000) | st.sampled_from(
    ["", "\x00", "\ud800", "n" * 4097, "../x"]
)


@settings(
    max_examples=fuzz_examples(40),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(doc_name=_TEXT, layer_name=_TEXT, opacity=st.floats(allow_nan=True), blend=_TEXT)
def test_whatever_saves_loads_again(
    doc_name: str, layer_name: str, opacity: float, blend: str, tmp_path: Path
) -> None:
    """Fuzzer: every save either refuses in one line or writes a file that loads again."""
    path = tmp_path / "f.matshop"
    path.unlink(missing_ok=True)
    doc = Document(Schema.from_names(["roughness"]), 8, 8, name=doc_name)
    layer = doc.new_paint_layer("x")
    for key, value in (("name", layer_name), ("opacity", opacity), ("blend", blend)):
        try:
            layer.put(key, layer.validate(key, value, doc.schema))
        except ValueError:
            pass
    doc.insert_layer(layer)
    try:
        save_project(doc, path)
    except MatshopError as exc:
        assert "\n" not in str(exc) and str(path) in str(exc)
        assert not path.exists()
        return
    loaded = load_project(path).document
    assert loaded.name == doc.name and loaded.layers[0].name == layer.name
