"""Normal maps with known conventions, for calibrating ``guess_normal_convention``.

Height fields of the kinds texture sets carry (noise and rocks, bumps and
rivets, beveled bricks / tiles / planks, pure grooves ``f(u) + g(v)``,
scratches, fabric, mixtures) are baked to tangent-space normals (central
differences, Sobel, or a 2x supersampled bake whose normals are averaged),
either tiling the whole image or cut into UV islands (rotated pieces of
different fields on a flat background, with baker-style edge padding), then
encoded in both conventions and written by real encoders: PNG 8 and 16 bit,
JPEG at several qualities with 4:2:0 or 4:4:4 chroma. Reading them back goes
through ``matshop.io.images.read_image``, as a load does. Sizes are in UV
terms (a 4K brick map has the same bricks as a 256 one, with wider bevels),
and every map is a pure function of its :class:`MapSpec`.

The CI tests use :func:`ci_specs` (a few 256-512 maps); the calibration
(``benchmarks/normal_convention.py``) uses :func:`full_specs`.
"""

from __future__ import annotations

import itertools
import math
import zlib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
from scipy import ndimage
from scipy.spatial import cKDTree

from matshop.io.images import read_image
from matshop.spaces.frame import encode_normal_map

Height = Callable[[int, np.random.Generator], np.ndarray]

ENCODINGS = ("png8", "png16", "jpg95", "jpg90", "jpg75", "jpg50", "jpg90_444")
BAKERS = ("central", "sobel", "supersample")
LAYOUTS = ("tiled", "atlas")


@dataclass(frozen=True)
class MapSpec:
    """One corpus map: what was baked, how it was stored, and the true convention."""

    family: str
    layout: str
    size: int
    baker: str
    encoding: str
    convention: str
    seed: int

    @property
    def name(self) -> str:
        ext = "png" if self.encoding.startswith("png") else "jpg"
        return (
            f"{self.family}-{self.layout}-{self.size}-{self.baker}-{self.encoding}"
            f"-{self.convention}-s{self.seed}.{ext}"
        )

    @property
    def geometry(self) -> tuple[str, str, int, str, int]:
        """The part of the spec that decides the normals (shared by encodings, conventions)."""
        return self.family, self.layout, self.size, self.baker, self.seed


# ---------------------------------------------------------------------------
# height fields, in texel units; features are sized relative to the image


def _slope_scaled(h: np.ndarray, degrees: float) -> np.ndarray:
    """``h`` scaled so that its 95th-percentile slope is ``tan(degrees)``."""
    gy, gx = np.gradient(h)
    slope = np.percentile(np.hypot(gx, gy), 95)
    return h * (math.tan(math.radians(degrees)) / max(float(slope), 1e-12))


def _fractal(size: int, rng: np.random.Generator, beta: float, stretch_u: float = 1.0):
    """Periodic 1/f^beta noise, unit variance; ``stretch_u > 1`` elongates features along u."""
    white = rng.standard_normal((size, size)).astype(np.float32)
    fy = np.fft.fftfreq(size)[:, None] * size
    fx = np.fft.rfftfreq(size)[None, :] * size * stretch_u
    f = np.hypot(fx, fy)
    amp = np.where((f >= 1.5) & (f <= size / 3), np.maximum(f, 1.0) ** (-beta / 2), 0.0)
    h = np.fft.irfft2(np.fft.rfft2(white) * amp.astype(np.float32), s=(size, size))
    return (h / max(float(h.std()), 1e-12)).astype(np.float64)


def _noise(size: int, rng: np.random.Generator) -> np.ndarray:
    return _slope_scaled(_fractal(size, rng, rng.uniform(2.0, 3.5)), rng.uniform(15, 45))


