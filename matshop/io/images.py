"""Reading and writing single images through OpenImageIO.

Everything in memory is ``float32`` of shape ``(H, W, C)``. Integer files are
normalised to ``[0, 1]`` on read and quantised with rounding on write. Alpha in
PNG, TGA and TIFF is read and written *unassociated*, so packed maps that keep
data in alpha (Unity mask maps) survive exactly, even where alpha is 0.

Every failure a user can cause (missing, corrupt, truncated, absurd or
non-finite files; formats that cannot hold the data) raises
:class:`~matshop.errors.MatshopError` naming the file.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import OpenImageIO as oiio

from matshop.errors import MatshopError
from matshop.finite import all_finite
from matshop.io.atomic import atomic_target
from matshop.io.guard import check_input_file, check_text_name
from matshop.io.png_settings import PNG_FILTER, PNG_FILTERS, PNG_LEVEL
from matshop.memory import require_memory

#: Default guard against corrupt headers: refuse images with more pixels than
#: this (16384 x 16384, a 16K texture) before allocating anything. A file may
#: also hold at most ``4 * max_pixels`` values in all (e.g. 128-channel EXRs).
MAX_PIXELS = 16384 * 16384


_INTEGER_FORMATS = frozenset(
    {"uint8", "int8", "uint16", "int16", "uint32", "int32", "uint64", "int64"}
)


@dataclass(frozen=True)
class _Writable:
    oiio_name: str
    bit_depths: tuple[str, ...]
    channels: tuple[int, ...] | None  # None: any count up to OpenImageIO's limit
    unassociated_alpha: bool


_WRITABLE = {
    ".png": _Writable("png", ("uint8", "uint16"), (1, 2, 3, 4), True),
    ".jpg": _Writable("jpeg", ("uint8",), (1, 3), False),
    ".jpeg": _Writable("jpeg", ("uint8",), (1, 3), False),
    ".tif": _Writable("tiff", ("uint8", "uint16", "float"), None, True),
    ".tiff": _Writable("tiff", ("uint8", "uint16", "float"), None, True),
    ".exr": _Writable("openexr", ("half", "float"), None, False),
    ".tga": _Writable("targa", ("uint8",), (1, 3, 4), True),
}
_MAX_CHANNELS = 1024  # OpenImageIO's "limits:channels"
_DEFAULT_NAMES = {1: ("Y",), 2: ("Y", "A"), 3: ("R", "G", "B"), 4: ("R", "G", "B", "A")}


@dataclass(frozen=True)
class ImageInfo:
    """What an image file's header says (first subimage)."""

    path: Path
    width: int
    height: int
    channels: int
    channel_names: tuple[str, ...]
    bit_depth: str  #: pixel format as stored: "uint8", "uint16", "half", "float"...
    format: str  #: OpenImageIO's file format name, e.g. "png", "openexr", "jpeg"
    color_space: str  #: OpenImageIO's ``oiio:ColorSpace`` ("" when unknown)
    is_integer: bool
    alpha_channel: int = -1  #: index of alpha, -1 when none
    attributes: dict[str, Any] = field(default_factory=dict, compare=False)

    @property
    def pixels(self) -> int:
        return self.width * self.height


def probe_image(path: str | os.PathLike[str], *, max_pixels: int = MAX_PIXELS) -> ImageInfo:
    """Read only the header of ``path``; cheap even for huge files."""
    inp, info = _open(Path(path), max_pixels)
    inp.close()
    return info


#: threads inside :func:`_c_stderr_silenced`, and the real fd 2 while any is
_silenced = {"count": 0, "saved": -1}
_silenced_lock = threading.Lock()


@contextmanager
def _c_stderr_silenced() -> Iterator[None]:
    """Mute file descriptor 2 for the duration of a C library call.

    libpng prints "libpng error: ..." straight to fd 2 before OpenImageIO
    reports the same problem through ``geterror``; the user should see our
    one-line error only. fd 2 is shared by the process, so files read at once
    on several threads share one muting: the first mutes, the last restores.
    """
    with _silenced_lock:
        if _silenced["count"] == 0:
            saved = os.dup(2)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 2)
            os.close(devnull)
            _silenced["saved"] = saved
        _silenced["count"] += 1
    try:
        yield
    finally:
        with _silenced_lock:
            _silenced["count"] -= 1
            if _silenced["count"] == 0:
                os.dup2(_silenced["saved"], 2)
                os.close(_silenced["saved"])


