"""Image reading and writing through OpenImageIO: exact values, refusals, atomicity."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from matshop.errors import MatshopError
from matshop.io import atomic, images
from matshop.io.images import (
    ImageInfo,
    default_channel_names,
    probe_image,
    read_image,
    write_image,
)

RNG = np.random.default_rng(1234)


def oiio_write(path: Path, pixels: np.ndarray, fmt: str, names=None, attrs=None) -> Path:
    """Write with OpenImageIO directly (independent of the code under test)."""
    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, fmt)
    if names:
        spec.channelnames = names
        spec.alpha_channel = names.index("A") if "A" in names else -1
    spec.attribute("oiio:UnassociatedAlpha", 1)
    for key, value in (attrs or {}).items():
        spec.attribute(key, value)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    return path


def oiio_read(path: Path) -> tuple[np.ndarray, oiio.ImageSpec]:
    """Read native values (no float conversion) with OpenImageIO directly."""
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    inp = oiio.ImageInput.open(str(path), config)
    assert inp is not None, oiio.geterror()
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, spec.format)
    inp.close()
    return pixels, spec


def codes(shape: tuple[int, ...], dtype: str) -> np.ndarray:
    top = np.iinfo(dtype).max
    out = RNG.integers(0, top + 1, shape).astype(dtype)
    out.flat[:2] = (0, top)  # both ends present
    return out


def assert_one_line_naming(err: pytest.ExceptionInfo, path: Path) -> None:
    message = str(err.value)
    assert "\n" not in message
    assert path.name in message


def no_temp_files(folder: Path) -> bool:
    return not [p for p in folder.iterdir() if ".tmp-" in p.name]


# ---------------------------------------------------------------- reading


@pytest.mark.parametrize("channels", [1, 2, 3, 4])
@pytest.mark.parametrize("dtype", ["uint8", "uint16"])
def test_png_integer_codes_read_exactly(tmp_path, channels, dtype):
    names = default_channel_names(channels)
    values = codes((5, 7, channels), dtype)
    if channels in (2, 4):
        values[..., -1] = 0  # data under zero alpha must survive
        values[0, :, -1] = 77
    path = oiio_write(tmp_path / "a.png", values, dtype, list(names))
    pixels, info = read_image(path)
    assert pixels.dtype == np.float32 and pixels.shape == (5, 7, channels)
    top = np.iinfo(dtype).max
    np.testing.assert_array_equal(np.rint(pixels * top), values)
    assert (info.width, info.height, info.channels) == (7, 5, channels)
    assert info.bit_depth == dtype and info.is_integer and info.format == "png"
    assert info.channel_names == names
    assert isinstance(info.color_space, str)


@pytest.mark.parametrize("ext", ["png", "tga", "tif"])
def test_rgba_data_under_zero_alpha_survives_write_and_read(tmp_path, ext):
    values = codes((6, 6, 4), "uint8")
    values[..., 3] = 0
    values[1, 1, 3] = 3
    array = values.astype(np.float32) / 255
    path = tmp_path / f"mask.{ext}"
    write_image(path, array)
    native, spec = oiio_read(path)
    np.testing.assert_array_equal(native, values)
    back, _ = read_image(path)
    np.testing.assert_array_equal(back, array)


@pytest.mark.parametrize("fmt", ["half", "float"])
def test_exr_float_exact(tmp_path, fmt):
    values = (RNG.standard_normal((4, 6, 3)) * 10).astype(np.float16 if fmt == "half" else "f4")
    path = oiio_write(tmp_path / "h.exr", values, fmt)
    pixels, info = read_image(path)
    np.testing.assert_array_equal(pixels, values.astype(np.float32))
    assert info.bit_depth == fmt and not info.is_integer and info.format == "openexr"
    write_image(tmp_path / "w.exr", pixels, bit_depth=fmt)
    native, spec = oiio_read(tmp_path / "w.exr")
    assert str(spec.format) == fmt
    np.testing.assert_array_equal(native, values)


def test_many_channel_exr_names_and_attributes(tmp_path):
    values = RNG.random((3, 5, 128)).astype(np.float16).astype(np.float32)
    names = [f"d.{i:03d}" for i in range(128)]
    attrs = {"matshop:space": "distribution", "matshop:r_max": 0.75, "matshop:bins": 128}
    path = tmp_path / "mat_distribution.exr"
    write_image(path, values, bit_depth="half", channel_names=names, attributes=attrs)
    _, spec = oiio_read(path)
    assert list(spec.channelnames) == names
    pixels, info = read_image(path)
    np.testing.assert_array_equal(pixels, values)
    assert info.channel_names == tuple(names) and info.alpha_channel == -1
    assert info.attributes["matshop:space"] == "distribution"
    assert info.attributes["matshop:r_max"] == pytest.approx(0.75)
    assert info.attributes["matshop:bins"] == 128


def test_exr_channel_order_is_kept_or_refused(tmp_path):
    values = RNG.random((2, 3, 12)).astype(np.float32)
    path = tmp_path / "wide.exr"
    write_image(path, values, bit_depth="float")  # default names d.000 ... d.011
    back, info = read_image(path)
    np.testing.assert_array_equal(back, values)
    assert info.channel_names == tuple(f"d.{i:03d}" for i in range(12))
    before = path.read_bytes()
    names = [f"c{i}" for i in range(12)]  # EXR would store c0 c1 c10 c11 c2 ...
    with pytest.raises(MatshopError, match="sort in order") as err:
        write_image(path, values, bit_depth="float", channel_names=names)
    assert_one_line_naming(err, path)
    assert path.read_bytes() == before and no_temp_files(tmp_path)


@pytest.mark.parametrize(("ext", "depth"), [("tif", "uint8"), ("tif", "uint16"), ("tif", "float")])
def test_tiff_roundtrip_exact(tmp_path, ext, depth):
    if depth == "float":
        array = RNG.standard_normal((4, 4, 3)).astype(np.float32)
    else:
        top = np.iinfo(depth).max
        array = codes((4, 4, 3), depth).astype(np.float32) / top
    write_image(tmp_path / f"t.{ext}", array, bit_depth=depth)
    back, info = read_image(tmp_path / f"t.{ext}")
    assert info.format == "tiff" and info.bit_depth == depth
    np.testing.assert_allclose(back, array, rtol=0, atol=1e-7)


def test_jpeg_close(tmp_path):
    y, x = np.mgrid[0:32, 0:32] / 31.0
    array = np.stack([x, y, (x + y) / 2], axis=-1).astype(np.float32)
    write_image(tmp_path / "c.jpg", array)
    back, info = read_image(tmp_path / "c.jpg")
    assert info.format == "jpeg" and back.shape == array.shape
    assert np.abs(back - array).mean() < 0.01
    gray = array[..., :1]
    write_image(tmp_path / "g.jpeg", gray)
    assert read_image(tmp_path / "g.jpeg")[0].shape == (32, 32, 1)


def test_integer_quantisation_rounds_and_clips(tmp_path):
    target = codes((4, 8, 3), "uint8")
    array = (target.astype(np.float32) - 0.4) / 255  # truncation would give target - 1
    array[0, 0] = (-0.5, 1.5, 0.0)
    write_image(tmp_path / "q.png", array)
    native, _ = oiio_read(tmp_path / "q.png")
    expected = target.copy()
    expected[0, 0] = (0, 255, 0)
    np.testing.assert_array_equal(native, expected)
    write_image(tmp_path / "q16.png", np.full((2, 2), 0.5, np.float32), bit_depth="uint16")
    native, spec = oiio_read(tmp_path / "q16.png")
    assert spec.nchannels == 1 and native.max() == 32768  # rint(32767.5)


def test_probe_reads_header_only(tmp_path):
    path = oiio_write(tmp_path / "p.exr", np.zeros((3, 9, 2), np.float16), "half", ["Y", "A"])
    info = probe_image(path)
    assert isinstance(info, ImageInfo)
    assert (info.width, info.height, info.channels, info.alpha_channel) == (9, 3, 2, 1)
    assert info.pixels == 27 and info.path == path


# ---------------------------------------------------------------- bad input


def png_bytes(tmp_path: Path) -> bytes:
    path = oiio_write(tmp_path / "seed.png", codes((8, 8, 3), "uint8"), "uint8")
    return path.read_bytes()


def patch_ihdr(data: bytes, width: int, height: int) -> bytes:
    out = bytearray(data)
    assert out[12:16] == b"IHDR"
    struct.pack_into(">II", out, 16, width, height)
    struct.pack_into(">I", out, 29, zlib.crc32(bytes(out[12:29])) & 0xFFFFFFFF)
    return bytes(out)


def make_bad(kind: str, tmp_path: Path) -> Path:
    if kind == "missing":
        return tmp_path / "missing.png"
    if kind == "zero-byte":
        path = tmp_path / "empty.png"
        path.write_bytes(b"")
    elif kind == "text":
        path = tmp_path / "notes.png"
        path.write_text("not an image at all\n")
    elif kind == "unknown-format":
        path = tmp_path / "data.xyz"
        path.write_bytes(b"\x00\x01garbage" * 10)
    elif kind == "folder":
        path = tmp_path / "folder.png"
        path.mkdir()
    elif kind.startswith("truncated-"):
        ext = kind.split("-")[1]
        fmt = "half" if ext == "exr" else "uint8"
        values = codes((64, 64, 3), "uint8")
        full = oiio_write(tmp_path / f"full.{ext}", values.astype(fmt), fmt)
        data = full.read_bytes()
        path = tmp_path / f"cut.{ext}"
        path.write_bytes(data[: len(data) // 2])
    elif kind.startswith("huge-png-"):
        side = int(kind.split("-")[2])
        path = tmp_path / f"huge{side}.png"
        path.write_bytes(patch_ihdr(png_bytes(tmp_path), side, side))
    elif kind == "huge-exr":  # OpenImageIO lets this through: our guard must stop it
        path = oiio_write(tmp_path / "huge.exr", np.zeros((8, 8, 1), np.float16), "half")
        data = bytearray(path.read_bytes())
        for name in (b"dataWindow", b"displayWindow"):
            at = data.index(name + b"\x00box2i\x00") + len(name) + 11
            struct.pack_into("<4i", data, at, 0, 0, 19999, 19999)
        path.write_bytes(bytes(data))
    elif kind == "nan-inf":
        values = RNG.random((8, 8, 3)).astype(np.float32)
        values[0, 0, 0] = np.nan
        values[1, 1, :] = np.inf
        values[2, 2, 2] = -np.inf
        path = oiio_write(tmp_path / "bad.exr", values, "float")
    else:
        raise AssertionError(kind)
    return path


BAD = [
    "missing",
    "zero-byte",
    "text",
    "unknown-format",
    "folder",
    "truncated-png",
    "truncated-exr",
    "truncated-jpg",
    "huge-png-100000",
    "huge-png-20000",
    "huge-exr",
    "nan-inf",
]


@pytest.mark.parametrize("kind", BAD)
def test_bad_input_is_one_line_error_naming_file(tmp_path, kind):
    path = make_bad(kind, tmp_path)
    with pytest.raises(MatshopError) as err:
        read_image(path)
    assert_one_line_naming(err, path)
    if kind == "nan-inf":
        assert "3 of 64 texels" in str(err.value)


def test_huge_header_refused_before_allocation(tmp_path):
    # OpenImageIO 3.2 itself rejects PNG headers implausible for the file size
    # ("png header claims a 1144 MB image from a 388 byte file"); our guard
    # covers formats and sizes it lets through. Either way nothing is allocated.
    path = make_bad("huge-png-20000", tmp_path)
    with pytest.raises(MatshopError, match="header claims"):
        read_image(path)
    path = make_bad("huge-exr", tmp_path)
    with pytest.raises(MatshopError, match="20000x20000.*max_pixels"):
        read_image(path)
    assert probe_image(path, max_pixels=20000**2).width == 20000
    seed = tmp_path / "seed.png"  # 8x8 = 64 pixels, 3 channels
    with pytest.raises(MatshopError, match="max_pixels") as err:
        read_image(seed, max_pixels=63)
    assert_one_line_naming(err, seed)
    with pytest.raises(MatshopError, match="max_pixels"):
        probe_image(seed, max_pixels=63)
    assert read_image(seed, max_pixels=64)[0].shape == (8, 8, 3)


# ---------------------------------------------------------------- writing


@pytest.mark.parametrize(
    ("name", "shape", "depth", "match"),
    [
        ("f.png", (4, 4, 3), "float", "png cannot store float"),
        ("h.png", (4, 4, 3), "half", "png cannot store half"),
        ("many.png", (4, 4, 128), "uint16", "128 channels"),
        ("rgba.jpg", (4, 4, 4), "uint8", "4 channels"),
        ("u8.exr", (4, 4, 3), "uint8", "openexr cannot store uint8"),
        ("h.tif", (4, 4, 3), "half", "tiff cannot store half"),
        ("x.bmp", (4, 4, 3), "uint8", "cannot write .bmp"),
        ("noext", (4, 4, 3), "uint8", "cannot write"),
        ("shape.png", (4,), "uint8", "shape"),
    ],
)
def test_refused_combinations_leave_old_file(tmp_path, name, shape, depth, match):
    path = tmp_path / name
    path.write_bytes(b"previous contents")
    with pytest.raises(MatshopError, match=match) as err:
        write_image(path, np.zeros(shape, np.float32), bit_depth=depth)
    assert_one_line_naming(err, path)
    assert path.read_bytes() == b"previous contents"
    assert no_temp_files(tmp_path)


def test_refuses_bad_arrays_names_and_attributes(tmp_path):
    path = tmp_path / "x.exr"
    bad = np.zeros((2, 2, 3), np.float32)
    bad[0, 0, 1] = np.nan
    with pytest.raises(MatshopError, match="NaN or Inf values in 1 of 4"):
        write_image(path, bad, bit_depth="float")
    with pytest.raises(MatshopError, match="float pixels"):
        write_image(path, np.zeros((2, 2, 3), np.uint8), bit_depth="half")
    with pytest.raises(MatshopError, match="channel names"):
        write_image(path, np.zeros((2, 2, 3), np.float32), bit_depth="half", channel_names="RG")
    with pytest.raises(MatshopError, match="attribute"):
        write_image(path, np.zeros((2, 2, 3), np.float32), bit_depth="half", attributes={"a": []})
    with pytest.raises(MatshopError, match="does not exist"):
        write_image(tmp_path / "nowhere" / "x.png", np.zeros((2, 2), np.float32))
    assert not path.exists() and no_temp_files(tmp_path)


def test_failure_mid_write_keeps_old_file_and_removes_temp(tmp_path, monkeypatch):
    path = tmp_path / "mat_basecolor.png"
    write_image(path, np.full((4, 4, 3), 0.25, np.float32))
    before = path.read_bytes()
    seen = []

    def half_written(tmp, spec, pixels, target):
        seen.append(tmp)
        assert tmp.parent == path.parent and tmp.name.startswith(".mat_basecolor.tmp-")
        assert tmp.suffix == ".png"
        tmp.write_bytes(b"\x89PNG partial")
        raise MatshopError("disk full", target)

    monkeypatch.setattr(images, "_write_oiio", half_written)
    with pytest.raises(MatshopError, match="disk full"):
        write_image(path, np.zeros((4, 4, 3), np.float32))
    assert seen and path.read_bytes() == before and no_temp_files(tmp_path)


def test_fsync_failure_is_matshop_error_and_atomic(tmp_path, monkeypatch):
    path = tmp_path / "h.exr"
    write_image(path, np.ones((2, 2, 1), np.float32), bit_depth="half")
    before = path.read_bytes()

    def broken_fsync(fd):
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(atomic.os, "fsync", broken_fsync)
    with pytest.raises(MatshopError, match="Input/output error") as err:
        write_image(path, np.zeros((2, 2, 1), np.float32), bit_depth="half")
    assert_one_line_naming(err, path)
    assert path.read_bytes() == before and no_temp_files(tmp_path)


def test_successful_write_replaces_and_cleans_up(tmp_path):
    path = tmp_path / "r.png"
    path.write_bytes(b"old")
    write_image(path, np.full((3, 3), 1.0, np.float32))
    assert read_image(path)[0].min() == 1.0
    assert no_temp_files(tmp_path)
    reference = tmp_path / "reference"
    reference.write_bytes(b"")  # a new file gets the usual permissions, not mkstemp's 0600
    assert path.stat().st_mode & 0o777 == reference.stat().st_mode & 0o777
