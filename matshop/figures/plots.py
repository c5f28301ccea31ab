"""Figs. 4, 5, 6 as plots: lobe and profile scaling/interpolation, analytic fits.

- Fig. 5: the exact scaled CDF ``c(theta / s)`` against the family's CDF at the
  parameter the editing space predicts, for Phong, Beckmann (the paper's
  panels) and GGX, each in the paper's coordinate and the median-angle one; measurement: the worst
  CDF error (:func:`matshop.spaces.fit.scaling_fit`, all lobes and the lobes
  that fit the hemisphere).
- Fig. 4: sampled GGX lobes scaled by ``s`` and interpolated in the sampled
  editing space; measurement: the median lobe angle follows ``s`` and ``t``
  linearly, and ``x + x == 2 x``.
- Fig. 6: SubEdit profiles scaled and interpolated; measurement: albedo is
  unchanged and the mean scattering radius follows ``s``.
"""

from __future__ import annotations

import numpy as np

from ..spaces import get_space
from ..spaces.fit import FAMILIES, scaling_fit
from ..spaces.sampled import d_from_ggx, lobe_width, theta_centres
from ..spaces.subsurface import mean_radius, profile_albedo, profile_burley, radius_centres
from . import drawing
from .context import FigureContext, FigureResult

SCALES = (0.5, 1.5, 3.0)


def _fit_panel(space_name: str, family: str, param: float) -> tuple[np.ndarray, float, float]:
    fam = FAMILIES[family]
    space = get_space(space_name)
    fit = scaling_fit(space)
    theta = np.linspace(0.0, 0.5 * np.pi, 200)
    series, dashed = [], []
    phys = np.full((1, space.phys_channels), fam.to_phys(np.array(param)), np.float32)
    edit = space.to_edit(phys)
    for s in SCALES:
        norm = fam.cdf(0.5 * np.pi / s, param) if s > 1 else 1.0
        exact = np.minimum(fam.cdf(np.minimum(theta / s, 0.5 * np.pi), param) / norm, 1.0)
        predicted = float(
            fam.from_phys(space.from_edit(edit * np.float32(s)).astype(np.float64))[0, 0]
        )
        series += [
            (np.degrees(theta), exact, f"s={s:g} exact"),
            (np.degrees(theta), fam.cdf(theta, predicted), ""),
        ]
        dashed += [False, True]
    title = f"{space_name}: {fam.parameter}={param:g}"
    img = drawing.line_plot(
        series, size=(330, 230), ylim=(0, 1), title=title, xlabel="theta (deg)", dashed=dashed
    )
    worst, fits = fit.worst_all, fit.worst_fits
    img = drawing.caption(
        img,
        [
            f"worst |CDF err| all {worst.error:.3f} "
            f"({fam.parameter}={worst.param:.3g}, s={worst.scale:.3g})",
            f"lobes that fit the hemisphere {fits.error:.3f}",
        ],
        height=14,
        scale=0.35,
    )
    return img, worst.error, fits.error


def fig5(ctx: FigureContext) -> FigureResult:
    panels, values = [], {}
    for space_name, family, param in (
        ("phong_paper", "phong", 20.0),
        ("phong", "phong", 20.0),
        ("beckmann_identity", "beckmann", 0.2),
        ("beckmann_median", "beckmann", 0.2),
        ("ggx_alpha", "ggx", 0.2),
        ("ggx", "ggx", 0.2),
    ):
        img, worst, fits = _fit_panel(space_name, family, param)
        panels.append(img)
        values[f"{space_name}_worst"], values[f"{space_name}_fits"] = worst, fits
    image = drawing.caption(
        drawing.grid([panels[:2], panels[2:4], panels[4:]], gap=6),
        [
            "Fig. 5: scaling the edit value by s vs scaling the lobe's angles by s",
            "(solid: exact c(theta/s), dashed: the family's CDF at the predicted parameter).",
            "Phong, Beckmann (the paper's two analytic lobes), GGX; paper coordinate left,",
            "median-angle coordinate right (the default for Phong and GGX; Beckmann keeps m).",
        ],
    )
    path = ctx.save("fig5_analytic_fits", image)
    text = "; ".join(f"{k} {v:.3f}" for k, v in values.items())
    return FigureResult(
        "fig5", path, "worst CDF error (all lobes / lobes that fit): " + text, values
    )


def _density_theta(d: np.ndarray) -> np.ndarray:
    th = theta_centres(d.shape[-1])
    return 2.0 * np.pi * d * np.cos(th) * np.sin(th)


