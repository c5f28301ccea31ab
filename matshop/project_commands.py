"""What the project verbs do (parsing lives in :mod:`matshop.project_verbs`)."""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .errors import MatshopError, naming
from .io.project import find_recovery, load_project, save_project
from .layers import AddLayer, Document, History, Layer, RemoveLayer, SetMask, SetProperty
from .layers.layer import PaintLayer
from .material import Schema
from .paint import Swatch
from .paint.painter import StrokeSession
from .paint.strokefile import load_strokes

MAX_SIDE = 65536


def run(args: argparse.Namespace) -> int:
    handlers = {
        "new": cmd_new,
        "layer-add": cmd_layer_add,
        "layer-list": cmd_layer_list,
        "layer-set": cmd_layer_set,
        "layer-remove": cmd_layer_remove,
        "paint": cmd_paint,
        "flatten": cmd_flatten,
        "recover": cmd_recover,
    }
    with naming(args.project):  # every message names the project it is about
        return handlers[args.action](args)


def _names(text: str | None) -> list[str] | None:
    return None if text is None else [n.strip() for n in text.split(",") if n.strip()]


def _size(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not match:
        raise MatshopError(f"--size expects WIDTHxHEIGHT, got {text!r}")
    width, height = int(match[1]), int(match[2])
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        raise MatshopError(f"--size must be 1 to {MAX_SIDE} texels per side, got {text}")
    return height, width


def cmd_new(args: argparse.Namespace) -> int:
    path: Path = args.project
    if path.exists() and not args.force:
        raise MatshopError("already exists (use --force to overwrite)", path)
    _refuse_to_replace_autosave(path)
    if args.source is not None:
        from .io.material_io import load_material

        if args.size or args.params:
            raise MatshopError("--size and --params are for empty documents, not with --from")
        from .cli import load_options

        material, _ = load_material(args.source, **load_options(args))
        doc = Document.from_material(material)
    else:
        if not args.size or not args.params:
            raise MatshopError("give --from TEXTURE_SET, or --size and --params for an empty one")
        try:
            schema = Schema.from_names(_names(args.params) or [])
        except (KeyError, ValueError) as exc:
            raise MatshopError(f"--params: {exc}") from None
        height, width = _size(args.size)
        doc = Document(schema, height, width, name=path.name.split(".")[0])
    save_project(doc, path)
    print(f"created {path}: {doc.width}x{doc.height}, {', '.join(doc.schema.names)}")
    return 0


def _refuse_to_replace_autosave(path: Path) -> None:
    """A save removes the project's autosave: never do that to one newer than the project."""
    recovery = find_recovery(path)
    if recovery is not None:
        raise MatshopError(
            f"has a newer autosave ({recovery.name}) that saving would discard: "
            f"`matshop recover {path}` restores it, or delete it to discard it",
            path,
        )


def _open(path: Path, *, for_writing: bool = True) -> tuple[Document, History, dict]:
    """Load a project; a verb that will save it first makes sure no autosave is lost."""
    if for_writing:
        _refuse_to_replace_autosave(path)
    project = load_project(path)
    recovery = None if for_writing else find_recovery(path)
    if recovery is not None:
        print(
            f"matshop: note: {path} has a newer autosave ({recovery.name}); "
            f"`matshop recover {path}` restores it",
            file=sys.stderr,
        )
    return project.document, History(project.document), project.settings


def cmd_recover(args: argparse.Namespace) -> int:
    recovery = find_recovery(args.project)
    if recovery is None:
        raise MatshopError("has no autosave newer than itself", args.project)
    project = load_project(recovery)  # a damaged autosave fails here, the project untouched
    save_project(project.document, args.project, settings=project.settings)  # discards it
    print(f"restored {args.project} from {recovery.name}")
    return 0


def find_layer(doc: Document, key: str | int, path: Path | None = None) -> Layer:
    """A layer by name, or by id (a number that is no layer's name)."""
    if isinstance(key, str):
        named = [layer for layer in doc if layer.name == key]
        if len(named) == 1:
            return named[0]
        if len(named) > 1:
            raise MatshopError(f"{len(named)} layers are named {key!r}: use the id", path)
        if not key.isdigit():
            raise MatshopError(f"no layer named {key!r} ({_layer_names(doc)})", path)
    layer_id = int(key)
    for layer in doc:
        if layer.id == layer_id:
            return layer
    raise MatshopError(f"no layer with id {layer_id} ({_layer_names(doc)})", path)


def _layer_names(doc: Document) -> str:
    return "layers: " + (", ".join(f"{layer.id} {layer.name!r}" for layer in doc) or "none")


def _fill_from_values(doc: Document, pairs: Sequence[str]) -> tuple[np.ndarray, list[str]]:
    values = {}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        if not sep:
            raise MatshopError(f"--value expects PARAM=V[,V...], got {pair!r}")
        try:
            values[name.strip()] = [float(v) for v in text.split(",")]
        except ValueError:
            raise MatshopError(f"--value {name.strip()}: not numbers: {text!r}") from None
    try:
        vector, _ = Swatch("fill", values).edit_values(doc.schema)
    except ValueError as exc:
        raise MatshopError(f"--value: {exc}") from None
    return vector, list(values)


def _fill_from_set(doc: Document, source: Path) -> tuple[np.ndarray, list[str]]:
    from .io.material_io import load_material

    material, _ = load_material(source)
    if material.size != doc.size:
        raise MatshopError(
            f"is {material.size[1]}x{material.size[0]}, the project {doc.width}x{doc.height}",
            source,
        )
    edit = material.to_edit()
    data = np.empty((*doc.size, doc.channels), np.float32)
    data[...] = doc.background
    shared = edit.copy_into(doc.schema, data)
    if not shared:
        raise MatshopError(
            f"shares no parameter with the project (has {', '.join(edit.schema.names)})", source
        )
    return data, shared


def cmd_layer_add(args: argparse.Namespace) -> int:
    from .ops import get_op

    doc, history, settings = _open(args.project)
    props: dict = {}
    for key in ("opacity", "blend"):
        if getattr(args, key) is not None:
            props[key] = getattr(args, key)
    if args.hidden:
        props["visible"] = False
    parameters = _names(args.params)
    misplaced = {
        "--value": args.value and args.kind != "fill",
        "--from": args.source is not None and args.kind != "fill",
        "--op": args.op is not None and args.kind != "filter",
    }
    for option, wrong in misplaced.items():
        if wrong:
            raise MatshopError(f"{option} does not apply to a {args.kind} layer")
    try:
        if args.kind == "paint":
            layer = doc.new_paint_layer(args.name, **props)
        elif args.kind == "group":
            layer = doc.new_group_layer(args.name, **props)
        elif args.kind == "fill":
            if bool(args.value) == (args.source is not None):
                raise MatshopError("a fill layer needs --value PARAM=V... or --from TEXTURE_SET")
            if args.value:
                value, defined = _fill_from_values(doc, args.value)
                layer = doc.new_fill_layer(args.name, value=value, **props)
            else:
                data, defined = _fill_from_set(doc, args.source)
                layer = doc.new_fill_layer(args.name, source=data, **props)
            # a fill only affects what it defines, unless told otherwise
            parameters = parameters or defined
        else:
            if not args.op:
                raise MatshopError("a filter layer needs --op NAME [KEY=VALUE ...]")
            spec = get_op(args.op[0])
            layer = doc.new_filter_layer(
                spec.name, args.name, op_params=spec.parse_args(args.op[1:]), **props
            )
        if parameters is not None:
            layer.put("parameters", layer.validate("parameters", parameters, doc.schema))
    except ValueError as exc:
        raise MatshopError(str(exc), args.project) from None
    index = args.index
    if args.group is not None:
        group = find_layer(doc, args.group, args.project)
        if group.kind != "group":
            raise MatshopError(f"layer {group.name!r} is not a group", args.project)
        if index is not None:
            raise MatshopError("give --index or --group, not both")
        layer.put("parent", group.id)
        index = doc.index_of(group.id)  # members sit just below their group
    if index is not None and not 0 <= index <= len(doc):
        raise MatshopError(f"--index must be 0 to {len(doc)}", args.project)
    generated = None
    if getattr(args, "mask_generator", None):
        if args.mask is not None:
            raise MatshopError("give --mask or --mask-generator, not both")
        generated = _generated_mask(doc, args.mask_generator, args.project)
    history.push(AddLayer(layer, index))
    if args.mask is not None:
        from .api import load_mask

        history.push(SetMask(layer.id, doc.new_mask(array=load_mask(args.mask, doc.size))))
    if generated is not None:
        history.push(SetMask(layer.id, doc.new_mask(array=generated[..., None])))
    save_project(doc, args.project, settings=settings)
    print(f"added {layer.kind} layer {layer.id} {layer.name!r}")
    return 0


_GENERATOR_OPTIONS = {
    "radius_px": float,
    "level": float,
    "contrast": float,
    "blur_px": float,
    "invert": lambda text: _boolean("invert", text),
}


def _boolean(name: str, text: str) -> bool:
    value = text.strip().lower()
    if value not in ("true", "false", "1", "0", "yes", "no"):
        raise MatshopError(f"--mask-generator {name} must be true or false, got {text!r}")
    return value in ("true", "1", "yes")


def _generated_mask(doc: Document, words: Sequence[str], project: Path) -> np.ndarray:
    """The --mask-generator mask (H, W) from the document's normals as they are now."""
    from .ops.generators import GENERATORS, generate_mask

    name, *pairs = words
    if name not in GENERATORS:
        raise MatshopError(f"--mask-generator must be one of {', '.join(GENERATORS)}, got {name!r}")
    if "normal" not in doc.schema.names:
        raise MatshopError(
            f"--mask-generator {name} needs a normal map; the project has none", project
        )
    options = {}
    for pair in pairs:
        key, sep, text = pair.partition("=")
        if not sep or key not in _GENERATOR_OPTIONS:
            raise MatshopError(
                f"--mask-generator takes {', '.join(f'{k}=...' for k in _GENERATOR_OPTIONS)}, "
                f"got {pair!r}"
            )
        try:
            options[key] = _GENERATOR_OPTIONS[key](text)
        except ValueError:
            raise MatshopError(f"--mask-generator {key} must be a number, got {text!r}") from None
        if key != "invert" and not np.isfinite(options[key]):
            raise MatshopError(f"--mask-generator {key} must be finite, got {text!r}")
    normals = doc.physical()["normal"][..., :3]
    try:
        return generate_mask(normals, name, **options)
    except ValueError as exc:
        raise MatshopError(f"--mask-generator: {exc}") from None


def cmd_layer_list(args: argparse.Namespace) -> int:
    doc, _, _ = _open(args.project, for_writing=False)
    print(f"{args.project}: {doc.width}x{doc.height}, {', '.join(doc.schema.names)}")
    for index, layer in enumerate(doc):
        facts = [layer.kind, f"opacity {layer.opacity:g}", layer.blend]
        if not layer.visible:
            facts.append("hidden")
        if layer.parameters is not None:
            facts.append("affects " + ",".join(layer.parameters))
        if layer.mask is not None:
            facts.append("inverted mask" if layer.mask_inverted else "mask")
        if layer.parent is not None:
            facts.append(f"in group {layer.parent}")
        if isinstance(layer, PaintLayer):
            facts.append(f"{len(list(layer.pixels.keys()))} painted tiles")
        print(f"  {index:2d}  id {layer.id:<3d} {layer.name!r}: {', '.join(facts)}")
    return 0


def _property_value(name: str, text: str) -> object:
    if name in ("visible", "mask_inverted"):
        if text.lower() not in ("true", "false", "1", "0", "yes", "no"):
            raise MatshopError(f"{name} must be true or false, got {text!r}")
        return text.lower() in ("true", "1", "yes")
    if name == "opacity":
        try:
            return float(text)
        except ValueError:
            raise MatshopError(f"opacity must be a number, got {text!r}") from None
    if name == "parameters":
        return None if text.lower() in ("all", "") else _names(text)
    return text


def cmd_layer_set(args: argparse.Namespace) -> int:
    doc, history, settings = _open(args.project)
    layer = find_layer(doc, args.layer, args.project)
    for pair in args.settings:
        name, sep, text = pair.partition("=")
        name = name.strip()
        if not sep:
            raise MatshopError(f"expected KEY=VALUE, got {pair!r}")
        if name not in layer.PROPERTIES:
            known = ", ".join(layer.PROPERTIES)
            raise MatshopError(f"{layer.kind} layers have no property {name!r} (has: {known})")
        try:
            history.push(SetProperty(layer.id, name, _property_value(name, text.strip())))
        except ValueError as exc:
            raise MatshopError(f"layer {layer.name!r}: {exc}", args.project) from None
    save_project(doc, args.project, settings=settings)
    print(f"changed layer {layer.id} {layer.name!r}")
    return 0


def cmd_layer_remove(args: argparse.Namespace) -> int:
    doc, history, settings = _open(args.project)
    layer = find_layer(doc, args.layer, args.project)
    history.push(RemoveLayer(layer.id))
    save_project(doc, args.project, settings=settings)
    print(f"removed layer {layer.id} {layer.name!r}")
    return 0


def cmd_paint(args: argparse.Namespace) -> int:
    strokes = load_strokes(args.stroke)  # a bad stroke file fails before the project is read
    doc, history, settings = _open(args.project)
    default = find_layer(doc, args.layer, args.project) if args.layer else None
    if default is None:
        painted = [layer for layer in doc if isinstance(layer, PaintLayer)]
        default = painted[-1] if painted else None
    total = 0
    for number, stroke in enumerate(strokes, 1):
        if stroke.layer is not None:
            layer = find_layer(doc, stroke.layer, args.stroke)
        elif default is not None:
            layer = default
        else:
            raise MatshopError(
                "no paint layer: add one with `matshop layer add PROJECT paint`", args.project
            )
        try:
            session = StrokeSession(doc, layer.id, stroke.brush, history=history, **stroke.options)
        except ValueError as exc:
            raise MatshopError(f"stroke {number}: {exc}", args.stroke) from None
        if session.note:
            print(f"stroke {number}: {session.note}")
            if stroke.layer is None:  # later strokes go where this one went
                default = doc.layer(session.layer_id)
        session.add(stroke.samples)
        session.end()
        total += session.dabs
    save_project(doc, args.project, settings=settings)
    print(f"painted {len(strokes)} stroke(s), {total} dabs, into {args.project}")
    return 0


def cmd_flatten(args: argparse.Namespace) -> int:
    from .io.material_io import save_material
    from .progress import progress_bar

    doc, _, _ = _open(args.project, for_writing=False)
    material = doc.flatten_physical()
    with progress_bar("writing") as report:
        written = save_material(material, args.output, overwrite=args.force, progress=report)
    for path in written:
        print(f"wrote {path}")
    return 0
