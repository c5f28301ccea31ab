"""Every bad input found by the attack runs: one line naming the file or option, exit 2,
nothing written; degenerate but valid inputs (a 1x1 set, a tiny blur) write what the source
files' own codes say (read with OpenImageIO)."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest
from oracle import file_codes

from matshop.cli import main
from matshop.io.images import write_image
from matshop.io.project import save_project
from matshop.layers import Document
from matshop.material import Schema


def _set(folder: Path, size: int, stem: str = "m") -> Path:
    folder.mkdir(parents=True)
    rng = np.random.default_rng(size)
    write_image(folder / f"{stem}_basecolor.png", rng.random((size, size, 3)).astype(np.float32))
    write_image(folder / f"{stem}_roughness.png", rng.random((size, size, 1)).astype(np.float32))
    normal = np.zeros((size, size, 3), np.float32)
    normal[..., 2] = 1.0
    write_image(folder / f"{stem}_normal.png", normal * 0.5 + 0.5)
    return folder


@pytest.fixture(scope="module")
def sets(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("sets")
    mask = np.zeros((16, 16, 1), np.float32)
    mask[4:8, 4:8] = 1.0
    write_image(root / "mask.png", mask)
    project = root / "p.matshop"
    doc = Document(Schema.from_names(["base_color", "roughness"]), 16, 16, name="p")
    doc.insert_layer(doc.new_paint_layer("Paint"))
    save_project(doc, project)
    return {
        "small": _set(root / "small", 16),
        "one": _set(root / "one", 1),
        "mask": root / "mask.png",
        "project": project,
        "root": root,
    }


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def refuses(argv: list[object], capfd: pytest.CaptureFixture[str], *named: object) -> str:
    """Run the real command; it must refuse in one line naming ``named``."""
    capfd.readouterr()
    code = main([str(a) for a in argv])
    err = capfd.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("matshop: error: "), err
    for name in named:
        assert str(name) in err, err
    return err


# ------------------------------------------------ degenerate but valid inputs work


def _source(folder: Path, tag: str) -> np.ndarray:
    return file_codes(folder / f"m_{tag}.png")


#: what each degenerate run must write, file -> its channels' codes, from the source
#: files' own codes: convert copies; a blur of a 1x1 set is the identity (a normalised
#: kernel over one texel, wrapped); sigma 0.05 px is a one-tap kernel (the next tap's
#: weight is e^-200); glTF packs R ao (none: 1 -> 255), G roughness, B metallic (none: 0)
COPY = {"m_basecolor.png": "basecolor", "m_roughness.png": "roughness", "m_normal_gl.png": "normal"}
DEGENERATE = {
    "1x1-convert": (["convert", "{one}", "{out}"], "one", COPY),
    "1x1-blur": (["apply", "{one}", "{out}", "--op", "blur", "sigma_px=2"], "one", COPY),
    "tiny-blur": (["apply", "{small}", "{out}", "--op", "blur", "sigma_px=0.05"], "small", COPY),
    "1x1-export": (
        ["export", "{one}", "{out}", "--preset", "gltf"],
        "one",
        {
            "m_baseColor.png": "basecolor",
            "m_normal.png": "normal",
            "m_occlusionRoughnessMetallic.png": (255, "roughness", 0),
        },
    ),
    # a project holds the set: its flattened files are the source's
    "1x1-new": (["new", "{out}.matshop", "--from", "{one}"], "one", COPY),
}


def _expected(folder: Path, truth: str | tuple) -> np.ndarray:
    if isinstance(truth, str):
        return _source(folder, truth)
    size = _source(folder, "roughness").shape[:2]
    planes = [np.full(size, t) if isinstance(t, int) else _source(folder, t)[..., 0] for t in truth]
    return np.stack(planes, axis=-1)


@pytest.mark.parametrize("case", sorted(DEGENERATE))
def test_degenerate_inputs_write_the_source_codes(case: str, sets: dict, tmp_path: Path) -> None:
    argv, source, files = DEGENERATE[case]
    out = tmp_path / "out"
    names = {"one": sets["one"], "small": sets["small"], "out": out}
    assert main([a.format(**names) for a in argv]) == 0
    if argv[0] == "new":
        assert sorted(p.name for p in tmp_path.iterdir()) == ["out.matshop"]
        assert main(["flatten", str(out) + ".matshop", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(files)
    for name, truth in files.items():
        written, expected = file_codes(out / name), _expected(sets[source], truth)
        assert written.shape == expected.shape, name
        assert np.abs(written - expected).max() <= 1, (name, written.ravel(), expected.ravel())


def test_a_1x1_set_is_described_and_nothing_written(
    sets: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["info", str(sets["one"])]) == 0
    printed = capsys.readouterr().out
    assert "1 x 1 texels" in printed
    for tag in ("basecolor", "roughness", "normal"):
        assert f"m_{tag}.png" in printed
    assert list(tmp_path.iterdir()) == []


def test_a_tiny_blur_filter_layer_saves_and_flattens(sets: dict, tmp_path: Path) -> None:
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(sets["small"])]) == 0
    assert main(["layer", "add", str(project), "filter", "--op", "blur", "sigma_px=0.05"]) == 0
    assert main(["flatten", str(project), str(tmp_path / "out")]) == 0
    # sigma 0.05 px is a one-tap kernel: the flattened set is the source set
    flat = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert flat == ["m_basecolor.png", "m_normal_gl.png", "m_roughness.png"]
    for name in ("basecolor", "roughness"):
        source = _source(sets["small"], name)
        written = file_codes(tmp_path / "out" / f"m_{name}.png")
        assert np.abs(source - written).max() <= 1


# ------------------------------------------------ option and parameter errors

OPTION_CASES = {
    "bilateral-sigma-over-image": (
        ["apply", "{small}", "{out}", "--op", "bilateral", "sigma_px=1000"],
        "sigma",
    ),
    "clone-offset-inf": (
        ["apply", "{small}", "{out}", "--op", "clone", "region={mask}", "offset=inf,0"],
        "offset",
    ),
    "clone-offset-1e18": (
        ["apply", "{small}", "{out}", "--op", "clone", "region={mask}", "offset=1e18,0"],
        "offset",
    ),
    "space-bogus": (["info", "{small}", "--space", "roughness=bogus"], "bogus"),
    "space-nosuch": (["info", "{small}", "--space", "nosuch=ggx"], "nosuch"),
    "export-size": (["export", "{small}", "{out}", "--preset", "gltf", "--size", "65536"], "65536"),
    "render-exposure": (["render", "{small}", "{out}.png", "--exposure", "1e308"], "--exposure"),
    "render-tiles": (["render", "{small}", "{out}.png", "--tiles", "nan"], "--tiles"),
    "render-light": (["render", "{small}", "{out}.png", "--light", "0,0,1:1e308"], "--light"),
    "overflowing-ops": (
        ["apply", "{small}", "{out}", *(["--op", "scale", "factor=100"] * 24)],
        "op scale produced NaN or infinite",
    ),
}


@pytest.mark.parametrize("case", list(OPTION_CASES))
def test_bad_options_are_one_line_and_write_nothing(
    case: str, sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    argv, named = OPTION_CASES[case]
    out = tmp_path / "out"
    names = {"small": sets["small"], "mask": sets["mask"], "out": out}
    before = _files(sets["root"])
    refuses([a.format(**names) for a in argv], capfd, named)
    assert list(tmp_path.iterdir()) == [] and _files(sets["root"]) == before


def test_an_overflowing_filter_layer_names_the_project_and_its_op(
    sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(sets["small"])]) == 0
    for _ in range(24):
        assert main(["layer", "add", str(project), "filter", "--op", "scale", "factor=100"]) == 0
    refuses(["flatten", project, tmp_path / "out"], capfd, project, "(scale) produced NaN")
    refuses(["export", project, tmp_path / "out", "--preset", "gltf"], capfd, project, "scale")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.matshop"]


# ------------------------------------------------ bad files

STROKE = {"swatch": {"name": "s", "values": {"base_color": [0.5, 0.3, 0.1], "roughness": [0.4]}}}
LINE = [[1, 1], [9, 9]]
STROKE_CASES = {
    "target-alpha": {**STROKE, "target": "alpha", "points": LINE},
    "equal-pressures": {**STROKE, "brush": {"size_pressure": [[0.5, 0], [0.5, 1]]}, "points": LINE},
    "decreasing-pressures": {
        **STROKE,
        "brush": {"opacity_pressure": [[0, 0], [1, 1], [0.5, 0.5]]},
        "points": LINE,
    },
    "clone-offset-inf": {"mode": "clone", "clone_offset": [float("inf"), 0], "points": LINE},
    "clone-offset-1e18": {"mode": "clone", "clone_offset": [1e18, 0], "points": LINE},
    "points-1e12-apart": {**STROKE, "points": [[1, 1], [1e12, 5]]},
    "points-1e308-apart": {**STROKE, "points": [[1, 1], [1e308, 5]]},
    "swatch-1e308": {"swatch": {"name": "s", "values": {"roughness": [1e308]}}, "points": LINE},
    "long-fine-stroke": {
        **STROKE,
        "brush": {"radius_px": 0.5, "spacing": 0.01},
        "points": [[0, 0], [300000, 0]],
    },
}


@pytest.mark.parametrize("case", list(STROKE_CASES))
def test_bad_stroke_files_are_one_line_and_paint_nothing(
    case: str, sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    project = tmp_path / "p.matshop"
    project.write_bytes(sets["project"].read_bytes())
    strokes = tmp_path / "s.json"
    strokes.write_text(json.dumps({"strokes": [STROKE_CASES[case]]}))  # inf as Infinity
    saved = project.read_bytes()
    refuses(["paint", project, "--stroke", strokes], capfd, strokes)
    assert project.read_bytes() == saved


def test_a_stroke_file_is_bounded_in_dabs_as_a_whole(
    sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Three strokes of ~100 000 dabs each: each is allowed, the file (300 000) is not."""
    project = tmp_path / "p.matshop"
    project.write_bytes(sets["project"].read_bytes())
    fine = {**STROKE, "brush": {"radius_px": 0.5, "spacing": 0.01}, "points": [[0, 0], [5e4, 0]]}
    strokes = tmp_path / "s.json"
    strokes.write_text(json.dumps({"strokes": [fine] * 3}))
    saved = project.read_bytes()
    err = refuses(["paint", project, "--stroke", strokes], capfd, strokes, "3 strokes")
    assert "dabs" in err and project.read_bytes() == saved


