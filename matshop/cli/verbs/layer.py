"""``matshop layer add|list|set|remove PROJECT ...``: edit a project's layer stack."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ...errors import MatshopError, naming
from ...io.project import save_project
from ...layers import AddLayer, Document, RemoveLayer, SetMask, SetProperty
from ...layers.layer import PaintLayer
from ...paint import Swatch
from ..project import about_project, find_layer, names, open_project


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = "Edit the layer stack of a project."
    actions = parser.add_subparsers(dest="layer_action", metavar="ACTION", required=True)
    add = actions.add_parser(
        "add",
        help="add a paint, fill, filter or group layer on top (or at --index, or into --group)",
        epilog="examples: layer add p.matshop fill --value base_color=0.6,0.25,0.1 "
        "--value roughness=0.8 | layer add p.matshop fill --from rust/ --mask m.png | "
        "layer add p.matshop filter --op bilateral sigma_px=6 | layer add p.matshop paint",
    )
    add.add_argument("project", type=Path, metavar="PROJECT")
    add.add_argument("kind", choices=("paint", "fill", "filter", "group"))
    add.add_argument("--name")
    add.add_argument("--opacity", type=float)
    add.add_argument("--blend", help="normal, add, subtract, multiply or detail")
    add.add_argument("--params", help="parameters the layer affects (default: all)")
    add.add_argument("--hidden", action="store_true", help="add it hidden")
    add.add_argument("--index", type=int, help="stack position (0 = bottom; default: top)")
    add.add_argument("--group", help="put it into this group (just below the group layer)")
    add.add_argument(
        "--value",
        action="append",
        default=[],
        metavar="PARAM=V[,V...]",
        help="fill: a constant physical value (repeatable), e.g. roughness=0.8",
    )
    add.add_argument("--from", dest="source", type=Path, help="fill: a texture set")
    add.add_argument(
        "--op", nargs="+", metavar=("NAME", "KEY=VALUE"), help="filter: the op and its parameters"
    )
    add.add_argument("--mask", type=Path, help="grayscale image as the layer's mask")
    add.add_argument(
        "--mask-generator",
        nargs="+",
        metavar=("NAME", "KEY=VALUE"),
        help="a mask generated from the material's normals as they are when the layer is "
        "added: cavity, edge or ao, with radius_px (4), level (0.5), contrast (1), "
        "blur_px (0), invert (false); e.g. --mask-generator cavity radius_px=6 contrast=2",
    )
    add.set_defaults(run=cmd_layer_add)

    listing = actions.add_parser("list", help="list the layers, bottom to top")
    listing.add_argument("project", type=Path, metavar="PROJECT")
    listing.set_defaults(run=cmd_layer_list)

    change = actions.add_parser(
        "set",
        help="change layer properties: name, visible, opacity, blend, parameters",
        epilog="example: layer set p.matshop Rust opacity=0.5 blend=multiply visible=false",
    )
    change.add_argument("project", type=Path, metavar="PROJECT")
    change.add_argument("layer", metavar="LAYER", help="layer name or id")
    change.add_argument("settings", nargs="+", metavar="KEY=VALUE")
    change.set_defaults(run=cmd_layer_set)

    remove = actions.add_parser("remove", help="remove a layer")
    remove.add_argument("project", type=Path, metavar="PROJECT")
    remove.add_argument("layer", metavar="LAYER", help="layer name or id")
    remove.set_defaults(run=cmd_layer_remove)


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
    with naming(what="--value"):
        vector, _ = Swatch("fill", values).edit_values(doc.schema)
    return vector, list(values)


def _fill_from_set(doc: Document, source: Path) -> tuple[np.ndarray, list[str]]:
    from ...io.material_io import load_material

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


@about_project
def cmd_layer_add(args: argparse.Namespace) -> int:
    from ...ops import get_op

    doc, history, settings = open_project(args.project)
    props: dict = {}
    for key in ("opacity", "blend"):
        if getattr(args, key) is not None:
            props[key] = getattr(args, key)
    if args.hidden:
        props["visible"] = False
    parameters = names(args.params)
    misplaced = {
        "--value": args.value and args.kind != "fill",
        "--from": args.source is not None and args.kind != "fill",
        "--op": args.op is not None and args.kind != "filter",
    }
    for option, wrong in misplaced.items():
        if wrong:
            raise MatshopError(f"{option} does not apply to a {args.kind} layer")
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
        from ...api import load_mask

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
    from ...ops.generators import GENERATORS, generate_mask

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
    with naming(what="--mask-generator"):
        return generate_mask(normals, name, **options)


@about_project
def cmd_layer_list(args: argparse.Namespace) -> int:
    return list_layers(args.project)


def list_layers(project: Path) -> int:
    """Print the project's size, parameters and layers, bottom to top."""
    doc, _, _ = open_project(project, for_writing=False)
    print(f"{project}: {doc.width}x{doc.height}, {', '.join(doc.schema.names)}")
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
        return None if text.lower() in ("all", "") else names(text)
    return text


@about_project
def cmd_layer_set(args: argparse.Namespace) -> int:
    doc, history, settings = open_project(args.project)
    layer = find_layer(doc, args.layer, args.project)
    for pair in args.settings:
        name, sep, text = pair.partition("=")
        name = name.strip()
        if not sep:
            raise MatshopError(f"expected KEY=VALUE, got {pair!r}")
        if name not in layer.PROPERTIES:
            known = ", ".join(layer.PROPERTIES)
            raise MatshopError(f"{layer.kind} layers have no property {name!r} (has: {known})")
        value = _property_value(name, text.strip())
        with naming(what=f"layer {layer.name!r}"):
            history.push(SetProperty(layer.id, name, value))
    save_project(doc, args.project, settings=settings)
    print(f"changed layer {layer.id} {layer.name!r}")
    return 0


@about_project
def cmd_layer_remove(args: argparse.Namespace) -> int:
    doc, history, settings = open_project(args.project)
    layer = find_layer(doc, args.layer, args.project)
    history.push(RemoveLayer(layer.id))
    save_project(doc, args.project, settings=settings)
    print(f"removed layer {layer.id} {layer.name!r}")
    return 0
