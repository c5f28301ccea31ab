"""Figs. 2 and 7: edits of real texture sets, rendered, with what they measurably did.

- Fig. 2(a): Gaussian blur of the frame perturbations of the bundled tile set,
  as a height field vs in the frame editing space. Blurring a height field is
  blurring its slope field ``(-n_x / n_z, -n_y / n_z)`` (differentiation commutes
  with convolution), so that is how it is computed: exact, no integration.
  Measurement: the mean tilt of the normals. A linear blur of rotations
  cannot increase it; a blur of slopes spreads a steep groove wall into a
  wide ramp that stays steep -- the "overly curved" look.
- Fig. 2(b): unsharp masking (the ``detail`` op) of all parameters at once, in
  physical space (the raw file values) vs edit space. Measurement: how much
  of the roughness map the op pushes out of range (clamped at export) and
  the gain of highlight-size contrast (std of the GGX median lobe angle).
- Fig. 7: a gallery of ops on the shared chessboard set (bundled sample if
  absent), each tile captioned with the number it changed.
"""

from __future__ import annotations

import numpy as np

from ..api import EditableMaterial
from ..io.material_io import load_material
from ..material import Material
from . import drawing
from .common import detail_on_file_values, height_blur, resized, swatch, with_maps, wrap_blur
from .context import SAMPLE, FigureContext, FigureResult
from .measure import tilt_deg


def fig2(ctx: FigureContext) -> FigureResult:
    material, _ = load_material(SAMPLE)
    base = material.maps["normal"]
    t0 = float(tilt_deg(base).mean())
    rows, values = [], {"tilt_original": t0}
    tiles_edit, tiles_height, lines = [swatch(ctx, material)], [swatch(ctx, material)], []
    for sigma in (3.0, 10.0):
        edited = EditableMaterial(material.to_edit()).apply("blur", sigma_px=sigma, params="normal")
        n_edit = edited.physical().maps["normal"]
        n_height = height_blur(base, sigma)
        te, th = float(tilt_deg(n_edit).mean()), float(tilt_deg(n_height).mean())
        values[f"tilt_edit_s{sigma:g}"], values[f"tilt_height_s{sigma:g}"] = te, th
        tiles_edit.append(swatch(ctx, with_maps(material, normal=n_edit)))
        tiles_height.append(swatch(ctx, with_maps(material, normal=n_height)))
        lines.append(f"sigma {sigma:g}px: mean tilt edit {te:.1f} deg, height field {th:.1f} deg")
    rows.append(
        [
            drawing.side_label(
                drawing.grid([tiles_edit], gap=2),
                ["(a) blur of frames", "in edit space", "sigma 0, 3, 10 px"],
            )
        ]
    )
    rows.append(
        [
            drawing.side_label(
                drawing.grid([tiles_height], gap=2),
                ["(a) blur of frames", "as a height field", "sigma 0, 3, 10 px"],
            )
        ]
    )

    # (b) unsharp masking of all parameters
    amount, sigma_px, sigma_range = 2.0, 6.0, 0.2
    edit_result = (
        EditableMaterial(material.to_edit())
        .apply("detail", amount=amount, sigma_px=sigma_px, sigma_range=sigma_range)
        .physical()
    )
    phys_result, out_of_range = _physical_detail(material, amount, sigma_px, sigma_range)
    r0 = material.maps["roughness"][..., 0]
    angle = lambda r: np.degrees(np.arctan(np.clip(r, 0.0, 1.0) ** 2))  # noqa: E731
    gain_e = float(angle(edit_result.maps["roughness"][..., 0]).std() / angle(r0).std())
    gain_p = float(angle(phys_result.maps["roughness"][..., 0]).std() / angle(r0).std())
    e_edit = EditableMaterial(material.to_edit()).apply(
        "detail", amount=amount, sigma_px=sigma_px, sigma_range=sigma_range
    )
    ggx = material.schema["roughness"].space
    raw_edit = e_edit.edit["roughness"][..., 0]
    lo, hi = ggx.edit_range.lo, ggx.edit_range.hi
    clip_edit = float(np.mean((raw_edit < lo) | (raw_edit > hi)))
    values |= {
        "gain_edit": gain_e,
        "gain_physical": gain_p,
        "clipped_edit": clip_edit,
        "clipped_physical": out_of_range,
    }
    tiles_b = [swatch(ctx, material), swatch(ctx, edit_result), swatch(ctx, phys_result)]
    rows.append(
        [
            drawing.side_label(
                drawing.grid([tiles_b], gap=2),
                ["(b) unsharp mask,", "all parameters:", "original, edit,", "physical space"],
            )
        ]
    )
    b_line = (
        f"(b) roughness out of range: edit {100 * clip_edit:.1f}%, "
        f"physical {100 * out_of_range:.1f}%; "
        f"highlight-size contrast gain: edit x{gain_e:.2f}, physical x{gain_p:.2f}"
    )
    image = drawing.caption(
        drawing.grid(rows, gap=3),
        [
            f"Fig. 2: bundled tile set. (a) mean normal tilt originally {t0:.1f} deg; " + lines[0],
            "   " + lines[1],
            b_line,
        ],
    )
    text = f"original tilt {t0:.1f} deg; " + "; ".join(lines) + "; " + b_line
    return FigureResult("fig2", ctx.save("fig2_frames_and_unsharp", image), text, values)