def fig4(ctx: FigureContext) -> FigureResult:
    space = get_space("sampled")
    deg = np.degrees(theta_centres())
    original = d_from_ggx(0.15)
    e = space.to_edit(original[None])[0]
    scaled = {s: space.from_edit((s * e)[None])[0] for s in (0.75, 1.5)}
    doubled = space.from_edit((e + e)[None])[0]
    twice = space.from_edit((2.0 * e)[None])[0]
    base = lobe_width(original)
    ratios = {s: float(lobe_width(d) / base) for s, d in scaled.items()}
    left = drawing.line_plot(
        [(deg, _density_theta(original), "original GGX 0.15")]
        + [(deg, _density_theta(d), f"scaled s={s:g}") for s, d in scaled.items()],
        size=(340, 240),
        xlim=(0, 60),
        ylim=(0, 6),
        title="scaling (sampled edit space)",
        xlabel="theta (deg)",
    )
    d1, d2 = d_from_ggx(0.05), d_from_ggx(0.4)
    e1, e2 = space.to_edit(d1[None])[0], space.to_edit(d2[None])[0]
    ts = (0.25, 0.5, 0.75)
    mixed = {t: space.from_edit(((1 - t) * e1 + t * e2)[None])[0] for t in ts}
    w1, w2 = float(lobe_width(d1)), float(lobe_width(d2))
    deviation = max(abs(float(lobe_width(d)) - ((1 - t) * w1 + t * w2)) for t, d in mixed.items())
    right = drawing.line_plot(
        [(deg, _density_theta(d1), "original 1 (0.05)")]
        + [(deg, _density_theta(d), f"t={t:g}") for t, d in mixed.items()]
        + [(deg, _density_theta(d2), "original 2 (0.4)")],
        size=(340, 240),
        xlim=(0, 60),
        ylim=(0, 13),
        title="interpolation",
        xlabel="theta (deg)",
    )
    plus = float(np.abs(doubled - twice).max() / twice.max())
    values = {
        "ratio_s0.75": ratios[0.75],
        "ratio_s1.5": ratios[1.5],
        "interp_dev_deg": np.degrees(deviation),
        "x_plus_x_rel": plus,
    }
    text = (
        f"median angle x{ratios[0.75]:.3f} for s=0.75, x{ratios[1.5]:.3f} for s=1.5; "
        f"interpolated median angles off linear by <= {np.degrees(deviation):.3f} deg; "
        f"|(x+x) - 2x| / max = {plus:.1e}"
    )
    image = drawing.caption(
        drawing.grid([[left, right]], gap=6),
        [
            "Fig. 4: density over theta, 2 pi d cos sin, of sampled GGX lobes (128 bins)"
            " edited in the",
            "inverse-CDF space. " + text.split("; ", 1)[0],
            text.split("; ", 1)[1],
        ],
    )
    return FigureResult("fig4", ctx.save("fig4_sampled_distributions", image), text, values)


def fig6(ctx: FigureContext) -> FigureResult:
    space = get_space("subsurface")
    r = radius_centres()
    original = profile_burley(0.6, 0.06)
    e = space.to_edit(original[None])[0]
    scaled = {}
    for s in (0.75, 1.5):
        x = e.copy()
        x[1:] *= s  # the radii; the albedo channel stays
        scaled[s] = space.from_edit(x[None])[0]
    a0, m0 = float(profile_albedo(original)), float(mean_radius(original))
    stats = {
        s: (float(profile_albedo(p)) / a0, float(mean_radius(p)) / m0) for s, p in scaled.items()
    }
    left = drawing.line_plot(
        [(r, original * r, "original")]
        + [(r, p * r, f"scaled s={s:g}") for s, p in scaled.items()],
        size=(340, 240),
        xlim=(0, 1),
        ylim=(0, 6),
        title="scaling: p(r) r",
        xlabel="r",
    )
    p1, p2 = profile_burley(0.3, 0.03), profile_burley(0.8, 0.12)
    e1, e2 = space.to_edit(p1[None])[0], space.to_edit(p2[None])[0]
    mixed = {t: space.from_edit(((1 - t) * e1 + t * e2)[None])[0] for t in (0.25, 0.5, 0.75)}
    right = drawing.line_plot(
        [(r, p1 * r, "original 1")]
        + [(r, p * r, f"t={t:g}") for t, p in mixed.items()]
        + [(r, p2 * r, "original 2")],
        size=(340, 240),
        xlim=(0, 1),
        ylim=(0, 4),
        title="interpolation: p(r) r",
        xlabel="r",
    )
    values = {f"albedo_ratio_s{s:g}": a for s, (a, _) in stats.items()}
    values |= {f"radius_ratio_s{s:g}": m for s, (_, m) in stats.items()}
    text = "; ".join(
        f"s={s:g}: albedo x{a:.4f}, mean radius x{m:.3f}" for s, (a, m) in stats.items()
    )
    image = drawing.caption(
        drawing.grid([[left, right]], gap=6),
        ["Fig. 6: SubEdit profiles (Burley, 32 bins) scaled and interpolated in edit space.", text],
    )
    return FigureResult("fig6", ctx.save("fig6_subsurface_profiles", image), text, values)
