"""The warm-up's work: the engine's public paths run once on small data.

Going through the paths the editor takes (read, convert, paint, composite, filter, show,
render, write) instead of calling kernels directly is what makes each kernel meet the
argument types the editor gives it (dtype, dimensions, array layout), and numba keys
its cache entries by those types.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

#: texels a side of the warm-up's data: big enough to take the tiled paths (several
#: 64-texel tiles, chunked conversions), small enough to run in moments once compiled
SIDE_PX = 256


def _plausible(space: Any, shape: tuple[int, int]) -> np.ndarray:
    """Physical values ``space`` accepts, varied across the texels."""
    from ..spaces.sampled import SampledDistributionSpace, d_from_ggx
    from ..spaces.subsurface import SubsurfaceProfileSpace, profile_burley

    ramp = np.linspace(0.1, 0.9, shape[0] * shape[1], dtype=np.float32).reshape(shape)
    if isinstance(space, SampledDistributionSpace):
        return d_from_ggx(ramp * 0.5, space.phys_channels)
    if isinstance(space, SubsurfaceProfileSpace):
        return profile_burley(ramp, 0.2 + 0.2 * ramp, n=space.phys_channels)
    if space.phys_channels == 3 and "normal" in space.name:
        tilt = np.stack([0.3 * ramp - 0.15, 0.15 - 0.3 * ramp, np.ones_like(ramp)], axis=-1)
        return (tilt / np.linalg.norm(tilt, axis=-1, keepdims=True)).astype(np.float32)
    return np.repeat(ramp[..., None], space.phys_channels, axis=-1)


def _spaces() -> None:
    """Every editing space, both ways."""
    from ..spaces import all_spaces

    for space in all_spaces().values():
        edit = space.to_edit(_plausible(space, (SIDE_PX, SIDE_PX)))
        space.from_edit(edit)


def _material() -> Any:
    """A material with every parameter kind, converted both ways as one edit vector."""
    from ..material import PARAMETER_KINDS, Material, Schema

    schema = Schema.from_names(PARAMETER_KINDS)
    maps = {p.name: _plausible(p.space, (SIDE_PX, SIDE_PX)) for p in schema.parameters}
    material = Material("warm-up", schema, maps)
    material.to_edit().to_physical()
    return material


def _texture_set(folder: Path) -> Any:
    """A small PBR set written (8- and 16-bit PNG) and read back as the editor opens one."""
    from ..io.images import write_image
    from ..io.material_io import load_material

    ramp = np.linspace(0.0, 1.0, SIDE_PX * SIDE_PX, dtype=np.float32).reshape(SIDE_PX, -1)
    gray = ramp[..., None]
    normal = np.stack([0.5 + 0.2 * ramp, 0.5 - 0.2 * ramp, np.ones_like(ramp)], axis=-1)
    write_image(folder / "w_basecolor.png", np.repeat(gray, 3, axis=-1))
    write_image(folder / "w_normal.png", normal)
    write_image(folder / "w_roughness.png", gray, bit_depth="uint16")
    write_image(folder / "w_metallic.png", gray)
    write_image(folder / "w_ao.png", gray)
    write_image(folder / "w_height.png", gray, bit_depth="uint16")
    material, _ = load_material(folder)
    return material


def _show(doc: Any) -> None:
    """Read the flatten as the editor does after a change: the canvas and the 3D view read
    it a piece at a time (tiles, 256 x 256 bands), the background flatten updates it."""
    layout = doc.layout
    for max_texels in (64 * 64, 256 * 256):
        for rect in layout.rects_of(layout.all_tiles(), max_texels=max_texels):
            doc.physical(rect, copy=False)
    doc.update()
    doc.flatten_edit()


def _wave(count: int = 24) -> list[Any]:
    from ..paint import StrokeSample

    return [
        StrokeSample(SIDE_PX * (0.1 + 0.8 * t), SIDE_PX * (0.5 + 0.3 * np.sin(6 * t)), 0.3 + t / 2)
        for t in np.linspace(0.0, 1.0, count)
    ]


def _paint(doc: Any, history: Any, swatch: Any) -> None:
    """Round dabs and every tip (random dynamics; a stencil), erase, clone, a mask."""
    from ..layers import AddLayer
    from ..paint import Brush, Dynamics, Stencil, StrokeSession
    from ..paint.tips import SHAPES, procedural_tip

    paint = doc.new_paint_layer("paint", parameters=swatch.parameters)
    history.push(AddLayer(paint))
    jitter = Dynamics(rotation="random", size_jitter=0.3, angle_jitter_deg=20.0, scatter_across=0.5)
    ramp = np.tile(np.linspace(0.0, 1.0, 32, dtype=np.float32), (32, 1))
    stencil = Stencil(ramp, centre=(SIDE_PX / 2, SIDE_PX / 2), scale=4.0, angle_deg=30.0)
    strokes = [({}, None), ({}, stencil)]
    for name in SHAPES:
        tip = procedural_tip(name)
        strokes += [({"tip": tip, "dynamics": jitter}, None), ({"tip": tip}, stencil)]
    for brush, with_stencil in strokes:
        stroke = StrokeSession(
            doc, paint.id, Brush(radius_px=20.0, **brush), swatch=swatch, stencil=with_stencil,
            history=history,
        )  # fmt: skip
        stroke.add(_wave())
        stroke.end()
        _show(doc)
    for mode in ("erase", "clone"):
        stroke = StrokeSession(
            doc, paint.id, Brush(radius_px=10.0), mode=mode, clone_offset=(20.0, 10.0),
            history=history,
        )  # fmt: skip
        stroke.add(_wave())
        stroke.end()
        _show(doc)
    paint_mask = doc.new_mask(1.0)
    doc.set_mask(paint.id, paint_mask)
    stroke = StrokeSession(doc, paint.id, Brush(radius_px=10.0), target="mask", history=history)
    stroke.add(_wave())
    stroke.end()
    _show(doc)


#: which parameters a layer affects decides how the compositor hands its channels to the
#: blend kernels (all: the whole array; one: a strided view; two apart: a gathered copy),
#: and each is a different array layout to numba, so a different compiled signature
_PARAMETER_SETS = (None, ("roughness",), ("base_color", "roughness"))


def _blending(doc: Any, layers: list[Any]) -> None:
    """The compositor's blend step for each kind of channel selection (``layers``), on
    blocks either side of the size where the blend kernel goes parallel, with a layer's
    values as each kind of array numba tells apart: a filter's output (contiguous), a
    fill's constant (broadcast, read-only), a paint layer's pixels (strided: they sit
    beside their coverage channel). Every layout the editor's blends can meet."""
    from ..layers.blend import _PARALLEL_FROM
    from ..layers.compositor import blend_into

    channels = doc.schema.channel_indices().size
    for texels in (64 * 64, 2 * _PARALLEL_FROM):  # the parallel side even for one channel
        side = int(np.sqrt(texels))
        below = np.full((side, side, channels), 0.5, np.float32)
        alpha = np.full((side, side), 0.5, np.float32)
        with_coverage = np.concatenate([below, alpha[..., None]], axis=-1)
        kinds = (below + 0.1, np.broadcast_to(below[0, 0], below.shape), with_coverage[..., :-1])
        for layer in layers:
            for values in kinds:
                blend_into(layer, doc.schema, below, values, alpha, below[0, 0].copy())