def _physical_detail(material: Material, amount: float, sigma_px: float, sigma_range: float):
    """The detail op on the raw file values (each channel a linear [0, 1] scalar)."""
    names = material.schema.names
    maps = detail_on_file_values(
        material, amount=amount, sigma_px=sigma_px, sigma_range=sigma_range
    )
    r = maps["roughness"]
    out_of_range = float(np.mean((r < 0.0) | (r > 1.0)))
    for n in names:
        if n == "normal":
            v = maps[n]
            maps[n] = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-6)
        else:
            maps[n] = np.clip(maps[n], 0.0, 1.0)
    return Material(material.name, material.schema, maps, material.sources), out_of_range


def _luma(material: Material) -> np.ndarray:
    lin = material.schema["base_color"].space.to_edit(material.maps["base_color"])
    return lin @ np.array([0.2126, 0.7152, 0.0722], np.float32)


def _high_freq(x: np.ndarray) -> float:
    return float((x - wrap_blur(x[..., None], 3.0)[..., 0]).std())


def fig7(ctx: FigureContext) -> FigureResult:
    material, _ = load_material(ctx.data)
    material = resized(material, 512)
    h, w = material.size
    edit0 = material.to_edit()
    tiles, values = [], {}

    def run(label: str, measure: str, op: str, **kwargs) -> EditableMaterial:
        m = EditableMaterial(edit0).apply(op, **kwargs)
        phys = m.physical()
        tiles.append(
            drawing.caption(swatch(ctx, phys, 200), [label, measure], height=13, scale=0.33)
        )
        return m

    tilt0 = float(tilt_deg(material.maps["normal"]).mean())
    tiles.append(
        drawing.caption(
            swatch(ctx, material, 200),
            ["original", f"mean tilt {tilt0:.2f} deg"],
            height=13,
            scale=0.33,
        )
    )
    scaled = (
        EditableMaterial(edit0)
        .apply("scale", factor=3.0, params="normal")
        .apply("scale", factor=0.6, params="base_color")
    )
    tilt1 = float(tilt_deg(scaled.physical().maps["normal"]).mean())
    values["scale_tilt"] = tilt1 / tilt0
    tiles.append(
        drawing.caption(
            swatch(ctx, scaled.physical(), 200),
            ["(a) scale frames x3, kd x0.6", f"mean tilt x{tilt1 / tilt0:.2f}"],
            height=13,
            scale=0.33,
        )
    )

    l0 = _luma(material)
    m = EditableMaterial(edit0).apply(
        "curves",
        points=[(0, 0), (0.25, 0.12), (0.75, 0.88), (1, 1)],
        params=["base_color", "roughness", "normal"],
    )
    values["curves_contrast"] = float(_luma(m.physical()).std() / l0.std())
    tiles.append(
        drawing.caption(
            swatch(ctx, m.physical(), 200),
            ["(b) S-curve on kd, r, frames", f"kd contrast x{values['curves_contrast']:.2f}"],
            height=13,
            scale=0.33,
        )
    )

    m = EditableMaterial(edit0).apply(
        "bilateral", sigma_px=6.0, sigma_range=0.15, params=["base_color", "normal"]
    )
    values["bilateral_hf"] = _high_freq(_luma(m.physical())) / _high_freq(l0)
    tiles.append(
        drawing.caption(
            swatch(ctx, m.physical(), 200),
            ["(c) bilateral on kd + frames", f"kd fine detail x{values['bilateral_hf']:.2f}"],
            height=13,
            scale=0.33,
        )
    )

    x = np.clip((np.linspace(0.0, 1.0, w, dtype=np.float32) - 0.3) / 0.4, 0.0, 1.0)
    ramp = np.tile(x * x * (3.0 - 2.0 * x), (h, 1))  # smoothstep over the middle 40%
    metal = edit0.data.copy()
    sl = edit0.schema.edit_slices
    metal[..., sl["base_color"]] = np.array([0.55, 0.4, 0.22], np.float32)  # linear bronze
    metal[..., sl["metallic"]] = 1.0
    m = EditableMaterial(edit0).apply("composite", over=metal, mask=ramp)
    values["composite_left"] = float(np.abs(m.edit.data[:, 0] - edit0.data[:, 0]).max())
    tiles.append(
        drawing.caption(
            swatch(ctx, m.physical(), 200),
            [
                "(d) composite metal, ramp mask",
                f"left column unchanged: {values['composite_left']:.1e}",
            ],
            height=13,
            scale=0.33,
        )
    )

    # the paper's (e)-(f): unsharp masking of the BRDF parameters, then of the frames
    m = EditableMaterial(edit0).apply(
        "detail", amount=3.0, sigma_px=4.0, sigma_range=0.1, params=["base_color", "roughness"]
    )
    values["detail_hf"] = _high_freq(_luma(m.physical())) / _high_freq(l0)
    tiles.append(
        drawing.caption(
            swatch(ctx, m.physical(), 200),
            ["(e) unsharp mask, kd + roughness", f"kd fine detail x{values['detail_hf']:.2f}"],
            height=13,
            scale=0.33,
        )
    )
    tilt_map0 = tilt_deg(material.maps["normal"])
    m = EditableMaterial(edit0).apply(
        "detail", amount=3.0, sigma_px=4.0, sigma_range=0.1, params=["normal"]
    )
    tilt_map = tilt_deg(m.physical().maps["normal"])
    values["detail_tilt_hf"] = _high_freq(tilt_map) / _high_freq(tilt_map0)
    tiles.append(
        drawing.caption(
            swatch(ctx, m.physical(), 200),
            ["(f) unsharp mask, frames", f"tilt fine detail x{values['detail_tilt_hf']:.2f}"],
            height=13,
            scale=0.33,
        )
    )

    s = w // 8
    region = np.array([[5 * s, s], [7 * s, s], [7 * s, 3 * s], [5 * s, 3 * s]], dtype=np.float64)
    m = EditableMaterial(edit0).apply("clone", region=region, offset=(-4 * s, 4 * s))
    values["clone_changed"] = float(np.mean(np.any(m.edit.data != edit0.data, axis=2)))
    tiles.append(
        drawing.caption(
            swatch(ctx, m.physical(), 200),
            [
                "(g) seamless clone (checker",
                f"square), {100 * values['clone_changed']:.1f}% of texels",
            ],
            height=13,
            scale=0.33,
        )
    )

    image = drawing.caption(
        drawing.grid([tiles[:4], tiles[4:]], gap=3),  # original, (a)-(c) | (d)-(g)
        [
            f"Fig. 7: ops in edit space on '{material.name}' ({w}x{h}), "
            "rendered as swatches (studio + key light)."
        ],
    )
    text = "; ".join(f"{k} {v:.3g}" for k, v in values.items())
    return FigureResult("fig7", ctx.save("fig7_gallery", image), text, values)
