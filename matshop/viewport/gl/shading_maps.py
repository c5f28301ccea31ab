"""Physical maps -> the shading textures the surface shader reads, and their mip levels.

The conversion is the reference renderer's own (:func:`matshop.render.surface.prepare`
on the block's maps, no prefilter): linear ``kd``/``ks`` from the color spaces or
the metallic workflow, the lobe parameter (GGX ``alpha = r^2``, Beckmann ``m``,
Phong ``n``, Ashikhmin-Shirley ``nu, nv``), tangent-space normal and tangent,
``ao``, ``emissive``. It is pointwise, so a tile converts on its own and the
dirty-tile path produces the same values as a full upload.

Packed four channels per texture so a shader lookup is few fetches:

==============  ========================================
``kd_ao``       kd.rgb, ao (1 without an ao map)
``ks_lobe``     ks.rgb, lobe parameter 0
``normal_lobe`` tangent-space normal xyz, lobe parameter 1 (AS ``nv``)
``tangent``     tangent-space tangent xyz, 0 (only with a 6-channel frame)
``emissive``    emissive rgb, 0 (only with an emissive map)
``q0``-``q3``   sampled lobes: ``sin^2 theta`` at 16 quantile levels (below)
==============  ========================================

Sampled (tabulated) lobes travel as a lookup of their edit value, the
inverse CDF, cut down from the sampled space's 128 levels to the 16 levels
``y_j = (j + 1/2) / 16`` -- exactly the ``u1`` of a 16-point Hammersley set,
so the GPU draws the reference's 16 environment samples exactly (the
reference's own interpolation, :func:`matshop.render.sampling.sample_quantiles`,
computes them). The table holds ``x = sin^2 theta`` rather than ``theta``:
the projected-solid-angle measure is ``cos sin dtheta dphi = dx dphi / 2``, so
a CDF piecewise linear in ``x`` has the *finite* piecewise-constant density
``D = (dy / dx) / pi``, which the shader uses for the samples' pdf and, made
linear inside each segment without changing its mass, for the directional
lights' ``D(h)`` (so ``integral D (h.n) dw = 1`` as for the space's bins).
That is the approximation: D is read from 17 segments of the inverse CDF
instead of the reference's 128-bin table (``tests/test_viewport_gl_lobes.py``
measures it). ``set_lobe("ggx")`` shows
a sampled lobe as the GGX lobe with its median angle (``alpha = tan c^-1(1/2)``).

``set_lobe`` overrides convert analytic parameters by the usual equivalences
(Beckmann ``m = alpha``, Phong ``n = 2 / m^2 - 2``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ...material import Material, Schema
from ...render.surface import MIN_ROUGHNESS, prepare

QUANTILE_TEXTURES = ("q0", "q1", "q2", "q3")
TEXTURES = ("kd_ao", "ks_lobe", "normal_lobe", "tangent", "emissive", *QUANTILE_TEXTURES)
FAMILIES = ("ggx", "beckmann", "phong", "ashikhmin_shirley", "sampled")
#: the quantile levels on the GPU: the u1 of a 16-point Hammersley set
QUANTILE_LEVELS = (np.arange(16) + 0.5) / 16


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
    """The shading textures ``(h, w, 4)`` float32 of one block of physical maps."""
    material = Material("block", schema, {name: maps[name] for name in schema.names})
    surface = prepare(material)
    family = surface.family
    lobe = surface.lobe
    target = lobe_family(schema, override)
    h, w = surface.kd.shape[:2]
    quantiles = None
    if target == "sampled":
        quantiles = quantile_table(surface.quantiles, surface.levels)
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
    if quantiles is not None:
        for k, name in enumerate(QUANTILE_TEXTURES):
            out[name] = quantiles[..., 4 * k : 4 * k + 4]
    return {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in out.items()}


def quantile_table(quantiles: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """``sin^2 theta`` ``(H, W, 16)`` of tabulated lobes at :data:`QUANTILE_LEVELS`.

    ``quantiles`` ``(H, W, M)`` is the sampled space's edit value at ``levels``;
    read exactly as the reference's sampler reads it (sorted, clamped, linear
    in ``theta`` between levels).
    """
    from ...render.sampling import sample_quantiles

    h, w, m = quantiles.shape
    u2 = np.zeros(QUANTILE_LEVELS.size)
    _, _, hz, _ = sample_quantiles(quantiles.reshape(-1, m), levels, QUANTILE_LEVELS, u2)
    return np.clip(1.0 - hz * hz, 0.0, 1.0).reshape(h, w, -1).astype(np.float32)


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
        names.extend(QUANTILE_TEXTURES)
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
