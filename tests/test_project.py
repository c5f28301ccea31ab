""".matshop project files: bit-identical round trips, atomic saves, recovery, hostile files."""

from __future__ import annotations

import copy
import io
import json
import os
import selectors
import signal
import subprocess
import sys
import time
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from matshop.errors import MatshopError
from matshop.io.material_io import load_material
from matshop.io.project import (
    FORMAT_VERSION,
    autosave_path,
    discard_recovery,
    find_recovery,
    load_project,
    save_project,
    write_recovery,
)
from matshop.layers import (
    AddLayer,
    Document,
    FillLayer,
    FilterLayer,
    History,
    PaintLayer,
    PaintTransaction,
    Rect,
    SetMask,
    SetProperty,
    TileGrid,
)
from matshop.material import Schema

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"


# ----------------------------------------------------------------- documents


def _dab(doc: Document, history: History, layer_id: int, rect: Rect, seed: int, target="pixels"):
    """A soft round dab of random values (so tiles hold varied, non-trivial floats)."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0 : rect.height, 0 : rect.width]
    r = np.hypot((yy - rect.height / 2) / rect.height, (xx - rect.width / 2) / rect.width)
    alpha = np.clip(1.5 - 3 * r, 0, 1).astype(np.float32)
    tx = PaintTransaction(doc, layer_id, target)
    if target == "pixels":
        tx.paint(rect, rng.normal(0.4, 0.3, doc.channels).astype(np.float32), alpha)
    else:
        tx.paint(rect, float(rng.uniform(0, 1)), alpha)
    history.push(tx.commit(), applied=True)


def build_stack(doc: Document) -> Document:
    """Every kind of layer state a project must keep, on top of ``doc`` (scaled to its size)."""
    history = History(doc)
    h, w = doc.size
    s = max(1, min(h, w) // 128)  # dab sizes follow the document

    def add(layer):
        history.push(AddLayer(layer))
        return layer.id

    def rect(x, y, dx, dy):
        return Rect.from_size(x * s, y * s, dx * s, dy * s)

    paint = add(doc.new_paint_layer("strokes", opacity=0.8))
    for seed, (x, y) in enumerate([(5, 5), (40, 30), (90, 70)]):
        _dab(doc, history, paint, rect(x, y, 30, 25), seed)
    hidden = add(doc.new_paint_layer("hidden", blend="multiply", visible=False))
    _dab(doc, history, hidden, rect(10, 60, 50, 40), 7)
    tint = add(
        doc.new_fill_layer(
            "tint",
            value=np.linspace(-0.2, 0.3, doc.channels, dtype=np.float32),
            blend="subtract",
            opacity=0.3,
            parameters=[doc.schema.names[-1]],
        )
    )
    history.push(SetMask(tint, doc.new_mask(0.0)))
    _dab(doc, history, tint, rect(30, 20, 60, 60), 11, target="mask")
    history.push(SetProperty(tint, "mask_inverted", True))
    gradient = np.linspace(0, 1, w, dtype=np.float32)[None, :].repeat(h, 0)
    detail = add(doc.new_paint_layer("grain", blend="detail", opacity=0.6))
    _dab(doc, history, detail, rect(60, 10, 40, 40), 13)
    history.push(SetMask(detail, doc.new_mask(array=gradient)))
    blur = add(doc.new_filter_layer("blur", op_params={"sigma_px": 1.5, "border": "clamp"}))
    history.push(SetMask(blur, doc.new_mask(0.25)))
    _dab(doc, history, blur, rect(0, 0, 50, 50), 17, target="mask")
    add(
        doc.new_filter_layer(
            "curves",
            op_params={"points": ((0.0, 0.05), (0.5, 0.6), (1.0, 0.95))},
            parameters=[doc.schema.names[0]],
            blend="add",
            opacity=0.4,
        )
    )
    base = doc.layers[0]
    assert isinstance(base, FillLayer) and base.source is not None
    rolled = np.roll(base.source, (h // 3, w // 5), axis=(0, 1))
    over = add(doc.new_fill_layer("rust", source=rolled, opacity=0.25))
    history.push(SetProperty(over, "value", np.full(doc.channels, 0.5, np.float32)))
    # a group: its members sit just below it
    members = [add(doc.new_paint_layer(f"member {n}", blend="add")) for n in range(2)]
    _dab(doc, history, members[0], rect(20, 50, 40, 40), 19)
    group = add(doc.new_group_layer("group", opacity=0.7, parameters=[doc.schema.names[0]]))
    for member in members:
        history.push(SetProperty(member, "parent", group))
    history.push(SetMask(group, doc.new_mask(0.5)))
    unnamed = add(doc.new_paint_layer("empty"))
    history.push(SetProperty(unnamed, "name", ""))  # an empty name stays empty
    return doc


@pytest.fixture(scope="module")
def sample_doc() -> Document:
    material, _ = load_material(SAMPLE)
    return build_stack(Document.from_material(material))


@pytest.fixture(scope="module")
def tiny_doc() -> Document:
    """A 40x52 document with short edge tiles: cheap enough to fuzz."""
    schema = Schema.from_names(["base_color", "roughness"])
    rng = np.random.default_rng(0)
    doc = Document(schema, 40, 52, tile_size=16, name="tiny")
    source = rng.uniform(0, 1, (40, 52, schema.edit_width)).astype(np.float32)
    doc.insert_layer(doc.new_fill_layer("base", source=source))
    return build_stack(doc)


def assert_grids_equal(a: TileGrid | None, b: TileGrid | None) -> None:
    assert (a is None) == (b is None)
    if a is None or b is None:
        return
    assert a.channels == b.channels and a.layout == b.layout
    assert np.array_equal(a.fill, b.fill) and b.fill.dtype == np.float32
    assert sorted(a.keys()) == sorted(b.keys())
    for key in a.keys():
        tile_a, tile_b = a.get(key), b.get(key)
        assert tile_b.dtype == np.float32 and not tile_b.flags.writeable
        assert np.array_equal(tile_a, tile_b)


def assert_same_document(a: Document, b: Document) -> None:
    assert (a.name, a.size, a.layout, repr(a.schema)) == (b.name, b.size, b.layout, repr(b.schema))
    assert np.array_equal(a.background, b.background)
    assert [layer.id for layer in a] == [layer.id for layer in b]
    for la, lb in zip(a.layers, b.layers, strict=True):
        assert type(la) is type(lb)
        # op_params may hold arrays: compared below
        assert {**la.describe(), "op_params": None} == {**lb.describe(), "op_params": None}
        assert_grids_equal(la.mask, lb.mask)
        if isinstance(la, PaintLayer):
            assert_grids_equal(la.pixels, lb.pixels)
        if isinstance(la, FillLayer):
            for name in ("value", "source"):
                va, vb = getattr(la, name), getattr(lb, name)
                assert (va is None) == (vb is None)
                if va is not None:
                    assert vb.dtype == np.float32 and np.array_equal(va, vb)
        if isinstance(la, FilterLayer):
            assert la.op == lb.op and la.op_params.keys() == lb.op_params.keys()
            for key, value in la.op_params.items():
                assert np.array_equal(value, lb.op_params[key])
    flat_a, flat_b = a.flatten_edit(), b.flatten_edit()
    assert flat_b.dtype == np.float32 and np.array_equal(flat_a, flat_b)


# ----------------------------------------------------------------- round trips


def test_sample_round_trip_is_bit_identical(sample_doc: Document, tmp_path: Path) -> None:
    path = tmp_path / "tiles.matshop"
    settings = {"active_layer": 3, "view": {"zoom": 1.5, "channels": ["base_color"]}}
    save_project(sample_doc, path, settings=settings)
    project = load_project(path)
    assert project.format_version == FORMAT_VERSION
    assert project.settings == settings and project.path == path
    assert_same_document(sample_doc, project.document)
    # the loaded document keeps working: new layers get fresh ids
    fresh = project.document.new_paint_layer()
    assert fresh.id > max(layer.id for layer in sample_doc)
    # and saving it again gives the same bytes (saves are deterministic)
    again = tmp_path / "again.matshop"
    save_project(project.document, again, settings=settings)
    assert again.read_bytes() == path.read_bytes()


@pytest.mark.skipif(not CHESSBOARD.is_dir(), reason="no ../shared/data/chessboard")
def test_2k_round_trip_is_bit_identical(tmp_path: Path) -> None:
    material, _ = load_material(CHESSBOARD)
    doc = build_stack(Document.from_material(material))
    path = tmp_path / "chessboard.matshop"
    save_project(doc, path)
    assert_same_document(doc, load_project(path).document)


def test_layers_are_inflated_a_chunk_at_a_time(
    sample_doc: Document, tmp_path: Path, monkeypatch
) -> None:
    """zipfile joins what one read inflates into one bytes object while holding the GIL
    (a 2K layer read whole held it ~140 ms: the editor's event loop stalled on reopen),
    so members are read in chunks: every read of the real loader, counted, is bounded."""
    from matshop.io import project_store

    path = tmp_path / "sample.matshop"
    save_project(sample_doc, path)
    monkeypatch.setattr(project_store, "_READ_CHUNK", 4096)
    asked: list[int] = []
    real_read = zipfile.ZipExtFile.read

    def counted_read(self, n=-1):
        asked.append(n)
        return real_read(self, n)

    monkeypatch.setattr(zipfile.ZipExtFile, "read", counted_read)
    assert_same_document(sample_doc, load_project(path).document)
    biggest = max(info.file_size for info in zipfile.ZipFile(path).infolist())
    assert biggest > 10 * 4096 and len(asked) > biggest // 4096  # chunks were read
    assert all(0 < n <= 4096 + 1 for n in asked)


def test_an_empty_layer_adds_little(tmp_path: Path) -> None:
    material, _ = load_material(SAMPLE)
    doc = Document.from_material(material)
    save_project(doc, tmp_path / "one.matshop")
    doc.insert_layer(doc.new_paint_layer("nothing yet"))
    save_project(doc, tmp_path / "two.matshop")
    extra = (tmp_path / "two.matshop").stat().st_size - (tmp_path / "one.matshop").stat().st_size
    assert 0 < extra < 1024


def test_array_filter_parameters_are_stored_inside(tmp_path: Path) -> None:
    schema = Schema.from_names(["roughness"])
    doc = Document(schema, 32, 32, tile_size=16)
    doc.insert_layer(doc.new_fill_layer(value=np.array([0.3], np.float32)))
    region = np.zeros((32, 32), bool)
    region[8:20, 6:18] = True
    doc.insert_layer(doc.new_filter_layer("clone", op_params={"region": region, "offset": (5, 3)}))
    save_project(doc, tmp_path / "clone.matshop")
    loaded = load_project(tmp_path / "clone.matshop").document
    assert loaded.layers[1].op_params["region"].dtype == bool
    assert_same_document(doc, loaded)


def test_unsaveable_documents_leave_the_previous_file(tiny_doc: Document, tmp_path: Path) -> None:
    path = tmp_path / "p.matshop"
    save_project(tiny_doc, path)
    before = path.read_bytes()
    with pytest.raises(MatshopError, match="settings must be plain finite JSON"):
        save_project(tiny_doc, path, settings={"when": object()})
    doc = Document(tiny_doc.schema, 16, 16, tile_size=16)
    layer = doc.new_paint_layer()
    doc.insert_layer(layer)
    tx = PaintTransaction(doc, layer.id)
    tx.write(Rect(0, 0, 2, 2), np.full((2, 2, doc.channels + 1), np.nan, np.float32))
    tx.commit()
    with pytest.raises(MatshopError, match="NaN or infinite") as caught:
        save_project(doc, path)
    assert str(caught.value).startswith(str(path))
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.matshop"]  # no temp left


# ----------------------------------------------------------------- hostile files


def _members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as archive:
        return {name: archive.read(name) for name in archive.namelist()}


def _rezip(members: dict[str, bytes], compression: int = zipfile.ZIP_STORED) -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return out.getvalue()


def _with_manifest(change: Callable[[dict], object]) -> Callable[[bytes, Path], bytes]:
    def tamper(data: bytes, path: Path) -> bytes:
        members = _members(path)
        manifest = json.loads(members["manifest.json"])
        change(manifest)
        members["manifest.json"] = json.dumps(manifest).encode()
        return _rezip(members)

    return tamper


def _with_members(change: Callable[[dict[str, bytes]], object]) -> Callable[[bytes, Path], bytes]:
    def tamper(data: bytes, path: Path) -> bytes:
        members = _members(path)
        change(members)
        return _rezip(members)

    return tamper


def _layer(kind: str, manifest: dict) -> dict:
    return next(layer for layer in manifest["layers"] if layer["kind"] == kind)


def _paint(manifest: dict) -> dict:
    return next(layer for layer in manifest["layers"] if layer["kind"] == "paint")


def _flip_stored_payload(data: bytes, path: Path) -> bytes:
    members = _members(path)
    archive = bytearray(_rezip(members))
    member = _paint(json.loads(members["manifest.json"]))["pixels"]["member"]
    at = archive.index(members[member][:64]) + 100  # inside the stored tile bytes
    archive[at] ^= 0x40
    return bytes(archive)


def _nan_tile(members: dict[str, bytes]) -> None:
    manifest = json.loads(members["manifest.json"])
    name = _paint(manifest)["pixels"]["member"]
    values = np.frombuffer(members[name], "<f4").copy()
    values[5] = np.inf
    members[name] = values.tobytes()


def _one_more_tile(manifest: dict) -> None:
    pixels = _paint(manifest)["pixels"]
    taken = {tuple(key) for key in pixels["tiles"]}
    free = next((r, c) for r in range(99) for c in range(99) if (r, c) not in taken)
    pixels["tiles"].append(list(free))


def _bzip2(data: bytes, path: Path) -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as archive:
        for name, content in _members(path).items():
            archive.writestr(name, content, zipfile.ZIP_BZIP2 if name == "manifest.json" else 0)
    return out.getvalue()


CORRUPT: dict[str, tuple[Callable[[bytes, Path], bytes], str]] = {
    "not a zip": (lambda d, p: b"just some text, not a project\n" * 10, "not a zip archive"),
    "empty file": (lambda d, p: b"", "not a zip archive"),
    "truncated": (lambda d, p: d[: len(d) // 2], "not a zip archive, or truncated"),
    "truncated to the tail": (lambda d, p: d[len(d) // 2 :], "is damaged or truncated"),
    "crc error": (_flip_stored_payload, "is damaged"),
    "no manifest": (_with_members(lambda m: m.pop("manifest.json")), "no manifest.json"),
    "manifest not json": (
        _with_members(lambda m: m.update({"manifest.json": b"{'layers': ["})),
        "manifest is not valid JSON",
    ),
    "manifest not utf-8": (
        _with_members(lambda m: m.update({"manifest.json": b'{"a": "\xff"}'})),
        "manifest is not valid JSON",
    ),
    "manifest a list": (
        _with_members(lambda m: m.update({"manifest.json": b"[1, 2]"})),
        "manifest must be an object",
    ),
    "background not a list": (
        _with_manifest(lambda m: m["document"].update(background="NAN")),
        "background must be a list",
    ),
    "NaN literal": (
        _with_members(
            lambda m: m.update(
                {"manifest.json": m["manifest.json"].replace(b'"opacity":', b'"opacity":NaN,"x":')}
            )
        ),
        "not a finite number",
    ),
    "repeated key": (
        _with_members(
            lambda m: m.update(
                {"manifest.json": m["manifest.json"].replace(b"{", b'{"a":1,"a":2,')}
            )
        ),
        "repeats a key",
    ),
    "other format": (_with_manifest(lambda m: m.update(format="krita")), "not a matshop project"),
    "newer format": (
        _with_manifest(lambda m: m.update(format_version=3)),
        "made by a newer matshop (format 3, this version reads up to 1",
    ),
    "version a string": (
        _with_manifest(lambda m: m.update(format_version="1")),
        "format_version must be a whole number",
    ),
    "height a string": (
        _with_manifest(lambda m: m["document"].update(height="512")),
        "document height must be a whole number",
    ),
    "negative width": (
        _with_manifest(lambda m: m["document"].update(width=-4)),
        "document width=-4 is outside [1, 65536]",
    ),
    "absurd width": (
        _with_manifest(lambda m: m["document"].update(width=100_000)),
        "document width=100000 is outside [1, 65536]",
    ),
    "one-texel tiles on a huge document": (
        _with_manifest(lambda m: m["document"].update(width=60_000, height=60_000, tile_size=1)),
        "tiles, more than 1048576",
    ),
    "missing layers": (_with_manifest(lambda m: m.pop("layers")), "manifest: missing 'layers'"),
    "unknown layer kind": (
        _with_manifest(lambda m: m["layers"][1].update(kind="adjustment")),
        "unknown layer kind 'adjustment'",
    ),
    "unknown blend mode": (
        _with_manifest(lambda m: m["layers"][1].update(blend="glow")),
        "unknown blend mode 'glow'",
    ),
    "unknown space": (
        _with_manifest(lambda m: m["schema"][0].update(space="warp")),
        "editing space 'warp'",
    ),
    "space width changed": (
        _with_manifest(lambda m: m["schema"][0].update(edit_channels=7)),
        "the file was saved with 7",
    ),
    "opacity out of range": (
        _with_manifest(lambda m: m["layers"][1].update(opacity=2.0)),
        "opacity=2 is outside [0, 1]",
    ),
    "visible a number": (
        _with_manifest(lambda m: m["layers"][1].update(visible=1)),
        "visible must be true or false",
    ),
    "unknown parameter": (
        _with_manifest(lambda m: m["layers"][1].update(parameters=["glossiness"])),
        "no parameter(s) ['glossiness'] in this material",
    ),
    "parent not an id": (
        _with_manifest(lambda m: m["layers"][1].update(parent="group")),
        "parent must be a whole number",
    ),
    "duplicate ids": (
        _with_manifest(lambda m: m["layers"][2].update(id=m["layers"][1]["id"])),
        "same id",
    ),
    "unknown op": (
        _with_manifest(lambda m: _layer("filter", m).update(op="sharpen")),
        "unknown op 'sharpen'",
    ),
    "bad op parameter": (
        _with_manifest(lambda m: _layer("filter", m)["op_params"].update(sigma_px=-3)),
        "sigma_px",
    ),
    "region names an outside file": (
        _with_manifest(
            lambda m: _layer("filter", m).update(op="clone", op_params={"region": "/etc/passwd"})
        ),
        "only an array stored in the project",
    ),
    "more tiles than the grid has": (
        _with_manifest(lambda m: _paint(m)["pixels"].update(tiles=[[0, 0]] * 10_000)),
        "more than",
    ),
    "tile outside the grid": (
        _with_manifest(lambda m: _paint(m)["pixels"]["tiles"].append([0, 10_000])),
        "tile column=10000 is outside",
    ),
    "tile twice": (
        _with_manifest(
            lambda m: _paint(m)["pixels"]["tiles"].append(_paint(m)["pixels"]["tiles"][0])
        ),
        "lists a tile twice",
    ),
    "wrong channel count": (
        _with_manifest(lambda m: _paint(m)["pixels"].update(channels=2)),
        "channels, the schema needs",
    ),
    "big-endian tiles": (
        _with_manifest(lambda m: _paint(m)["pixels"].update(dtype=">f4")),
        "little-endian float32",
    ),
    "payload size mismatch": (_with_manifest(_one_more_tile), "its declared shape needs"),
    "nan in a tile": (_with_members(_nan_tile), "NaN or infinite values"),
    "member reference escapes": (
        _with_manifest(lambda m: _paint(m)["pixels"].update(member="../../etc/passwd")),
        "not a plain name inside",
    ),
    "absolute member reference": (
        _with_manifest(lambda m: _paint(m)["pixels"].update(member="/etc/passwd")),
        "not a plain name inside",
    ),
    "member referenced twice": (
        _with_manifest(
            lambda m: m["layers"][-1]["pixels"].update(member=_paint(m)["pixels"]["member"])
        ),
        "a second time",
    ),
    "referenced member missing": (
        _with_manifest(lambda m: _paint(m)["pixels"].update(member="layers/elsewhere.f32")),
        "member layers/elsewhere.f32 is missing",
    ),
    "member named ../": (
        _with_members(lambda m: m.update({"../../evil.sh": b"rm -rf /"})),
        "points outside the container",
    ),
    "absolute member name": (
        _with_members(lambda m: m.update({"/etc/cron.d/evil": b"x"})),
        "points outside the container",
    ),
    "zip bomb by declared size": (
        _with_manifest(
            lambda m: (
                m["document"].update(height=65536, width=65536),
                [
                    layer["source"].update(shape=[65536, 65536, 9])
                    for layer in m["layers"]
                    if layer.get("source")
                ],
            )
        ),
        "GiB of memory, more than the limit",
    ),
    "unsupported compression": (_bzip2, "unsupported compression"),
}


@pytest.fixture(scope="module")
def valid_project(sample_doc: Document, tmp_path_factory) -> bytes:
    path = tmp_path_factory.mktemp("valid") / "valid.matshop"
    save_project(sample_doc, path)
    return path.read_bytes()


@pytest.mark.parametrize("case", list(CORRUPT))
def test_corrupt_files_give_one_clear_line(case: str, valid_project: bytes, tmp_path: Path) -> None:
    original = tmp_path / "original.matshop"
    original.write_bytes(valid_project)
    tamper, problem = CORRUPT[case]
    path = tmp_path / "broken.matshop"
    path.write_bytes(tamper(valid_project, original))
    before, stat = path.read_bytes(), path.stat()
    with pytest.raises(MatshopError) as caught:
        load_project(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    assert problem in message, message
    assert path.read_bytes() == before and path.stat().st_mtime_ns == stat.st_mtime_ns
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.matshop", "original.matshop"]


def test_memory_limit_is_configurable(valid_project: bytes, tmp_path: Path) -> None:
    path = tmp_path / "p.matshop"
    path.write_bytes(valid_project)
    with pytest.raises(MatshopError, match="more than the limit"):
        load_project(path, max_bytes=1 << 20)
    assert load_project(path, max_bytes=64 << 20).document.size == (512, 512)


def test_missing_file_and_directory(tmp_path: Path) -> None:
    with pytest.raises(MatshopError, match="file not found"):
        load_project(tmp_path / "nope.matshop")
    with pytest.raises(MatshopError, match="is a folder"):
        load_project(tmp_path)


@pytest.fixture(scope="module")
def tiny_project(tiny_doc: Document, tmp_path_factory) -> bytes:
    path = tmp_path_factory.mktemp("tiny") / "tiny.matshop"
    save_project(tiny_doc, path)
    return path.read_bytes()


def _load_or_clean_error(tmp_path: Path, data: bytes) -> None:
    """Loading either works (and the document flattens) or raises MatshopError; nothing else."""
    path = tmp_path / "fuzzed.matshop"
    path.write_bytes(data)
    try:
        project = load_project(path)
    except MatshopError as error:
        assert str(error).startswith(str(path)) and "\n" not in str(error)
    else:  # whatever passed the checks must be a working document
        doc = project.document
        assert doc.flatten_edit().shape == (*doc.size, doc.channels)
    assert path.read_bytes() == data


FUZZ = settings(
    max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@FUZZ
@given(st.data())
def test_fuzzed_bytes_load_or_fail_cleanly(tiny_project: bytes, tmp_path: Path, data) -> None:
    blob = bytearray(tiny_project)
    if data.draw(st.booleans(), label="truncate"):
        blob = blob[: data.draw(st.integers(0, len(blob) - 1), label="length")]
    for _ in range(data.draw(st.integers(1, 4), label="flips")):
        if blob:
            at = data.draw(st.integers(0, len(blob) - 1), label="at")
            blob[at] ^= data.draw(st.integers(1, 255), label="xor")
    _load_or_clean_error(tmp_path, bytes(blob))


#: values that often pass a type check, so fuzzing reaches the deeper checks and the build
PLAUSIBLE = st.sampled_from(
    [0, 1, 2, 3, 15, 16, 64, -1, 0.0, 0.25, 1.0, 1.5, True, False, None, [], {}, [0, 0], [1, 2]]
    + ["normal", "add", "detail", "paint", "fill", "filter", "blur", "curves", "clone", "wrap"]
    + ["roughness", "base_color", "ggx", "srgb", "<f4", "|b1", "../x", "layers/0001/pixels.f32"]
)
JSON_VALUES = PLAUSIBLE | st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(2**70), 2**70)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=6,
)


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from _paths(value, (*prefix, index))


@FUZZ
@given(st.data())
def test_tampered_manifests_load_or_fail_cleanly(tiny_project: bytes, tmp_path: Path, data) -> None:
    members = {}
    with zipfile.ZipFile(io.BytesIO(tiny_project)) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    manifest = json.loads(members["manifest.json"])
    for _ in range(data.draw(st.integers(1, 3), label="changes")):
        paths = [p for p in _paths(manifest) if p][::-1]  # deep leaves first: shrinks there
        where = data.draw(st.sampled_from(paths), label="where")
        parent = manifest
        for step in where[:-1]:
            parent = parent[step]
        if data.draw(st.booleans(), label="delete"):
            del parent[where[-1]]
        else:
            # a copy: PLAUSIBLE hands out the same list objects, which would nest into
            # themselves (a cycle) and change between examples
            parent[where[-1]] = copy.deepcopy(data.draw(JSON_VALUES, label="value"))
    members["manifest.json"] = json.dumps(manifest).encode()
    _load_or_clean_error(tmp_path, _rezip(members))


# ----------------------------------------------------------------- atomic saves


_CHILD = """
import sys, time
from matshop.io import project_store
from matshop.io.project import load_project, save_project

source, target, mode = sys.argv[1:4]
project = load_project(source)
doc = project.document
if mode == "slow":
    doc.insert_layer(doc.new_fill_layer("new", value=[0.5] * doc.channels))
    write = project_store._write_payload

    def slow(archive, payload):
        write(archive, payload)
        print("writing", flush=True)
        time.sleep(60)

    project_store._write_payload = slow
    save_project(doc, target)
else:
    while True:
        save_project(doc, target, settings=project.settings)
        print("saved", flush=True)
"""


def _child(tmp_path: Path, source: Path, target: Path, mode: str) -> subprocess.Popen:
    script = tmp_path / "child.py"
    script.write_text(_CHILD)
    return subprocess.Popen(
        [sys.executable, str(script), str(source), str(target), mode],
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )


def _first_line(child: subprocess.Popen, timeout_s: float = 120.0) -> str:
    """The child's first line of output; a child that hangs silently fails the test."""
    assert child.stdout is not None
    with selectors.DefaultSelector() as selector:
        selector.register(child.stdout, selectors.EVENT_READ)
        assert selector.select(timeout_s), f"no output from the child in {timeout_s:.0f} s"
    return child.stdout.readline().strip()


def _kill(child: subprocess.Popen) -> None:
    os.kill(child.pid, signal.SIGKILL)
    child.wait(timeout=30)
    assert child.returncode == -signal.SIGKILL


def test_killing_a_save_mid_write_keeps_the_previous_file(
    sample_doc: Document, tmp_path: Path
) -> None:
    target = tmp_path / "work.matshop"
    save_project(sample_doc, target)
    before = target.read_bytes()
    child = _child(tmp_path, target, target, "slow")
    try:
        assert _first_line(child) == "writing"
        temps = list(tmp_path.glob(".work.tmp-*.matshop"))
        assert len(temps) == 1 and temps[0].stat().st_size > 0  # killed half-way through
    finally:
        _kill(child)
    assert target.read_bytes() == before
    assert_same_document(sample_doc, load_project(target).document)


def test_killing_repeated_saves_at_random_leaves_a_whole_file(
    tiny_doc: Document, tmp_path: Path
) -> None:
    source, target = tmp_path / "source.matshop", tmp_path / "target.matshop"
    save_project(tiny_doc, source)
    expected = source.read_bytes()
    child = _child(tmp_path, source, target, "loop")
    rng = np.random.default_rng(714)  # a reproducible kill moment
    try:
        assert _first_line(child) == "saved"
        time.sleep(rng.uniform(0.0, 0.5))
    finally:
        _kill(child)
    assert target.read_bytes() == expected  # every save wrote the same bytes, or none at all
    assert_same_document(tiny_doc, load_project(target).document)


# ----------------------------------------------------------------- recovery


def test_recovery_file_is_found_restored_and_discarded(tiny_doc: Document, tmp_path: Path) -> None:
    path = tmp_path / "scene.matshop"
    assert autosave_path(path) == tmp_path / ".scene.matshop.recovery"
    assert find_recovery(path) is None
    save_project(tiny_doc, path)
    saved = path.read_bytes()
    time.sleep(0.05)  # file times tick in jiffies: make the recovery visibly newer
    recovery = write_recovery(tiny_doc, path, {"autosave": True})
    assert recovery == autosave_path(path) and find_recovery(path) == recovery
    assert path.read_bytes() == saved  # an autosave never touches the project
    restored = load_project(recovery)
    assert restored.settings == {"autosave": True}
    assert_same_document(tiny_doc, restored.document)
    save_project(tiny_doc, path)
    assert not recovery.exists() and find_recovery(path) is None


def test_stale_or_orphan_recovery(tiny_doc: Document, tmp_path: Path) -> None:
    path = tmp_path / "scene.matshop"
    recovery = write_recovery(tiny_doc, path)
    assert find_recovery(path) == recovery  # never saved: the autosave is all there is
    save_project(tiny_doc, path)
    write_recovery(tiny_doc, path)
    os.utime(recovery, ns=(1, 1))  # older than the project: superseded, not offered
    assert find_recovery(path) is None
    discard_recovery(path)
    discard_recovery(path)  # nothing left: still fine
    assert not recovery.exists()
