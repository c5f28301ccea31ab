"""Fig. 7(h): anisotropy controlled by scaling edit values -- the lobe's per axis, then the frames.

The shared chessboard set has neither tangents nor an anisotropic lobe, so
they are synthesised (:func:`matshop.figures.synthetic.with_anisotropy`): a
constant tangent field at ``TANGENT_DEG`` from the texture's ``u`` axis, in the
normal + tangent frame space, and an Ashikhmin-Shirley lobe ``nu = nv`` with
the median angle of each texel's GGX lobe. Then, in edit space:

1. the lobe's tangent-axis edit value ``nu~`` (a median angle) is scaled by
   ``STRETCH`` and ``nv~`` is left alone: the isotropic highlight stretches
   along the tangent;
2. the frame edit values (log quaternions) are scaled by ``s``: the tangent
   turns from ``TANGENT_DEG`` to ``s * TANGENT_DEG`` and the stretched
   highlight turns with it (the paper's "controlling anisotropic direction by
   scaling frames").

Measurement: the shape of the highlight on the ball (:func:`matshop.render.
measure.highlight_shape`, half-maximum region) in a specular-only render lit
from the camera, where the ball's texture axes are the image axes (tangent
= +x, bitangent = +y). It is taken on the chessboard ball (black albedo,
so the measurement sees the lobe and frames, with the texture's roughness
variation) and on a control ball of constant roughness (the set's median).
"""

from __future__ import annotations

import cv2
import numpy as np

from ..io.material_io import load_material
from ..material import EditMaterial, Material
from ..render import scenes
from ..render.integrator import DirectionalLight
from ..render.materials import constant
from ..render.render import render
from . import drawing
from .common import resized
from .context import FigureContext, FigureResult, display
from .measure import HighlightShape, highlight_shape
from .synthetic import with_anisotropy

TANGENT_DEG = 60.0
STRETCH = 2.5
FRAME_SCALES = (0.0, 0.5, 1.5)
#: from the camera: the highlight sits at the front of the ball, where the
#: ball's tangent / bitangent are the image's +x / +y
LIGHT = DirectionalLight((0.0, 0.0, 1.0), (4.0, 4.0, 4.0))
BALL = 160
MEASURE = 256
CROP = 64
#: texture offset that puts the highlight on the set's plain weathered area:
#: at the default u = 0 it falls on a streaky strip next to the board's
#: edge, whose roughness alone stretches even a GGX highlight 1.8x
U_OFFSET = 0.15
#: smoothing before thresholding: the roughness texture's grain breaks up the region
SMOOTH_PX = 1.5


def ball(size: int) -> scenes.GBuffer:
    """The sphere scene, its texture shifted by ``U_OFFSET`` (the highlight's spot)."""
    gbuf = scenes.sphere(size)
    gbuf.uv = gbuf.uv + np.array([U_OFFSET, 0.0])
    return gbuf


def variants(material: Material) -> list[tuple[str, Material, float | None]]:
    """``(label, material, expected highlight axis in degrees or None)`` for each ball."""
    aniso = with_anisotropy(material, tangent_deg=TANGENT_DEG)
    edit = aniso.to_edit()
    sl = edit.schema.edit_slices
    stretched = edit.data.copy()
    stretched[..., sl["anisotropic_exponents"].start] *= np.float32(STRETCH)
    out: list[tuple[str, Material, float | None]] = [
        ("GGX from the set", material, None),
        ("AS, nu = nv", aniso, None),
        (f"nu~ x{STRETCH:g}", _physical(edit, stretched), TANGENT_DEG),
    ]
    for s in FRAME_SCALES:
        data = stretched.copy()
        data[..., sl["normal"]] *= np.float32(s)
        out.append((f"nu~ x{STRETCH:g}, frames x{s:g}", _physical(edit, data), s * TANGENT_DEG))
    return out


def _physical(edit: EditMaterial, data: np.ndarray) -> Material:
    return EditMaterial(edit.name, edit.schema, data, edit.sources).to_physical()


def _specular_only(material: Material) -> Material:
    """Black albedo, no metal: ``ks = 0.04`` everywhere, the lobe and frames untouched."""
    maps = dict(material.maps)
    for name in ("base_color", "metallic"):
        if name in maps:
            maps[name] = np.zeros_like(maps[name])
    return Material(material.name, material.schema, maps, material.sources)


