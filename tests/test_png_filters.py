"""PNG writing at every row filter and level: the file decodes to exactly the data written,
and its rows carry the filter asked for (read from the file's own bytes)."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from matshop.errors import MatshopError
from matshop.io.images import PNG_FILTERS, write_image

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"
#: PNG's filter-type byte at the start of each row (PNG spec 9.2); adaptive may mix them
ROW_FILTER = {"none": 0, "sub": 1, "up": 2, "avg": 3, "paeth": 4}


def row_filters(path: Path, row_bytes: int) -> set[int]:
    """The filter-type bytes of every row, from the PNG's IDAT stream (no decoder)."""
    data = path.read_bytes()
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        if kind == b"IDAT":
            idat += data[pos + 8 : pos + 8 + length]
        pos += 12 + length
    raw = zlib.decompress(idat)
    return set(raw[:: row_bytes + 1])


def image() -> np.ndarray:
    """A real map's corner when the shared data is there (smooth and textured rows), else noise."""
    if DATA.is_dir():
        inp = oiio.ImageInput.open(str(DATA / "chessboard_base_color.jpg"))
        pixels = inp.read_image(0, 0, 0, 3, "float")
        inp.close()
        return np.ascontiguousarray(pixels[:96, :80])
    rng = np.random.default_rng(3)
    return rng.random((96, 80, 3), dtype=np.float32)


@pytest.mark.parametrize("name", list(PNG_FILTERS))
@pytest.mark.parametrize(("depth", "level"), [("uint8", 2), ("uint16", 1), ("uint8", 9)])
def test_png_reads_back_exactly_with_the_filter_asked_for(tmp_path, name, depth, level):
    pixels = image()
    path = tmp_path / "x.png"
    write_image(path, pixels, bit_depth=depth, png_level=level, png_filter=name)
    inp = oiio.ImageInput.open(str(path))
    back = inp.read_image(0, 0, 0, 3, depth)
    inp.close()
    top = np.iinfo(depth).max
    np.testing.assert_array_equal(back, np.rint(np.clip(pixels, 0, 1) * top).astype(depth))
    used = row_filters(path, pixels.shape[1] * 3 * np.dtype(depth).itemsize)
    if name == "adaptive":
        assert used <= set(ROW_FILTER.values())
    else:
        assert used == {ROW_FILTER[name]}


def test_unknown_filter_is_refused_naming_the_file(tmp_path):
    with pytest.raises(MatshopError, match="x.png.*PNG filter must be one of"):
        write_image(tmp_path / "x.png", np.zeros((2, 2, 3), np.float32), png_filter="best")
    assert not (tmp_path / "x.png").exists()
