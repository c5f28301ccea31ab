"""What each ``matshop`` verb does; :mod:`matshop.cli` only parses arguments."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from .errors import MatshopError
from .io.material_io import LoadReport, load_material, save_material
from .io.textureset import TextureSet
from .material import EditMaterial, Material
from .progress import progress_bar

_ENCODINGS = {
    "srgb": "sRGB (exact)",
    "gamma22": "gamma 2.2",
}


def run(args: argparse.Namespace) -> int:
    handler = {
        "info": cmd_info,
        "convert": cmd_convert,
        "apply": cmd_apply,
        "ops": cmd_ops,
        "spaces": cmd_spaces,
        "demo": cmd_demo,
    }
    return handler[args.verb](args)


def _load(path: Path, args: argparse.Namespace) -> tuple[Material, LoadReport]:
    from .cli import load_options

    return load_material(path, **load_options(args))


def _encoding(material: Material, name: str) -> str:
    space = material.schema[name].space.name
    if space in _ENCODINGS:
        return _ENCODINGS[space]
    source = material.sources.get(name, {})
    if "convention" in source:
        return f"{source['convention']} normals ({source['convention_source']})"
    if "inverted" in source:
        return "linear (inverted gloss)"
    if "packed" in source:
        return f"linear ({source['packed']} channel {'RGBA'[source['channel']]})"
    return "linear"


def describe(material: Material, report: LoadReport) -> str:
    """The human-readable summary ``matshop info`` prints."""
    height, width = material.size
    ts = report.texture_set
    lines = [f"texture set {material.name!r} in {ts.folder}: {width} x {height} texels", ""]
    header = ("parameter", "file", "format", "depth", "encoding", "edit space")
    rows = []
    for param in material.schema.parameters:
        source = material.sources.get(param.name, {})
        file = Path(source.get("file", "-")).name
        info = next((i for i in report.infos.values() if Path(i.path).name == file), None)
        rows.append(
            (
                param.name,
                file,
                info.format if info else "-",
                info.bit_depth if info else source.get("bit_depth", "-"),
                _encoding(material, param.name),
                f"{param.space.name} ({param.phys_channels}->{param.edit_channels})",
            )
        )
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    for row in [header, *rows]:
        cells = (str(c).ljust(w) for c, w in zip(row, widths, strict=True))
        lines.append(("  " + "  ".join(cells)).rstrip())
    lines.append("")
    lines.append(
        f"edit vector: {material.schema.edit_width} channels per texel "
        f"({', '.join(f'{n} {s}' for n, s in _slices(material))})"
    )
    lines.extend(report.notes)
    lines.extend(f"not used: {name} ({why})" for name, why in not_used(ts))
    return "\n".join(lines)


def not_used(ts: TextureSet) -> list[tuple[str, str]]:
    """(file name, why) for every file beside the set that is not loaded."""
    rows = [(p.name, "name matches no map") for p in ts.unrecognised]
    rows += [
        (p.name, f"the other {slot} convention") for slot, ps in ts.alternates.items() for p in ps
    ]
    rows += [(p.name, why) for p, why in ts.not_used.items()]
    return sorted(rows)


def _slices(material: Material) -> list[tuple[str, str]]:
    return [(name, f"[{sl.start}:{sl.stop}]") for name, sl in material.schema.edit_slices.items()]


def cmd_info(args: argparse.Namespace) -> int:
    from .io.inputs import is_project

    if is_project(args.path):  # a project: its size, parameters and layer stack
        from .project_commands import cmd_layer_list

        return cmd_layer_list(argparse.Namespace(project=args.path))
    material, report = _load(args.path, args)
    print(describe(material, report))
    return 0


def roundtrip_errors(before: Material, after: Material) -> dict[str, str]:
    """Worst error per parameter, in the unit a user reads it in."""
    errors = {}
    for param in before.schema.parameters:
        a = before.maps[param.name].astype(np.float64)
        b = after.maps[param.name].astype(np.float64)
        if param.name == "normal":
            cos = np.clip(np.sum(a[..., :3] * b[..., :3], axis=-1), -1.0, 1.0)
            errors[param.name] = f"{np.degrees(np.arccos(cos.min())):.3f} deg"
        elif param.phys_channels > 3:
            scale = np.abs(a).sum(axis=-1).mean()
            rel = np.abs(a - b).sum(axis=-1).mean() / max(scale, 1e-12)
            errors[param.name] = f"{100 * rel:.3f}% mean relative L1"
        else:
            errors[param.name] = f"{255 * np.abs(a - b).max():.3f} / 255"
    return errors


def convert(
    input_path: Path,
    output: Path,
    *,
    args: argparse.Namespace,
    sampled_distribution: bool = False,
    force: bool = False,
) -> tuple[Material, list[Path], dict[str, str]]:
    """import -> edit space -> back -> write; returns what was written and the errors."""
    material, _ = _load(input_path, args)
    if sampled_distribution:
        from .derive import with_sampled_distribution

        material = with_sampled_distribution(material)
    with progress_bar("to edit space") as report:
        edit = material.to_edit(progress=report)
    with progress_bar("from edit space") as report:
        back = edit.to_physical(progress=report)
    with progress_bar("writing") as report:
        written = save_material(back, output, overwrite=force, progress=report)
    return back, written, roundtrip_errors(material, back)


def print_convention(material: Material | EditMaterial) -> None:
    """Say how the normal map was read: a wrong guess would flip every file written."""
    from .io.normal_convention import convention_line

    line = convention_line(material.sources)
    if line is not None:
        print(line)


def cmd_convert(args: argparse.Namespace) -> int:
    back, written, errors = convert(
        args.input,
        args.output,
        args=args,
        sampled_distribution=args.sampled_distribution,
        force=args.force,
    )
    print_convention(back)
    for path in written:
        print(f"wrote {path}")
    for name, error in errors.items():
        print(f"round trip {name}: worst error {error}")
    return 0


def cmd_apply(args: argparse.Namespace) -> int:
    from .api import EditableMaterial
    from .cli import load_options
    from .opchain import run_steps, step_from_words
    from .ops import get_op

    # parse every op before any work, so a typo in the last one costs nothing
    params = None if args.params is None else args.params.split(",")
    steps = [step_from_words(words, params=params, mask=args.mask) for words in args.op]
    m = EditableMaterial.from_path(args.input, **load_options(args))
    print_convention(m.edit)
    with progress_bar("applying") as report:
        run_steps(m, steps, progress=report)
    with progress_bar("writing") as report:
        written = m.save(args.output, overwrite=args.force, progress=report)
    for name, bound, names in m.history:
        spec = get_op(name)
        settings = " ".join(f"{k}={spec.param(k).format(v)}" for k, v in bound.items())
        print(f"applied {name} {settings} to {', '.join(names)}")
    for path in written:
        print(f"wrote {path}")
    return 0


def cmd_ops(args: argparse.Namespace) -> int:
    from .ops import all_ops

    for spec in all_ops().values():
        kind = "linear" if spec.linear else "non-linear"
        print(f"{spec.name}: {spec.summary} ({kind})")
        for extra in spec.all_inputs:
            need = "required" if extra in spec.inputs else "optional"
            print(f"    {extra + '=PATH':<26s} another texture set ({need})")
        for param in spec.params:
            facts = []
            if param.unit:
                facts.append(param.unit)
            if param.hard_range and param.kind in ("float", "int"):
                facts.append(f"{param.hard_range[0]:g} to {param.hard_range[1]:g}")
            if param.choices:
                facts.append(" | ".join(param.choices))
            setting = f"{param.name}={param.format(param.default)}"
            print(f"    {setting:<26s} {param.doc}" + (f" ({'; '.join(facts)})" if facts else ""))
    return 0


def cmd_spaces(args: argparse.Namespace) -> int:
    from .material import PARAMETER_KINDS
    from .spaces import all_spaces

    spaces = sorted(all_spaces().items())
    defaults: dict[str, list[str]] = {}
    for kind in PARAMETER_KINDS.values():
        defaults.setdefault(kind.default_space, []).append(kind.name)
    # several names may register one space (same kind, same meaning): the first
    # name in order is the space, the others its aliases
    first_name: dict[tuple, str] = {}
    for name, space in spaces:
        first_name.setdefault((type(space), space.description), name)
    rows = [("space", "channels", "default for", "meaning")]
    for name, space in spaces:
        primary = first_name[(type(space), space.description)]
        meaning = space.description if primary == name else f"alias of {primary}"
        channels = f"{space.phys_channels} -> {space.edit_channels}"
        rows.append((name, channels, ", ".join(defaults.get(name, [])) or "-", meaning))
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    for row in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(row[:3], widths, strict=True)), row[3])
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    sample = args.sample or Path(__file__).resolve().parent.parent / "resources" / "sample"
    if not sample.exists():
        raise MatshopError("bundled sample not found (run scripts/make_sample.py)", sample)
    # the editor is not built yet: until it is, the demo is headless everywhere
    material, report = _load(sample, _defaults(args))
    print(describe(material, report))
    print()
    for label, sub, sampled in (
        ("round trip through edit space", "roundtrip", False),
        ("with a sampled 128-bin distribution", "sampled", True),
    ):
        back, written, errors = convert(
            sample,
            args.out / sub,
            args=_defaults(args),
            sampled_distribution=sampled,
            force=True,
        )
        print(f"{label}: {len(written)} files in {args.out / sub}")
        for name, error in errors.items():
            print(f"  {name:14s} worst error {error}")
    _demo_layers(material, args.out)
    return 0


def _demo_layers(material: Material, out: Path) -> None:
    """A layered project: a bronze brush stroke, then rust through a gradient mask."""
    import numpy as np

    from .io.material_io import save_material
    from .io.project import save_project
    from .layers import AddLayer, Document, History, SetMask
    from .paint import Brush, StrokeSample, StrokeSession, Swatch
    from .render.render import render

    doc = Document.from_material(material)
    history = History(doc)
    height, width = doc.size
    names = set(doc.schema.names)
    bronze = Swatch(
        "bronze",
        {
            k: v
            for k, v in {
                "base_color": (0.45, 0.25, 0.08),
                "roughness": (0.3,),
                "metallic": (1.0,),
                "normal": (0.0, 0.0, 1.0),
            }.items()
            if k in names
        },
    )
    paint = doc.new_paint_layer("Bronze", parameters=bronze.parameters)
    history.push(AddLayer(paint))
    stroke = StrokeSession(
        doc, paint.id, Brush(radius_px=width / 40, hardness=0.7), swatch=bronze, history=history
    )
    t = np.linspace(0.0, 1.0, 64)
    stroke.add(
        StrokeSample(width * (0.1 + 0.8 * x), height * (0.5 + 0.3 * np.sin(6 * x)), 0.3 + 0.7 * x)
        for x in t
    )
    stroke.end()
    if {"base_color", "roughness"} <= names:
        rust_value, _ = Swatch(
            "rust", {"base_color": (0.3, 0.08, 0.03), "roughness": (0.85,)}
        ).edit_values(doc.schema)
        rust = doc.new_fill_layer("Rust", value=rust_value, parameters=["base_color", "roughness"])
        history.push(AddLayer(rust))
        # a smooth periodic gradient across the (tiling) texture: no seam at its edge
        ramp = (0.5 - 0.5 * np.cos(np.linspace(0, 2 * np.pi, width, endpoint=False))).astype(
            np.float32
        )
        history.push(SetMask(rust.id, doc.new_mask(array=np.repeat(ramp[None, :], height, 0))))
    project = out / "layered.matshop"
    save_project(doc, project)
    flattened = doc.flatten_physical()
    written = save_material(flattened, out / "layered", overwrite=True)
    image = render(flattened, scene="sphere", size=256)
    from .io.images import write_image

    write_image(out / "layered_ball.png", image.display()[..., :3])
    print(
        f"layered project (a bronze stroke, rust through a gradient mask): {project}, "
        f"flattened to {len(written)} files in {out / 'layered'}, "
        f"rendered to {out / 'layered_ball.png'}"
    )


def _defaults(args: argparse.Namespace) -> argparse.Namespace:
    return argparse.Namespace(
        space=getattr(args, "space", []), normal_convention=None, material=None, map=[]
    )
