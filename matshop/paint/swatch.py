"""Material swatches: what a brush paints, for any subset of the parameters.

A swatch stores *physical* values (a color as its file's sRGB-encoded values
in [0, 1], a roughness, a unit normal...)
so a saved library means the same thing whatever editing spaces a document
uses; it is converted to edit values when a stroke starts. Bronze, say, is a
color, a roughness, a metallic value and a flat frame, painted in one stroke.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InvalidValue, MatshopError, naming
from ..io.atomic import atomic_target
from ..io.jsonfile import read_json
from ..material import Schema

LIBRARY_FORMAT = "matshop-swatches"
LIBRARY_VERSION = 1


@dataclass(frozen=True)
class Swatch:
    """A named set of physical parameter values."""

    name: str
    values: Mapping[str, tuple[float, ...]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        clean = {}
        for param, value in self.values.items():
            try:
                array = np.atleast_1d(np.asarray(value, dtype=np.float64))
            except (TypeError, ValueError):  # text, ragged lists: not numbers
                array = np.empty(0)
            vector = tuple(array.tolist()) if array.ndim == 1 else ()
            if not vector or not all(math.isfinite(v) for v in vector):
                raise InvalidValue(f"swatch {self.name!r}: {param} must be finite numbers")
            clean[str(param)] = vector
        if not clean:
            raise InvalidValue(f"swatch {self.name!r} has no values")
        object.__setattr__(self, "values", clean)

    @property
    def parameters(self) -> tuple[str, ...]:
        return tuple(self.values)

    def edit_values(self, schema: Schema) -> tuple[np.ndarray, np.ndarray]:
        """``(edit vector (C,), indices of the channels it defines)`` for ``schema``.

        Channels of parameters the swatch does not define are 0 and not listed.
        """
        unknown = [p for p in self.values if p not in schema]
        if unknown:
            raise InvalidValue(
                f"swatch {self.name!r} sets {', '.join(unknown)}, which this material "
                f"does not have (it has {', '.join(schema.names)})"
            )
        vector = np.zeros(schema.edit_width, dtype=np.float32)
        channels = []
        for param in schema.parameters:
            if param.name not in self.values:
                continue
            with np.errstate(over="ignore"):  # too large for float32: refused below
                phys = np.asarray(self.values[param.name], dtype=np.float32)
            if not np.isfinite(phys).all():
                raise InvalidValue(f"swatch {self.name!r}: {param.name} values are out of range")
            if phys.size != param.phys_channels:
                raise InvalidValue(
                    f"swatch {self.name!r}: {param.name} needs {param.phys_channels} "
                    f"value(s), got {phys.size}"
                )
            where = schema.edit_slices[param.name]
            with np.errstate(all="ignore"):  # an overflow shows as non-finite: refused below
                vector[where] = param.space.to_edit(phys.reshape(1, 1, -1))[0, 0]
            if not np.isfinite(vector[where]).all():
                raise InvalidValue(f"swatch {self.name!r}: {param.name} values are out of range")
            channels.extend(range(where.start, where.stop))
        return vector, np.asarray(channels, dtype=np.intp)

    @classmethod
    def from_physical(
        cls,
        name: str,
        maps: Mapping[str, np.ndarray],
        x: int,
        y: int,
        parameters: Sequence[str] | None = None,
    ) -> Swatch:
        """The eyedropper: texel (x, y) of physical maps (e.g. ``Document.physical()``)."""
        names = list(maps) if parameters is None else list(parameters)
        return cls(name, {p: tuple(np.asarray(maps[p][y, x]).ravel().tolist()) for p in names})

    def to_json(self) -> dict:
        return {"name": self.name, "values": {k: list(v) for k, v in self.values.items()}}

    @classmethod
    def from_json(cls, data: object) -> Swatch:
        if not isinstance(data, dict) or not isinstance(data.get("values"), dict):
            raise InvalidValue("a swatch is an object with a name and a values object")
        return cls(str(data.get("name", "swatch")), data["values"])


def save_swatches(path: str | Path, swatches: Sequence[Swatch]) -> None:
    """Write a swatch library (JSON) atomically."""
    document = {
        "format": LIBRARY_FORMAT,
        "version": LIBRARY_VERSION,
        "swatches": [s.to_json() for s in swatches],
    }
    with atomic_target(Path(path)) as temp:
        Path(temp).write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")


def load_swatches(path: str | Path) -> list[Swatch]:
    """Read a swatch library; a bad file is one clear error naming it."""
    path = Path(path)
    data = read_json(path, "swatch library")
    if not isinstance(data, dict) or data.get("format") != LIBRARY_FORMAT:
        raise MatshopError(f'not a swatch library (no "format": "{LIBRARY_FORMAT}")', path)
    version = data.get("version")
    if not isinstance(version, int) or version > LIBRARY_VERSION:
        raise MatshopError(
            f"swatch library version {version!r}; this matshop reads up to {LIBRARY_VERSION}",
            path,
        )
    items = data.get("swatches", [])
    if not isinstance(items, list):
        raise InvalidValue('"swatches" must be a list', path)
    with naming(path):
        return [Swatch.from_json(item) for item in items]
