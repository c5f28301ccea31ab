"""Fig. 3: interpolation strips in edit space and in physical space, with measured linearity.

Each row interpolates between the same two materials in ``K`` equal steps,
once linearly in the parameter's editing space (``from_edit((1-t) e0 + t e1)``)
and once linearly in the physical value files hold. Its measurement is an
appearance quantity read from renders, chosen *independent of the editing
coordinates* (an energy or a median lobe angle would be the very quantity the
default coordinates are built from, so their R^2 could not fail):

- colors (kd, ks): the ball's perceived lightness, CIE L* of its mean
  reflected luminance (studio light);
- lobes (Phong n, Beckmann m, GGX r, sampled d, anisotropic nu): the
  highlight's half-maximum width -- the largest angle between a pixel's normal
  and the light's half vector among the pixels at least half as bright as the
  brightest (its 98th percentile), from a specular-only render under one
  directional light: set by the lobe's shape near its peak, not by its CDF.

``R^2`` of the linear fit says how evenly the steps change appearance; the
paper's claim is that edit-space steps are even (R^2 near 1) and physical
steps are not.
"""

from __future__ import annotations

import numpy as np

from ..render import scenes
from ..render.integrator import DirectionalLight
from ..render.materials import constant
from ..render.render import render
from ..spaces import get_space
from ..spaces.sampled import d_from_ggx
from . import drawing
from .context import FigureContext, FigureResult, display

STEPS = 7
BALL = 84
#: the light of the highlight measurement: up-left in front; view along +z
LIGHT = DirectionalLight((-0.5, 0.5, 1.0), (4.0, 4.0, 4.0))

#: (row label, parameter, space, physical endpoints, fixed parameters, measure)
ROWS = [
    (
        "kd (diffuse)",
        "diffuse",
        "srgb",
        (0.08, 0.92),
        {"specular": 0.2, "roughness": 0.5},
        "energy",
    ),
    (
        "ks (specular)",
        "specular",
        "srgb",
        (0.08, 0.92),
        {"diffuse": 0.03, "roughness": 0.35},
        "energy",
    ),
    ("Phong n", "phong_exponent", "phong", (8.0, 3000.0), {"base_color": 0.1}, "width"),
    ("Beckmann m", "beckmann_roughness", "beckmann", (0.04, 0.5), {"base_color": 0.1}, "width"),
    ("GGX r", "roughness", "ggx", (0.15, 0.85), {"base_color": 0.1}, "width"),
    ("sampled d (GGX)", "distribution", "sampled", (0.02, 0.45), {"base_color": 0.1}, "width"),
    (
        "aniso. nu",
        "anisotropic_exponents",
        "ashikhmin_shirley",
        (10.0, 2000.0),
        {"base_color": 0.1},
        "width",
    ),
]


def _physical(param: str, value: float) -> np.ndarray:
    if param in ("diffuse", "specular"):
        return np.full(3, value)
    if param == "distribution":
        return d_from_ggx(value)  # endpoints given as GGX alpha
    if param == "anisotropic_exponents":
        return np.array([value, 2000.0])  # nu varies, nv fixed
    return np.array([value])


def interpolate(space_name: str, p0: np.ndarray, p1: np.ndarray, t: np.ndarray, *, edit: bool):
    """``(K, C)`` physical values along the strip, linear in edit or in physical space."""
    t = t[:, None]
    if not edit:
        return ((1.0 - t) * p0 + t * p1).astype(np.float32)
    space = get_space(space_name)
    e0 = space.to_edit(p0[None].astype(np.float32))[0]
    e1 = space.to_edit(p1[None].astype(np.float32))[0]
    return space.from_edit(((1.0 - t) * e0 + t * e1).astype(np.float32))