def read_image(
    path: str | os.PathLike[str], *, max_pixels: int = MAX_PIXELS
) -> tuple[np.ndarray, ImageInfo]:
    """Read the first subimage of ``path`` as float32 ``(H, W, C)``.

    Integer formats are normalised to ``[0, 1]``; alpha stays unassociated.
    Headers larger than ``max_pixels`` are refused before allocation (raise
    the limit to load legitimately huge files). Float files containing NaN or
    Inf are refused, so only clean data enters the editor.
    """
    path = Path(path)
    inp, info = _open(path, max_pixels)
    try:  # float32 result plus the decoded buffer: a small PNG can declare a huge image
        w, h, c = info.width, info.height, info.channels
        require_memory(w * h * c * 8, f"reading its {w}x{h}x{c} pixels", path)
    except MatshopError:
        inp.close()
        raise
    # 8/16-bit codes are divided here so that ``code / 255`` is correctly rounded
    # (OpenImageIO multiplies by 1/255, one ulp off) and writes round-trip exactly.
    native = info.bit_depth in ("uint8", "uint16") and not inp.spec().channelformats
    try:
        with _c_stderr_silenced():
            pixels = inp.read_image(0, 0, 0, info.channels, info.bit_depth if native else "float")
        error = inp.geterror() if inp.has_error else ""
    finally:
        inp.close()
    if pixels is None or error:
        raise MatshopError(f"truncated or corrupt image: {error or 'read failed'}", path)
    if native:  # divided in place: one float32 array (page faults cost as much as the division)
        pixels = pixels.astype(np.float32)
        pixels /= np.float32(np.iinfo(info.bit_depth).max)
    pixels = np.asarray(pixels, dtype=np.float32)
    expected = (info.height, info.width, info.channels)
    if pixels.size != np.prod(expected):
        raise MatshopError(f"read {pixels.shape} pixels, header says {expected}", path)
    pixels = np.ascontiguousarray(pixels.reshape(expected))
    if not info.is_integer:
        _check_finite(pixels, path, "contains")
    return pixels, info


#: Rec. 709 luminance weights: the gray of a color image used as a mask or a scalar
REC709 = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)


def luminance(pixels: np.ndarray) -> np.ndarray:
    """``(H, W)`` gray of image pixels ``(H, W, C)``: gray (+alpha) as is, RGB(A) by Rec. 709."""
    if pixels.shape[2] >= 3:
        return pixels[..., :3] @ REC709
    return np.ascontiguousarray(pixels[..., 0])


