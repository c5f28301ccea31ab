"""Physical maps -> the shading textures the surface shader reads, and their mip levels.

The conversion is the reference renderer's own (:func:`matshop.render.surface.prepare`
on the block's maps, no prefilter): linear ``kd``/``ks`` from the color spaces or
the metallic workflow, the lobe parameter (GGX ``alpha = r^2``, Beckmann ``m``,
Phong ``n``, Ashikhmin-Shirley ``nu, nv``), tangent-space normal and tangent,
``ao``, ``emissive``. It is pointwise, so a tile converts on its own and the
dirty-tile path produces the same values as a full upload.

Packed four channels per texture so a shader lookup is few fetches:

================  ========================================
``kd_ao``         kd.rgb, ao (1 without an ao map)
``ks_lobe``       ks.rgb, lobe parameter 0
``normal_lobe``   tangent-space normal xyz, lobe parameter 1 (AS ``nv``)
``tangent``       tangent-space tangent xyz, 0 (only with a 6-channel frame)
``emissive``      emissive rgb, 0 (only with an emissive map)
``distribution``  sampled lobes: the table and its inverse-CDF nodes, a 2D
                  array texture of RGBA layers (:mod:`.sampled_lobe` says how)
================  ========================================

``set_lobe("ggx")`` shows a sampled lobe as the GGX lobe with its median angle
(``alpha = tan c^-1(1/2)``).

``set_lobe`` overrides convert analytic parameters by the usual equivalences
(Beckmann ``m = alpha``, Phong ``n = 2 / m^2 - 2``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ...material import Material, Schema
from ...ops.variance import moments_covariance, slope_moments, widen_render_lobe
from ...render.surface import MIN_ROUGHNESS, prepare
from . import sampled_lobe

#: textures of several RGBA layers (GL_TEXTURE_2D_ARRAY)
ARRAY_TEXTURES = ("distribution",)
TEXTURES = ("kd_ao", "ks_lobe", "normal_lobe", "tangent", "emissive", *ARRAY_TEXTURES)
FAMILIES = ("ggx", "beckmann", "phong", "ashikhmin_shirley", "sampled")


def _slope(family: str, lobe: np.ndarray) -> np.ndarray:
    """An rms-slope-like roughness ``(H, W)`` of any family (GGX alpha ~ Beckmann m)."""
    if family in ("ggx", "beckmann"):
        return lobe[..., 0]
    exponent = lobe[..., 0] if family == "phong" else np.sqrt(lobe[..., 0] * lobe[..., 1])
    return np.sqrt(2.0 / (np.maximum(exponent, 0.0) + 2.0))


def convert_lobe(family: str, lobe: np.ndarray, target: str) -> np.ndarray:
    """Lobe parameters ``(H, W, 2)`` of ``target`` approximating ``family``'s ``lobe``."""
    if family == target:
        out = lobe
    else:
        m = np.clip(_slope(family, lobe), MIN_ROUGHNESS, None)
        if target in ("ggx", "beckmann"):
            out = m[..., None]
        else:
            n = 2.0 / (m * m) - 2.0
            out = n[..., None] if target == "phong" else np.stack([n, n], axis=-1)
    out = np.asarray(out, dtype=np.float32)
    if out.shape[-1] == 1:
        out = np.concatenate([out, np.zeros_like(out)], axis=-1)
    return out


def lobe_family(schema: Schema, override: str | None = None) -> str:
    """The D family the shader uses for ``schema`` (the reference's choice unless overridden)."""
    if override is not None:
        if override not in FAMILIES:
            raise ValueError(f"unknown lobe {override!r} (use one of {', '.join(FAMILIES)})")
        if override == "sampled" and "distribution" not in schema:
            raise ValueError("the sampled lobe needs a tabulated distribution")
        return override
    for name, family in (
        ("distribution", "sampled"),
        ("anisotropic_exponents", "ashikhmin_shirley"),
        ("phong_exponent", "phong"),
        ("beckmann_roughness", "beckmann"),
    ):
        if name in schema:
            return family
    return "ggx"


def pack(
    schema: Schema, maps: Mapping[str, np.ndarray], override: str | None = None
) -> dict[str, np.ndarray]:
    """The shading textures ``(h, w, 4 layers)`` float32 of one block of physical maps."""
    material = Material("block", schema, {name: maps[name] for name in schema.names})
    surface = prepare(material)
    family = surface.family
    lobe = surface.lobe
    target = lobe_family(schema, override)
    h, w = surface.kd.shape[:2]
    table = None
    if target == "sampled":
        table = surface.lobe
        lobe = np.zeros((h, w, 2), np.float32)
    else:
        if family == "sampled":
            family, lobe = "ggx", _median_alpha(surface.quantiles, surface.levels)
        lobe = convert_lobe(family, lobe, target)
    ao = surface.ao if surface.ao is not None else np.ones((h, w, 1), np.float32)
    out = {
        "kd_ao": np.concatenate([surface.kd, ao], axis=2),
        "ks_lobe": np.concatenate([surface.ks, lobe[..., :1]], axis=2),
        "normal_lobe": np.concatenate([surface.normal, lobe[..., 1:2]], axis=2),
    }
    zero = np.zeros((h, w, 1), np.float32)
    if surface.tangent is not None:
        out["tangent"] = np.concatenate([surface.tangent, zero], axis=2)
    if surface.emissive is not None:
        out["emissive"] = np.concatenate([surface.emissive, zero], axis=2)
    if table is not None:
        out["distribution"] = sampled_lobe.pack(table, surface.quantiles, surface.levels)
    return {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in out.items()}


