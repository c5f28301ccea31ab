"""Fig. 1: edit sequences (burn, age, clean, clone a decoration), in edit vs physical space.

The paper's Fig. 1 builds complex looks from chains of simple operations in
editing space. Here each sequence is a list of ops (the registry's own, with
the same parameters) run twice on the data set (reduced to 384^2):

- in **edit space** (:class:`matshop.api.EditableMaterial`), as matshop does;
- in **physical space**: on the values the files hold, every channel a plain
  linear number (colors as sRGB values, perceptual roughness, normal xyz),
  renormalised / clipped once at the end, as an image editor would.

Sequences (masks are smooth blobs, so both rows edit the same texels):

1. **burn**: kd x0.25, roughness x1.6, frames x2.5 inside a blob;
2. **age**: bilateral on kd and frames, a flattening curve on kd, roughness x1.4;
3. **clean** (of the aged result): bilateral on everything, roughness x0.7;
4. **clone**: a seamless (mean-value) clone of a piece of the board elsewhere.

Measured on the physical results, against what each op asked for: the linear
albedo and the mean tilt inside the burn blob (asked x0.25 and x2.5), the
GGX highlight size (median lobe angle ``atan(r^2)``) after ageing and after
cleaning (asked x1.4 and x0.7 of the lobe), and how far the two clones
differ (normals in degrees, linear albedo).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..api import EditableMaterial
from ..io.material_io import load_material
from ..material import Material, Schema
from ..ops import get_op
from . import drawing
from .common import resized, swatch
from .context import FigureContext, FigureResult
from .measure import tilt_deg

SIZE = 384
TILE = 150

Step = tuple[str, dict[str, Any]]


def _blob(size: int, cx: float, cy: float, radius: float) -> np.ndarray:
    rows, cols = np.mgrid[0:size, 0:size].astype(np.float32)
    d = np.hypot(cols - cx * size, rows - cy * size) / (radius * size)
    return np.clip(1.5 - 1.5 * d, 0.0, 1.0) ** 2  # smooth, full inside 1/3 of the radius


def sequences(size: int) -> dict[str, list[Step]]:
    """The four sequences as (op, parameters) steps; masks are arrays."""
    burn = _blob(size, 0.3, 0.55, 0.28)
    s = size // 8
    region = np.array([[5 * s, s], [7 * s, s], [7 * s, 3 * s], [5 * s, 3 * s]], np.float64)
    return {
        "burn": [
            ("scale", {"factor": 0.25, "params": "base_color", "mask": burn}),
            ("scale", {"factor": 1.6, "params": "roughness", "mask": burn}),
            ("scale", {"factor": 2.5, "params": "normal", "mask": burn}),
        ],
        "age": [
            (
                "bilateral",
                {"sigma_px": 4.0, "sigma_range": 0.2, "params": ["base_color", "normal"]},
            ),
            ("curves", {"points": [(0, 0.15), (1, 0.85)], "params": "base_color"}),
            ("scale", {"factor": 1.4, "params": "roughness"}),
        ],
        "clean": [
            ("bilateral", {"sigma_px": 3.0, "sigma_range": 0.1}),
            ("scale", {"factor": 0.7, "params": "roughness"}),
        ],
        "clone": [("clone", {"region": region, "offset": (-4 * s, 3 * s)})],
    }


# --------------------------------------------------------------------------- physical twin


def _raw(material: Material) -> tuple[np.ndarray, Schema, dict[str, list[str]]]:
    """The file values as one stack of identity channels, and each parameter's channels."""
    stack, chans, names = [], {}, []
    for name in material.schema.names:
        width = material.maps[name].shape[2]
        chans[name] = [f"{name}{k}" for k in range(width)]
        names += chans[name]
        stack.append(material.maps[name])
    schema = Schema.from_names(names, {c: "identity_unbounded" for c in names})
    return np.concatenate(stack, axis=2).astype(np.float32), schema, chans


def _from_raw(material: Material, stack: np.ndarray) -> Material:
    maps, start = {}, 0
    for name in material.schema.names:
        width = material.maps[name].shape[2]
        v = stack[..., start : start + width]
        start += width
        if name == "normal":
            v = v / np.maximum(np.linalg.norm(v[..., :3], axis=-1, keepdims=True), 1e-6)
        else:
            v = np.clip(v, 0.0, 1.0)
        maps[name] = v.astype(np.float32)
    return Material(material.name, material.schema, maps, material.sources)


def apply_physical(material: Material, steps: Sequence[Step]) -> list[Material]:
    """The steps on the raw file values; the material after each step."""
    stack, schema, chans = _raw(material)
    out = []
    for op, kwargs in steps:
        kwargs = dict(kwargs)
        params = kwargs.pop("params", None)
        if params is not None:
            params = [params] if isinstance(params, str) else params
            params = [c for p in params for c in chans[p]]
        spec = get_op(op)
        bound = spec.bind({k: v for k, v in kwargs.items() if k != "mask"})
        stack = spec.function(stack, schema=schema, params=params, mask=kwargs.get("mask"), **bound)
        out.append(_from_raw(material, stack))
    return out


