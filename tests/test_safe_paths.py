"""No input decides where matshop writes: every writing verb, hostile names, nothing outside OUT.

Each case builds a real input whose data carries a hostile name (a project's
``document.name``, a texture set's file names, a preset's ``fileName`` or
``name``, ``--name``), runs the real command, and compares the whole tree
around OUT before and after: the only new or changed files are inside OUT,
and each has a plain name.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.images import write_image
from matshop.io.material_io import load_material, save_material
from matshop.io.project import save_project
from matshop.io.safe_names import MAX_FILE_NAME_BYTES, check_file_name, safe_stem
from matshop.layers import Document
from matshop.material import Material, Schema

HOSTILE = [
    "../../ESCAPED",
    "..",
    "/tmp/ABSOLUTE",  # replaced by an absolute path under tmp_path in the tests
    "x/y/z",
    "a\\b",
    "nul\x00byte",
    "bell\x07\nnewline",
    "C:evil",
    "é" * 300,
    "n" * 4000,
    "\ud800lone-surrogate",
    "{material}",
]


def _tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every file under ``root`` with its size and modification time."""
    return {
        str(p.relative_to(root)): (p.lstat().st_size, p.lstat().st_mtime_ns)
        for p in root.rglob("*")
        if not p.is_dir()
    }


def _hostile(name: str, tmp_path: Path) -> str:
    return str(tmp_path / "victim" / "ABSOLUTE") if name == "/tmp/ABSOLUTE" else name


def _assert_only_inside(root: Path, before: dict, out: Path) -> list[Path]:
    """Nothing outside ``out`` changed; returns the files written inside it."""
    after = _tree(root)
    inside = str(out.relative_to(root))
    changed = {k for k in after if before.get(k) != after[k]}
    outside = sorted(k for k in changed | (set(before) - set(after)) if not k.startswith(inside))
    assert outside == [], f"written or removed outside OUT: {outside}"
    written = sorted(out.rglob("*")) if out.exists() else []
    for path in written:
        check_file_name(path.name)  # a plain name: no separator, no control character
        assert path.parent == out, path
    return written


def _project(path: Path, name: str) -> Path:
    """A valid project whose manifest names the document ``name`` (as a tampered file may)."""
    doc = Document(Schema.from_names(["base_color", "roughness"]), 8, 8, name="mat")
    save_project(doc, path)
    with zipfile.ZipFile(path) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    manifest = json.loads(members["manifest.json"])
    manifest["document"]["name"] = name
    members["manifest.json"] = json.dumps(manifest).encode()  # lone surrogates as \ud800
    with zipfile.ZipFile(path, "w") as archive:
        for member, data in members.items():
            archive.writestr(member, data)
    return path


@pytest.fixture
def root(tmp_path: Path) -> Path:
    (tmp_path / "victim").mkdir()
    (tmp_path / "victim" / "ABSOLUTE_roughness.png").write_bytes(b"user's own file")
    (tmp_path / "work").mkdir()
    return tmp_path


@pytest.mark.parametrize("name", HOSTILE, ids=range(len(HOSTILE)))
def test_flatten_names_files_from_out_and_a_safe_stem(name: str, root: Path) -> None:
    project = _project(root / "work" / "p.matshop", _hostile(name, root))
    out = root / "work" / "a" / "b" / "out"
    before = _tree(root)
    code = main(["flatten", str(project), str(out)])
    written = _assert_only_inside(root, before, out)
    if "\ud800" in name:  # not text: refused on load, as a save would refuse it
        assert code == 2 and written == []
        return
    assert code == 0
    assert sorted(p.name.rsplit("_", 1)[1] for p in written) == ["basecolor.png", "roughness.png"]
    stem = written[0].name.rsplit("_", 1)[0]
    assert stem == safe_stem(_hostile(name, root))
    # what was written loads again as a set
    material, _ = load_material(out)
    assert sorted(material.maps) == ["base_color", "roughness"]


@pytest.mark.parametrize("name", HOSTILE, ids=range(len(HOSTILE)))
def test_export_from_a_project_and_with_name(name: str, root: Path) -> None:
    project = _project(root / "work" / "p.matshop", _hostile(name, root))
    for n, extra in enumerate(([], ["--name", _hostile(name, root)])):
        if "\x00" in name and extra:
            continue  # argv cannot carry NUL
        out = root / "work" / f"out{n}"
        before = _tree(root)
        argv = ["export", str(project), str(out), "--preset", "gltf", "--mtlx", "--usdz", *extra]
        code = main(argv)
        written = _assert_only_inside(root, before, out)
        assert code == (2 if "\ud800" in name else 0)
        suffixes = {p.suffix for p in written}
        assert code == 2 or {".mtlx", ".usda", ".usdz"} <= suffixes


PRESET_FILE_NAMES = [
    "../{material}_{channel}.{ext}",
    "/abs/{channel}.{ext}",
    "a{.png",
    "}",
    "{",
    "x\x00{channel}.png",
    "{channel}\n.{ext}",
    "..",
    ".hidden_{channel}.{ext}",
    "{material.__class__}.png",
    "{0}.png",
    "{channel!r}.{ext}",
    "{channel:>300}.{ext}",
    "C:{channel}.{ext}",
]