def mip_chain(
    packed: Mapping[str, np.ndarray], levels: int, n_bins: int = 0, *, widen: str | None = None
) -> dict[str, list[np.ndarray]]:
    """Each texture of ``packed`` and its ``levels`` 2x2-mean levels (:func:`box_mips`).

    A sampled lobe's (``n_bins`` bins) nodes are its averaged table's
    (:func:`.sampled_lobe.renode`), as the reference's prefilter samples the mixture.
    ``widen``: the lobe family whose parameters each level widens by the slope
    covariance its averaging removed from the level-0 normals (keep variance, specular
    anti-aliasing): analytic lobes by :func:`matshop.ops.variance.widen_render_lobe`,
    a sampled lobe's averaged table by the trace's Gaussian slope convolution
    (:func:`.sampled_lobe.widen`) before its nodes are taken.
    """
    out = {name: box_mips(block, levels) for name, block in packed.items()}
    lost = _lost_covariances(packed["normal_lobe"], len(out["ks_lobe"]) - 1) if widen else []
    if "distribution" in out:
        chain = out["distribution"]
        for level in range(1, len(chain)):
            texels = chain[level]
            if widen == "sampled":
                cov = lost[level]
                texels = sampled_lobe.widen(texels, n_bins, cov[..., 0] + cov[..., 2])
            chain[level] = sampled_lobe.renode(texels, n_bins)
    if widen is not None and widen != "sampled":
        _widen_levels(out, lost, widen)
    return out


def _lost_covariances(normal_lobe: np.ndarray, levels: int) -> list[np.ndarray]:
    """Per level, the slope covariance ``(xx, xy, yy)`` its 2x2 means removed from the
    level-0 normals (level 0: none); the moments are averaged once for all levels."""
    averaged = box_mips(slope_moments(normal_lobe[..., :3]), levels)
    return [moments_covariance(m) for m in averaged]


def _widen_levels(out: dict[str, list[np.ndarray]], lost: list[np.ndarray], family: str) -> None:
    for level in range(1, len(out["ks_lobe"])):
        tangent = out["tangent"][level][..., :3] if "tangent" in out else None
        ks, nl = out["ks_lobe"][level], out["normal_lobe"][level]
        lobe = np.stack([ks[..., 3], nl[..., 3]], axis=-1)
        wide = widen_render_lobe(family, lobe, lost[level], tangent).astype(np.float32)
        out["ks_lobe"][level] = np.concatenate([ks[..., :3], wide[..., :1]], axis=-1)
        out["normal_lobe"][level] = np.concatenate([nl[..., :3], wide[..., 1:]], axis=-1)


def _median_alpha(quantiles: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """GGX ``alpha = tan(theta_median)`` of tabulated lobes (their inverse CDF at y = 1/2)."""
    y = np.asarray(levels, dtype=np.float64)
    k = int(np.clip(np.searchsorted(y, 0.5) - 1, 0, y.size - 2))
    t = float(np.clip((0.5 - y[k]) / (y[k + 1] - y[k]), 0.0, 1.0))
    theta = quantiles[..., k] + t * (quantiles[..., k + 1] - quantiles[..., k])
    return np.clip(np.tan(np.clip(theta, 0.0, 1.5)), MIN_ROUGHNESS, 1.0)[..., None]


def present(schema: Schema, family: str | None = None) -> tuple[str, ...]:
    """Which of :data:`TEXTURES` a material of ``schema`` fills, shown with lobe ``family``."""
    names = ["kd_ao", "ks_lobe", "normal_lobe"]
    if "normal" in schema and schema["normal"].phys_channels >= 6:
        names.append("tangent")
    if "emissive" in schema:
        names.append("emissive")
    if (family or lobe_family(schema)) == "sampled":
        names.append("distribution")
    return tuple(names)


def box_mips(block: np.ndarray, levels: int) -> list[np.ndarray]:
    """``block`` and ``levels`` successive 2x2 means (what glGenerateMipmap computes for
    power-of-two sizes, and cv2 INTER_AREA halving in the reference)."""
    out = [block]
    for _ in range(levels):
        b = out[-1]
        h, w = b.shape[0] // 2, b.shape[1] // 2
        if h < 1 or w < 1:
            break
        b = b[: 2 * h, : 2 * w]
        out.append(0.25 * (b[0::2, 0::2] + b[1::2, 0::2] + b[0::2, 1::2] + b[1::2, 1::2]))
    return out
