"""``--png-level`` and the presets' ``pngLevel``: the PNGs written carry the zlib level
asked for (read from the files' own zlib headers) and the same pixels at every level."""

from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from matshop.cli import main

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def zlib_level_class(path: Path) -> int:
    """FLEVEL of the PNG's zlib stream (RFC 1950): 0 for levels 0-1, 1 for 2-5, 2 for 6,
    3 for 7-9, as zlib writes it."""
    data = path.read_bytes()
    pos = 8
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        if kind == b"IDAT":
            cmf, flg = data[pos + 8], data[pos + 9]
            assert (cmf * 256 + flg) % 31 == 0 and cmf & 0x0F == zlib.DEFLATED
            return flg >> 6
        pos += 12 + length
    raise AssertionError(f"{path} has no IDAT")


def pixels(folder: Path) -> dict[str, np.ndarray]:
    out = {}
    for path in sorted(folder.glob("*.png")):
        inp = oiio.ImageInput.open(str(path))
        out[path.name] = inp.read_image(0, 0, 0, inp.spec().nchannels, inp.spec().format)
        inp.close()
    return out


def test_apply_writes_pngs_at_the_level_asked_for(tmp_path: Path) -> None:
    # one map is enough: the option reaches every PNG through the same writer
    source = tmp_path / "in"
    source.mkdir()
    for name in ("tiles_basecolor.png", "tiles_roughness.png"):
        (source / name).write_bytes((SAMPLE / name).read_bytes())
    op = ["--op", "blur", "sigma_px=2"]
    assert main(["apply", str(source), str(tmp_path / "default"), *op]) == 0
    assert main(["apply", str(source), str(tmp_path / "l9"), *op, "--png-level", "9"]) == 0
    assert main(["apply", str(source), str(tmp_path / "l0"), *op, "--png-level", "0"]) == 0
    default, best, stored = (pixels(tmp_path / n) for n in ("default", "l9", "l0"))
    assert len(default) == 2 and default.keys() == best.keys() == stored.keys()
    for name in default:
        np.testing.assert_array_equal(best[name], default[name])
        np.testing.assert_array_equal(stored[name], default[name])
        assert zlib_level_class(tmp_path / "default" / name) == 1  # level 2
        assert zlib_level_class(tmp_path / "l9" / name) == 3
        assert zlib_level_class(tmp_path / "l0" / name) == 0
    sizes = [sum(p.stat().st_size for p in (tmp_path / n).iterdir()) for n in ("l9", "l0")]
    assert sizes[0] < sizes[1]


def _preset(tmp_path: Path, level: object) -> Path:
    preset = {
        "name": "levels",
        "pngLevel": level,
        "maps": [{"channel": "BaseColor", "fileFormat": "png", "srcMapName": "base_color"}],
    }
    path = tmp_path / "levels.json"
    path.write_text(json.dumps(preset))
    return path


def test_export_takes_the_presets_level_and_the_option_overrides_it(tmp_path: Path) -> None:
    preset = _preset(tmp_path, 9)
    args = ["export", str(SAMPLE / "tiles_basecolor.png"), "--preset-file", str(preset)]
    assert main([*args[:2], str(tmp_path / "p"), *args[2:]]) == 0
    assert main([*args[:2], str(tmp_path / "o"), *args[2:], "--png-level", "1"]) == 0
    (from_preset,) = (tmp_path / "p").glob("*.png")
    (overridden,) = (tmp_path / "o").glob("*.png")
    assert zlib_level_class(from_preset) == 3
    assert zlib_level_class(overridden) == 0
    assert pixels(tmp_path / "p")[from_preset.name].tobytes() == (
        pixels(tmp_path / "o")[overridden.name].tobytes()
    )


@pytest.mark.parametrize("level", [10, -1, 2.5, "9", True])
def test_a_bad_preset_level_is_one_line_and_writes_nothing(tmp_path: Path, capsys, level) -> None:
    preset = _preset(tmp_path, level)
    out = tmp_path / "out"
    argv = ["export", str(SAMPLE), str(out), "--preset-file", str(preset)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "levels.json" in err and "pngLevel" in err
    assert not out.exists()


@pytest.mark.parametrize("level", ["10", "-1", "x"])
def test_a_bad_option_exits_2_and_writes_nothing(tmp_path: Path, capsys, level) -> None:
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exit_:
        main(["apply", str(SAMPLE), str(out), "--op", "blur", "sigma_px=2", "--png-level", level])
    assert exit_.value.code == 2
    assert not out.exists()
