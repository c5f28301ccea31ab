"""Fuzzers over the real command: stroke files, presets, op parameters, project manifests
and zips, image sets. Every example must end in exit 0 or 2 (2: one line on stderr), raise
nothing (no traceback), write nothing outside OUT, leave a refused project untouched, and
finish in bounded time.

Seconds each in CI; ``pytest --long`` runs 50x the examples (tests/fuzz_settings.py).
"""

from __future__ import annotations

import io
import json
import shutil
import tempfile
import time
import warnings
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from fuzz_settings import fuzz_examples
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from matshop.cli import main
from matshop.io.images import write_image
from matshop.io.project import load_project, save_project
from matshop.io.safe_names import check_file_name
from matshop.layers import Document
from matshop.material import Schema
from matshop.ops import all_ops

#: a hang guard, not a speed test: one example of these tiny inputs takes well under a second
MAX_SECONDS = 60

FUZZ = settings(
    max_examples=fuzz_examples(25),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("fuzz")
    rng = np.random.default_rng(7)
    folder = root / "set"
    folder.mkdir()
    write_image(folder / "m_basecolor.png", rng.random((8, 8, 3)).astype(np.float32))
    write_image(folder / "m_roughness.png", rng.random((8, 8, 1)).astype(np.float32))
    normal = np.zeros((8, 8, 3), np.float32)
    normal[..., 2] = 1.0
    write_image(folder / "m_normal.png", normal * 0.5 + 0.5)
    doc = Document(Schema.from_names(["base_color", "roughness"]), 8, 8, name="p")
    doc.insert_layer(doc.new_paint_layer("Paint"))
    doc.insert_layer(doc.new_filter_layer("blur", "Blur", op_params={"sigma_px": 1.0}))
    save_project(doc, root / "p.matshop")
    return root


def _tree(root: Path) -> dict[str, tuple[int, int]]:
    return {
        str(p.relative_to(root)): (p.lstat().st_size, p.lstat().st_mtime_ns)
        for p in root.rglob("*")
        if not p.is_dir()
    }


@contextmanager
def sandbox(base: Path) -> Iterator[Path]:
    """A fresh folder per example; afterwards nothing outside its ``out`` may have changed."""
    work = Path(tempfile.mkdtemp(dir=base))
    before = _tree(base)
    try:
        yield work
        after = _tree(base)
        out = str((work / "out").relative_to(base))
        changed = {k for k in after.keys() | before.keys() if before.get(k) != after.get(k)}
        outside = [k for k in changed if not k.startswith((out, str(work.relative_to(base))))]
        assert outside == [], outside
        for path in (work / "out").rglob("*") if (work / "out").exists() else ():
            check_file_name(path.name)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def run_cli(argv: list[object], capfd: pytest.CaptureFixture[str], out: Path | None = None) -> int:
    """Run the real command; a refusal (2) is one line and, saves being all-or-nothing,
    leaves no file in ``out``."""
    capfd.readouterr()
    start = time.monotonic()
    words = [str(a) for a in argv]
    try:
        code = main(words)  # an exception here is the traceback a user would see
        refusal = "matshop: error: "
    except SystemExit as usage:  # argparse refuses the words themselves (an op named "-x")
        code = usage.code
        refusal = f"matshop {words[0]}: error: "
    err = capfd.readouterr().err
    assert time.monotonic() - start < MAX_SECONDS
    assert code in (0, 2), (code, err)
    if code == 2:
        lines = [line for line in err.splitlines() if line.startswith(refusal)]
        assert len(lines) == 1 and "Traceback" not in err, err
        if out is not None and out.exists():
            assert [p for p in out.rglob("*") if not p.is_dir()] == [], err
    return code


# ------------------------------------------------ values

_EXTREME = st.sampled_from(
    [0, -1, 1, 0.5, 1e-300, -1e-300, 1e12, -1e12, 1e308, -1e308, 2**62, 2**64, 65536, 0.05]
)
_NUMBER = st.one_of(
    _EXTREME, st.floats(allow_nan=False, allow_infinity=True), st.integers(-(10**20), 10**20)
)
_SCALAR = st.one_of(st.none(), st.booleans(), _NUMBER, st.text(max_size=20))
_JSON = st.recursive(
    _SCALAR,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)


def _dump(value: object) -> str:
    return json.dumps(value)  # inf -> Infinity, as a hand-written file may hold


# ------------------------------------------------ stroke files

_POINT = st.lists(_NUMBER, min_size=1, max_size=4)
_SWATCH_VALUES = st.fixed_dictionaries(
    {},
    optional={
        "base_color": st.lists(_NUMBER, max_size=4),
        "roughness": st.lists(_NUMBER, max_size=2),
    },
)
_STROKE = st.fixed_dictionaries(
    {"points": st.one_of(st.lists(_POINT, min_size=1, max_size=6), _JSON)},
    optional={
        "mode": st.sampled_from(["paint", "erase", "clone", "alpha", ""]) | _JSON,
        "target": st.sampled_from(["pixels", "mask", "alpha"]) | _JSON,
        "brush": st.fixed_dictionaries(
            {},
            optional={
                "radius_px": _NUMBER,
                "spacing": _NUMBER,
                "hardness": _NUMBER,
                "size_pressure": st.lists(st.lists(_NUMBER, max_size=3), max_size=4) | _JSON,
            },
        ),
        "swatch": st.fixed_dictionaries(
            {
                "name": st.text(max_size=5),
                "values": _SWATCH_VALUES,
            }
        )
        | _JSON,
        "clone_offset": st.lists(_NUMBER, max_size=3) | _JSON,
        "mask_value": _NUMBER | _JSON,
        "layer": st.sampled_from(["Paint", "Blur", 1, 2, 99, "nope"]) | _JSON,
    },
)


@FUZZ
@given(strokes=st.one_of(st.lists(_STROKE, max_size=3), _JSON))
def test_fuzz_stroke_files(base: Path, strokes: object, capfd: pytest.CaptureFixture[str]) -> None:
    with sandbox(base) as work:
        project = work / "p.matshop"
        shutil.copy(base / "p.matshop", project)
        stroke_file = work / "s.json"
        stroke_file.write_text(_dump({"strokes": strokes}))
        saved = project.read_bytes()
        if run_cli(["paint", project, "--stroke", stroke_file], capfd) == 2:
            assert project.read_bytes() == saved
        load_project(project)


# ------------------------------------------------ presets

_TEMPLATE = st.one_of(
    st.sampled_from(
        [
            "{material}_{channel}.{ext}",
            "{preset}/{channel}.png",
            "../{channel}.{ext}",
            "a{.png",
            "}",
            "x\x00.png",
            "{channel}",
            ".{ext}",
            "{material.__class__}.png",
            "C:{channel}.png",
        ]
    ),
    st.text(max_size=30),
)
_MAP = st.fixed_dictionaries(
    {"channel": st.sampled_from(["c", "..", ".x", "BaseColor"]) | st.text(max_size=10)},
    optional={
        "srcMapName": st.sampled_from(["base_color", "roughness", "normal", "nope"]) | _JSON,
        "fileName": _TEMPLATE,
        "fileFormat": st.sampled_from(["png", "exr", "tga", "jpg", "bogus"]) | _JSON,
        "bitDepth": st.sampled_from(["8", "16", "half", "float", 3]) | _JSON,
        "dithering": st.sampled_from([True, False, "false", "true", "no"]) | _JSON,
        "channels": st.lists(
            st.fixed_dictionaries(
                {"destChannel": st.sampled_from(["R", "G", "B", "A", 0, 5, -1])},
                optional={
                    "srcMapName": st.sampled_from(["roughness", "base_color"]),
                    "value": _NUMBER,
                },
            ),
            max_size=5,
        ),
    },
)


@FUZZ
@given(
    name=st.text(max_size=20) | st.sampled_from(["../../x", "/abs", "a\x00b"]),
    maps=st.lists(_MAP, max_size=3) | _JSON,
    extra=_JSON,
)
def test_fuzz_preset_files(
    base: Path, name: str, maps: object, extra: object, capfd: pytest.CaptureFixture[str]
) -> None:
    with sandbox(base) as work:
        preset = work / "preset.json"
        preset.write_text(_dump({"name": name, "maps": maps, "extra": extra}))
        run_cli(
            ["export", base / "set", work / "out", "--preset-file", preset], capfd, work / "out"
        )


# ------------------------------------------------ op parameters

_OPS = sorted(all_ops())
_VALUE_TEXT = st.one_of(
    st.sampled_from(
        [
            "inf",
            "-inf",
            "nan",
            "1e308",
            "-1e308",
            "0",
            "0.05",
            "1e18,0",
            "inf,0",
            "0,0;1,1",
            "0,0;0,1",
            "wrap",
            "clamp",
            "true",
            "",
            ",",
            ";",
            "{set}",
        ]
    ),
    _NUMBER.map(str),
    st.text(max_size=10),
)


@FUZZ
@given(
    steps=st.lists(
        st.tuples(
            st.sampled_from(_OPS) | st.text(max_size=6),
            st.lists(
                st.tuples(
                    st.sampled_from(
                        [
                            "sigma_px",
                            "factor",
                            "offset",
                            "points",
                            "amount",
                            "gamma",
                            "border",
                            "region",
                            "over",
                            "source",
                            "sigma_range",
                            "channel_factors",
                            "opacity",
                        ]
                    ),
                    _VALUE_TEXT,
                ),
                max_size=3,
            ),
        ),
        min_size=1,
        max_size=3,
    ),
    params=st.none() | st.sampled_from(["roughness", "normal", "kd", "nope", ""]),
)
@example(steps=[("-:", [])], params=None)  # found by CI: an op name argparse takes for an option
def test_fuzz_op_parameters(
    base: Path, steps: list, params: str | None, capfd: pytest.CaptureFixture[str]
) -> None:
    with sandbox(base) as work:
        argv: list[object] = ["apply", base / "set", work / "out"]
        for name, pairs in steps:
            argv += [
                "--op",
                name,
                *(f"{k}={v.replace('{set}', str(base / 'set'))}" for k, v in pairs),
            ]
        if params is not None:
            argv += ["--params", params]
        if run_cli(argv, capfd, work / "out") == 0:
            assert len(list((work / "out").iterdir())) == 3


# ------------------------------------------------ project manifests and zips


def _members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as archive:
        return {info.filename: archive.read(info) for info in archive.infolist()}


def _paths(node: object, prefix: tuple = ()) -> list[tuple]:
    found = [prefix]
    if isinstance(node, dict):
        for key, value in node.items():
            found += _paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            found += _paths(value, (*prefix, index))
    return found


@FUZZ
@given(data=st.data())
def test_fuzz_project_manifests_and_zips(
    base: Path, data: st.DataObject, capfd: pytest.CaptureFixture[str]
) -> None:
    members = _members(base / "p.matshop")
    manifest = json.loads(members["manifest.json"])
    for _ in range(data.draw(st.integers(1, 3))):
        path = data.draw(st.sampled_from(_paths(manifest)[1:]))
        parent = manifest
        for key in path[:-1]:
            parent = parent[key]
        parent[path[-1]] = data.draw(_JSON | st.sampled_from(["../../x", "/abs", 2**62, 10**30]))
    text = _dump(manifest)
    if data.draw(st.booleans()):
        cut = data.draw(st.integers(0, len(text)))
        text = text[:cut]
    members["manifest.json"] = text.encode()
    extra = data.draw(st.sampled_from([None, "../evil", "/abs", "layers/0000/pixels.f32", "a\\b"]))
    buffer = io.BytesIO()
    with warnings.catch_warnings(), zipfile.ZipFile(buffer, "w") as archive:
        warnings.simplefilter("ignore")  # duplicate member names are one of the tricks
        for name, payload in members.items():
            archive.writestr(name, payload)
        if extra is not None:
            archive.writestr(extra, b"\x00" * 8)
    with sandbox(base) as work:
        project = work / "p.matshop"
        project.write_bytes(buffer.getvalue())
        verb = data.draw(st.sampled_from(["flatten", "layer-list", "layer-add", "export"]))
        saved = project.read_bytes()
        if verb == "flatten":
            code = run_cli(["flatten", project, work / "out"], capfd, work / "out")
        elif verb == "export":
            code = run_cli(
                ["export", project, work / "out", "--preset", "gltf"], capfd, work / "out"
            )
        elif verb == "layer-list":
            code = run_cli(["layer", "list", project], capfd)
        else:
            code = run_cli(["layer", "add", project, "paint"], capfd)
            if code == 0:
                load_project(project)  # what was saved loads again
        if code == 2:
            assert project.read_bytes() == saved


# ------------------------------------------------ image sets


@FUZZ
@given(
    width=st.integers(1, 12),
    height=st.integers(1, 12),
    channels=st.sampled_from([1, 2, 3, 4]),
    depth=st.sampled_from(["uint8", "uint16"]),
    cut=st.none() | st.integers(0, 400),
    flip=st.none() | st.tuples(st.integers(0, 400), st.integers(1, 255)),
    slot=st.sampled_from(["basecolor", "roughness", "normal"]),
)
def test_fuzz_image_sets(
    base: Path,
    width: int,
    height: int,
    channels: int,
    depth: str,
    cut: int | None,
    flip: tuple[int, int] | None,
    slot: str,
    capfd: pytest.CaptureFixture[str],
) -> None:
    with sandbox(base) as work:
        folder = work / "set"
        shutil.copytree(base / "set", folder)
        image = folder / f"m_{slot}.png"
        rng = np.random.default_rng(width * 100 + height)
        write_image(
            image, rng.random((height, width, channels)).astype(np.float32), bit_depth=depth
        )
        raw = bytearray(image.read_bytes())
        if flip is not None and flip[0] < len(raw):
            raw[flip[0]] ^= flip[1]
        if cut is not None:
            raw = raw[:cut]
        image.write_bytes(bytes(raw))
        verb = ["convert", folder, work / "out"] if width % 2 else ["info", folder]
        run_cli(verb, capfd, work / "out")