def _rocks(size: int, rng: np.random.Generator) -> np.ndarray:
    """Voronoi stones: domed cells separated by creases, plus fine noise."""
    work = min(size, 1024)
    cells = rng.integers(12, 60)
    pts = rng.uniform(0, work, size=(cells, 2))
    tiled = np.concatenate(
        [pts + work * np.array(o) for o in itertools.product((-1, 0, 1), repeat=2)]
    )
    rows, cols = np.mgrid[0:work, 0:work]
    d, _ = cKDTree(tiled).query(np.stack([rows.ravel(), cols.ravel()], 1), k=2)
    border = ((d[:, 1] - d[:, 0]) / 2).reshape(work, work)
    if work != size:
        border = ndimage.zoom(border, size / work, order=1)
    border *= size / work
    width = size / rng.uniform(12, 30)
    dome = np.sqrt(np.clip(border / width, 0, 1) * (2 - np.clip(border / width, 0, 1)))
    h = dome * width * rng.uniform(0.4, 1.0) + 0.03 * width * _fractal(size, rng, 2.5)
    return h


def _bumps(size: int, rng: np.random.Generator) -> np.ndarray:
    """Gaussian bumps and dents, and steep-sided rivets."""
    h = np.zeros((size, size))
    for _ in range(int(rng.integers(15, 60))):
        radius = size * rng.uniform(0.01, 0.06)
        r0, c0 = rng.uniform(0, size, 2)
        half = int(3 * radius) + 2
        r_lo, c_lo = max(int(r0) - half, 0), max(int(c0) - half, 0)
        rr, cc = np.mgrid[r_lo : min(int(r0) + half, size), c_lo : min(int(c0) + half, size)]
        d2 = ((rr - r0) ** 2 + (cc - c0) ** 2) / radius**2
        if rng.random() < 0.5:
            bump = radius * rng.uniform(-0.6, 0.6) * np.exp(-d2 * 2)
        else:  # rivet: a cap with a steep rim
            bump = radius * rng.uniform(0.3, 0.8) * np.clip(1 - d2, 0, None) ** 1.5
        h[rr, cc] += bump
    return h


def _bevel(dist: np.ndarray, width: float, rounded: bool) -> np.ndarray:
    t = np.clip(dist / width, 0.0, 1.0)
    return np.sin(t * np.pi / 2) if rounded else t


def _blocks(
    size: int,
    rng: np.random.Generator,
    rows: int,
    aspect: float,
    stagger: str,
    detail: float,
) -> np.ndarray:
    """Rectangular blocks (bricks, tiles, planks) with beveled edges and mortar.

    Each block's height is the bevel of the distance to its nearest edge (a
    mitred frustum), with a small random plateau offset; ``stagger`` is
    ``"half"`` (running bond), ``"none"`` (grid) or ``"random"`` (plank ends).
    """
    block_h = size / rows
    block_w = block_h * aspect
    mortar = block_h * rng.uniform(0.03, 0.08)
    bevel = block_h * rng.uniform(0.04, 0.15)
    rounded = bool(rng.random() < 0.5)
    angle = rng.uniform(25, 60)
    y = np.arange(size) + 0.5
    x = np.arange(size) + 0.5
    row = np.floor(y / block_h).astype(int)
    dy = np.minimum(y - row * block_h, (row + 1) * block_h - y)  # to the row's edges
    offsets = {
        "half": (row % 2) * block_w / 2,
        "none": np.zeros(rows + 1)[row],
        "random": rng.uniform(0, block_w, rows + 1)[row],
    }[stagger]
    xs = x[None, :] + offsets[:, None]
    col = np.floor(xs / block_w)
    dx = np.minimum(xs - col * block_w, (col + 1) * block_w - xs)
    dist = np.minimum(dx, dy[:, None]) - mortar / 2
    plateau = rng.uniform(-0.15, 0.15, (rows + 1, int(size / block_w) + 3))
    offset = plateau[row[:, None], col.astype(int) % plateau.shape[1]]
    h = bevel * math.tan(math.radians(angle)) * _bevel(dist, bevel, rounded) * (1 + offset)
    if detail:  # surface texture (wood grain along planks)
        grain = 4.0 if stagger == "random" else 1.0
        h += detail * bevel * _fractal(size, rng, 3.0, stretch_u=grain)
    return h


def _bricks(size: int, rng: np.random.Generator) -> np.ndarray:
    detail = float(rng.choice([0.0, 0.0, 0.05, 0.15]))
    return _blocks(size, rng, int(rng.integers(6, 16)), 2.0, "half", detail)


