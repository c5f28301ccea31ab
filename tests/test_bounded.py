"""Bounded time and memory: sizes from files are checked against the machine before
allocating, special files are refused before opening, group nesting is bounded.

Memory refusals are checked under ``MATSHOP_MEMORY_LIMIT`` (what matshop
assumes is available), so they behave the same on any machine.
"""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.errors import MatshopError
from matshop.io.images import read_image
from matshop.io.project import load_project, save_project
from matshop.layers import Document
from matshop.material import Schema
from matshop.memory import available_bytes

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"


def run_child(*argv: object, timeout: float = 120) -> subprocess.CompletedProcess:
    """The real command in its own process, so a hang fails the test instead of the suite."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "matshop", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        cwd=ROOT,
    )


def one_line_refusal(result: subprocess.CompletedProcess, *named: object) -> None:
    assert result.returncode == 2, result.stderr
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr, result.stderr
    for name in named:
        assert str(name) in result.stderr, result.stderr


@pytest.fixture
def project(tmp_path: Path) -> Path:
    path = tmp_path / "p.matshop"
    doc = Document(Schema.from_names(["base_color", "roughness"]), 64, 64, name="p")
    layer = doc.new_paint_layer("Paint")
    doc.insert_layer(layer)
    save_project(doc, path)
    return path


# ------------------------------------------------ special files


@pytest.mark.parametrize("special", ["fifo", "/dev/zero"])
@pytest.mark.parametrize("role", ["stroke", "preset", "project", "image"])
def test_special_files_are_refused_before_opening(
    special: str, role: str, project: Path, tmp_path: Path
) -> None:
    if special == "fifo":
        path = tmp_path / {"stroke": "s.json", "preset": "p.json", "project": "f.matshop"}.get(
            role, "mask.png"
        )
        os.mkfifo(path)
    else:
        path = Path(special)
    out = tmp_path / "out"
    if role == "stroke":
        result = run_child("paint", project, "--stroke", path)
    elif role == "preset":
        result = run_child("export", SAMPLE, out, "--preset-file", path)
    elif role == "project":
        result = run_child("flatten", path, out)
    else:
        result = run_child("apply", SAMPLE, out, "--op", "blur", "--mask", path)
    one_line_refusal(result, path)
    assert "FIFO" in result.stderr or "device" in result.stderr
    assert not out.exists()


# ------------------------------------------------ memory, checked before allocating


def _png_header_only(path: Path, width: int, height: int) -> None:
    """A PNG that declares ``width x height`` gray pixels and holds almost none (a bomb)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    rows = zlib.compress(b"\x00" * (width + 1) * 4)  # four rows of the promised thousands
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", rows) + chunk(b"IEND", b"")
    )


