"""A small layer stack composited by hand, checked in memory and through the files.

The expected texels are written out below with numpy arithmetic from the
blend formulas of DESIGN.md (alpha-over, multiply, detail, pass-through
groups, masks, inverted masks, parameter limits) and the sRGB transfer
function of CONVENTIONS.md: nothing here comes from matshop's compositor or
from ``flatten_reference``. The same stack is saved as a project, flattened
by the ``matshop flatten`` command and the written files read back with
OpenImageIO.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from oracle import file_codes as _codes
from oracle import srgb_encode

from matshop.cli import main
from matshop.io.project import save_project
from matshop.layers import AddLayer, Document, History, PaintTransaction, Rect, SetMask
from matshop.material import Schema

SCHEMA = Schema.from_names(["base_color", "metallic", "ao"])  # 3 + 1 + 1 edit channels
BC, MET, AO = slice(0, 3), 3, 4


def build() -> Document:
    """1 x 4 texels, five layers and a group; every number below is used by ``expected``."""
    doc = Document(SCHEMA, 1, 4, tile_size=2, name="oracle")
    history = History(doc)
    vec = lambda bc, met, ao: np.array([*bc, met, ao], np.float32)  # noqa: E731
    push = lambda layer: history.push(AddLayer(layer))  # noqa: E731
    push(doc.new_fill_layer("base", value=vec((0.2, 0.4, 0.6), 0.0, 1.0)))
    rust = doc.new_fill_layer(
        "rust",
        value=vec((0.5, 0.1, 0.05), 1.0, 0.5),
        opacity=0.5,
        parameters=["base_color", "metallic"],
    )
    push(rust)
    mask = doc.new_mask(array=np.array([[[1.0], [0.5], [0.0], [1.0]]], np.float32))
    history.push(SetMask(rust.id, mask))
    group = doc.new_group_layer("wear", opacity=0.8)
    push(group)
    member = doc.new_fill_layer(
        "dark", value=vec((0.5, 0.5, 0.5), 0.2, 0.25), blend="multiply", parent=group.id
    )
    history.push(AddLayer(member, 2))  # just below its group
    detail = np.array([[[0, 0, 0, 0, 0.1], [0, 0, 0, 0, 0.3], [0, 0, 0, 0, 0.2], [0] * 4 + [0.4]]])
    push(
        doc.new_fill_layer(
            "grain", source=detail.astype(np.float32), blend="detail", parameters=["ao"]
        )
    )
    clean = doc.new_fill_layer(
        "clean", value=vec((0, 0, 0), 0.3, 0), parameters=["metallic"], mask_inverted=True
    )
    push(clean)
    mask = doc.new_mask(array=np.array([[[1.0], [1.0], [0.0], [0.0]]], np.float32))
    history.push(SetMask(clean.id, mask))
    painted = doc.new_paint_layer("scratch", parameters=["base_color"])
    push(painted)
    tx = PaintTransaction(doc, painted.id)
    tx.paint(Rect(1, 0, 3, 1), vec((1.0, 1.0, 1.0), 0, 0), np.array([[0.25, 0.5]], np.float32))
    history.push(tx.commit(), applied=True)
    return doc


def expected() -> np.ndarray:
    """The composite in edit space, texel by texel, by the formulas alone."""
    e = np.zeros((4, 5))
    e[:, BC], e[:, MET], e[:, AO] = (0.2, 0.4, 0.6), 0.0, 1.0
    # rust: normal blend, weight = mask x opacity, only base color and metallic
    w = np.array([1.0, 0.5, 0.0, 1.0]) * 0.5
    rust = np.array([0.5, 0.1, 0.05, 1.0])
    e[:, :4] = (1 - w)[:, None] * e[:, :4] + w[:, None] * rust
    # the group: its member multiplies every parameter at full weight, then the
    # group mixes that with its input by its opacity 0.8
    members = e * np.array([0.5, 0.5, 0.5, 0.2, 0.25])
    e = 0.2 * e + 0.8 * members
    # detail on ao: add the layer's deviation from its mean (0.25)
    e[:, AO] += np.array([0.1, 0.3, 0.2, 0.4]) - 0.25
    # clean: inverted mask [0, 0, 1, 1], metallic only, normal blend to 0.3
    shown = np.array([0.0, 0.0, 1.0, 1.0])
    e[:, MET] = (1 - shown) * e[:, MET] + shown * 0.3
    # scratch: white painted on texels 1 and 2 with alpha 0.25 and 0.5, base color only
    a = np.array([0.0, 0.25, 0.5, 0.0])
    e[:, BC] = (1 - a)[:, None] * e[:, BC] + a[:, None] * 1.0
    return e


def test_stack_flattens_to_the_hand_computed_texels() -> None:
    doc = build()
    got = doc.flatten_edit()[0].astype(np.float64)
    np.testing.assert_allclose(got, expected(), atol=2e-6)
    physical = doc.flatten_physical().maps
    want = expected()
    np.testing.assert_allclose(physical["base_color"][0], srgb_encode(want[:, BC]), atol=2e-6)
    np.testing.assert_allclose(physical["metallic"][0, :, 0], want[:, MET], atol=2e-6)
    np.testing.assert_allclose(physical["ao"][0, :, 0], np.clip(want[:, AO], 0, 1), atol=2e-6)


def test_the_saved_project_flattens_to_the_same_texels_on_disk(tmp_path: Path) -> None:
    project = tmp_path / "oracle.matshop"
    save_project(build(), project)
    assert main(["flatten", str(project), str(tmp_path / "out")]) == 0
    want = expected()
    files = {p.name: p for p in (tmp_path / "out").iterdir()}
    assert sorted(files) == ["oracle_ao.png", "oracle_basecolor.png", "oracle_metallic.png"]
    codes = {
        "basecolor": np.rint(srgb_encode(want[:, BC]) * 255),
        "metallic": np.rint(want[:, MET] * 255),
        "ao": np.rint(np.clip(want[:, AO], 0, 1) * 255),
    }
    for tag, code in codes.items():
        written = _codes(files[f"oracle_{tag}.png"])[0]
        written = written if written.ndim == 2 else written[:, None]
        # 8-bit files are dithered: one code either way
        assert np.abs(written[:, : code.reshape(4, -1).shape[1]] - code.reshape(4, -1)).max() <= 1


GOLDEN = Path(__file__).parent / "data" / "oracle_format1.matshop"


def test_a_committed_format_1_project_still_flattens_to_the_hand_computed_texels() -> None:
    """tests/data/oracle_format1.matshop was written once by matshop 0.1 (format 1) from
    :func:`build` and is never rewritten: every later version must read it the same."""
    from matshop.io.project import load_project

    project = load_project(GOLDEN)
    assert project.format_version == 1
    doc = project.document
    assert [layer.name for layer in doc.layers] == [
        "base", "rust", "dark", "wear", "grain", "clean", "scratch"
    ]  # fmt: skip
    np.testing.assert_allclose(doc.flatten_edit()[0].astype(np.float64), expected(), atol=2e-6)
