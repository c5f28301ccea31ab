"""Fig. 8: SubEdit profiles scaled in edit space, under diffuse and under line light.

A swatch whose profile alternates between two Burley profiles (a checker of
mean free paths, one albedo) is edited the paper's way: the profile's radii
(its inverse-CDF edit channels) are scaled by ``s``, its albedo channel left
alone. Each result is shown twice:

- under diffuse light (a uniform environment), rendered by the reference
  renderer's swatch scene: it looks the same for every ``s``, because the
  albedo is unchanged (measured: the mean radiance relative to ``s = 1``);
- under a sharp line light (irradiance on one texel column, none elsewhere),
  carried by the renderer's BSSRDF transport (:func:`.subsurface.transport`):
  light bleeds further from the line as ``s`` grows (measured: the mean
  distance of the reflected light from the line, relative to ``s = 1``, and
  its total, which the albedo fixes).
"""

from __future__ import annotations

import numpy as np

from ..render import environment
from ..render.materials import from_maps
from ..render.render import RenderedImage, render
from ..render.subsurface import transport
from ..spaces import get_space
from ..spaces.subsurface import profile_burley
from . import drawing
from .context import FigureContext, FigureResult, display

SIZE = 96
SCALES = (0.5, 1.0, 2.0)
ALBEDO = 0.8
#: Burley scale ``d`` of the two checker profiles, in units of r_max
MEAN_FREE_PATHS = (0.03, 0.08)
#: the renderer's default: 16 texels per r_max
TEXEL = 1.0 / 16.0
TINT = (0.9, 0.55, 0.45)


def _profiles() -> np.ndarray:
    rows, cols = np.mgrid[0:SIZE, 0:SIZE]
    checker = ((rows // 24 + cols // 24) % 2).astype(bool)
    thin, thick = (profile_burley(ALBEDO, d) for d in MEAN_FREE_PATHS)
    return np.where(checker[..., None], thick, thin).astype(np.float32)


def scale_radii(profile: np.ndarray, s: float) -> np.ndarray:
    """The profile with its radii scaled by ``s`` in edit space (albedo channel untouched)."""
    space = get_space("subsurface")
    edit = space.to_edit(profile)
    edit[..., space.profile_channels] *= np.float32(s)
    return space.from_edit(edit)


def line_light(profile: np.ndarray) -> np.ndarray:
    """Radiance ``(H, W, 3)`` under unit irradiance on the middle texel column."""
    irradiance = np.zeros((*profile.shape[:2], 3))
    irradiance[:, SIZE // 2] = 1.0
    return transport(profile, irradiance, r_max=1.0, texel_size=TEXEL) / np.pi


def _big(tile: np.ndarray) -> np.ndarray:
    return np.repeat(np.repeat(tile, 2, axis=0), 2, axis=1)


def fig8(ctx: FigureContext) -> FigureResult:
    base = _profiles()
    tint = np.broadcast_to(np.asarray(TINT, np.float32), (SIZE, SIZE, 3))
    distance = np.abs(np.arange(SIZE) - SIZE // 2) * TEXEL
    diffuse_tiles, line_tiles, series, values = [], [], [], {}
    stats = {}
    for s in SCALES:
        profile = scale_radii(base, s)
        material = from_maps({"base_color": tint.copy(), "profile": profile})
        image = render(
            material,
            scene="swatch",
            size=SIZE,
            environment=environment.uniform(1.0),
            specular=False,
        )
        line = line_light(profile)
        across = line[..., 0].mean(axis=0)
        stats[s] = (
            float(image.radiance.mean()),
            float(np.sum(across * distance) / np.sum(across)),
            float(line[..., 0].sum()),
        )
        diffuse_tiles.append(
            drawing.caption(_big(display(image)), [f"s = {s:g}, diffuse light"], scale=0.4)
        )
        line_image = RenderedImage(line.astype(np.float32), np.ones((SIZE, SIZE), np.float32))
        line_tiles.append(
            drawing.caption(
                _big(display(line_image, exposure=2.0)), [f"s = {s:g}, line light"], scale=0.4
            )
        )
        series.append((np.arange(SIZE) - SIZE // 2, across, f"s={s:g}"))
    ref = stats[1.0]
    for s, (mean, spread, total) in stats.items():
        values[f"diffuse_ratio_s{s:g}"] = mean / ref[0]
        values[f"line_spread_ratio_s{s:g}"] = spread / ref[1]
        values[f"line_total_ratio_s{s:g}"] = total / ref[2]
    plot = drawing.line_plot(
        series,
        size=(6 * SIZE + 4, 220),
        xlim=(-24, 24),
        title="line light: radiance across the line",
        xlabel="texels from the line",
    )
    lines = [
        "Fig. 8: SubEdit profile radii scaled by s = "
        + ", ".join(f"{s:g}" for s in SCALES)
        + " in edit space (albedo channel untouched);",
        "checker of two Burley profiles (d = 0.03, 0.08 r_max), albedo 0.8.",
        "Diffuse light: mean radiance x"
        + " / x".join(f"{values[f'diffuse_ratio_s{s:g}']:.3f}" for s in SCALES)
        + " (albedo kept).",
        "Line light: mean distance of the light from the line x"
        + " / x".join(f"{values[f'line_spread_ratio_s{s:g}']:.2f}" for s in SCALES)
        + ", total x"
        + " / x".join(f"{values[f'line_total_ratio_s{s:g}']:.3f}" for s in SCALES)
        + ".",
    ]
    image = drawing.caption(
        drawing.grid([diffuse_tiles, line_tiles, [plot]], gap=2), lines, scale=0.38
    )
    text = "; ".join(f"{k} {v:.3f}" for k, v in values.items())
    return FigureResult("fig8", ctx.save("fig8_subsurface_scaling", image), text, values)
