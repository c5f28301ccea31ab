"""Batch recipes: an op chain in TOML (the CLI's own words), or a ``.matshop`` look.

    [[ops]]
    op = "blur"
    sigma_px = 2
    params = ["normal", "roughness"]
    mask = "masks/edges.png"        # relative to the recipe

    [export]                        # optional: write for an engine instead of raw maps
    preset = "gltf"
    size = 1024
    glb = true

Everything is checked when the recipe loads, before any set is touched: an
unknown op, key or parameter, a value out of range, a missing mask file, an
unknown preset. Each problem is one :class:`MatshopError` naming the file and
the key. Op settings go through the op registry (``parse_args`` for text in
the CLI's spelling, ``bind`` for every value), the same checks ``apply`` runs.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from ..io.inputs import is_project
from ..material import PARAMETER_KINDS
from ..opchain import Step, checked
from ..ops import OpError, get_op
from ..ops.selection import PARAMETER_ALIASES

_OP_KEYS = ("op", "params", "mask")
_EXPORT_KEYS = ("preset", "size", "glb", "mtlx", "strict")
#: op parameter kinds whose text is a file, taken relative to the recipe
_FILE_KINDS = ("path", "region")


@dataclass(frozen=True)
class ExportPlan:
    """The recipe's ``[export]`` table: write for an engine instead of raw maps."""

    preset: str
    size: int | None = None
    glb: bool = False
    mtlx: bool = False
    strict: bool = False


@dataclass(frozen=True)
class Recipe:
    """What every set of a batch gets: an op chain or a look, then raw maps or an export."""

    source: Path
    steps: tuple[Step, ...] = ()
    #: a ``.matshop`` project whose layers above its base are applied instead of steps
    look: Path | None = None
    export: ExportPlan | None = None

    def with_export(self, preset: str | None, size: int | None) -> Recipe:
        """The recipe with the command line's ``--preset`` / ``--size`` over its ``[export]``."""
        if preset is None and size is None:
            return self
        base = self.export or ExportPlan("")
        plan = replace(base, preset=preset or base.preset, size=base.size if size is None else size)
        if not plan.preset:
            raise MatshopError("--size needs an export preset (--preset or [export] preset)")
        _check_export(plan, "--")
        return replace(self, export=plan)


def load_recipe(path: str | os.PathLike[str]) -> Recipe:
    """Read and fully validate the recipe at ``path`` (TOML, or a ``.matshop`` look)."""
    path = Path(path)
    if not path.is_file():
        raise MatshopError("recipe not found", path)
    if is_project(path):
        from .look import check_look

        check_look(path)
        return Recipe(path, look=path.resolve())
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise MatshopError(f"not a TOML recipe: {exc}", path) from None
    except OSError as exc:
        raise MatshopError(f"cannot read: {exc.strerror or exc}", path) from None
    _only(data, ("ops", "export"), "", path)
    ops = data.get("ops", [])
    if not isinstance(ops, list) or not all(isinstance(t, dict) for t in ops):
        raise MatshopError("ops must be [[ops]] tables", path)
    export = _export(data["export"], path) if "export" in data else None
    if not ops and export is None:
        raise MatshopError("the recipe has no [[ops]] and no [export]: nothing to do", path)
    steps = tuple(_step(table, f"ops[{i}]", path) for i, table in enumerate(ops, 1))
    return Recipe(path, steps, export=export)


def _only(table: dict[str, Any], known: tuple[str, ...], where: str, path: Path) -> None:
    for key in table:
        if key not in known:
            raise MatshopError(f"{where}{key}: unknown key (expected {', '.join(known)})", path)


