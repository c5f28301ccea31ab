"""The Python API for scripts: open a texture set, apply ops, save.

    import matshop
    m = matshop.open("textures/rock/")
    m.apply("blur", sigma_px=4, params=["normal", "roughness"])
    m.apply("scale", factor=0.5, params="base_color", mask="masks/left.png")
    m.save("out/rock_edited/")

Everything runs in edit space on one concatenated array; ``save`` converts
back through each parameter's ``from_edit`` once. The CLI's ``apply`` verb is
a thin shell over this class.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from .errors import MatshopError
from .io.masks import load_mask
from .io.material_io import LoadReport, load_material, save_material
from .material import EditMaterial, Material, ProgressCallback
from .ops import get_op
from .ops.selection import resolve_params
from .ops.spec import OpTarget, run_op

PathLike = str | os.PathLike[str]


class EditableMaterial:
    """A texture set held in edit space, with ops applied in place of the array."""

    def __init__(self, edit: EditMaterial, report: LoadReport | None = None) -> None:
        self.edit = edit
        self.report = report
        #: (op name, bound parameters, selected parameters) in the order applied
        self.history: list[tuple[str, dict[str, Any], tuple[str, ...]]] = []

    @classmethod
    def from_path(cls, path: PathLike, **load_options: Any) -> EditableMaterial:
        material, report = load_material(path, **load_options)
        return cls(material.to_edit(), report)

    @property
    def schema(self):
        return self.edit.schema

    @property
    def size(self) -> tuple[int, int]:
        return self.edit.size

    def _as_mask(self, mask: PathLike | np.ndarray | None) -> np.ndarray | None:
        if mask is None or isinstance(mask, np.ndarray):
            return mask
        return load_mask(mask, self.size)

    def _aligned(
        self, other: Any, params: list[str], *, same_size: bool
    ) -> tuple[np.ndarray, list[str]]:
        """Another texture set as an array laid out like this material's edit vector.

        A texture set given as a path or an EditableMaterial contributes only
        the parameters it has (in the same editing space); the others are not
        selected. ``same_size`` inputs (a layer composited over) must match
        this material's size; a clone source may have any size.
        """
        if isinstance(other, np.ndarray):
            return other, params
        path = None if isinstance(other, EditableMaterial) else other
        material = other if path is None else EditableMaterial.from_path(path)
        if same_size and material.size != self.size:
            raise MatshopError(
                f"layer is {material.size[1]}x{material.size[0]}, the material is "
                f"{self.size[1]}x{self.size[0]}",
                path,
            )
        if material.size == self.size:
            aligned = self.edit.data.copy()
        else:
            aligned = np.zeros((*material.size, self.edit.data.shape[-1]), np.float32)
        shared = material.edit.copy_into(self.schema, aligned, params)
        if not shared:
            raise MatshopError(
                f"shares no selected parameter with the material (it has "
                f"{', '.join(material.schema.names)})",
                path,
            )
        return aligned, shared

    def apply(
        self,
        op: str,
        *,
        params: list[str] | str | None = None,
        mask: PathLike | np.ndarray | None = None,
        **values: Any,
    ) -> EditableMaterial:
        """Apply op ``op`` with its parameters (see ``matshop ops``); returns ``self``.

        ``params`` selects material parameters by name (aliases like ``kd``
        work); ``mask`` is an (H, W) array or a grayscale image path.
        """
        spec = get_op(op)
        inputs = {name: values.pop(name) for name in spec.inputs if name in values}
        missing = [name for name in spec.inputs if name not in inputs]
        if missing:
            raise MatshopError(f"{op}: needs {', '.join(missing)}=... (another texture set)")
        optional = {name: values.pop(name) for name in spec.optional_inputs if name in values}
        names = resolve_params(self.schema, params, op)
        # a separate source (a clone's) may have another size: the region is in its pixels
        size = None if optional else self.size
        bound = spec.bind(values, OpTarget(self.schema, names, size))
        for name in inputs:
            inputs[name], names = self._aligned(inputs[name], names, same_size=True)
        for name in optional:
            optional[name], names = self._aligned(optional[name], names, same_size=False)
        result = run_op(
            f"op {op}",
            spec.function,
            self.edit.data,
            *inputs.values(),
            **optional,
            schema=self.schema,
            params=names,
            mask=self._as_mask(mask),
            **bound,
        )
        self.edit = EditMaterial(self.edit.name, self.schema, result, self.edit.sources)
        self.history.append((op, bound, tuple(names)))
        return self

    def physical(self, progress: ProgressCallback | None = None) -> Material:
        """The material converted back to physical maps."""
        return self.edit.to_physical(progress=progress)

    def save(
        self,
        out_dir: PathLike,
        *,
        overwrite: bool = False,
        progress: ProgressCallback | None = None,
        png_level: int | None = None,
    ) -> list[Path]:
        """Write the physical maps into ``out_dir``; returns the files written.

        ``png_level``: zlib level of the PNGs, 0-9 (default
        :data:`~matshop.io.images.PNG_LEVEL`).
        """
        return save_material(
            self.physical(), out_dir, overwrite=overwrite, progress=progress, png_level=png_level
        )


def open(path: PathLike, **load_options: Any) -> EditableMaterial:  # noqa: A001 - the API verb
    """Open a texture set (a folder or one of its maps) for editing."""
    return EditableMaterial.from_path(path, **load_options)
