"""Fig. 2 again, on synthetic materials built to show what the bundled tile set cannot.

The tile set's normals tilt 13 degrees on average and its roughness is GGX
perceptual roughness, nearly linear in highlight size; on it both halves of
Fig. 2 measure small differences (:func:`matshop.figures.edits.fig2`).
Here the same two edits run on synthetic data (:mod:`matshop.figures.synthetic`):

(a) Gaussian blur of the frames of steep studs (walls at 55 degrees, flat tops
    and ground), as a height field vs in edit space. Measured: the mean tilt
    and the fraction of texels steeper than 30 degrees.
(b) Unsharp masking of all parameters of glossy Phong tiles (n = 400) in
    rough grout (n = 40), in physical space (the exponent as a texture holds
    it, scaled to [0, 1]) vs edit space. The blur is Gaussian (the ``detail``
    op with a range sigma far above any step), so the two differ only in the
    space. Measured: the largest change of the highlight size (median lobe
    angle) on the rough side and on the glossy side of the tile edges, and
    the share of texels whose exponent the op pushes below 0.
"""

from __future__ import annotations

import numpy as np

from ..api import EditableMaterial
from ..material import Material
from ..render.integrator import DirectionalLight
from ..render.materials import from_maps
from ..render.render import render
from ..spaces.frame import height_to_normal
from . import drawing
from .common import detail_on_file_values, height_blur, swatch, with_maps
from .context import FigureContext, FigureResult, display
from .measure import median_lobe_deg, steep_fraction, tilt_deg
from .synthetic import phong_tiles, steep_studs

SIGMAS = (3.0, 10.0)
WALL_DEG = 55.0
STEEP_DEG = 30.0
#: the unsharp mask of (b): a Gaussian blur (range sigma 100x the edit range)
AMOUNT, SIGMA_PX, SIGMA_RANGE = 0.6, 4.0, 100.0
#: the physical exponent map is stored as n / N_SCALE, as an 8/16-bit texture would hold it
N_SCALE = 400.0
#: (b) is shown on a ball: on a flat swatch every texel sees the same half
#: vector, so a highlight's size shows only as a uniform brightness
KEY = DirectionalLight((-0.4, 0.5, 1.0), (3.0, 3.0, 3.0))
BALL = 224


def _ball(ctx: FigureContext, material: Material) -> np.ndarray:
    image = render(material, size=BALL, environment=ctx.environment, lights=(KEY,), samples=24)
    return display(image)


