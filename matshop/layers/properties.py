"""The layer properties, described once: type, range, text form, edit label, merging.

The layer model validates with :meth:`LayerProperty.check`, project loading
checks a manifest's stored values with the same function, ``matshop layer set``
reads a value's text with :meth:`LayerProperty.parse`, and an edit of a property
takes its label and whether slider moves merge from here. A property's check
knows only the value and the schema; rules that need the layer itself (a fill
value's width, a filter's settings, a group's blend) stay with the layer kind.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InvalidValue
from ..material import Schema
from ..ops.generators import MaskGenerator
from ..ops.spec import parse_bool
from .blend import get_blend_mode

#: the layer kinds (``Layer.kind``), bottom of the class hierarchy first
KINDS = ("paint", "fill", "filter", "group")


def _text(value: Any, schema: Schema) -> str:
    if not isinstance(value, str):
        raise InvalidValue(f"name must be text, got {type(value).__name__}")
    return value


def _bool(name: str) -> Callable[[Any, Schema], bool]:
    def check(value: Any, schema: Schema) -> bool:
        if not isinstance(value, bool | np.bool_):
            raise InvalidValue(f"{name} must be true or false, got {value!r}")
        return bool(value)

    return check


def _unit(name: str) -> Callable[[Any, Schema], float]:
    def check(value: Any, schema: Schema) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float | np.number):
            raise InvalidValue(f"{name} must be a number, got {value!r}")
        number = float(value)
        if not (math.isfinite(number) and 0.0 <= number <= 1.0):
            raise InvalidValue(f"{name}={number:g} is outside [0, 1]")
        return number

    return check


def _blend(value: Any, schema: Schema) -> str:
    if not isinstance(value, str):
        raise InvalidValue(f"blend must be a blend mode's name, got {value!r}")
    try:
        return get_blend_mode(value).name
    except ValueError as exc:
        raise InvalidValue(str(exc)) from None


def _parameters(value: Any, schema: Schema) -> tuple[str, ...] | None:
    """Schema parameter names in schema order; None (or all of them) means all."""
    if value is None:
        return None
    # a sequence (an order-less set or a mapping is a mistake, not a selection)
    names = [value] if isinstance(value, str) else value
    if not isinstance(names, list | tuple) or not all(isinstance(n, str) for n in names):
        raise InvalidValue(f"parameters must be parameter names, got {value!r}")
    unknown = [n[:40] for n in names if n not in schema]
    if unknown:
        raise InvalidValue(f"no parameter(s) {unknown} in this material (has: {schema.names})")
    if not names:
        raise InvalidValue("a layer must affect at least one parameter (None means all)")
    if len(set(names)) != len(names):
        raise InvalidValue(f"parameters {names} name one twice")
    chosen = set(names)
    ordered = tuple(n for n in schema.names if n in chosen)
    return None if len(ordered) == len(schema.names) else ordered


def _layer_id(value: Any, schema: Schema) -> int | None:
    if value is None:  # the document checks that a given id names a group
        return None
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise InvalidValue(f"parent must be a group layer id or None, got {value!r}")
    return int(value)


def _generator(value: Any, schema: Schema) -> MaskGenerator | None:
    """A mask generator (or its JSON form); None: the layer's mask is not generated."""
    if value is None:
        return None
    generator = MaskGenerator.from_json(value)
    if "normal" not in schema.names:
        raise InvalidValue(
            f"a {generator.kind} mask is generated from the normals; this material has none"
        )
    return generator


def parse_generator(text: str) -> MaskGenerator | None:
    """``cavity radius_px=6 contrast=2`` (or ``none``) as a generator (InvalidValue if not)."""
    name, *pairs = text.split()
    if name.lower() == "none" and not pairs:
        return None
    settings: dict[str, Any] = {"kind": name}
    for pair in pairs:
        key, sep, word = pair.partition("=")
        if not sep:
            raise InvalidValue(f"mask generator settings are KEY=VALUE, got {pair[:40]!r}")
        try:
            settings[key] = parse_bool(word) if key == "invert" else float(word)
        except (ValueError, InvalidValue):
            kind = "true or false" if key == "invert" else "a number"
            raise InvalidValue(
                f"mask generator {key[:40]} must be {kind}, got {word[:40]!r}"
            ) from None
    return MaskGenerator.from_json(settings)