def apply_edit(material: Material, steps: Sequence[Step]) -> list[Material]:
    """The steps in edit space; the material after each step."""
    m = EditableMaterial(material.to_edit())
    out = []
    for op, kwargs in steps:
        m = m.apply(op, **kwargs)
        out.append(m.physical())
    return out


# --------------------------------------------------------------------------- measurements


def _linear_albedo(material: Material) -> np.ndarray:
    v = material.maps["base_color"].astype(np.float64)
    lin = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    return lin @ np.array([0.2126, 0.7152, 0.0722])


def _lobe_deg(material: Material) -> np.ndarray:
    r = np.clip(material.maps["roughness"][..., 0].astype(np.float64), 0.0, 1.0)
    return np.degrees(np.arctan(r * r))


def measure(start: Material, name: str, result: Material, steps: Sequence[Step]) -> dict:
    """What the sequence did, relative to its start, in the quantities its ops ask for."""
    if name == "burn":
        inside = steps[0][1]["mask"] > 0.99
        albedo = _linear_albedo(result)[inside].mean() / _linear_albedo(start)[inside].mean()
        tilt = (
            tilt_deg(result.maps["normal"])[inside].mean()
            / tilt_deg(start.maps["normal"])[inside].mean()
        )
        return {"albedo": float(albedo), "tilt": float(tilt)}
    if name in ("age", "clean"):
        return {"lobe": float(np.median(_lobe_deg(result)) / np.median(_lobe_deg(start)))}
    return {}


def fig1(ctx: FigureContext) -> FigureResult:
    material, _ = load_material(ctx.data)
    material = resized(material, SIZE)
    rows, values, lines = [], {}, []
    steps_of = sequences(SIZE)
    starts = {"burn": material, "age": material, "clone": material}
    results: dict[str, dict[str, list[Material]]] = {}
    for name in ("burn", "age", "clean", "clone"):
        steps = steps_of[name]
        if name == "clean":  # cleans what ageing did, in each space
            edit_start, phys_start = results["age"]["edit"][-1], results["age"]["physical"][-1]
        else:
            edit_start = phys_start = starts[name]
        edit = apply_edit(edit_start, steps)
        phys = apply_physical(phys_start, steps)
        results[name] = {"edit": edit, "physical": phys}
        ops = ", ".join(op for op, _ in steps)
        for space, seq, first in (("edit", edit, edit_start), ("physical", phys, phys_start)):
            got = measure(first, name, seq[-1], steps)
            values |= {f"{name}_{space}_{k}": v for k, v in got.items()}
            tiles = [swatch(ctx, m, TILE) for m in [first, *seq]]
            label = [f"{name}", f"in {space} space", ops[:26]]
            label += [f"{k} x{v:.2f}" for k, v in got.items()]
            rows.append([drawing.side_label(drawing.grid([tiles], gap=2), label, width=150)])
    diff = np.degrees(
        np.arccos(
            np.clip(
                np.sum(
                    results["clone"]["edit"][-1].maps["normal"][..., :3]
                    * results["clone"]["physical"][-1].maps["normal"][..., :3],
                    axis=-1,
                ),
                -1.0,
                1.0,
            )
        )
    )
    values["clone_normal_diff_deg_max"] = float(diff.max())
    albedo_diff = np.abs(
        _linear_albedo(results["clone"]["edit"][-1])
        - _linear_albedo(results["clone"]["physical"][-1])
    )
    values["clone_albedo_diff_max"] = float(albedo_diff.max())
    lines.append(
        f"burn asked kd x0.25, frames x2.5: albedo x{values['burn_edit_albedo']:.2f} edit / "
        f"x{values['burn_physical_albedo']:.2f} physical, tilt x{values['burn_edit_tilt']:.2f} / "
        f"x{values['burn_physical_tilt']:.2f}"
    )
    lines.append(
        f"age asked lobe x1.4: x{values['age_edit_lobe']:.2f} / x{values['age_physical_lobe']:.2f};"
        f" clean asked x0.7: x{values['clean_edit_lobe']:.2f} / "
        f"x{values['clean_physical_lobe']:.2f}; the clones differ by at most "
        f"{values['clone_normal_diff_deg_max']:.2f} deg in normal, "
        f"{values['clone_albedo_diff_max']:.3f} in linear albedo"
    )
    image = drawing.caption(
        drawing.grid(rows, gap=3),
        [
            f"Fig. 1: edit sequences on '{material.name}' ({SIZE}x{SIZE}): each in edit space and"
            " the same ops on the file values (physical).",
            *lines,
        ],
    )
    text = "; ".join(f"{k} {v:.3g}" for k, v in values.items())
    return FigureResult("fig1", ctx.save("fig1_edit_sequences", image), text, values)