def test_a_png_bomb_is_refused_by_its_header(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    bomb = tmp_path / "set" / "m_roughness.png"
    bomb.parent.mkdir()
    _png_header_only(bomb, 8192, 8192)  # 512 MiB as float32 pixels, a file of ~200 bytes
    monkeypatch.setenv("MATSHOP_MEMORY_LIMIT", "256M")
    with pytest.raises(MatshopError, match="memory") as caught:
        read_image(bomb)
    assert caught.value.path == str(bomb)
    capfd.readouterr()
    assert main(["convert", str(bomb.parent), str(tmp_path / "out")]) == 2
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and str(bomb) in err and "libpng" not in err
    assert not (tmp_path / "out").exists()


def test_declared_tiles_are_checked_against_memory_before_reading(
    project: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capfd: pytest.CaptureFixture[str],
) -> None:
    strokes = tmp_path / "s.json"
    swatch = {"name": "s", "values": {"base_color": [0.5, 0.3, 0.1], "roughness": [0.4]}}
    stroke = {"swatch": swatch, "brush": {"radius_px": 40}, "points": [[0, 32], [64, 32]]}
    strokes.write_text(json.dumps({"strokes": [stroke]}))
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 0
    monkeypatch.setenv("MATSHOP_MEMORY_LIMIT", "16K")  # the painted tiles take 80 KiB
    capfd.readouterr()
    assert main(["layer", "list", str(project)]) == 2
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and str(project) in err and "memory" in err, err


def test_a_tiny_manifest_for_a_huge_document_is_refused_before_flattening(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    project = tmp_path / "huge.matshop"
    size = ["--size", "16384x16384", "--params", "base_color,roughness"]
    assert main(["new", str(project), *size]) == 0
    assert project.stat().st_size < 2048  # an empty document costs nothing ...
    monkeypatch.setenv("MATSHOP_MEMORY_LIMIT", "2G")
    assert main(["layer", "list", str(project)]) == 0  # ... and listing it allocates nothing
    out = tmp_path / "out"
    for argv in (["flatten", project, out], ["export", project, out, "--preset", "gltf"]):
        capfd.readouterr()
        assert main([str(a) for a in argv]) == 2
        err = capfd.readouterr().err
        assert err.count("\n") == 1 and str(project) in err and "16384x16384" in err, err
    assert not out.exists()


def test_the_memory_limit_reads_the_machine_and_the_override(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("MATSHOP_MEMORY_LIMIT", raising=False)
    machine = available_bytes()
    meminfo = Path("/proc/meminfo")
    if meminfo.exists():
        line = next(x for x in meminfo.read_text().splitlines() if x.startswith("MemAvailable"))
        reported = int(line.split()[1]) * 1024
        assert 0 < machine <= reported * 1.5
    monkeypatch.setenv("MATSHOP_MEMORY_LIMIT", "3M")
    assert available_bytes() == 3 << 20


# ------------------------------------------------ group nesting


def _nested_groups(depth: int) -> Document:
    doc = Document(Schema.from_names(["roughness"]), 8, 8, name="g")
    parent = None
    for number in range(depth):
        group = doc.new_group_layer(f"g{number}")
        if parent is not None:
            group.put("parent", parent)
        doc.insert_layer(group, 0)  # members sit below their group
        parent = group.id
    fill = doc.new_fill_layer("inner", value=np.array([0.25], np.float32))
    fill.put("parent", parent)
    doc.insert_layer(fill, 0)
    return doc


def test_group_nesting_is_bounded_on_load_and_save(tmp_path: Path) -> None:
    ok = tmp_path / "ok.matshop"
    save_project(_nested_groups(32), ok)
    load_project(ok)
    with pytest.raises(MatshopError, match="nested more than 32"):
        save_project(_nested_groups(33), tmp_path / "deep.matshop")
    assert not (tmp_path / "deep.matshop").exists()
    # a file that nests deeper (made by hand) is refused on load, in one line
    with zipfile.ZipFile(ok) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    manifest = json.loads(members["manifest.json"])
    groups = [layer for layer in manifest["layers"] if layer["kind"] == "group"]
    extra = dict(groups[-1], id=10_000, name="outer", parent=None)
    groups[-1]["parent"] = 10_000
    manifest["layers"].append(extra)
    members["manifest.json"] = json.dumps(manifest).encode()
    deep = tmp_path / "deep.matshop"
    with zipfile.ZipFile(deep, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    with pytest.raises(MatshopError, match="nested more than 32"):
        load_project(deep)


def test_thousands_of_groups_flatten_in_linear_time(tmp_path: Path) -> None:
    """4000 groups of one member each: the membership walk is one pass, not cubic
    (before: 1000 groups took 24 s); the value is the closed form of the stack."""
    doc = Document(Schema.from_names(["roughness"]), 8, 8, name="g")
    for number in range(4000):
        group = doc.new_group_layer(f"g{number}", opacity=0.5)
        doc.insert_layer(group)
        fill = doc.new_fill_layer(f"f{number}", value=np.array([1.0], np.float32))
        fill.put("parent", group.id)
        doc.insert_layer(fill, len(doc.layers) - 1)
    path = tmp_path / "groups.matshop"
    save_project(doc, path)
    result = run_child("flatten", path, tmp_path / "out", timeout=300)
    assert result.returncode == 0, result.stderr
    # each group mixes a fill of edit value 1 at half opacity over its input:
    # x_k = 0.5 x_{k-1} + 0.5, from 0 -> 1 - 2^-4000 = 1 (GGX edit alpha = r^2 -> r = 1)
    flat = load_project(path).document.flatten_edit()
    assert np.allclose(flat, 1.0, atol=1e-6)