def test_a_preset_writes_a_bounded_number_of_files(
    sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    preset = tmp_path / "preset.json"
    maps = [{"channel": f"c{n}", "srcMapName": "roughness"} for n in range(65)]
    preset.write_text(json.dumps({"name": "many", "maps": maps}))
    refuses(["export", sets["small"], tmp_path / "out", "--preset-file", preset], capfd, "65 maps")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["preset.json"]


def _deep_json(depth: int) -> str:
    return "[" * depth + "]" * depth


def _manifest_edit(project: Path, edit) -> None:
    with zipfile.ZipFile(project) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    members["manifest.json"] = edit(members["manifest.json"].decode()).encode()
    with zipfile.ZipFile(project, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)


FILE_CASES = {
    "stroke-deeply-nested": ("stroke", lambda p: p.write_text(_deep_json(100_000))),
    "stroke-5000-digit-int": (
        "stroke",
        lambda p: p.write_text('{"points": [[1' + "0" * 5000 + ", 1]]}"),
    ),
    "preset-deeply-nested-json": (
        "preset.json",
        lambda p: p.write_text('{"name": "x", "maps": ' + _deep_json(100_000) + "}"),
    ),
    "preset-deeply-nested-toml": (
        "preset.toml",
        lambda p: p.write_text('name = "x"\nmaps = ' + _deep_json(100_000)),
    ),
    "preset-dithering-string": (
        "preset.json",
        lambda p: p.write_text(
            json.dumps(
                {
                    "name": "x",
                    "maps": [{"channel": "c", "srcMapName": "roughness", "dithering": "no"}],
                }
            )
        ),
    ),
    "manifest-5000-digit-int": (
        "project",
        lambda p: _manifest_edit(p, lambda t: t.replace('"height":16', '"height":1' + "0" * 5000)),
    ),
    "manifest-deep-settings": (
        "project",
        lambda p: _manifest_edit(
            p, lambda t: t.replace('"settings":{}', '"settings":' + _deep_json(100_000))
        ),
    ),
    "manifest-infinite-clone-offset": (
        "project",
        lambda p: _manifest_edit(
            p,
            lambda t: t.replace(
                '"layers":[',
                '"layers":[{"kind":"filter","id":99,"name":"c","visible":true,"opacity":1.0,'
                '"blend":"normal","parameters":null,"mask_inverted":false,"mask":null,'
                '"op":"clone","op_params":{"offset":[1e400,0]}},',
            ),
        ),
    ),
    "manifest-huge-clone-offset": (
        "project",
        lambda p: _manifest_edit(
            p,
            lambda t: t.replace(
                '"layers":[',
                '"layers":[{"kind":"filter","id":99,"name":"c","visible":true,"opacity":1.0,'
                '"blend":"normal","parameters":null,"mask_inverted":false,"mask":null,'
                '"op":"clone","op_params":{"offset":[1000000000000000000,0]}},',
            ),
        ),
    ),
}


@pytest.mark.parametrize("case", list(FILE_CASES))
def test_bad_files_are_one_line_naming_the_file(
    case: str, sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    kind, make = FILE_CASES[case]
    project = tmp_path / "p.matshop"
    project.write_bytes(sets["project"].read_bytes())
    out = tmp_path / "out"
    if kind == "stroke":
        bad = tmp_path / "s.json"
        argv = ["paint", project, "--stroke", bad]
    elif kind.startswith("preset"):
        bad = tmp_path / kind
        argv = ["export", sets["small"], out, "--preset-file", bad]
    else:
        bad = project
        argv = ["flatten", project, out]
    make(bad)
    before = _files(tmp_path)
    refuses(argv, capfd, bad)
    assert _files(tmp_path) == before


def test_non_utf8_file_names_are_one_line(
    sets: dict, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    import os

    folder = Path(os.fsdecode(os.fsencode(str(tmp_path)) + b"/set"))
    folder.mkdir()
    for name in ("basecolor", "roughness"):
        target = os.fsencode(str(folder)) + b"/m\xff_" + name.encode() + b".png"
        Path(os.fsdecode(target)).write_bytes((sets["small"] / f"m_{name}.png").read_bytes())
    for argv in (["info", folder], ["convert", folder, tmp_path / "out"]):
        refuses(argv, capfd, "UTF-8")
    bad_out = Path(os.fsdecode(os.fsencode(str(tmp_path)) + b"/out\xff"))
    refuses(["convert", sets["small"], bad_out], capfd, "UTF-8")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set"]