def half_max_width(image, gbuf: scenes.GBuffer) -> float:
    """Half-maximum highlight width (degrees): the 98th percentile of the angle between
    pixel normals and the light's half vector over pixels at least half the peak."""
    energy = image.radiance[gbuf.mask].sum(axis=1)
    h = LIGHT.unit()[None, :] + gbuf.view
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip(np.sum(gbuf.normal * h, axis=1), -1.0, 1.0)))
    bright = energy >= 0.5 * energy.max()
    return float(np.percentile(angle[bright], 98))


def lightness(image, gbuf: scenes.GBuffer) -> float:
    """CIE L* of the ball's mean luminance (white = luminance 1)."""
    y = float(image.radiance[gbuf.mask].mean(axis=0) @ np.array([0.2126, 0.7152, 0.0722]))
    f = np.cbrt(y) if y > (6 / 29) ** 3 else y / (3 * (6 / 29) ** 2) + 4 / 29
    return 116.0 * f - 16.0


def r_squared(t: np.ndarray, y: np.ndarray) -> float:
    """Coefficient of determination of the least-squares line through ``(t, y)``."""
    slope, intercept = np.polyfit(t, y, 1)
    residual = np.sum((y - (slope * t + intercept)) ** 2)
    total = np.sum((y - y.mean()) ** 2)
    return float(1.0 - residual / total) if total > 0 else 1.0


def _strip(ctx, label, param, space, ends, fixed, measure, edit, t):
    p0, p1 = (_physical(param, v) for v in ends)
    values = interpolate(space, p0, p1, t, edit=edit)
    gbuf = scenes.sphere(BALL)
    tiles, metric = [], []
    for value in values:
        srgb_fixed = {
            k: (v, v, v) if k in ("diffuse", "specular", "base_color") else v
            for k, v in fixed.items()
        }
        material = constant(**{param: value}, **srgb_fixed)
        tiles.append(display(render(material, scene=gbuf, environment=ctx.environment, samples=48)))
        if measure == "energy":
            img = render(material, scene=gbuf, environment=ctx.environment, samples=16)
            metric.append(lightness(img, gbuf))
        else:
            spec = constant(**{param: value}, base_color=(0.0, 0.0, 0.0))
            img = render(
                spec, scene=gbuf, environment_scale=0.0, lights=(LIGHT,), background=(0, 0, 0)
            )
            metric.append(half_max_width(img, gbuf))
    return tiles, np.array(metric)


def fig3(ctx: FigureContext) -> FigureResult:
    t = np.linspace(0.0, 1.0, STEPS)
    rows, values, summary = [], {}, []
    for label, param, space, ends, fixed, measure in ROWS:
        quantity = "lightness L*" if measure == "energy" else "half-max width"
        r2 = {}
        for edit in (True, False):
            tiles, metric = _strip(ctx, label, param, space, ends, fixed, measure, edit, t)
            r2[edit] = r_squared(t, metric)
            unit = "" if measure == "energy" else " deg"
            lines = [
                label,
                f"linear in {'edit' if edit else 'physical'}",
                f"{quantity}: R2 = {r2[edit]:.4f}",
                f"{metric[0]:.3g} .. {metric[-1]:.3g}{unit}",
            ]
            rows.append([drawing.side_label(drawing.grid([tiles], gap=0), lines, width=180)])
        key = param.split("_")[0]
        values[f"{key}_edit_r2"], values[f"{key}_physical_r2"] = r2[True], r2[False]
        summary.append(f"{label} {r2[True]:.3f}/{r2[False]:.3f}")
    image = drawing.caption(
        drawing.grid(rows, gap=3),
        [
            "Fig. 3: linear interpolation between the same two materials, 7 steps,"
            " in edit space (upper row)",
            "and in physical space (lower row). R2: linear fit vs the step of an appearance"
            " measure independent",
            "of the coordinates: lightness L* (colors), half-maximum highlight width (lobes).",
        ],
    )
    path = ctx.save("fig3_interpolation_strips", image)
    return FigureResult("fig3", path, "R2 edit/physical: " + "; ".join(summary), values)
