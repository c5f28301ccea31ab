"""``matshop layer add|list|set|remove PROJECT ...``: edit a project's layer stack."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ...errors import MatshopError, naming
from ...io.project import save_project
from ...layers import AddLayer, Document, History, RemoveLayer, SetMask, SetProperty
from ...layers.layer import PaintLayer
from ...layers.properties import PROPERTIES, parse_generator
from ...paint import Swatch
from ..project import about_project, find_layer, names, open_project


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = "Edit the layer stack of a project."
    actions = parser.add_subparsers(dest="layer_action", metavar="ACTION", required=True)
    add = actions.add_parser(
        "add",
        help="add a paint, fill, filter or group layer on top (or at --index, or into --group), "
        "or an image as a paint layer's values or as a layer's mask",
        epilog="examples: layer add p.matshop fill --value base_color=0.6,0.25,0.1 "
        "--value roughness=0.8 | layer add p.matshop fill --from rust/ --mask m.png | "
        "layer add p.matshop filter --op bilateral sigma_px=6 | layer add p.matshop paint | "
        "layer add p.matshop image decal.png --params base_color | "
        "layer add p.matshop image bumps.png --as-height --height-px 6 | "
        "layer add p.matshop image dirt.png --as-mask --layer Rust. An image of another "
        "size than the project is resampled to it (area-averaged down, bilinear up), "
        "with a note.",
    )
    add.add_argument("project", type=Path, metavar="PROJECT")
    add.add_argument("kind", choices=("paint", "fill", "filter", "group", "image"))
    add.add_argument(
        "file",
        nargs="?",
        type=Path,
        metavar="FILE",
        help="image: the image (its alpha, if any, is the layer's coverage)",
    )
    add.add_argument(
        "--as-height",
        action="store_true",
        help="image: FILE is a height map, made into normals (the layer affects normal)",
    )
    add.add_argument(
        "--height-px",
        type=float,
        help="image --as-height: texel widths of displacement FILE's full range spans (8)",
    )
    add.add_argument(
        "--as-mask",
        action="store_true",
        help="image: make FILE (gray, or a color image's luminance) the mask of --layer",
    )
    add.add_argument(
        "--layer", dest="masked", help="image --as-mask: the layer to mask (default: the top one)"
    )
    add.add_argument("--name")
    add.add_argument("--opacity", type=float)
    add.add_argument("--blend", help="normal, add, subtract, multiply or detail")
    add.add_argument(
        "--params",
        help="parameters the layer affects (default: all); image: those taking its values",
    )
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
        help="a mask generated from the normals of the material below the layer, kept up "
        "to date as the layers below change: cavity, edge or ao, with radius_px (4), "
        "level (0.5), contrast (1), blur_px (0), invert (false); e.g. --mask-generator "
        "cavity radius_px=6 contrast=2 (change it later with layer set ... "
        "'mask_generator=edge radius_px=3', or mask_generator=none)",
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
    if getattr(args, "mask_generator", None):
        if args.mask is not None:
            raise MatshopError("give --mask or --mask-generator, not both")
        if "normal" not in doc.schema.names:
            raise MatshopError(
                f"--mask-generator {args.mask_generator[0][:40]} needs a normal map; "
                "the project has none",
                args.project,
            )
        with naming(what="--mask-generator"):
            props["mask_generator"] = parse_generator(" ".join(args.mask_generator))
    parameters = names(args.params)
    image = args.kind == "image"
    misplaced = {
        "--value": args.value and args.kind != "fill",
        "--from": args.source is not None and args.kind != "fill",
        "--op": args.op is not None and args.kind != "filter",
        "FILE": args.file is not None and not image,
        "--as-height": args.as_height and not image,
        "--height-px": args.height_px is not None and not args.as_height,
        "--as-mask": args.as_mask and not image,
        "--layer": args.masked is not None and not args.as_mask,
    }
    for option, wrong in misplaced.items():
        if wrong:
            raise MatshopError(f"{option} does not apply to a {args.kind} layer")
    if image and args.file is None:
        raise MatshopError("an image layer needs the image: layer add PROJECT image FILE ...")
    if args.as_mask:
        return _image_as_mask(args, doc, history, settings)
    content: dict = {}
    if args.kind == "fill":
        if bool(args.value) == (args.source is not None):
            raise MatshopError("a fill layer needs --value PARAM=V... or --from TEXTURE_SET")
        if args.value:
            value, defined = _fill_from_values(doc, args.value)
            content["value"] = value
        else:
            content["source"], defined = _fill_from_set(doc, args.source)
        # a fill only affects what it defines, unless told otherwise
        parameters = parameters or defined
    elif args.kind == "filter":
        if not args.op:
            raise MatshopError("a filter layer needs --op NAME [KEY=VALUE ...]")
        spec = get_op(args.op[0])
        content.update(op=spec.name, op_params=spec.parse_args(args.op[1:]))
    if image:
        layer = _image_layer(args, doc, parameters, props)
        if parameters is not None:
            layer.put("parameters", layer.validate("parameters", parameters, doc.schema))
    else:
        if parameters is not None:
            props["parameters"] = parameters
        layer = doc.new_layer(args.kind, args.name, **content, **props)
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
    history.push(AddLayer(layer, index))
    if args.mask is not None:
        from ...api import load_mask

        history.push(SetMask(layer.id, doc.new_mask(array=load_mask(args.mask, doc.size))))
    save_project(doc, args.project, settings=settings)
    print(f"added {layer.kind} layer {layer.id} {layer.name!r}")
    return 0


def _image_layer(
    args: argparse.Namespace, doc: Document, parameters: tuple[str, ...] | None, props: dict
) -> PaintLayer:
    """The paint layer holding FILE's values for --params (or normals from a height)."""
    from ...image_content import HEIGHT_PX, image_layer

    if args.as_height:
        parameters = parameters or ("normal",)
    elif not parameters:
        raise MatshopError(
            "an image layer needs --params (the parameters taking its values), "
            "--as-height (normals from a height map) or --as-mask"
        )
    height_px = HEIGHT_PX if args.height_px is None else args.height_px
    layer, notes = image_layer(
        doc,
        args.file,
        parameters,
        name=args.name,
        as_height=args.as_height,
        height_px=height_px,
        **props,
    )
    for note in notes:
        print(note)
    return layer


def _image_as_mask(
    args: argparse.Namespace, doc: Document, history: History, settings: dict
) -> int:
    """``layer add PROJECT image FILE --as-mask [--layer LAYER]``: FILE masks that layer."""
    from ...image_content import image_mask

    others = {
        "--params": args.params,
        "--as-height": args.as_height,
        "--name": args.name,
        "--opacity": args.opacity is not None,
        "--blend": args.blend,
        "--index": args.index is not None,
        "--group": args.group,
        "--mask": args.mask,
        "--mask-generator": getattr(args, "mask_generator", None),
    }
    for option, given in others.items():
        if given:
            raise MatshopError(f"{option} does not apply with --as-mask (the image is a mask)")
    if args.masked is not None:
        layer = find_layer(doc, args.masked, args.project)
    elif len(doc):
        layer = doc.layers[-1]
    else:
        raise MatshopError("the project has no layer to mask", args.project)
    mask, notes = image_mask(doc, args.file)
    history.push(SetMask(layer.id, mask))
    save_project(doc, args.project, settings=settings)
    for note in notes:
        print(note)
    print(f"masked layer {layer.id} {layer.name!r} with {args.file.name}")
    return 0


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
        with naming(what=f"layer {layer.name!r}"):
            history.push(SetProperty(layer.id, name, PROPERTIES[name].from_text(text)))
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
