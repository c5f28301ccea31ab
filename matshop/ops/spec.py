"""Declarative descriptions of operations and their parameters.

Each op module declares one :class:`OpSpec`: its name, what it does, whether
it is linear in the edit values, and every parameter with unit, default,
hard range (validation) and UI range (sliders), in the manner of GEGL's
``value_range``/``ui_range``; the checks that involve several parameters, or
the material the op will run on (:class:`OpTarget`); and its *reach*, how many
texels around an output texel it reads (what a tiled filter layer needs as
margin). :meth:`OpSpec.bind` runs every check, so whatever the CLI, the Python
API, filter layers, recipes and tool panels accept can run. Adding an op is
one module and one registry entry.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from ..errors import InvalidValue
from ..finite import all_finite

ParamKind = Literal[
    "float", "int", "bool", "choice", "points", "offset", "path", "region", "floats"
]


#: offsets beyond 16x the largest document side mean nothing more (and overflow int32)
MAX_OFFSET_PX = 1 << 20


class OpError(InvalidValue):
    """A bad op name or parameter value: one line naming the op and the parameter.

    Also a ValueError: the kernels' own argument checks raise it, and code
    that calls them directly keeps catching ValueError.
    """


#: what :attr:`OpSpec.reach` returns for an op whose every output texel may
#: depend on every input texel (a tiled filter layer recomputes the whole image)
WHOLE_IMAGE = None

#: texels of context, or :data:`WHOLE_IMAGE`
Reach = int | None


@dataclass(frozen=True)
class OpTarget:
    """What an op will run on, as far as it is known before it runs.

    Checks that need more than the parameters (a count per selected edit
    channel, a sigma against the image size) use what is given and skip what
    is not: the Python API knows everything at bind time, a filter layer its
    document, a recipe nothing until it meets a material (then it binds again).
    """

    #: the material's schema (None: unknown)
    schema: Any = None
    #: the selected parameter names (None: all of the schema)
    params: Sequence[str] | str | None = None
    #: (height, width) in texels (None: unknown)
    size: tuple[int, int] | None = None


#: a check of bound values against each other and the target; raises OpError
Check = Callable[[Mapping[str, Any], OpTarget], None]
#: an op's reach for bound values on a target
ReachRule = Callable[[Mapping[str, Any], OpTarget], Reach]


def pointwise(values: Mapping[str, Any], target: OpTarget) -> Reach:
    """The reach of an op whose output texel reads only the same input texel."""
    return 0


def parse_bool(text: str) -> bool:
    """The one spelling of true and false on the command line (ValueError otherwise)."""
    lowered = text.strip().lower()
    if lowered in ("1", "true", "yes", "on"):
        return True
    if lowered in ("0", "false", "no", "off"):
        return False
    raise ValueError(f"not true or false: {text!r}")


@dataclass(frozen=True)
class ParamSpec:
    """One parameter of an op.

    ``hard_range`` bounds what is accepted at all; ``ui_range`` is what a
    slider spans by default. ``unit`` is part of the name too (``sigma_px``).
    """

    name: str
    kind: ParamKind
    default: Any
    doc: str
    unit: str = ""
    hard_range: tuple[float, float] | None = None
    ui_range: tuple[float, float] | None = None
    choices: tuple[str, ...] = ()
    required: bool = False
    #: the value a saved filter layer that predates this parameter gets (keeps old
    #: projects looking as they did); None: the default
    missing: Any = None

    def parse(self, text: str, op: str) -> Any:
        """Parse a command-line ``key=value`` value into this parameter's type."""
        try:
            if self.kind == "float":
                return float(text)
            if self.kind == "floats":  # "1,2.5,1"
                return tuple(float(v) for v in text.split(","))
            if self.kind == "int":
                return int(text)
            if self.kind == "bool":
                return parse_bool(text)
            if self.kind == "points":  # "0,0;0.5,0.7;1,1"
                return [tuple(float(v) for v in pair.split(",")) for pair in text.split(";")]
            if self.kind == "offset":  # "dx,dy"
                dx, dy = (int(round(float(v))) for v in text.split(","))
                return (dx, dy)
        except (ValueError, OverflowError):  # OverflowError: int(inf)
            raise OpError(f"{op}: {self.name}={text!r} is not a valid {self.kind}") from None
        if self.kind == "region":
            return _parse_region(text, op, self.name)
        return text  # choice, path: validated later

    def format(self, value: Any) -> str:
        """The command-line spelling of ``value`` (what :meth:`parse` reads back)."""
        if self.kind == "points":
            return ";".join(f"{x:g},{y:g}" for x, y in value)
        if self.kind == "offset":
            return f"{value[0]},{value[1]}"
        if self.kind == "floats" and value is not None:
            return ",".join(f"{v:g}" for v in value)
        if self.kind == "region" and isinstance(value, np.ndarray):
            if value.dtype == bool:
                return f"<mask of {int(value.sum())} texels>"
            return ";".join(f"{x:g},{y:g}" for x, y in value)
        if isinstance(value, float):
            return f"{value:g}"
        return str(value).lower() if isinstance(value, bool) else str(value)

    def validate(self, value: Any, op: str) -> Any:
        """Check ``value`` against the declared type and hard range; return it normalised."""
        where = f"{op}: {self.name}"
        if self.kind in ("float", "int"):
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise OpError(f"{where} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise OpError(f"{where} must be finite, got {value!r}")
            if self.kind == "int" and value != int(value):
                raise OpError(f"{where} must be a whole number, got {value!r}")
            value = int(value) if self.kind == "int" else float(value)
            if self.hard_range is not None:
                lo, hi = self.hard_range
                if not lo <= value <= hi:
                    unit = f" {self.unit}" if self.unit else ""
                    raise OpError(f"{where}={value:g} is outside [{lo:g}, {hi:g}]{unit}")
        elif self.kind == "bool":
            if not isinstance(value, bool):
                raise OpError(f"{where} must be true or false, got {value!r}")
        elif self.kind == "choice":
            if value not in self.choices:
                raise OpError(f"{where}={value!r}: choose one of {', '.join(self.choices)}")
        elif self.kind == "floats":
            if value is not None:
                value = _validate_floats(value, where, self.hard_range)
        elif self.kind == "points":
            value = _validate_points(value, where, self.hard_range)
        elif self.kind == "region":
            value = _validate_region(value, where)
        elif self.kind == "offset":
            try:
                dx, dy = value
                value = (int(dx), int(dy))
            except (TypeError, ValueError, OverflowError):
                raise OpError(f"{where} must be two whole numbers dx,dy, got {value!r}") from None
            if max(abs(v) for v in value) > MAX_OFFSET_PX:
                raise OpError(f"{where}={value} is outside [{-MAX_OFFSET_PX}, {MAX_OFFSET_PX}] px")
        return value


def run_op(what: str, function: Callable[..., np.ndarray], *args: Any, **kwargs: Any) -> np.ndarray:
    """``function(*args, **kwargs)`` if all its values are finite; else an
    :class:`OpError` naming ``what`` (the op, or the filter layer running it).

    Extreme but legal parameters can overflow; the result is refused where
    it is made, so nothing non-finite reaches a layer, a file or the screen
    (and the overflow itself is that error, not a warning).
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        result = function(*args, **kwargs)
    if not all_finite(result):
        bad = int((~np.isfinite(result).reshape(*result.shape[:2], -1).all(axis=-1)).sum())
        raise OpError(f"{what} produced NaN or infinite values in {bad} texel(s)")
    return result


def _validate_floats(
    value: Any, where: str, hard_range: tuple[float, float] | None
) -> tuple[float, ...]:
    try:
        numbers = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise OpError(f"{where} must be numbers, got {value!r}") from None
    if not numbers or not all(math.isfinite(v) for v in numbers):
        raise OpError(f"{where} must be finite numbers, got {value!r}")
    if hard_range is not None:
        lo, hi = hard_range
        outside = [v for v in numbers if not lo <= v <= hi]
        if outside:
            raise OpError(f"{where}: {outside[0]:g} is outside [{lo:g}, {hi:g}]")
    return numbers


def _parse_region(text: str, op: str, name: str) -> Any:
    """``x,y;x,y;...`` is a polygon in pixels; anything else names a mask image."""
    if ";" in text and not Path(text).exists():
        try:
            return np.array(
                [[float(v) for v in pair.split(",")] for pair in text.split(";")], dtype=np.float64
            )
        except ValueError:
            raise OpError(f"{op}: {name}={text!r} is neither x,y;x,y;... nor an image") from None
    return Path(text)


def _validate_region(value: Any, where: str) -> Any:
    if isinstance(value, str | Path):
        from ..io.masks import load_region  # only when a mask file is given

        return load_region(value)
    if hasattr(value, "clone"):  # precomputed CloneCoordinates
        return value
    array = np.asarray(value)
    if array.ndim == 2 and array.shape[1] == 2 and array.dtype != bool and len(array) >= 3:
        if not np.isfinite(array).all():
            raise OpError(f"{where}: polygon vertices must be finite")
        return array.astype(np.float64)
    if array.ndim == 2 and array.shape[1] != 2 or array.dtype == bool:
        return array.astype(bool) if array.dtype == bool else array > 0.5
    raise OpError(f"{where} must be a mask image or a polygon x,y;x,y;x,y (3+ vertices)")


def _validate_points(
    value: Any, where: str, hard_range: tuple[float, float] | None
) -> tuple[tuple[float, float], ...]:
    try:
        points = tuple((float(x), float(y)) for x, y in value)
    except (TypeError, ValueError):
        raise OpError(f"{where} must be control points x,y;x,y;..., got {value!r}") from None
    if len(points) < 2:
        raise OpError(f"{where} needs at least two control points, got {len(points)}")
    if not all(math.isfinite(c) for point in points for c in point):
        raise OpError(f"{where} control points must be finite")
    xs = [x for x, _ in points]
    if any(b <= a for a, b in zip(xs, xs[1:], strict=False)):
        raise OpError(f"{where} control points need strictly increasing x, got {xs}")
    if hard_range is not None and (xs[0] < hard_range[0] or xs[-1] > hard_range[1]):
        raise OpError(f"{where} x must lie in [{hard_range[0]:g}, {hard_range[1]:g}]")
    return points


@dataclass(frozen=True)
class OpSpec:
    """An operation: the pure function and everything a front end needs to offer it."""

    name: str
    label: str
    summary: str
    function: Callable[..., Any]
    params: tuple[ParamSpec, ...]
    #: linear in the edit values (op(a x + b y) == a op(x) + b op(y)): the
    #: principled ops of the seed paper, flagged so the UI can say so
    linear: bool
    #: reads a neighbourhood (has a ``border`` parameter)
    neighbourhood: bool = False
    #: parameter families it is meant for ("all" or space names)
    suits: tuple[str, ...] = ("all",)
    #: extra inputs beyond the edit array (e.g. the layer composited over),
    #: passed positionally; on the command line each is ``name=PATH`` of a texture set
    inputs: tuple[str, ...] = field(default_factory=tuple)
    #: like ``inputs`` but optional, passed by keyword (e.g. a clone's source)
    optional_inputs: tuple[str, ...] = field(default_factory=tuple)
    #: checks across parameters and against the target, run by :meth:`bind`
    checks: tuple[Check, ...] = ()
    #: texels of context one output texel reads (:data:`WHOLE_IMAGE`: all of them).
    #: Required for neighbourhood ops; pointwise ops read 0
    reach: ReachRule | None = None

    def __post_init__(self) -> None:
        if self.reach is None:
            if self.neighbourhood:
                raise TypeError(f"op {self.name!r} reads a neighbourhood: declare its reach")
            object.__setattr__(self, "reach", pointwise)

    @property
    def all_inputs(self) -> tuple[str, ...]:
        return self.inputs + self.optional_inputs

    def param(self, name: str) -> ParamSpec:
        for spec in self.params:
            if spec.name == name:
                return spec
        known = ", ".join(p.name for p in self.params)
        raise OpError(f"{self.name}: unknown parameter {name!r} (has: {known})")

    def bind(self, values: Mapping[str, Any], target: OpTarget | None = None) -> dict[str, Any]:
        """Defaults filled in, every value validated, alone, against the others and
        against ``target`` as far as it is known: ready to call ``function``.

        Raises :class:`OpError` (an :class:`~matshop.errors.InvalidValue`);
        nothing that binds fails for its parameters when it runs.
        """
        bound = {}
        for key in values:
            self.param(key)  # unknown names fail loudly
        for spec in self.params:
            if spec.name in values:
                bound[spec.name] = spec.validate(values[spec.name], self.name)
            elif spec.required:
                raise OpError(f"{self.name}: parameter {spec.name!r} is required")
            else:
                bound[spec.name] = spec.default
        self.check(bound, target)
        return bound

    def check(self, bound: Mapping[str, Any], target: OpTarget | None = None) -> None:
        """Run the op's cross-parameter and target checks on already typed values."""
        for check in self.checks:
            check(bound, target or OpTarget())

    def reach_of(self, bound: Mapping[str, Any], target: OpTarget | None = None) -> Reach:
        """Texels of context the op reads around each output texel (None: the whole image)."""
        assert self.reach is not None  # set in __post_init__
        return self.reach(bound, target or OpTarget())

    def parse_args(self, pairs: Sequence[str]) -> dict[str, Any]:
        """``["sigma_px=4", "border=clamp"]`` -> typed, unvalidated values.

        Inputs (``over=PATH``) stay strings: the caller loads them.
        """
        values = {}
        for pair in pairs:
            key, sep, text = pair.partition("=")
            key, text = key.strip(), text.strip()
            if not sep:
                raise OpError(f"{self.name}: expected key=value, got {pair!r}")
            if key in self.all_inputs:
                if not text:
                    raise OpError(f"{self.name}: {key}= needs the path of a texture set")
                values[key] = text
            else:
                values[key] = self.param(key).parse(text, self.name)
        return values


BORDER = ParamSpec(
    "border",
    "choice",
    "wrap",
    "how neighbourhoods treat the image edge: wrap (tiling textures) or clamp",
    choices=("wrap", "clamp"),
)
