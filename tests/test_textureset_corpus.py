"""Real folder layouts (tests/textureset_corpus.py) open as the set they must produce."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import textureset_corpus as corpus

from matshop.errors import MatshopError
from matshop.io.material_io import load_material
from matshop.io.textureset import SeveralMaterials, detect_texture_set


@pytest.mark.parametrize("case", corpus.CASES, ids=lambda c: c.name)
def test_folder_opens_as_the_expected_set(case: corpus.Case, tmp_path: Path) -> None:
    folder = corpus.build(case, tmp_path)
    if case.several:
        with pytest.raises(SeveralMaterials) as err:
            detect_texture_set(folder)
        assert err.value.choices == list(case.several)
        assert "\n" not in str(err.value) and "--material" in str(err.value)
        return
    ts = detect_texture_set(folder, material=case.material)
    assert {slot: path.name for slot, path in ts.maps.items()} == case.maps
    assert all(path.parent == folder for path in ts.maps.values())
    for name, words in case.not_used.items():
        assert words in ts.not_used.get(folder / name, ""), (name, ts.not_used)
    used = set(ts.maps.values())
    assert not used & set(ts.not_used), "a file is both used and reported unused"
    assert sorted(p.name for p in ts.unrecognised) == sorted(case.unrecognised)
    for words in case.notes:
        assert any(words in note for note in ts.notes), (words, ts.notes)
    # every listed set loads: no stray file makes it unloadable
    material, report = load_material(folder, material=case.material)
    assert material.size == (corpus.SIZE, corpus.SIZE)
    assert {Path(s["file"]).name for s in material.sources.values()} <= set(case.maps.values())


def _matshop(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "matshop", *args], capture_output=True, text=True, timeout=120
    )


def _case(name: str) -> corpus.Case:
    return next(c for c in corpus.CASES if c.name == name)


def test_info_lists_materials_and_takes_one_by_name(tmp_path: Path) -> None:
    folder = corpus.build(_case("materialx_chess_set_one_chosen"), tmp_path)
    refused = _matshop("info", str(folder))
    assert refused.returncode == 2 and refused.stdout == ""
    (line,) = refused.stderr.strip().splitlines()
    for name in ("chessboard", "king_black", "king_white", "--material NAME"):
        assert name in line
    chosen = _matshop("info", str(folder), "--material", "king_white")
    assert chosen.returncode == 0, chosen.stderr
    assert "king_white_base_color.jpg" in chosen.stdout
    assert "metallic: king_shared_metallic.jpg, shared with king_*" in chosen.stdout
    unknown = _matshop("info", str(folder), "--material", "queen")
    assert unknown.returncode == 2 and "no material 'queen'" in unknown.stderr


def test_info_reports_files_it_does_not_use(tmp_path: Path) -> None:
    folder = corpus.build(_case("materialx_brick_with_masks"), tmp_path)
    done = _matshop("info", str(folder))
    assert done.returncode == 0, done.stderr
    for name in ("brick_mask.jpg", "brick_dirt_mask.jpg", "brick_variation_mask.jpg"):
        assert f"not used: {name} (a generic mask)" in done.stdout
    assert "not used: brick_dirt_gray.jpg (name matches no map)" in done.stdout


def test_explicit_maps_add_and_override(tmp_path: Path) -> None:
    folder = corpus.build(_case("materialx_brick_with_masks"), tmp_path)
    done = _matshop(
        "info", str(folder), "--map", f"metallic={folder / 'brick_variation_mask.jpg'}",
        "--map", f"base_color={folder / 'brick_dirt_gray.jpg'}",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    rows = {line.split()[0]: line for line in done.stdout.splitlines() if line.startswith("  ")}
    assert "brick_variation_mask.jpg" in rows["metallic"]
    assert "brick_dirt_gray.jpg" in rows["base_color"]
    assert "base_color: brick_dirt_gray.jpg (given explicitly)" in done.stdout
    material, _ = load_material(folder, maps={"metallic": folder / "brick_variation_mask.jpg"})
    assert Path(material.sources["metallic"]["file"]).name == "brick_variation_mask.jpg"


def test_explicit_maps_open_a_folder_detection_cannot(tmp_path: Path) -> None:
    folder = tmp_path / "scan"
    corpus.build(corpus.Case("scan", {"IMG_0001.png": (3, "uint8")}, {}), tmp_path)
    with pytest.raises(MatshopError, match="no texture maps recognised"):
        load_material(folder)
    material, report = load_material(folder, maps={"base_color": folder / "IMG_0001.png"})
    assert tuple(material.schema.names) == ("base_color",) and material.name == "scan"


@pytest.mark.parametrize(
    ("arg", "words"),
    [
        ("sheen=x.png", "unknown map slot"),
        ("roughness={folder}/nope.png", "nope.png: --map roughness: file not found"),
        ("roughness", "--map expects SLOT=FILE"),
        ("roughness={folder}/big.png", "all maps of a texture set must have the same resolution"),
    ],
)
def test_bad_explicit_maps_are_one_line(tmp_path: Path, arg: str, words: str) -> None:
    case = _case("materialx_brick_with_masks")
    folder = corpus.build(case, tmp_path)
    corpus.build(corpus.Case("x", {"big.png": corpus.OTHER_SIZE}, {}), tmp_path)
    (tmp_path / "x" / "big.png").rename(folder / "big.png")
    out = tmp_path / "out"
    done = _matshop("convert", str(folder), str(out), "--map", arg.format(folder=folder))
    assert done.returncode == 2 and done.stdout == ""
    (line,) = done.stderr.strip().splitlines()
    assert words in line and "Traceback" not in done.stderr
    assert not out.exists()
