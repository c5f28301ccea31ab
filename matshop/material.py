"""Channel schemas and the two material containers.

A :class:`Schema` says which parameters a material has and, for each, its
editing space; it lays the edit channels of all parameters side by side so
one texel is one concatenated edit vector with named slices. That lets a
single operation act on several parameters at once (the seed paper's main
workflow point) while every parameter keeps its own meaning.

:class:`Material` holds physical maps (what files hold, decoded to float32);
:class:`EditMaterial` holds the concatenated edit-space array. Conversion runs
in row bands so huge or wide materials (1K x 128-channel distributions) stay
within memory and can report progress.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np

from . import buffers
from .errors import InvalidValue, UnknownName
from .spaces import Space, get_space
from .spaces._kernels import run_steps
from .spaces.base import as_channels

#: Called with (rows done, rows total) during long conversions.
ProgressCallback = Callable[[int, int], None]

#: Texel budget for one band of a conversion; bounds temporaries to a few
#: hundred MB even for 128-channel parameters.
_BAND_TEXELS = 1 << 18


@dataclass(frozen=True)
class ParameterKind:
    """What a named parameter is: its editing space by default, how files hold it, how
    panels name it. The one place these facts live; importer, exporter and UI read it."""

    name: str
    label: str
    default_space: str
    #: the file-name slot the parameter is usually imported from
    description: str
    #: fits a toggle button four to a row (the layers panel)
    button: str = ""
    #: fits a narrow panel's list (brush, curves, swatches)
    short: str = ""
    #: a display-encoded color (sRGB in files, color3 in MaterialX)
    color: bool = False
    #: the tag of the file it is saved to (``name_tag.png``); None: not saved to files yet
    file_tag: str | None = None
    #: how a file of the slot of the same name is read: "color" (RGB), "scalar" (the
    #: first channel) or "wide" (every channel: sampled functions); None: another way
    imported_as: str | None = None


def _kind(
    name: str, label: str, space: str, description: str, button: str, short: str, **facts
) -> ParameterKind:
    return ParameterKind(name, label, space, description, button, short, **facts)


#: The parameters matshop knows, by canonical name. Data, not branches: the
#: importer, the exporter and the UI all read this table.
PARAMETER_KINDS: dict[str, ParameterKind] = {
    kind.name: kind
    for kind in (
        _kind("base_color", "Base color", "srgb", "albedo / base color, sRGB", "Color",
              "Base color", color=True, file_tag="basecolor", imported_as="color"),
        _kind("diffuse", "Diffuse kd", "srgb", "diffuse reflectance kd, sRGB", "Diffuse",
              "Diffuse", color=True),
        _kind("specular", "Specular ks", "srgb", "specular reflectance ks, sRGB", "Specular",
              "Specular", color=True, file_tag="specular", imported_as="color"),
        _kind("emissive", "Emissive", "srgb", "emitted color, sRGB", "Emissive", "Emissive",
              color=True, file_tag="emissive", imported_as="color"),
        _kind("metallic", "Metallic", "identity", "metalness, linear", "Metal", "Metallic",
              file_tag="metallic", imported_as="scalar"),
        _kind("roughness", "Roughness (GGX)", "ggx", "GGX perceptual roughness r", "Rough",
              "Roughness", file_tag="roughness", imported_as="scalar"),
        _kind("phong_exponent", "Phong exponent", "phong", "Phong exponent n", "Phong",
              "Phong n"),
        _kind("anisotropic_exponents", "Anisotropic exponents", "ashikhmin_shirley",
              "Ashikhmin-Shirley nu, nv", "Aniso", "Aniso n"),
        _kind("beckmann_roughness", "Beckmann roughness", "beckmann", "Beckmann slope m",
              "Beckm.", "Beckmann m"),
        _kind("distribution", "Microfacet distribution", "sampled", "sampled d(theta)", "D(θ)",
              "Distribution", file_tag="distribution", imported_as="wide"),
        _kind("profile", "Subsurface profile", "subsurface", "SubEdit profile p(r)", "Profile",
              "Subsurface", file_tag="profile", imported_as="wide"),
        _kind("normal", "Normal", "normal", "tangent-space frame (normal map)", "Normal",
              "Normal", file_tag="normal"),
        _kind("ao", "Ambient occlusion", "identity", "ambient occlusion, linear", "AO",
              "Occlusion", file_tag="ao", imported_as="scalar"),
        _kind("opacity", "Opacity", "identity", "opacity / alpha, linear", "Alpha", "Opacity",
              file_tag="opacity", imported_as="scalar"),
        _kind("transmission", "Transmission", "identity", "transmission weight, linear",
              "Transm.", "Transmission", file_tag="transmission", imported_as="scalar"),
        _kind("height", "Height", "identity_unbounded", "displacement, linear", "Height",
              "Height", file_tag="height", imported_as="scalar"),
    )
}  # fmt: skip

#: parameters whose values are display-encoded colors
COLOR_PARAMETERS = frozenset(name for name, kind in PARAMETER_KINDS.items() if kind.color)


@dataclass(frozen=True)
class Parameter:
    """One parameter of a material: its name and editing space."""

    name: str
    space: Space

    @property
    def phys_channels(self) -> int:
        return self.space.phys_channels

    @property
    def edit_channels(self) -> int:
        return self.space.edit_channels

    @property
    def label(self) -> str:
        kind = PARAMETER_KINDS.get(self.name)
        return kind.label if kind else self.name


class Schema:
    """An ordered set of parameters and the layout of their edit channels."""

    def __init__(self, parameters: Iterable[Parameter]) -> None:
        self.parameters: tuple[Parameter, ...] = tuple(parameters)
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise InvalidValue(f"duplicate parameter names in schema: {names}")
        self.edit_slices: dict[str, slice] = {}
        start = 0
        for param in self.parameters:
            self.edit_slices[param.name] = slice(start, start + param.edit_channels)
            start += param.edit_channels
        self.edit_width = start

    @classmethod
    def from_names(cls, names: Iterable[str], spaces: Mapping[str, str] | None = None) -> Schema:
        """Build a schema from parameter names, each with its default space
        unless ``spaces`` overrides it (``{"roughness": "ggx_alpha"}``)."""
        spaces = dict(spaces or {})
        params = []
        for name in names:
            kind = PARAMETER_KINDS.get(name)
            space_name = spaces.get(name) or (kind.default_space if kind else None)
            if space_name is None:
                raise UnknownName(f"unknown parameter {name!r}: give its editing space explicitly")
            params.append(Parameter(name, get_space(space_name)))
        return cls(params)

    def __getitem__(self, name: str) -> Parameter:
        for param in self.parameters:
            if param.name == name:
                return param
        raise UnknownName(f"no parameter {name!r} in this material (has: {', '.join(self.names)})")

    def __contains__(self, name: object) -> bool:
        return name in self.edit_slices

    def __len__(self) -> int:
        return len(self.parameters)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    def channel_indices(self, names: Iterable[str] | None = None) -> np.ndarray:
        """Edit-channel indices covered by ``names`` (all parameters if None)."""
        if names is None:
            return np.arange(self.edit_width)
        chunks = [np.arange(self.edit_width)[self.edit_slices[self[n].name]] for n in names]
        return np.concatenate(chunks) if chunks else np.zeros(0, dtype=np.intp)

    def describe(self) -> list[tuple[str, str, int, int]]:
        """(parameter, space, physical width, edit width) rows, for ``info`` and the UI."""
        return [(p.name, p.space.name, p.phys_channels, p.edit_channels) for p in self.parameters]

    def __repr__(self) -> str:
        inner = ", ".join(f"{p.name}:{p.space.name}" for p in self.parameters)
        return f"Schema({inner})"


def _maps_in_one_buffer(
    height: int, width: int, parameters: Iterable[Parameter]
) -> dict[str, np.ndarray]:
    """Each parameter's ``(H, W, phys_channels)`` map, C-contiguous, one after another
    in one pooled buffer (:mod:`.buffers`).

    One buffer of the set's bytes rather than one per map: an edit array of the same
    bytes (the physical and edit widths are equal in most sets) that an op left
    behind is then reused whole, instead of new pages for every map. ``matshop
    apply`` blurs the edit array and writes the set: its maps took 128 MB of new
    memory at 2K, which on a virtual machine whose free memory the host takes
    back cost up to 2 ms a MB to map again.
    """
    parameters = list(parameters)
    texels = height * width
    block = buffers.empty((texels * sum(p.phys_channels for p in parameters),))
    maps, start = {}, 0
    for p in parameters:
        stop = start + texels * p.phys_channels
        maps[p.name] = block[start:stop].reshape(height, width, p.phys_channels)
        start = stop
    return maps


def _bands(height: int, width: int, channels: int) -> list[tuple[int, int]]:
    rows = max(1, _BAND_TEXELS * 4 // max(1, width * max(channels, 4)))
    return [(r, min(height, r + rows)) for r in range(0, height, rows)]


@dataclass
class Material:
    """A material in physical encoding: one ``(H, W, C)`` float32 map per parameter."""

    name: str
    schema: Schema
    maps: dict[str, np.ndarray]
    #: free-form provenance per parameter (source file, bit depth, convention, ...)
    sources: dict[str, dict] = field(default_factory=dict)

    def __post_init__(self) -> None:
        missing = [n for n in self.schema.names if n not in self.maps]
        if missing:
            raise InvalidValue(f"material {self.name!r} lacks maps for {missing}")
        shapes = {n: self.maps[n].shape[:2] for n in self.schema.names}
        if len(set(shapes.values())) > 1:
            raise InvalidValue(f"material {self.name!r}: maps differ in size: {shapes}")
        for param in self.schema.parameters:
            arr = self.maps[param.name]
            if arr.ndim != 3 or arr.shape[2] != param.phys_channels:
                raise InvalidValue(
                    f"material {self.name!r}: {param.name} needs (H, W, {param.phys_channels}),"
                    f" got {arr.shape}"
                )

    @property
    def size(self) -> tuple[int, int]:
        """(height, width) in texels."""
        first = self.maps[self.schema.names[0]]
        return first.shape[0], first.shape[1]

    def to_edit(self, progress: ProgressCallback | None = None) -> EditMaterial:
        """Convert every parameter into its editing space, concatenated per texel."""
        height, width = self.size
        edit = buffers.empty((height, width, self.schema.edit_width))
        slices = self.schema.edit_slices
        # spaces that are one kernel step convert together, in one pass over the texels
        fused = [(p, p.space.to_edit_step()) for p in self.schema.parameters]
        run_steps(
            [
                (
                    step,
                    as_channels(self.maps[p.name], p.phys_channels, p.name),
                    edit[..., slices[p.name]],
                )
                for p, step in fused
                if step is not None
            ]
        )
        rest = [p for p, step in fused if step is None]
        bands = _bands(height, width, self.schema.edit_width)
        for done, (r0, r1) in enumerate(bands, 1):
            for param in rest:
                param.space.to_edit_into(
                    self.maps[param.name][r0:r1], edit[r0:r1, :, slices[param.name]]
                )
            if progress:
                progress(done, len(bands))
        return EditMaterial(self.name, self.schema, edit, dict(self.sources))


@dataclass
class EditMaterial:
    """A material in editing space: one ``(H, W, schema.edit_width)`` float32 array."""

    name: str
    schema: Schema
    data: np.ndarray
    sources: dict[str, dict] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.data.ndim != 3 or self.data.shape[2] != self.schema.edit_width:
            raise ValueError(
                f"edit data must be (H, W, {self.schema.edit_width}), got {self.data.shape}"
            )

    @property
    def size(self) -> tuple[int, int]:
        return self.data.shape[0], self.data.shape[1]

    def __getitem__(self, name: str) -> np.ndarray:
        """The edit channels of one parameter (a view: writes go into ``data``)."""
        return self.data[..., self.schema.edit_slices[self.schema[name].name]]

    def copy_into(
        self, schema: Schema, out: np.ndarray, params: Iterable[str] | None = None
    ) -> list[str]:
        """Write the parameters this material shares with ``schema`` into ``out``.

        ``out`` is ``(H, W, schema.edit_width)`` laid out like ``schema``; a
        parameter is shared when both have it in the same editing space.
        ``params`` limits the candidates (default: all of ``schema``). Returns
        the names written, in the order of ``params``.
        """
        shared = []
        for name in schema.names if params is None else params:
            if name in self.schema and self.schema[name].space == schema[name].space:
                out[..., schema.edit_slices[name]] = self[name]
                shared.append(name)
        return shared

    def to_physical(self, progress: ProgressCallback | None = None) -> Material:
        """Convert back through every space's ``from_edit`` (clamping happens here)."""
        height, width = self.size
        maps = _maps_in_one_buffer(height, width, self.schema.parameters)
        slices = self.schema.edit_slices
        fused = [(p, p.space.from_edit_step()) for p in self.schema.parameters]
        run_steps(
            [
                (step, self.data[..., slices[p.name]], maps[p.name])
                for p, step in fused
                if step is not None
            ]
        )
        rest = [p for p, step in fused if step is None]
        bands = _bands(height, width, max(p.phys_channels for p in self.schema.parameters))
        for done, (r0, r1) in enumerate(bands, 1):
            for param in rest:
                param.space.from_edit_into(
                    self.data[r0:r1, :, slices[param.name]], maps[param.name][r0:r1]
                )
            if progress:
                progress(done, len(bands))
        return Material(self.name, self.schema, maps, dict(self.sources))