def _document(material: Any) -> Any:
    """Paint; fill with every blend mode (masked); filter layers of every op; each shown,
    with layers on all, one and two apart of the parameters."""
    from ..layers import BLEND_MODES, AddLayer, Document, History
    from ..ops import all_ops
    from ..paint import Swatch

    doc = Document.from_material(material)
    history = History(doc)
    swatch = Swatch("warm-up", {"base_color": (0.6, 0.3, 0.1), "roughness": (0.4,)})
    _paint(doc, history, swatch)
    value, _ = swatch.edit_values(doc.schema)
    fills = []
    for i, blend in enumerate(BLEND_MODES):
        only = _PARAMETER_SETS[i % len(_PARAMETER_SETS)]
        fills.append(doc.new_fill_layer(blend, value=value, blend=blend, mask=doc.new_mask(0.5)))
        history.push(AddLayer(fills[-1]))
        if only is not None:
            doc.set_property(fills[-1].id, "parameters", list(only))
        _show(doc)
    _blending(doc, fills[: len(_PARAMETER_SETS)])
    for name, spec in all_ops().items():
        if spec.inputs or any(p.required for p in spec.params):
            continue  # needs a second image or a value only an artist can give
        for only in _PARAMETER_SETS:
            props = {} if only is None else {"parameters": list(only)}
            history.push(AddLayer(doc.new_filter_layer(name, **props)))
            _show(doc)
    # the bilateral's default sigma runs the separable filter, a wider one the lattice
    history.push(AddLayer(doc.new_filter_layer("bilateral", op_params={"sigma_px": 8.0})))
    _show(doc)
    return doc.flatten_physical()


def _render_and_write(material: Any, folder: Path) -> None:
    """Thumbnails (sphere, swatch) in a procedural and a file environment; files out."""
    from ..io.images import write_image
    from ..io.material_io import save_material
    from ..render.environment import load_environment
    from ..render.render import render

    sky = np.tile(np.linspace(2.0, 0.1, 16, dtype=np.float32)[:, None, None], (1, 32, 3))
    write_image(folder / "sky.exr", sky, bit_depth="float")
    for scene, environment in (("sphere", "sky"), ("swatch", load_environment(folder / "sky.exr"))):
        image = render(material, scene=scene, size=48, environment=environment, samples=4)
        write_image(folder / f"{scene}.png", image.display()[..., :3])
    save_material(material, folder / "out", overwrite=True)


def jobs(folder: Path) -> list[tuple[str, Callable[[], object]]]:
    """The warm-up's steps, in order, each ``(label, run)``; ``folder`` takes their files."""
    state: dict[str, Any] = {}
    return [
        ("editing spaces", _spaces),
        ("a material of every parameter", _material),
        ("reading a texture set", lambda: state.setdefault("set", _texture_set(folder))),
        ("painting, layers, filters", lambda: state.setdefault("flat", _document(state["set"]))),
        ("rendering and writing", lambda: _render_and_write(state["flat"], folder)),
    ]