def measure(material: Material, size: int = MEASURE) -> tuple[HighlightShape, np.ndarray]:
    """The highlight's shape on a specular-only ball lit from the camera, and its energy image."""
    image = render(
        _specular_only(material),
        scene=ball(size),
        environment_scale=0.0,
        lights=(LIGHT,),
        background=(0.0, 0.0, 0.0),
    )
    energy = image.radiance.sum(axis=2)
    return highlight_shape(energy, smooth_px=SMOOTH_PX), energy


def _crop_tile(energy: np.ndarray, shape: HighlightShape) -> np.ndarray:
    """The centre of the measured render, scaled up, with the half-maximum axes drawn."""
    h, w = energy.shape
    r0, c0 = (h - CROP) // 2, (w - CROP) // 2
    crop = energy[r0 : r0 + CROP, c0 : c0 + CROP] / max(float(energy.max()), 1e-12)
    grey = (255 * np.sqrt(np.clip(crop, 0.0, 1.0))).astype(np.uint8)
    tile = cv2.resize(grey, (BALL, BALL), interpolation=cv2.INTER_NEAREST)
    tile = np.repeat(tile[..., None], 3, axis=2)
    k = BALL / CROP
    centre = (BALL // 2, BALL // 2)
    for length, angle, color in (
        (shape.major_px, shape.angle_deg, (230, 60, 40)),
        (shape.minor_px, shape.angle_deg + 90.0, (60, 140, 230)),
    ):
        a = np.radians(angle)
        dx, dy = 2.0 * length * k * np.cos(a), -2.0 * length * k * np.sin(a)
        p0 = (int(centre[0] - dx), int(centre[1] - dy))
        p1 = (int(centre[0] + dx), int(centre[1] + dy))
        cv2.line(tile, p0, p1, color, 1, cv2.LINE_AA)
    return tile


def fig7h(ctx: FigureContext) -> FigureResult:
    material, _ = load_material(ctx.data)
    material = resized(material, 512)
    r_median = float(np.median(material.maps["roughness"])) if "roughness" in material.maps else 0.5
    control = constant(64, base_color=(0.2, 0.2, 0.2), roughness=r_median, normal=(0, 0, 1))
    values: dict[str, float] = {}
    top, bottom, lines = [], [], []
    for k, ((label, mat, expected), (_, ctl, _)) in enumerate(
        zip(variants(material), variants(control), strict=True)
    ):
        shown = render(
            mat, scene=ball(BALL), environment=ctx.environment, lights=(LIGHT,), samples=32
        )
        top.append(drawing.caption(display(shown), [label], height=13, scale=0.33))
        shape, energy = measure(mat)
        shape_c, _ = measure(ctl)
        values[f"aspect_{k}"], values[f"angle_{k}"] = shape.aspect, shape.angle_deg
        values[f"control_aspect_{k}"] = shape_c.aspect
        values[f"control_angle_{k}"] = shape_c.angle_deg
        want = "" if expected is None else f" (want {expected:.0f})"
        bottom.append(
            drawing.caption(
                _crop_tile(energy, shape),
                [
                    f"aspect {shape.aspect:.2f}, axis {shape.angle_deg:.0f} deg",
                    f"control {shape_c.aspect:.2f}, {shape_c.angle_deg:.0f} deg{want}",
                ],
                height=13,
                scale=0.33,
            )
        )
        lines.append(
            f"{label}: aspect {shape.aspect:.2f} axis {shape.angle_deg:.1f} "
            f"(control {shape_c.aspect:.2f} / {shape_c.angle_deg:.1f})"
        )
    image = drawing.caption(
        drawing.grid([top, bottom], gap=3),
        [
            f"Fig. 7(h): '{material.name}' given a synthetic tangent field ({TANGENT_DEG:g} deg"
            " from u) and an Ashikhmin-Shirley lobe nu = nv of its roughness's median angle.",
            "Top: studio + light from the camera. Bottom: centre of a specular-only render,"
            " half-maximum axes (red major, blue minor);",
            "aspect = major / minor extent, axis counter-clockwise from the tangent u;"
            f" control: constant roughness {r_median:.2f}.",
        ],
    )
    path = ctx.save("fig7h_anisotropy", image)
    return FigureResult("fig7h", path, "; ".join(lines), values)