@pytest.mark.parametrize("template", PRESET_FILE_NAMES, ids=range(len(PRESET_FILE_NAMES)))
def test_hostile_preset_file_names_are_one_line_and_write_nothing(
    template: str, root: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    project = _project(root / "work" / "p.matshop", "mat")
    preset = root / "work" / "preset.json"
    maps = [{"channel": "BaseColor", "srcMapName": "base_color", "fileName": template}]
    preset.write_text(json.dumps({"name": "mine", "maps": maps}))
    out = root / "work" / "out"
    before = _tree(root)
    capfd.readouterr()
    code = main(["export", str(project), str(out), "--preset-file", str(preset)])
    err = capfd.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and str(preset) in err and "Traceback" not in err
    assert _assert_only_inside(root, before, out) == []


@pytest.mark.parametrize(
    "preset_name", ["../../ESCAPED", "/abs/x", "a\x00b", "é" * 300], ids=range(4)
)
@pytest.mark.parametrize("channel", ["..", "BaseColor"])
def test_preset_names_and_channels_stay_inside(
    preset_name: str, channel: str, root: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    project = _project(root / "work" / "p.matshop", "mat")
    preset = root / "work" / "preset.json"
    maps = [{"channel": channel, "srcMapName": "base_color", "fileName": "{preset}_{channel}.png"}]
    preset.write_text(json.dumps({"name": preset_name, "maps": maps}))
    out = root / "work" / "out"
    before = _tree(root)
    code = main(["export", str(project), str(out), "--preset-file", str(preset)])
    written = _assert_only_inside(root, before, out)
    if channel == "..":
        assert code == 2 and written == []  # a channel is a plain name, not a leading dot
    else:
        assert code == 0
        assert [p.name for p in written] == [f"{safe_stem(preset_name, 'preset')}_BaseColor.png"]


def test_dithering_false_in_a_preset_file_means_false(root: Path) -> None:
    from matshop.export.presets import load_preset

    preset = root / "work" / "preset.json"
    maps = [{"channel": "c", "srcMapName": "base_color", "dithering": "false"}]
    preset.write_text(json.dumps({"name": "p", "maps": maps}))
    assert load_preset(path=preset).outputs[0].dithering is False
    maps[0]["dithering"] = "sometimes"
    preset.write_text(json.dumps({"name": "p", "maps": maps}))
    with pytest.raises(Exception, match="dithering"):
        load_preset(path=preset)


SET_NAMES = ["\x01ctl", "n" * 230, "a..b", "-dash", "sp ace"]


@pytest.mark.parametrize("stem", SET_NAMES, ids=range(len(SET_NAMES)))
@pytest.mark.parametrize("verb", ["convert", "apply"])
def test_convert_and_apply_of_sets_with_odd_names(stem: str, verb: str, root: Path) -> None:
    folder = root / "work" / "set"
    folder.mkdir()
    rng = np.random.default_rng(1)
    write_image(folder / f"{stem}_basecolor.png", rng.random((8, 8, 3)).astype(np.float32))
    write_image(folder / f"{stem}_roughness.png", rng.random((8, 8, 1)).astype(np.float32))
    out = root / "work" / "out"
    before = _tree(root)
    extra = ["--op", "scale", "factor=0.5"] if verb == "apply" else []
    assert main([verb, str(folder), str(out), *extra]) == 0
    written = _assert_only_inside(root, before, out)
    assert len(written) == 2
    material, _ = load_material(out)  # what it wrote loads again
    assert sorted(material.maps) == ["base_color", "roughness"]


@pytest.mark.parametrize("name", HOSTILE, ids=range(len(HOSTILE)))
def test_save_material_api(name: str, root: Path) -> None:
    maps = {"roughness": np.full((4, 4, 1), 0.5, np.float32)}
    material = Material(_hostile(name, root), Schema.from_names(["roughness"]), maps)
    out = root / "work" / "out"
    before = _tree(root)
    written = save_material(material, out)
    assert _assert_only_inside(root, before, out) == written


@pytest.mark.parametrize("name", ["../x.png", "/abs.png", "a\x00.png", "..", ".", "", "é" * 150])
def test_the_file_set_writer_refuses_names_that_are_not_plain(name: str, root: Path) -> None:
    from matshop.errors import MatshopError
    from matshop.io.fileset import PendingFile, write_all

    out = root / "work" / "out"
    before = _tree(root)
    with pytest.raises(MatshopError, match="refusing to write"):
        write_all(out, [PendingFile(name, lambda p: p.write_bytes(b"x"))], force=True)
    assert _assert_only_inside(root, before, out) == []


def test_safe_stems_are_bounded_plain_and_stable() -> None:
    for name in [*HOSTILE, "", ".", "...", "-", "ok_name-1.2"]:
        stem = safe_stem(name)
        assert stem and len(stem) <= 100 and check_file_name(stem + "_basecolor.png")
        assert not stem.startswith((".", "-"))
        assert safe_stem(stem) == stem
    assert safe_stem("ok_name-1.2") == "ok_name-1.2"
    assert len(("n" * 5000).encode()) > MAX_FILE_NAME_BYTES


def test_safe_stems_keep_names_in_any_script_within_a_byte_bound() -> None:
    """Umlauts and CJK names are safe on every file system: keep them, bounded in bytes."""
    assert safe_stem("Holz_Oberfläche") == "Holz_Oberfläche"
    assert safe_stem("木材 の 床") == "木材_の_床"
    long = safe_stem("木" * 300)
    assert long == "木" * 33 and len(long.encode()) <= 100  # 3 bytes each, cut whole
    assert safe_stem("a\udcffb") == "a_b"  # a lone surrogate (undecodable bytes) is unsafe
    assert check_file_name(safe_stem("é" * 400) + "_basecolor.png")