def _tiles(size: int, rng: np.random.Generator) -> np.ndarray:
    detail = float(rng.choice([0.0, 0.0, 0.05]))
    return _blocks(size, rng, int(rng.integers(3, 10)), 1.0, "none", detail)


def _planks(size: int, rng: np.random.Generator) -> np.ndarray:
    detail = float(rng.choice([0.0, 0.1, 0.3]))  # wood grain, stretched along the boards
    return _blocks(size, rng, int(rng.integers(4, 10)), rng.uniform(4, 10), "random", detail)


def _grooves(size: int, rng: np.random.Generator) -> np.ndarray:
    """Pure f(u) + g(v): V or U grooves on a grid, plus 1-D noise profiles."""
    x = np.arange(size) + 0.5

    def profile() -> np.ndarray:
        period = size / rng.integers(3, 12)
        width = period * rng.uniform(0.05, 0.25)
        d = np.abs((x % period) - period / 2) - (period / 2 - width)
        groove = np.clip(d / width, 0, 1)
        groove = groove**2 if rng.random() < 0.5 else groove
        ridge = 1.0 if rng.random() < 0.8 else -1.0  # mostly grooves, some ridges
        wobble = np.convolve(rng.standard_normal(size), np.ones(9) / 9, mode="same")
        return -ridge * width * rng.uniform(0.5, 1.5) * groove + 0.05 * width * wobble

    return profile()[None, :] + profile()[:, None]


def _scratches(size: int, rng: np.random.Generator) -> np.ndarray:
    """Thin grooves along random segments; a third of them axis-aligned."""
    h = 0.02 * _fractal(size, rng, 3.0) * size / 64
    for _ in range(int(rng.integers(20, 120))):
        length = size * rng.uniform(0.05, 0.5)
        theta = rng.choice([0.0, np.pi / 2]) if rng.random() < 0.33 else rng.uniform(0, np.pi)
        width = rng.uniform(1.0, 3.0) * max(size / 512, 1.0)
        p0 = rng.uniform(0, size, 2)
        p1 = p0 + length * np.array([math.sin(theta), math.cos(theta)])
        lo = np.maximum(np.floor(np.minimum(p0, p1) - 2 * width), 0).astype(int)
        hi = np.minimum(np.ceil(np.maximum(p0, p1) + 2 * width), size).astype(int)
        if np.any(hi <= lo):
            continue
        rr, cc = np.mgrid[lo[0] : hi[0], lo[1] : hi[1]]
        pts = np.stack([rr, cc], -1) + 0.5
        seg = p1 - p0
        t = np.clip(((pts - p0) @ seg) / (seg @ seg), 0, 1)
        dist = np.linalg.norm(pts - (p0 + t[..., None] * seg), axis=-1)
        h[rr, cc] -= width * rng.uniform(0.5, 1.5) * np.clip(1 - dist / width, 0, 1) ** 2
    return h


def _fabric(size: int, rng: np.random.Generator) -> np.ndarray:
    """Plain or twill weave: thread profiles modulated by the over/under pattern."""
    pitch = size / rng.integers(16, 64)
    rows, cols = np.mgrid[0:size, 0:size] + 0.5
    u, v = cols / pitch, rows / pitch
    twill = rng.random() < 0.4
    phase = np.pi * (np.floor(u) + (np.floor(v) if not twill else 0.5 * np.floor(v)))
    warp = np.abs(np.sin(np.pi * u)) * (1 + np.cos(np.pi * v + phase)) / 2
    weft = np.abs(np.sin(np.pi * v)) * (1 - np.cos(np.pi * u + phase)) / 2
    h = np.maximum(warp, weft) + 0.1 * _fractal(size, rng, 2.5)
    return _slope_scaled(h, rng.uniform(20, 45))


def _mixed(size: int, rng: np.random.Generator) -> np.ndarray:
    base = _bricks(size, rng) if rng.random() < 0.5 else _planks(size, rng)
    return base + 0.3 * _scratches(size, rng) + 0.3 * _bumps(size, rng)


