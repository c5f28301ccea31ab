"""Every verb refuses a bad value the same way, through the real command line: one
line on stderr naming the value, exit status 2, no traceback, and nothing written
(no output folder, the inputs and the project byte for byte as they were).

The values come from what each verb documents: an op parameter outside the range
its spec declares (for every parameter of every registered op, through `apply`
and through `layer add ... filter`), a name no registry knows, text where a
number goes, a file field a preset or stroke file does not allow.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.images import write_image
from matshop.io.project import save_project
from matshop.layers import Document
from matshop.material import Schema
from matshop.ops import all_ops

SIZE = 16


@dataclass(frozen=True)
class Case:
    argv: list[str]
    #: what the one line must say (the option, parameter or field at fault)
    named: str
    #: files the case reads, written into its folder first: name -> JSON object or text
    files: dict[str, object] = field(default_factory=dict)


def _set(folder: Path) -> Path:
    folder.mkdir(parents=True)
    rng = np.random.default_rng(7)
    write_image(folder / "m_basecolor.png", rng.random((SIZE, SIZE, 3)).astype(np.float32))
    write_image(folder / "m_roughness.png", rng.random((SIZE, SIZE, 1)).astype(np.float32))
    normal = np.zeros((SIZE, SIZE, 3), np.float32)
    normal[..., 2] = 1.0
    write_image(folder / "m_normal.png", normal * 0.5 + 0.5)
    return folder


@pytest.fixture(scope="module")
def world(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("world")
    mask = np.zeros((SIZE, SIZE, 1), np.float32)
    mask[4:8, 4:8] = 1.0
    write_image(root / "mask.png", mask)
    doc = Document(Schema.from_names(["base_color", "roughness", "normal"]), SIZE, SIZE, name="p")
    doc.insert_layer(doc.new_paint_layer("Paint"))
    doc.insert_layer(doc.new_group_layer("Group"))
    save_project(doc, root / "p.matshop")
    return {"set": _set(root / "set"), "mask": root / "mask.png", "project": root / "p.matshop"}


# ------------------------------------------------------------------ op parameters


def _bad_words(kind: str, hard_range: tuple[float, float] | None) -> list[tuple[str, str]]:
    """(label, text) of values a parameter of ``kind`` refuses."""
    if kind in ("float", "int", "floats"):
        words = [("text", "abc"), ("nan", "nan")]
        if hard_range is not None:
            lo, hi = hard_range
            words += [("below", f"{lo - (hi - lo) - 1:g}"), ("above", f"{hi + (hi - lo) + 1:g}")]
        return words
    return {
        "choice": [("unknown", "bogus")],
        "bool": [("text", "maybe")],
        "points": [("text", "garbage"), ("decreasing", "0,0;0.8,0.5;0.2,1")],
        "region": [("missing", "{tmp}/no-such-mask.png")],  # named by its file
        "offset": [("infinite", "inf,0"), ("text", "abc")],
    }[kind]


def _op_cases() -> dict[str, Case]:
    cases = {}
    for spec in all_ops().values():
        needs = [f"{name}={{set}}" for name in spec.inputs]  # another texture set
        if any(p.kind == "region" for p in spec.params):
            needs.append("region={mask}")
        for param in spec.params:
            for label, text in _bad_words(param.kind, param.hard_range):
                others = [w for w in needs if not w.startswith(f"{param.name}=")]
                words = [spec.name, *others, f"{param.name}={text}"]
                named = "no-such-mask.png" if param.kind == "region" else param.name
                cases[f"apply-{spec.name}-{param.name}-{label}"] = Case(
                    ["apply", "{set}", "{out}", "--op", *words], named
                )
                if not spec.inputs:  # a filter layer runs on what is below it: one input
                    cases[f"layer-{spec.name}-{param.name}-{label}"] = Case(
                        ["layer", "add", "{project}", "filter", "--op", *words], named
                    )
        cases[f"apply-{spec.name}-unknown-parameter"] = Case(
            ["apply", "{set}", "{out}", "--op", spec.name, *needs, "sparkle=1"], "sparkle"
        )
    return cases


# ------------------------------------------------------------------ the verbs' own values

STROKE = {"swatch": {"name": "s", "values": {"roughness": [0.4]}}, "points": [[1, 1], [9, 9]]}
PRESET_MAP = {"channel": "rough", "srcMapName": "roughness"}
GOOD_STEP = '[[ops]]\nop = "blur"\nsigma_px = 1\n'


def _stroke(named: str = "", **changes: object) -> Case:
    """`paint` with a stroke file whose one stroke has ``changes`` (the first is named)."""
    named = named or next(iter(changes))
    return Case(
        ["paint", "{project}", "--stroke", "{tmp}/s.json"],
        named,
        {"s.json": {"strokes": [{**STROKE, **changes}]}},
    )


def _preset(named: str, **changes: object) -> Case:
    """`export` with a preset file whose one map has ``changes``."""
    preset = {"name": "mine", "maps": [{**PRESET_MAP, **changes}]}
    return Case(
        ["export", "{set}", "{out}", "--preset-file", "{tmp}/preset.json"],
        named,
        {"preset.json": preset},
    )


VERB_CASES: dict[str, Case] = {
    # load options, shared by every verb that reads a texture set
    "info-space-unknown": Case(["info", "{set}", "--space", "roughness=bogus"], "bogus"),
    "info-space-parameter": Case(["info", "{set}", "--space", "sparkle=ggx"], "sparkle"),
    "info-space-shape": Case(["info", "{set}", "--space", "roughness"], "--space"),
    "info-map-shape": Case(["info", "{set}", "--map", "=x.png"], "--map"),
    "info-map-missing": Case(["info", "{set}", "--map", "roughness={tmp}/nope.png"], "nope.png"),
    "info-material": Case(["info", "{set}", "--material", "nosuch"], "nosuch"),
    "info-path": Case(["info", "{tmp}/nowhere"], "nowhere"),
    "convert-space": Case(["convert", "{set}", "{out}", "--space", "roughness=srgb"], "srgb"),
    "convert-map": Case(["convert", "{set}", "{out}", "--map", "sparkle={mask}"], "sparkle"),
    "render-space": Case(["render", "{set}", "{out}.png", "--space", "roughness=x"], "'x'"),
    "export-space": Case(
        ["export", "{set}", "{out}", "--preset", "gltf", "--space", "roughness=x"], "'x'"
    ),
    "new-space": Case(["new", "{out}.matshop", "--from", "{set}", "--space", "x=ggx"], "'x'"),
    # apply's own options
    "apply-op-unknown": Case(["apply", "{set}", "{out}", "--op", "sharpen"], "sharpen"),
    "apply-params": Case(
        ["apply", "{set}", "{out}", "--op", "blur", "--params", "sparkle"], "sparkle"
    ),
    "apply-mask": Case(
        ["apply", "{set}", "{out}", "--op", "blur", "--mask", "{tmp}/no.png"], "no.png"
    ),
    "apply-setting-shape": Case(["apply", "{set}", "{out}", "--op", "blur", "sigma_px"], "blur"),
    # export
    "export-preset": Case(["export", "{set}", "{out}", "--preset", "unreel"], "unreel"),
    "export-size": Case(["export", "{set}", "{out}", "--preset", "gltf", "--size", "1000"], "1000"),
    "export-both-presets": Case(
        ["export", "{set}", "{out}", "--preset", "gltf", "--preset-file", "{tmp}/p.json"],
        "--preset",
    ),
    "export-keep-variance": Case(
        ["export", "{set}", "{out}", "--preset", "gltf", "--keep-variance"], "--keep-variance"
    ),
    "preset-format": _preset("fileFormat", fileFormat="gif"),
    "preset-depth": _preset("bitDepth", fileFormat="jpeg", bitDepth=16),
    "preset-color-space": _preset("colorSpace", colorSpace="acescg"),
    "preset-channel-name": _preset("channel", channel="../up"),
    "preset-template": _preset("fileName", fileName="{material}_{nope}.{ext}"),
    "preset-flag": _preset("'optional'", optional="sometimes"),
    "preset-channels": _preset(
        "destChannel", srcMapName=None, channels=[{"destChannel": "G", "value": 1}]
    ),
    "preset-transform": _preset(
        "transform",
        srcMapName=None,
        channels=[{"destChannel": "R", "srcMapName": "roughness", "transform": "sqrt"}],
    ),
    "preset-convention": Case(
        ["export", "{set}", "{out}", "--preset-file", "{tmp}/p.json"],
        "normalConvention",
        {"p.json": {"name": "x", "normalConvention": "vulkan", "maps": [PRESET_MAP]}},
    ),
    # render
    "render-size": Case(["render", "{set}", "{out}.png", "--size", "0"], "--size"),
    "render-samples": Case(["render", "{set}", "{out}.png", "--samples", "99999"], "--samples"),
    "render-exposure": Case(["render", "{set}", "{out}.png", "--exposure", "nan"], "--exposure"),
    "render-tiles": Case(["render", "{set}", "{out}.png", "--tiles", "0"], "--tiles"),
    "render-light-zero": Case(["render", "{set}", "{out}.png", "--light", "0,0,0"], "--light"),
    "render-light-text": Case(["render", "{set}", "{out}.png", "--light", "up"], "--light"),
    "render-light-negative": Case(
        ["render", "{set}", "{out}.png", "--light=0,0,1:-1"], "irradiance"
    ),
    "render-background": Case(
        ["render", "{set}", "{out}.png", "--background", "1,2"], "--background"
    ),
    "render-scene": Case(["render", "{set}", "{out}.png", "--scene", "{tmp}/no.obj"], "no.obj"),
    "render-no-env": Case(["render", "{set}", "{out}.png", "--no-env"], "--light"),
    # figures
    "figures-only": Case(["figures", "{out}", "--only", "fig99"], "fig99"),
    # new
    "new-size-text": Case(
        ["new", "{out}.matshop", "--size", "big", "--params", "roughness"], "--size"
    ),
    "new-size-zero": Case(
        ["new", "{out}.matshop", "--size", "0x8", "--params", "roughness"], "0x8"
    ),
    "new-size-huge": Case(
        ["new", "{out}.matshop", "--size", "99999x8", "--params", "roughness"], "99999"
    ),
    "new-params-unknown": Case(
        ["new", "{out}.matshop", "--size", "8x8", "--params", "sparkle"], "sparkle"
    ),
    "new-params-twice": Case(
        ["new", "{out}.matshop", "--size", "8x8", "--params", "roughness,roughness"], "roughness"
    ),
    "new-from-missing": Case(["new", "{out}.matshop", "--from", "{tmp}/nothing"], "nothing"),
    "new-from-and-size": Case(
        ["new", "{out}.matshop", "--from", "{set}", "--size", "8x8"], "--size"
    ),
    # layer add
    "add-opacity-above": Case(["layer", "add", "{project}", "paint", "--opacity", "2"], "opacity"),
    "add-opacity-nan": Case(["layer", "add", "{project}", "paint", "--opacity", "nan"], "opacity"),
    "add-blend": Case(["layer", "add", "{project}", "paint", "--blend", "screen"], "screen"),
    "add-group-blend": Case(
        ["layer", "add", "{project}", "group", "--blend", "multiply"], "normal"
    ),
    "add-params": Case(["layer", "add", "{project}", "paint", "--params", "sparkle"], "sparkle"),
    "add-params-none": Case(["layer", "add", "{project}", "paint", "--params", ","], "at least"),
    "add-index": Case(["layer", "add", "{project}", "paint", "--index", "99"], "--index"),
    "add-group-missing": Case(["layer", "add", "{project}", "paint", "--group", "Nope"], "Nope"),
    "add-group-not-group": Case(
        ["layer", "add", "{project}", "paint", "--group", "Paint"], "not a group"
    ),
    "add-fill-text": Case(
        ["layer", "add", "{project}", "fill", "--value", "roughness=rough"], "roughness"
    ),
    "add-fill-parameter": Case(
        ["layer", "add", "{project}", "fill", "--value", "sheen=1"], "sheen"
    ),
    "add-fill-channels": Case(
        ["layer", "add", "{project}", "fill", "--value", "base_color=0.5"], "base_color"
    ),
    "add-fill-infinite": Case(
        ["layer", "add", "{project}", "fill", "--value", "roughness=1e400"], "roughness"
    ),
    "add-fill-nan": Case(
        ["layer", "add", "{project}", "fill", "--value", "roughness=nan"], "roughness"
    ),
    "add-fill-shape": Case(
        ["layer", "add", "{project}", "fill", "--value", "roughness"], "--value"
    ),
    "add-filter-unknown": Case(
        ["layer", "add", "{project}", "filter", "--op", "sharpen"], "sharpen"
    ),
    "add-mask-missing": Case(
        ["layer", "add", "{project}", "paint", "--mask", "{tmp}/no.png"], "no.png"
    ),
    "add-generator-unknown": Case(
        ["layer", "add", "{project}", "paint", "--mask-generator", "rust"], "rust"
    ),
    "add-generator-radius": Case(
        ["layer", "add", "{project}", "paint", "--mask-generator", "cavity", "radius_px=0"],
        "radius_px",
    ),
    "add-generator-blur": Case(
        ["layer", "add", "{project}", "paint", "--mask-generator", "edge", "blur_px=1000"],
        "blur_px",
    ),
    "add-generator-text": Case(
        ["layer", "add", "{project}", "paint", "--mask-generator", "ao", "level=high"], "level"
    ),
    "add-generator-invert": Case(
        ["layer", "add", "{project}", "paint", "--mask-generator", "ao", "invert=maybe"],
        "invert",
    ),
    # layer set / remove / list
    "set-opacity-above": Case(["layer", "set", "{project}", "Paint", "opacity=1.5"], "opacity"),
    "set-opacity-text": Case(["layer", "set", "{project}", "Paint", "opacity=half"], "opacity"),
    "set-visible": Case(["layer", "set", "{project}", "Paint", "visible=maybe"], "visible"),
    "set-blend": Case(["layer", "set", "{project}", "Paint", "blend=screen"], "screen"),
    "set-group-blend": Case(["layer", "set", "{project}", "Group", "blend=add"], "normal"),
    "set-parameters": Case(["layer", "set", "{project}", "Paint", "parameters=sheen"], "sheen"),
    "set-property": Case(["layer", "set", "{project}", "Paint", "sparkle=1"], "sparkle"),
    "set-shape": Case(["layer", "set", "{project}", "Paint", "opacity"], "KEY=VALUE"),
    "set-layer": Case(["layer", "set", "{project}", "Nope", "opacity=1"], "Nope"),
    "set-layer-id": Case(["layer", "set", "{project}", "99", "opacity=1"], "99"),
    "remove-layer": Case(["layer", "remove", "{project}", "Nope"], "Nope"),
    "list-project": Case(["layer", "list", "{tmp}/none.matshop"], "none.matshop"),
    # paint: every field of a stroke
    "stroke-mode": _stroke(mode="smudge"),
    "stroke-target": _stroke(target="alpha"),
    "stroke-mask-value-range": _stroke("mask value", mask_value=2),
    "stroke-mask-value-text": _stroke(mask_value="opaque"),
    "stroke-clone-offset": _stroke(clone_offset=[1, "x"]),
    "stroke-clone-offset-far": _stroke("clone offset", mode="clone", clone_offset=[1e9, 0]),
    "stroke-wrap": _stroke(wrap="yes"),
    "stroke-layer": _stroke(layer=[1]),
    "stroke-layer-missing": _stroke(layer="Nope"),
    "stroke-layer-kind": _stroke(layer="Group"),
    "stroke-points": _stroke("pressure", points=[[1, 1, 2]]),
    "stroke-point-text": _stroke("bad point", points=[[1, "x"]]),
    "stroke-brush-radius": _stroke(brush={"radius_px": -1}),
    "stroke-brush-text": _stroke(brush={"hardness": "soft"}),
    "stroke-brush-setting": _stroke(brush={"sparkle": 1}),
    "stroke-brush-pressure": _stroke("pressure curve", brush={"size_pressure": [[0, 0], [2, 1]]}),
    "stroke-swatch-text": _stroke(swatch={"name": "s", "values": {"roughness": ["x"]}}),
    "stroke-swatch-nested": _stroke(swatch={"name": "s", "values": {"roughness": [[0.1, 0.2]]}}),
    "stroke-swatch-parameter": _stroke(swatch={"name": "s", "values": {"sheen": [1]}}),
    "stroke-swatch-shape": _stroke(swatch=[0.4]),
    "stroke-key": _stroke(sparkle=True),
    # the other project verbs
    "paint-layer": Case(
        ["paint", "{project}", "--stroke", "{tmp}/s.json", "--layer", "Nope"],
        "Nope",
        {"s.json": {"strokes": [STROKE]}},
    ),
    "recover-nothing": Case(["recover", "{project}"], "autosave"),
    "flatten-project": Case(["flatten", "{tmp}/none.matshop", "{out}"], "none.matshop"),
    "demo-sample": Case(["demo", "{tmp}/no-sample", "--out", "{out}"], "no-sample"),
    # batch: the recipe is checked before any set is read
    "batch-op-value": Case(
        ["batch", "{tmp}/r.toml", "{set}", "{out}"],
        "sigma_px",
        {"r.toml": '[[ops]]\nop = "blur"\nsigma_px = -1\n'},
    ),
    "batch-op-unknown": Case(
        ["batch", "{tmp}/r.toml", "{set}", "{out}"],
        "sharpen",
        {"r.toml": '[[ops]]\nop = "sharpen"\n'},
    ),
    "batch-preset": Case(
        ["batch", "{tmp}/r.toml", "{set}", "{out}", "--preset", "unreel"],
        "unreel",
        {"r.toml": GOOD_STEP},
    ),
    "batch-size": Case(
        ["batch", "{tmp}/r.toml", "{set}", "{out}", "--preset", "gltf", "--size", "1000"],
        "1000",
        {"r.toml": GOOD_STEP},
    ),
}

CASES = {**_op_cases(), **VERB_CASES}


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_the_cases_reach_every_verb_that_takes_a_value() -> None:
    from matshop.cli.registry import VERBS

    reached = {case.argv[0] for case in CASES.values()}
    # ops, spaces and warm-up take no value; open starts the editor (its path is checked there)
    assert reached == set(VERBS) - {"ops", "spaces", "warm-up", "open"}


@pytest.mark.parametrize("case", list(CASES))
def test_a_bad_value_is_one_line_exit_2_and_writes_nothing(
    case: str, world: dict[str, Path], tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    spec = CASES[case]
    project = tmp_path / "p.matshop"
    project.write_bytes(world["project"].read_bytes())
    for name, content in spec.files.items():
        text = content if isinstance(content, str) else json.dumps(content)
        (tmp_path / name).write_text(text, encoding="utf-8")
    names = {**world, "project": project, "out": tmp_path / "out", "tmp": tmp_path}
    argv = [word.format(**names) for word in spec.argv]
    before = {"tmp": _tree(tmp_path), "world": _tree(world["set"].parent)}
    capfd.readouterr()

    status = main(argv)

    err = capfd.readouterr().err
    assert status == 2, err
    assert err.startswith("matshop: error: ") and err.count("\n") == 1, err
    assert spec.named in err, err
    after = {"tmp": _tree(tmp_path), "world": _tree(world["set"].parent)}
    assert after == before  # no output, no partial file, the project untouched
