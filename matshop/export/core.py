"""``export_material``: one Material, one preset -> the files an engine loads.

Works on any :class:`~matshop.material.Material` (a texture set just loaded,
or a layered document flattened through ``from_edit``). The steps:

1. pick the preset's outputs the material needs (optional maps only when it
   has their parameters) and list parameters to fill with engine defaults
   (``strict`` turns that list into an error before any work);
2. resize to a power of two when asked (filtered in editing space);
3. write every output, plus an optional ``.glb`` and ``.mtlx``, all-or-nothing
   through :mod:`matshop.io.fileset`;
4. return an :class:`ExportSummary` of what was written.
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MatshopError
from ..io.fileset import PendingFile, check_targets, write_all
from ..io.images import probe_image, write_image
from ..io.normal_convention import CONVENTION_ATTRIBUTE
from ..io.safe_names import safe_stem
from ..material import COLOR_PARAMETERS, Material, ProgressCallback
from .obj import Mesh, read_obj, uv_sphere
from .pack import is_written, pack_output, plan_missing
from .presets import OutputSpec, Preset, load_preset
from .quantize import quantize
from .resize import is_power_of_two, resize_material, target_size

if TYPE_CHECKING:
    import MaterialX as mx


@dataclass(frozen=True)
class WrittenFile:
    """One file of an export and what it holds."""

    path: Path
    kind: str  #: ``texture``, ``gltf`` or ``mtlx``
    contents: str  #: e.g. ``R ao, G roughness, B metallic`` or ``base_color (srgb)``
    detail: str = ""  #: e.g. ``1024x1024 RGBA uint8 png``


@dataclass
class ExportSummary:
    """What :func:`export_material` wrote, for the CLI and the app."""

    preset: str
    material: str
    out_dir: Path
    size: tuple[int, int]  #: (height, width) of the written textures
    files: list[WrittenFile] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def file(self, suffix: str) -> Path:
        """The written path whose name ends with ``suffix`` (e.g. ``_ORM.png``)."""
        for written in self.files:
            if written.path.name.endswith(suffix):
                return written.path
        raise KeyError(suffix)

    def lines(self) -> list[str]:
        """Human-readable lines: one per file, then the warnings."""
        height, width = self.size
        lines = [
            f"exported {self.material!r} with preset {self.preset!r} "
            f"({width}x{height}) to {self.out_dir}:"
        ]
        for written in self.files:
            detail = f" [{written.detail}]" if written.detail else ""
            lines.append(f"  {written.path.name}: {written.contents}{detail}")
        lines.extend(f"warning: {w}" for w in self.warnings)
        return lines


def file_safe_name(name: str) -> str:
    """The ``{material}`` of exported file names (:func:`matshop.io.safe_names.safe_stem`)."""
    return safe_stem(name)


def describe_output(output: OutputSpec) -> str:
    """What an output file holds, e.g. ``R ao, G roughness, B metallic, A 1 - roughness``."""
    if output.channels is None:
        color = f" ({output.color_space})" if output.source in COLOR_PARAMETERS else ""
        return f"{output.source}{color}"
    parts = []
    for spec in output.channels:
        letter = "RGBA"[spec.dest] if spec.dest < 4 else str(spec.dest)
        if spec.source is None:
            what = f"{spec.value:g}"
        else:
            what = spec.source + (f"[{spec.source_channel}]" if spec.source_channel else "")
            what = f"1 - {what}" if spec.transform == "invert" else what
        parts.append(f"{letter} {what}")
    return ", ".join(parts)


def export_material(
    material: Material,
    preset: Preset | str,
    out_dir: str | os.PathLike,
    *,
    name: str | None = None,
    size: int | None = None,
    keep_variance: bool | None = None,
    strict: bool = False,
    force: bool = False,
    glb: bool = False,
    mesh: str | os.PathLike | None = None,
    mtlx: bool = False,
    usd: bool = False,
    usdz: bool = False,
    mtlx_shader: str = "open_pbr_surface",
    seed: int = 0,
    progress: ProgressCallback | None = None,
    png_level: int | None = None,
) -> ExportSummary:
    """Write ``material`` as ``preset`` says into ``out_dir``.

    Parameters
    ----------
    material : physical maps (any Material).
    preset : a :class:`Preset` or a built-in preset name.
    out_dir : folder, created if needed.
    name : the ``{material}`` of file names (default: the material's name).
    size : longest side in texels, a power of two; the material is resampled
        in editing space. Default: keep the material's size.
    keep_variance : with ``size``, widen the lobe by the normal tilt variance
        the reduction averages away (docs/variance.md). None: the preset's
        ``keepVariance``; True or False overrides it.
    strict : refuse to fill missing parameters with engine defaults.
    force : replace existing files.
    glb : also write ``<name>.glb`` (glTF binary: the material, glTF-packed
        PNG textures embedded, on ``mesh`` or the unit sphere).
    mesh : a Wavefront OBJ for the ``.glb`` and ``.usda`` (default: a UV sphere).
    mtlx : also write ``<name>.mtlx`` (a MaterialX material reading the textures).
    mtlx_shader : its surface shader: ``open_pbr_surface``, ``standard_surface`` or
        ``gltf_pbr`` (:data:`.mtlx.SHADING_MODELS`); also the USD's ``mtlx`` context.
    usd : also write ``<name>.usda``: the mesh, bound to a Material with a
        UsdPreviewSurface reading the textures and the MaterialX document as
        its ``mtlx`` render context (:mod:`.usd`).
    usdz : also write ``<name>.usdz``, the ``.usda`` and its textures packaged
        (implies ``usd``).
    seed : dithering noise seed.
    png_level : zlib level of the PNG textures, 0-9; None: the preset's ``pngLevel``,
        else the writer's default.
    progress : called with (files written, files) before the first file and after each;
        an exception it raises (a cancel) stops the export between files and, like any
        failure, leaves the output folder as it was (no new folder, no partial files).

    Raises
    ------
    MatshopError : one line naming the problem (and the file when there is one).
    """
    if isinstance(preset, str):
        preset = load_preset(preset)
    name = file_safe_name(name or material.name)
    out = Path(out_dir)
    outputs = [o for o in preset.outputs if is_written(material, o)]
    missing = plan_missing(material, preset)
    unfillable = [m for m in missing if m.fill is None]
    if unfillable or (strict and missing):
        first = (unfillable or missing)[0]
        others = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        if unfillable:
            raise MatshopError(f"preset {preset.name!r}: {first.message()}{others}")
        raise MatshopError(
            f"preset {preset.name!r}: {first.output} needs {first.parameter}, which the "
            f"material lacks{others}; strict mode refuses engine defaults"
        )
    warnings = [m.message() for m in missing]
    # refuse clashes before the costly part (resampling, packing)
    names = [o.file_for(name, preset.name) for o in outputs]
    usd = usd or usdz
    names += [f"{name}.glb"] * glb + [f"{name}.mtlx"] * mtlx
    names += [f"{name}.usda"] * usd + [f"{name}.usdz"] * usdz
    check_targets(out, names, force=force)
    texture_files = {o.channel: o.file_for(name, preset.name) for o in outputs}
    geometry = _geometry(mesh) if glb or usd else None  # bad meshes fail before any work
    mtlx_doc = None
    if mtlx or usd:
        from .mtlx import checked_document

        mtlx_doc = checked_document(preset, outputs, texture_files, name, mtlx_shader)

    if keep_variance is None:
        keep_variance = preset.keep_variance
    if size is not None:
        material = resize_material(
            material, target_size(material.size, size), keep_variance=keep_variance
        )
    elif not all(is_power_of_two(n) for n in material.size):
        height, width = material.size
        warnings.append(f"{width}x{height} is not a power of two; engines may pad or rescale it")

    pending: list[PendingFile] = []
    written: list[WrittenFile] = []
    for output in outputs:
        file_name = texture_files[output.channel]
        writer = _texture_writer(material, output, preset, seed, file_name, warnings, png_level)
        pending.append(PendingFile(file_name, writer))
        written.append(WrittenFile(out / file_name, "texture", describe_output(output)))
    if glb:
        from .gltf import glb_writer

        pending.append(PendingFile(f"{name}.glb", glb_writer(material, name, geometry, seed=seed)))
        written.append(WrittenFile(out / f"{name}.glb", "gltf", "glTF binary: material and mesh"))
    if mtlx:
        from .mtlx import mtlx_writer

        pending.append(PendingFile(f"{name}.mtlx", mtlx_writer(mtlx_doc)))
        written.append(WrittenFile(out / f"{name}.mtlx", "mtlx", f"MaterialX {mtlx_shader}"))
    if usd:
        pending += _usd_files(name, geometry, preset, outputs, texture_files, mtlx_doc, usdz)
        written.append(
            WrittenFile(out / f"{name}.usda", "usd", f"USD: mesh, UsdPreviewSurface, {mtlx_shader}")
        )
        if usdz:
            written.append(WrittenFile(out / f"{name}.usdz", "usd", "USDZ package"))
    write_all(out, pending, force=force, progress=progress)
    summary = ExportSummary(preset.name, name, out, material.size, warnings=warnings)
    summary.files = [_with_detail(w) for w in written]
    return summary


def _geometry(mesh: str | os.PathLike | None) -> Mesh:
    return read_obj(mesh) if mesh is not None else uv_sphere()


def _usd_files(
    name: str,
    geometry: Mesh,
    preset: Preset,
    outputs: list[OutputSpec],
    texture_files: dict[str, str],
    mtlx_doc: mx.Document,
    usdz: bool,
) -> list[PendingFile]:
    """The ``.usda`` (and ``.usdz``) writers; the stage is built (and a usdz
    refused) now, before anything is written."""
    from .usd import build_stage, check_usdz_files, referenced_files, usda_writer, usdz_writer

    stage = build_stage(name, geometry, preset, outputs, texture_files, mtlx_doc)
    files = [PendingFile(f"{name}.usda", usda_writer(stage))]
    if usdz:
        textures = referenced_files(stage)
        check_usdz_files(textures)
        writer = usdz_writer(f"{name}.usda", textures)
        files.append(PendingFile(f"{name}.usdz", writer, reads_others=True))
    return files


def _texture_writer(
    material: Material,
    output: OutputSpec,
    preset: Preset,
    seed: int,
    file_name: str,
    warnings: list[str],
    png_level: int | None = None,
) -> Callable[[Path], None]:
    """The closure writing one texture; packing happens only when it runs (files are
    written two at a time, so at most two outputs are in memory). Clipping is reported in
    ``warnings``."""

    def write(path: Path) -> None:
        array = pack_output(material, output, preset)
        if output.bit_depth in ("uint8", "uint16"):
            outside = int(np.count_nonzero((array < 0.0) | (array > 1.0)))
            if outside:
                warnings.append(
                    f"{file_name}: {outside} value(s) outside [0, 1] clipped "
                    f"(a float format such as exr keeps them)"
                )
        # one noise field per output, reproducible from the output's name
        codes = quantize(
            array,
            output.bit_depth,
            dither=output.dithering,
            seed=zlib.crc32(f"{seed}:{output.channel}".encode()),
        )
        frames = {"normal", "tangent"} & set(output.sources)
        # the convention travels with the file, so reading it back never guesses
        attributes = {CONVENTION_ATTRIBUTE: preset.normal_convention} if frames else None
        level = preset.png_level if png_level is None else png_level
        write_image(path, codes, bit_depth=output.bit_depth, attributes=attributes, png_level=level)

    return write


def _with_detail(written: WrittenFile) -> WrittenFile:
    if written.kind != "texture":
        size = written.path.stat().st_size
        return WrittenFile(written.path, written.kind, written.contents, f"{size} bytes")
    info = probe_image(written.path)
    names = "".join(info.channel_names) if info.channels <= 4 else f"{info.channels} channels"
    detail = f"{info.width}x{info.height} {names} {info.bit_depth} {info.format}"
    return WrittenFile(written.path, written.kind, written.contents, detail)