def resample_image(array: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``array`` (H, W) or (H, W, C) brought to ``size`` (rows, columns): area-averaged
    down (no aliasing), bilinear up."""
    if array.shape[:2] == tuple(size):
        return array
    import cv2

    shrinking = size[0] * size[1] < array.shape[0] * array.shape[1]
    out = cv2.resize(
        np.ascontiguousarray(array),
        (size[1], size[0]),
        interpolation=cv2.INTER_AREA if shrinking else cv2.INTER_LINEAR,
    )
    return out.reshape(*size, *array.shape[2:])  # cv2 drops a single channel's axis


def write_image(
    path: str | os.PathLike[str],
    array: np.ndarray,
    *,
    bit_depth: str = "uint8",
    channel_names: tuple[str, ...] | list[str] | None = None,
    attributes: dict[str, str | int | float] | None = None,
    png_level: int | None = None,
    png_filter: str = PNG_FILTER,
) -> None:
    """Write ``array`` (float ``(H, W[, C])``, integers scaled from ``[0, 1]``).

    The format comes from the extension (png, jpg/jpeg, tif/tiff, exr, tga);
    combinations it cannot store are refused before anything is written.
    Integer depths clip to ``[0, 1]`` and round to the nearest code value.
    ``attributes`` become file metadata (e.g. ``{"matshop:space": "ndf"}``).
    ``png_level`` is PNG's zlib level, 0-9 (default :data:`PNG_LEVEL`), ``png_filter``
    its row filter (a key of :data:`PNG_FILTERS`).
    The write is atomic: on failure any previous file at ``path`` is intact.
    """
    path = check_text_name(path)  # OpenImageIO takes text paths only
    pixels = _prepare(path, array, bit_depth)
    h, w, c = pixels.shape
    fmt = _WRITABLE[path.suffix.lower()]
    names = tuple(channel_names) if channel_names is not None else default_channel_names(c)
    if len(names) != c or len(set(names)) != c or not all(names):
        raise MatshopError(f"need {c} distinct non-empty channel names, got {names}", path)
    spec = oiio.ImageSpec(w, h, c, bit_depth)
    spec.channelnames = names
    spec.alpha_channel = names.index("A") if "A" in names else -1
    if fmt.unassociated_alpha:
        spec.attribute("oiio:UnassociatedAlpha", 1)
    if fmt.oiio_name == "jpeg":
        spec.attribute("Compression", "jpeg:95")
    if fmt.oiio_name == "png":
        level = PNG_LEVEL if png_level is None else png_level
        if not (isinstance(level, int) and 0 <= level <= 9):
            raise MatshopError(f"PNG compression level must be 0 to 9, got {level!r}", path)
        spec.attribute("png:compressionLevel", level)
        if png_filter not in PNG_FILTERS:
            raise MatshopError(
                f"PNG filter must be one of {', '.join(PNG_FILTERS)}, got {png_filter!r}", path
            )
        spec.attribute("png:filter", PNG_FILTERS[png_filter])
    for name, value in (attributes or {}).items():
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise MatshopError(f"attribute {name!r} must be str, int or float", path)
        spec.attribute(name, value)
    with atomic_target(path) as tmp:
        _write_oiio(tmp, spec, pixels, path)


def default_channel_names(channels: int) -> tuple[str, ...]:
    """Y, YA, RGB, RGBA; beyond 4 ``d.000, d.001, ...`` (zero-padded so that
    EXR, which stores channels sorted by name, keeps their order)."""
    if channels in _DEFAULT_NAMES:
        return _DEFAULT_NAMES[channels]
    width = max(3, len(str(channels - 1)))
    return tuple(f"d.{i:0{width}d}" for i in range(channels))


def _open(path: Path, max_pixels: int) -> tuple[oiio.ImageInput, ImageInfo]:
    """Open ``path`` for reading (unassociated alpha) and vet its header."""
    if check_input_file(path, "image file").st_size == 0:
        raise MatshopError("empty file (0 bytes), not an image", path)
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    with _c_stderr_silenced():  # libpng reports a bad header on fd 2 too
        inp = oiio.ImageInput.open(str(path), config)
    if inp is None:
        raise MatshopError(f"not a readable image: {oiio.geterror() or 'unknown format'}", path)
    try:
        info = _info(path, inp)
        _check_size(info, inp.spec().depth, max_pixels)
    except BaseException:
        inp.close()
        raise
    return inp, info


def _info(path: Path, inp: oiio.ImageInput) -> ImageInfo:
    spec = inp.spec()
    bit_depth = str(spec.format)
    return ImageInfo(
        path=path,
        width=spec.width,
        height=spec.height,
        channels=spec.nchannels,
        channel_names=tuple(spec.channelnames),
        bit_depth=bit_depth,
        format=inp.format_name(),
        color_space=str(spec.getattribute("oiio:ColorSpace") or ""),
        is_integer=bit_depth in _INTEGER_FORMATS,
        alpha_channel=spec.alpha_channel,
        attributes={a.name: a.value for a in spec.extra_attribs},
    )


def _check_size(info: ImageInfo, depth: int, max_pixels: int) -> None:
    w, h, c = info.width, info.height, info.channels
    if w <= 0 or h <= 0 or c <= 0:
        raise MatshopError(f"header claims an empty image ({w}x{h}, {c} channels)", info.path)
    if depth > 1:
        raise MatshopError(f"volume images (depth {depth}) are not supported", info.path)
    if w * h > max_pixels or w * h * c > 4 * max_pixels:
        raise MatshopError(
            f"header claims {w}x{h} with {c} channel(s), more than the limit of "
            f"{max_pixels} pixels (max_pixels); the file is probably corrupt",
            info.path,
        )


def _check_finite(pixels: np.ndarray, path: Path, verb: str) -> None:
    if all_finite(pixels):
        return
    bad = int((~np.isfinite(pixels).all(axis=-1)).sum())
    nan = int(np.isnan(pixels).any(axis=-1).sum())
    raise MatshopError(
        f"{verb} NaN or Inf values in {bad} of {pixels.shape[0] * pixels.shape[1]} texels "
        f"({nan} with NaN); only finite data can be edited",
        path,
    )


def _prepare(path: Path, array: np.ndarray, bit_depth: str) -> np.ndarray:
    """Check the format can store ``array`` and convert it to the file's type."""
    fmt = _WRITABLE.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted({k.lstrip(".") for k in _WRITABLE}))
        raise MatshopError(
            f"cannot write {path.suffix or 'files without extension'}: use one of {known}", path
        )
    if bit_depth not in fmt.bit_depths:
        raise MatshopError(
            f"{fmt.oiio_name} cannot store {bit_depth} data; use {' or '.join(fmt.bit_depths)}",
            path,
        )
    array = np.asarray(array)
    if array.ndim == 2:
        array = array[..., None]
    if array.ndim != 3 or array.shape[0] == 0 or array.shape[1] == 0 or array.shape[2] == 0:
        raise MatshopError(f"cannot write an array of shape {array.shape}", path)
    if not np.issubdtype(array.dtype, np.floating):
        raise MatshopError(f"expected float pixels in [0, 1], got {array.dtype}", path)
    c = array.shape[2]
    if (fmt.channels is not None and c not in fmt.channels) or c > _MAX_CHANNELS:
        allowed = fmt.channels or f"up to {_MAX_CHANNELS}"
        raise MatshopError(f"{fmt.oiio_name} cannot store {c} channels (allowed: {allowed})", path)
    if bit_depth in ("uint8", "uint16") and array.dtype in (np.float32, np.float64):
        from ._codes import to_codes  # numba: loaded only when integer files are written

        codes, bad = to_codes(array, bit_depth)
        if not bad:
            return codes
    _check_finite(array, path, "refusing to write")
    if bit_depth in ("uint8", "uint16"):
        top = np.iinfo(bit_depth).max
        return np.rint(np.clip(array, 0.0, 1.0) * top).astype(bit_depth)
    return np.ascontiguousarray(array, dtype=np.float16 if bit_depth == "half" else np.float32)


def _write_oiio(tmp: Path, spec: oiio.ImageSpec, pixels: np.ndarray, path: Path) -> None:
    """Write ``pixels`` into the (empty) temp file ``tmp``; errors name ``path``."""
    out = oiio.ImageOutput.create(str(tmp))
    if out is None:
        raise MatshopError(f"cannot write: {oiio.geterror()}", path)
    if not out.open(str(tmp), spec):
        raise MatshopError(f"cannot write: {out.geterror()}", path)
    reorders = out.format_name() == "openexr"  # EXR stores channels sorted by name
    ok = out.write_image(pixels)
    error = out.geterror() if (not ok or out.has_error) else ""
    closed = out.close()
    error = error or (out.geterror() if not closed else "")
    if not ok or not closed or error:
        raise MatshopError(f"cannot write: {error or 'write failed'}", path)
    if not reorders:
        return
    check = oiio.ImageInput.open(str(tmp))
    stored = tuple(check.spec().channelnames) if check is not None else ()
    if check is not None:
        check.close()
    if stored != tuple(spec.channelnames):
        raise MatshopError(
            f"channels {tuple(spec.channelnames)} would be stored as {stored}; "
            "choose names that sort in order (e.g. d.000, d.001, ...)",
            path,
        )