FAMILIES: dict[str, Height] = {
    "noise": _noise,
    "rocks": _rocks,
    "bumps": _bumps,
    "bricks": _bricks,
    "tiles": _tiles,
    "planks": _planks,
    "grooves": _grooves,
    "scratches": _scratches,
    "fabric": _fabric,
    "mixed": _mixed,
}


# ---------------------------------------------------------------------------
# baking and layout


def _gradients(h: np.ndarray, baker: str) -> tuple[np.ndarray, np.ndarray]:
    """``(dh/du, dh/dv)`` with ``v`` up the image (against the row index)."""
    if baker == "sobel":
        sobel_c, sobel_r = (ndimage.sobel(h, axis=a, mode="nearest") / 8 for a in (1, 0))
        return sobel_c, -sobel_r
    dh_dr, dh_dc = np.gradient(h)
    return dh_dc, -dh_dr


def bake(h: np.ndarray, baker: str) -> np.ndarray:
    """OpenGL tangent-space normals ``(H, W, 3)`` of the height ``h`` (texel units)."""
    if baker == "supersample":  # bake at twice the resolution, average the normals
        fine = ndimage.zoom(h, 2, order=3) * 2
        n = _unit(*_gradients(fine, "central"))
        n = n.reshape(h.shape[0], 2, h.shape[1], 2, 3).mean(axis=(1, 3))
        return n / np.linalg.norm(n, axis=-1, keepdims=True)
    return _unit(*_gradients(h, baker))


