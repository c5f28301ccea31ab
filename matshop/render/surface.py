"""A material's physical maps turned into shading inputs, and their texture lookup.

:func:`prepare` converts a :class:`~matshop.material.Material` once into
renderer units per texel (:class:`SurfaceMaps`), prefiltered to the scene's
pixel footprint; :meth:`SurfaceMaps.sample` then reads them bilinearly (with
wrap-around) at any texture coordinates, the way a GPU's linear filter reads
a mip level.

Which BRDF inputs come from which parameters:

- diffuse ``kd`` / specular ``ks``: ``diffuse`` and ``specular`` when the set has
  them (the paper's model; ``ks`` defaults to 0.04); otherwise the metallic
  workflow ``kd = base (1 - metallic)``, ``ks = 0.04 (1 - metallic) + base metallic``.
  Colors are decoded through their own editing space (whose edit value is
  linear reflectance) *before* filtering, as GPUs decode sRGB textures;
- the lobe: the first present of ``distribution`` (sampled), ``anisotropic_exponents``
  (Ashikhmin-Shirley), ``phong_exponent``, ``beckmann_roughness``, ``roughness``
  (GGX, ``alpha = r^2``); a material with none gets GGX ``alpha = 0.25``;
- ``normal`` (3 or 6 channels: normal, tangent) in tangent space; ``ao`` scales
  the environment's diffuse light; ``emissive`` adds; ``profile`` is kept for
  :mod:`matshop.render.subsurface`.

A sampled lobe is also converted to its edit value (the inverse CDF,
:class:`~matshop.spaces.sampled.SampledDistributionSpace`): the environment
integrator samples it from those quantiles, interpolated between texels the
way the paper interpolates distributions (Read 1999).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from ..material import Material
from ..spaces import get_space

DEFAULT_KS = 0.04
DEFAULT_ALPHA = 0.25
#: GGX alpha / Beckmann m below this are clamped (a perfect mirror has no finite D)
MIN_ROUGHNESS = 1e-3
_COLOR_SPACES = ("srgb", "gamma22")


@dataclass
class Surface:
    """Shading inputs at ``P`` points: linear colors, lobe, tangent-space frame."""

    kd: np.ndarray  # (P, 3)
    ks: np.ndarray  # (P, 3)
    family: str
    lobe: np.ndarray  # (P, k)
    normal: np.ndarray  # (P, 3) tangent space, unit
    tangent: np.ndarray | None = None  # (P, 3) tangent space, unit
    quantiles: np.ndarray | None = None  # (P, M) sampled lobes' inverse CDF
    ao: np.ndarray | None = None  # (P,)
    emissive: np.ndarray | None = None  # (P, 3)


@dataclass
class SurfaceMaps:
    """Per-texel shading inputs, ``(H, W, C)`` float32 each, ready to be sampled."""

    kd: np.ndarray
    ks: np.ndarray
    family: str
    lobe: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray | None = None
    quantiles: np.ndarray | None = None
    levels: np.ndarray | None = None
    ao: np.ndarray | None = None
    emissive: np.ndarray | None = None
    profile: np.ndarray | None = None
    profile_r_max: float = 1.0
    _stack: np.ndarray = field(init=False, repr=False)
    _slices: dict[str, slice] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        # one interleaved texture so that a lookup is four gathers, not four per map
        parts: list[tuple[str, np.ndarray]] = [
            (name, arr)
            for name in ("kd", "ks", "lobe", "normal", "tangent", "quantiles", "ao", "emissive")
            if (arr := getattr(self, name)) is not None
        ]
        self._slices = {}
        start = 0
        for name, arr in parts:
            self._slices[name] = slice(start, start + arr.shape[2])
            start += arr.shape[2]
        self._stack = np.ascontiguousarray(np.concatenate([a for _, a in parts], axis=2))

    @property
    def size(self) -> tuple[int, int]:
        return self.kd.shape[:2]

    def sample(self, uv: np.ndarray) -> Surface:
        """Bilinear, wrapped lookup of every map at ``uv`` ``(P, 2)``."""
        values = bilinear(self._stack, uv)
        get = {name: values[:, s] for name, s in self._slices.items()}
        normal = _unit(get["normal"])
        tangent = _unit(get["tangent"]) if "tangent" in get else None
        ao = get["ao"][:, 0] if "ao" in get else None
        return Surface(
            kd=get["kd"],
            ks=get["ks"],
            family=self.family,
            lobe=get["lobe"],
            normal=normal,
            tangent=tangent,
            quantiles=get.get("quantiles"),
            ao=ao,
            emissive=get.get("emissive"),
        )


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    flat = np.zeros_like(v)
    flat[:, 2] = 1.0
    return np.where(length > 1e-8, v / np.maximum(length, 1e-8), flat)


def bilinear(texture: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Sample ``texture`` ``(H, W, C)`` at ``uv`` ``(P, 2)`` (``v`` up, wrapping): ``(P, C)``."""
    h, w = texture.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = (1.0 - uv[:, 1]) * h - 0.5
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = (x - x0).astype(np.float32)[:, None]
    fy = (y - y0).astype(np.float32)[:, None]
    x0 = x0.astype(np.int64) % w
    y0 = y0.astype(np.int64) % h
    x1 = (x0 + 1) % w
    y1 = (y0 + 1) % h
    flat = texture.reshape(h * w, -1)
    top = flat[y0 * w + x0] * (1.0 - fx) + flat[y0 * w + x1] * fx
    bottom = flat[y1 * w + x0] * (1.0 - fx) + flat[y1 * w + x1] * fx
    return top * (1.0 - fy) + bottom * fy