def _kept(value: Any, schema: Schema) -> Any:
    return value  # checked by the layer kind (it needs the layer)


def _parse_number(text: str) -> float:
    return float(text)


def _parse_names(text: str) -> tuple[str, ...] | None:
    if text.strip().lower() in ("all", ""):
        return None
    return tuple(n.strip() for n in text.split(",") if n.strip())


def _parse_parent(text: str) -> int | None:
    return None if text.strip().lower() in ("none", "") else int(text)


@dataclass(frozen=True)
class LayerProperty:
    """One property: which kinds have it, how it is checked, spelled and labelled."""

    name: str
    #: what its type and range are, for people (``matshop layer set --help``, errors)
    kind: str
    #: the label of an edit that changes it
    label: str
    #: the layer kinds that have it
    kinds: tuple[str, ...]
    #: the value normalised, or InvalidValue (the schema for parameter names)
    check: Callable[[Any, Schema], Any]
    #: its command-line text to a value (ValueError when it does not read); None:
    #: not set from text
    parse: Callable[[str], Any] | None = None
    #: consecutive changes (slider moves) merge into one history step
    mergeable: bool = False

    def from_text(self, text: str) -> Any:
        """The value ``text`` spells (checked later, against the layer and schema)."""
        if self.parse is None:
            raise InvalidValue(f"{self.name} is not set from text")
        try:
            return self.parse(text.strip())
        except InvalidValue:
            raise
        except ValueError:
            raise InvalidValue(f"{self.name} must be {self.kind}, got {text!r}") from None


_ALL = KINDS
PROPERTIES: dict[str, LayerProperty] = {
    prop.name: prop
    for prop in (
        LayerProperty("name", "text", "Rename layer", _ALL, _text, str),
        LayerProperty(
            "visible", "true or false", "Layer visibility", _ALL, _bool("visible"), parse_bool
        ),
        LayerProperty(
            "opacity",
            "a number in [0, 1]",
            "Layer opacity",
            _ALL,
            _unit("opacity"),
            _parse_number,
            mergeable=True,
        ),
        LayerProperty("blend", "a blend mode", "Blend mode", _ALL, _blend, str),
        LayerProperty(
            "parameters",
            "parameter names, or all",
            "Layer parameters",
            _ALL,
            _parameters,
            _parse_names,
        ),
        LayerProperty(
            "mask_inverted",
            "true or false",
            "Invert mask",
            _ALL,
            _bool("mask_inverted"),
            parse_bool,
        ),
        LayerProperty(
            "mask_generator",
            "a generator and its settings (cavity radius_px=6 contrast=2), or none",
            "Generated mask",
            _ALL,
            _generator,
            parse_generator,
            mergeable=True,
        ),
        LayerProperty(
            "parent", "a group layer id, or none", "Set parent", _ALL, _layer_id, _parse_parent
        ),
        LayerProperty("value", "an edit vector", "Fill value", ("fill",), _kept, mergeable=True),
        LayerProperty("source", "an edit-space texture", "Fill texture", ("fill",), _kept),
        LayerProperty(
            "op_params", "the op's settings", "Filter settings", ("filter",), _kept, mergeable=True
        ),
        LayerProperty("filter", "an op and its settings", "Change filter", ("filter",), _kept),
    )
}


def properties_of(kind: str) -> tuple[str, ...]:
    """The property names a layer kind has, in table order."""
    return tuple(name for name, prop in PROPERTIES.items() if kind in prop.kinds)


def check_property(kind: str, name: str, value: Any, schema: Schema) -> Any:
    """``value`` normalised for property ``name`` of a ``kind`` layer, or InvalidValue."""
    prop = PROPERTIES.get(name)
    if prop is None or kind not in prop.kinds:
        raise InvalidValue(f"{kind} layers have no property {name!r}")
    return prop.check(value, schema)