def _unit(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    n = np.stack([-p, -q, np.ones_like(p)], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _islands(size: int, rng: np.random.Generator) -> list[tuple[int, int, int, int]]:
    """Guillotine-split the square into boxes and shrink each: UV islands with gaps."""
    boxes = [(0, 0, size, size)]
    for _ in range(int(rng.integers(2, 6))):
        boxes.sort(key=lambda b: (b[2] - b[0]) * (b[3] - b[1]))
        r0, c0, r1, c1 = boxes.pop()
        if r1 - r0 > c1 - c0:
            cut = int(r0 + (r1 - r0) * rng.uniform(0.3, 0.7))
            boxes += [(r0, c0, cut, c1), (cut, c0, r1, c1)]
        else:
            cut = int(c0 + (c1 - c0) * rng.uniform(0.3, 0.7))
            boxes += [(r0, c0, r1, cut), (r0, cut, r1, c1)]
    gap = max(size // 64, 2)
    return [(r0 + gap, c0 + gap, r1 - gap, c1 - gap) for r0, c0, r1, c1 in boxes]


def _atlas(size: int, baker: str, rng: np.random.Generator) -> np.ndarray:
    """Islands of different fields, rotated, on a flat background, with edge padding."""
    normals = np.zeros((size, size, 3))
    normals[..., 2] = 1.0
    inside = np.zeros((size, size), dtype=bool)
    pieces = [f for f in FAMILIES if f != "mixed"]
    for r0, c0, r1, c1 in _islands(size, rng):
        hgt, wid = r1 - r0, c1 - c0
        side = int(math.ceil(math.hypot(hgt, wid))) + 4
        field = FAMILIES[str(rng.choice(pieces))](side, rng)
        turn = rng.random()
        if turn < 0.5:
            field = np.rot90(field, int(rng.integers(0, 4)))
        else:
            field = ndimage.rotate(field, rng.uniform(0, 360), reshape=False, order=3)
        top, left = (side - hgt) // 2, (side - wid) // 2
        piece = bake(field, baker)[top : top + hgt, left : left + wid]
        shape = np.ones((hgt, wid), dtype=bool)
        if rng.random() < 0.5:  # an elliptical island: curved seams
            rr, cc = np.mgrid[0:hgt, 0:wid] + 0.5
            shape = ((rr / hgt - 0.5) ** 2 + (cc / wid - 0.5) ** 2) < 0.25
        region = normals[r0:r1, c0:c1]
        region[shape] = piece[shape]
        inside[r0:r1, c0:c1] |= shape
    pad = int(rng.choice([0, 2, 4, 8]))
    if pad:  # bakers pad islands by repeating their edge texels outwards
        dist, (ri, ci) = ndimage.distance_transform_edt(~inside, return_indices=True)
        grown = dist <= pad
        normals[grown] = normals[ri[grown], ci[grown]]
    return normals


def normals_for(spec: MapSpec) -> np.ndarray:
    """The OpenGL normals of ``spec`` (independent of its encoding and convention)."""
    rng = np.random.default_rng([spec.seed, zlib.crc32(repr(spec.geometry).encode())])
    if spec.layout == "atlas":
        return _atlas(spec.size, spec.baker, rng)
    return bake(FAMILIES[spec.family](spec.size, rng), spec.baker)


# ---------------------------------------------------------------------------
# files


def write_map(normals: np.ndarray, spec: MapSpec, folder: Path) -> Path:
    """Encode ``normals`` as ``spec`` says and write it into ``folder`` with a real encoder."""
    rgb = encode_normal_map(normals.astype(np.float32), convention=spec.convention)
    depth = "uint16" if spec.encoding == "png16" else "uint8"
    top = 65535 if depth == "uint16" else 255
    pixels = np.rint(np.clip(rgb, 0, 1) * top).astype(depth)
    path = folder / spec.name
    out_spec = oiio.ImageSpec(spec.size, spec.size, 3, depth)
    if spec.encoding.startswith("jpg"):
        quality = spec.encoding[3:].split("_")[0]
        out_spec.attribute("Compression", f"jpeg:{quality}")
        chroma = "4:4:4" if spec.encoding.endswith("444") else "4:2:0"
        out_spec.attribute("jpeg:subsampling", chroma)
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), out_spec) or not out.write_image(pixels):
        raise OSError(f"cannot write {path}: {oiio.geterror()}")
    out.close()
    return path


def write_corpus(specs: Iterable[MapSpec], folder: Path) -> Iterator[tuple[MapSpec, Path]]:
    """Write every spec's map into ``folder`` (baking each geometry once)."""
    folder.mkdir(parents=True, exist_ok=True)
    by_geometry: dict[tuple, list[MapSpec]] = {}
    for spec in specs:
        by_geometry.setdefault(spec.geometry, []).append(spec)
    for group in by_geometry.values():
        normals = normals_for(group[0])
        for spec in group:
            yield spec, write_map(normals, spec, folder)


def read_map(path: Path) -> np.ndarray:
    """The file's RGB as the loader sees it: float32 ``(H, W, 3)`` in [0, 1]."""
    pixels, _ = read_image(path)
    return pixels[..., :3]


def _specs(
    sizes: Iterable[int], seeds: Iterable[int], encodings_per_map: int, layouts=LAYOUTS
) -> list[MapSpec]:
    specs = []
    for size, seed, family, layout in itertools.product(sizes, seeds, FAMILIES, layouts):
        if layout == "atlas" and family != "mixed":
            continue  # an atlas mixes families itself; one per (size, seed)
        pick = np.random.default_rng([size, seed, zlib.crc32(family.encode())])
        baker = str(pick.choice(BAKERS))
        for encoding in pick.choice(ENCODINGS, encodings_per_map, replace=False):
            for convention in ("opengl", "directx"):
                fam = "atlas" if layout == "atlas" else family
                specs.append(MapSpec(fam, layout, size, baker, str(encoding), convention, seed))
    return specs


def ci_specs() -> list[MapSpec]:
    """A few 256-512 maps of every family, both conventions, JPEG and PNG (~60 maps)."""
    return _specs((256,), (0, 1), 1) + _specs((512,), (2,), 1)


def full_specs(seed_offset: int = 0) -> list[MapSpec]:
    """The calibration corpus: 256 to 4096 texels, several seeds and encodings.

    ``seed_offset`` draws a fresh corpus of the same make-up (a held-out check
    of a threshold chosen on the default one).
    """
    k = seed_offset
    return (
        _specs((256,), range(k + 10, k + 20), 3)
        + _specs((512,), range(k + 20, k + 28), 3)
        + _specs((1024,), range(k + 30, k + 34), 2)
        + _specs((2048,), range(k + 40, k + 42), 2)
        + _specs((4096,), (k + 50,), 1)
    )