def _linear_color(material: Material, name: str) -> np.ndarray:
    param = material.schema[name]
    space = param.space if param.space.name in _COLOR_SPACES else get_space("srgb")
    return space.to_edit(material.maps[name]).astype(np.float32)


def prefilter_factor(texture_size: tuple[int, int], uv_per_pixel: float) -> int:
    """Power-of-two reduction so one texel covers about one pixel (a mip level)."""
    texels_per_pixel = uv_per_pixel * max(texture_size)
    if texels_per_pixel <= 1.5:
        return 1
    return int(2 ** np.floor(np.log2(texels_per_pixel)))


def _reduce(array: np.ndarray, factor: int) -> np.ndarray:
    if factor <= 1:
        return array
    h, w, c = array.shape
    size = (max(1, w // factor), max(1, h // factor))
    if c <= 4:
        out = cv2.resize(array, size, interpolation=cv2.INTER_AREA)
        return out.reshape(size[1], size[0], c)
    chunks = [
        cv2.resize(np.ascontiguousarray(array[..., k : k + 4]), size, interpolation=cv2.INTER_AREA)
        for k in range(0, c, 4)
    ]
    return np.concatenate([ch.reshape(size[1], size[0], -1) for ch in chunks], axis=2)


def _lobe(material: Material) -> tuple[str, np.ndarray]:
    maps, h, w = material.maps, *material.size
    if "distribution" in maps:
        return "sampled", maps["distribution"]
    if "anisotropic_exponents" in maps:
        return "ashikhmin_shirley", np.clip(maps["anisotropic_exponents"], 0.0, None)
    if "phong_exponent" in maps:
        return "phong", np.clip(maps["phong_exponent"], 0.0, None)
    if "beckmann_roughness" in maps:
        return "beckmann", np.clip(maps["beckmann_roughness"], MIN_ROUGHNESS, None)
    if "roughness" in maps:
        return "ggx", np.clip(maps["roughness"] ** 2, MIN_ROUGHNESS, 1.0)
    return "ggx", np.full((h, w, 1), DEFAULT_ALPHA, dtype=np.float32)


def sampled_space(n_bins: int):
    """The sampled space of tables with ``n_bins`` bins (the registered one for 128)."""
    space = get_space("sampled")
    if n_bins != space.phys_channels:
        from ..spaces.sampled import SampledDistributionSpace

        space = SampledDistributionSpace(n_bins)
    return space


def lobe_quantiles(table: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tabulated lobes ``(H, W, N)`` -> their inverse CDF ``(H, W, M)`` float32 and its levels."""
    space = sampled_space(table.shape[-1])
    return space.to_edit(table).astype(np.float32), space.y


def prepare(material: Material, *, uv_per_pixel: float = 0.0) -> SurfaceMaps:
    """Shading inputs of ``material``, prefiltered for a view with ``uv_per_pixel``."""
    maps, (h, w) = material.maps, material.size
    factor = prefilter_factor((h, w), uv_per_pixel)
    if "diffuse" in maps:
        kd = _linear_color(material, "diffuse")
        ks = (
            _linear_color(material, "specular")
            if "specular" in maps
            else np.full((h, w, 3), DEFAULT_KS, dtype=np.float32)
        )
    else:
        base = (
            _linear_color(material, "base_color")
            if "base_color" in maps
            else np.full((h, w, 3), 0.5, dtype=np.float32)
        )
        metal = np.clip(maps["metallic"], 0.0, 1.0) if "metallic" in maps else 0.0
        kd = base * (1.0 - metal)
        ks = DEFAULT_KS * (1.0 - metal) + base * metal
        if "specular" in maps:
            ks = _linear_color(material, "specular")
    family, lobe = _lobe(material)
    if "normal" in maps:
        normal = maps["normal"][..., :3]
        tangent = maps["normal"][..., 3:6] if maps["normal"].shape[2] >= 6 else None
    else:
        normal = np.broadcast_to(np.array([0, 0, 1], np.float32), (h, w, 3))
        tangent = None
    reduce = lambda a: None if a is None else _reduce(np.ascontiguousarray(a, np.float32), factor)  # noqa: E731
    lobe = reduce(lobe)
    quantiles = levels = None
    if family == "sampled":
        quantiles, levels = lobe_quantiles(lobe)
    profile_space = material.schema["profile"].space if "profile" in maps else None
    return SurfaceMaps(
        kd=reduce(kd),
        ks=reduce(np.broadcast_to(ks, (h, w, 3))),
        family=family,
        lobe=lobe,
        normal=reduce(normal),
        tangent=reduce(tangent),
        quantiles=quantiles,
        levels=levels,
        ao=reduce(maps.get("ao")),
        emissive=reduce(_linear_color(material, "emissive") if "emissive" in maps else None),
        profile=reduce(maps.get("profile")),
        profile_r_max=float(getattr(profile_space, "r_max", 1.0)),
    )