def _step(table: dict[str, Any], where: str, path: Path) -> Step:
    name = table.get("op")
    if not isinstance(name, str):
        raise MatshopError(f'{where}.op: each [[ops]] table needs op = "NAME"', path)
    try:
        spec = get_op(name)
        values = {}
        for key, value in table.items():
            if key in _OP_KEYS:
                continue
            values[key] = _value(spec, key, value, path.resolve().parent)
        checked(name, values)
    except OpError as exc:
        raise MatshopError(f"{where} ({name}): {exc.problem}", path) from None
    params = _params(table.get("params"), f"{where}.params", path)
    mask = None
    if "mask" in table:
        mask = _file(table["mask"], f"{where}.mask", path)
        _readable_image(mask, f"{where}.mask", path)
    return Step(name, values, params, mask)


def _value(spec: Any, key: str, value: Any, base: Path) -> Any:
    """A TOML value as the registry takes it: text in the CLI's spelling is parsed."""
    if key in spec.all_inputs:
        if not isinstance(value, str) or not value:
            raise OpError(f"{spec.name}: {key} needs the path of a texture set")
        found = base / value
        if not found.exists():
            raise OpError(f"{spec.name}: {key}={value!r} not found beside the recipe")
        return str(found)
    param = spec.param(key)  # unknown keys fail here, naming the op's parameters
    if not isinstance(value, str) or param.kind == "choice":
        return value
    parsed = param.parse(value, spec.name)
    if param.kind in _FILE_KINDS and isinstance(parsed, Path) and not parsed.is_absolute():
        return base / parsed
    return parsed


def _params(value: Any, where: str, path: Path) -> tuple[str, ...] | None:
    if value is None:
        return None
    names = value.split(",") if isinstance(value, str) else value
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        raise MatshopError(f'{where}: a list of parameter names, e.g. ["normal"]', path)
    known = set(PARAMETER_KINDS) | set(PARAMETER_ALIASES)
    for name in names:
        if name.strip().lower() not in known:
            raise MatshopError(
                f"{where}: no parameter {name!r} (known: {', '.join(PARAMETER_KINDS)})", path
            )
    return tuple(n.strip() for n in names)


def _file(value: Any, where: str, path: Path) -> Path:
    if not isinstance(value, str) or not value:
        raise MatshopError(f"{where}: the path of a file, relative to the recipe", path)
    found = path.resolve().parent / value
    if not found.is_file():
        raise MatshopError(f"{where}: {value!r} not found beside the recipe", path)
    return found


def _readable_image(file: Path, where: str, path: Path) -> None:
    from ..io.images import read_image

    try:
        read_image(file)
    except MatshopError as exc:
        raise MatshopError(f"{where}: {exc}", path) from None


def _export(table: Any, path: Path) -> ExportPlan:
    if not isinstance(table, dict):
        raise MatshopError("export must be an [export] table", path)
    _only(table, _EXPORT_KEYS, "export.", path)
    preset = table.get("preset")
    if not isinstance(preset, str) or not preset:
        raise MatshopError("export.preset: a built-in preset name is required", path)
    size = table.get("size")
    if size is not None and (isinstance(size, bool) or not isinstance(size, int)):
        raise MatshopError(f"export.size: a whole number of texels, got {size!r}", path)
    flags = {}
    for key in ("glb", "mtlx", "strict"):
        flags[key] = table.get(key, False)
        if not isinstance(flags[key], bool):
            raise MatshopError(f"export.{key}: true or false, got {flags[key]!r}", path)
    plan = ExportPlan(preset, size, **flags)
    try:
        _check_export(plan, "export.")
    except MatshopError as exc:
        raise MatshopError(exc.problem, path) from None
    return plan


def _check_export(plan: ExportPlan, where: str) -> None:
    from ..export.presets import builtin_preset_names
    from ..export.resize import is_power_of_two

    names = builtin_preset_names()
    if plan.preset not in names:
        raise MatshopError(
            f"{where}preset: unknown preset {plan.preset!r} (built in: {', '.join(names)})"
        )
    if plan.size is not None and not is_power_of_two(plan.size):
        raise MatshopError(f"{where}size: a power of two (256, 512, 1024...), got {plan.size}")