def relief_blur(normal: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """``normal`` blurred by ``sigma`` px in the frame edit space and as a height field."""
    material = from_maps({"base_color": np.full(normal.shape, 0.5, np.float32), "normal": normal})
    edit = EditableMaterial(material.to_edit()).apply("blur", sigma_px=sigma, params="normal")
    return edit.physical().maps["normal"], height_blur(normal, sigma)


def _relief(ctx: FigureContext) -> tuple[list, list[str], dict[str, float]]:
    normal = height_to_normal(steep_studs(wall_deg=WALL_DEG))
    base = from_maps(
        {
            "base_color": np.full(normal.shape, 0.55, np.float32),
            "roughness": np.full(normal.shape[:2], 0.35, np.float32),
            "normal": normal,
        },
        name="synthetic studs",
    )
    t0, f0 = float(tilt_deg(normal).mean()), steep_fraction(normal, STEEP_DEG)
    values = {"studs_tilt_original": t0, "studs_steep_original": f0}
    tiles = {"edit": [swatch(ctx, base)], "height": [swatch(ctx, base)]}
    lines = []
    for sigma in SIGMAS:
        n_edit, n_height = relief_blur(normal, sigma)
        parts = []
        for key, n in (("edit", n_edit), ("height", n_height)):
            tilt, steep = float(tilt_deg(n).mean()), steep_fraction(n, STEEP_DEG)
            values[f"studs_tilt_{key}_s{sigma:g}"] = tilt
            values[f"studs_steep_{key}_s{sigma:g}"] = steep
            tiles[key].append(swatch(ctx, with_maps(base, normal=n)))
            parts.append(f"{key} {tilt:.1f} deg ({100 * steep:.0f}% steep)")
        lines.append(f"sigma {sigma:g}px: mean tilt " + ", ".join(parts))
    rows = [
        [
            drawing.side_label(
                drawing.grid([tiles["edit"]], gap=2),
                [
                    "(a) synthetic studs,",
                    f"{WALL_DEG:g} deg walls: blur",
                    "in edit space",
                    "sigma 0, 3, 10 px",
                ],
            )
        ],
        [
            drawing.side_label(
                drawing.grid([tiles["height"]], gap=2),
                ["(a) synthetic studs:", "blur as a", "height field", "sigma 0, 3, 10 px"],
            )
        ],
    ]
    head = (
        f"(a) studs: mean tilt {t0:.1f} deg, "
        f"{100 * f0:.0f}% of texels steeper than {STEEP_DEG:g} deg"
    )
    return rows, [head, *lines], values


def physical_unsharp(material: Material) -> tuple[Material, float]:
    """The unsharp mask on the file values (exponent as ``n / N_SCALE``); share of ``n < 0``."""
    maps = detail_on_file_values(
        material,
        amount=AMOUNT,
        sigma_px=SIGMA_PX,
        sigma_range=SIGMA_RANGE,
        scale={"phong_exponent": N_SCALE},
    )
    negative = float(np.mean(maps["phong_exponent"] < 0.0))
    maps = {n: np.clip(v, 0.0, None if n == "phong_exponent" else 1.0) for n, v in maps.items()}
    return Material(material.name, material.schema, maps, material.sources), negative


def _profile_plot(tiles: np.ndarray, angles: dict[str, np.ndarray]) -> np.ndarray:
    # the middle of the first band of tiled rows: it crosses tiles and vertical joints only
    tiled = tiles.any(axis=1)
    first = int(np.argmax(tiled))
    row = (2 * first + int(np.argmin(tiled[first:]))) // 2
    x = np.arange(96, dtype=float)
    series = [(x, a[row, :96], label) for label, a in angles.items()]
    return drawing.line_plot(
        series,
        size=(300, 224),
        ylim=(0.0, 60.0),
        title="median lobe angle along a row (deg)",
        xlabel="texel",
    )


def _unsharp(ctx: FigureContext) -> tuple[list, list[str], dict[str, float]]:
    material, tiles = phong_tiles()
    edit = EditableMaterial(material.to_edit()).apply(
        "detail", amount=AMOUNT, sigma_px=SIGMA_PX, sigma_range=SIGMA_RANGE
    )
    raw = edit.edit.data[..., edit.edit.schema.edit_slices["phong_exponent"]]
    edit_result = edit.physical()
    phys_result, negative = physical_unsharp(material)
    angle = {
        "original": median_lobe_deg(material.maps["phong_exponent"][..., 0]),
        "edit space": median_lobe_deg(edit_result.maps["phong_exponent"][..., 0]),
        "physical": median_lobe_deg(phys_result.maps["phong_exponent"][..., 0]),
    }
    a0 = angle["original"]
    values = {
        "tiles_negative_physical": negative,
        "tiles_below_range_edit": float(np.mean(raw < 0)),
    }
    lines = [
        f"(b) Phong tiles n = 400 ({a0[tiles].mean():.1f} deg) in grout n = 40"
        f" ({a0[~tiles].mean():.1f} deg); unsharp amount {AMOUNT:g}, Gaussian sigma {SIGMA_PX:g} px"
    ]
    for key, label in (("edit space", "edit"), ("physical", "physical")):
        rough_up = float((angle[key] - a0)[~tiles].max())
        gloss_down = float((a0 - angle[key])[tiles].max())
        values[f"tiles_rough_side_{label}"], values[f"tiles_glossy_side_{label}"] = (
            rough_up,
            gloss_down,
        )
        lines.append(
            f"   {label}: highlight size at the edges, rough side +{rough_up:.1f} deg,"
            f" glossy side -{gloss_down:.1f} deg"
        )
    lines[-1] += f"; {100 * negative:.0f}% of texels pushed to n < 0"
    row = [
        _ball(ctx, material),
        _ball(ctx, edit_result),
        _ball(ctx, phys_result),
        _profile_plot(tiles, angle),
    ]
    rows = [
        [
            drawing.side_label(
                drawing.grid([row], gap=2),
                [
                    "(b) synthetic Phong",
                    "tiles, unsharp mask:",
                    "original, edit,",
                    "physical space",
                ],
            )
        ]
    ]
    return rows, lines, values


def fig2_synthetic(ctx: FigureContext) -> FigureResult:
    rows_a, lines_a, values = _relief(ctx)
    rows_b, lines_b, values_b = _unsharp(ctx)
    image = drawing.caption(
        drawing.grid(rows_a + rows_b, gap=3),
        ["Fig. 2 on synthetic materials (not from any texture set)", *lines_a, *lines_b],
    )
    text = "; ".join(lines_a + lines_b)
    path = ctx.save("fig2b_synthetic_relief_and_phong", image)
    return FigureResult("fig2s", path, text, values | values_b)
