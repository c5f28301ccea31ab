"""`matshop apply` and the Python API run the same engine, and refuse bad input cleanly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import matshop
from matshop.cli import main
from matshop.io.images import read_image, write_image
from matshop.ops.blur import gaussian_blur

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def test_api_and_cli_write_identical_files(tmp_path: Path) -> None:
    mask = np.linspace(0, 1, 512, dtype=np.float32)[None, :].repeat(512, axis=0)
    write_image(tmp_path / "mask.png", mask[..., None], bit_depth="uint16")
    m = matshop.open(SAMPLE)
    m.apply("blur", sigma_px=3, params=["normal", "roughness"], mask=tmp_path / "mask.png")
    m.apply("scale", factor=0.5, params="kd")
    m.save(tmp_path / "api")
    argv = [
        "apply",
        str(SAMPLE),
        str(tmp_path / "cli"),
        "--mask",
        str(tmp_path / "mask.png"),
        "--op",
        "blur",
        "sigma_px=3",
        "--params",
        "normal,roughness",
    ]
    assert main(argv) == 0
    argv = [
        "apply",
        str(tmp_path / "cli"),
        str(tmp_path / "cli2"),
        "--op",
        "scale",
        "factor=0.5",
        "--params",
        "kd",
    ]
    assert main(argv) == 0
    # the two-step CLI went through 8-bit files in between, so compare the first step exactly
    m1 = matshop.open(SAMPLE).apply(
        "blur", sigma_px=3, params=["normal", "roughness"], mask=tmp_path / "mask.png"
    )
    m1.save(tmp_path / "api1")
    assert _files(tmp_path / "api1") == _files(tmp_path / "cli")
    assert [h[0] for h in m.history] == ["blur", "scale"]


def test_api_apply_equals_the_op_on_the_edit_array() -> None:
    m = matshop.open(SAMPLE)
    before = m.edit.data.copy()
    m.apply("blur", sigma_px=2.5, params="normal")
    expected = gaussian_blur(before, sigma_px=2.5, schema=m.schema, params=["normal"])
    assert np.array_equal(m.edit.data, expected)


def test_composite_over_another_set_only_changes_its_parameters(tmp_path: Path) -> None:
    # a "rust" set that has only a base color
    rust = tmp_path / "rust"
    rust.mkdir()
    write_image(rust / "rust_basecolor.png", np.tile([[[0.6, 0.25, 0.1]]], (512, 512, 1)))
    m = matshop.open(SAMPLE)
    before = m.edit.data.copy()
    ramp = np.linspace(0, 1, 512, dtype=np.float32)[None, :].repeat(512, axis=0)
    m.apply("composite", over=rust, mask=ramp)
    color = m.schema.edit_slices["base_color"]
    rest = np.setdiff1d(np.arange(m.schema.edit_width), np.arange(color.start, color.stop))
    assert np.array_equal(m.edit.data[..., rest], before[..., rest])
    rust_linear = matshop.open(rust).edit.data[0, 0]
    assert np.allclose(m.edit.data[:, -1, color], rust_linear, atol=1e-6)
    assert np.array_equal(m.edit.data[:, 0, color], before[:, 0, color])


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--op", "sharpen"], "unknown op 'sharpen'"),
        (["--op", "blur", "sigma_px=-2"], "outside"),
        (["--op", "blur", "sigma_px"], "expected key=value"),
        (["--op", "blur", "--params", "sheen"], "no parameter 'sheen'"),
        (["--op", "blur", "--mask", "MASK"], "mask is 8x8"),
        (["--op", "composite"], "needs over="),
    ],
)
def test_bad_apply_requests_exit_2_and_write_nothing(
    extra: list[str], expected: str, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    small = tmp_path / "mask.png"
    write_image(small, np.zeros((8, 8, 1), np.float32))
    extra = [str(small) if e == "MASK" else e for e in extra]
    out = tmp_path / "out"
    assert main(["apply", str(SAMPLE), str(out), *extra]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0], err
    if "MASK" in extra or "mask" in expected:
        assert "mask.png" in err[0]
    assert not out.exists()


def test_masked_result_is_written_through_from_edit(tmp_path: Path) -> None:
    assert (
        main(
            [
                "apply",
                str(SAMPLE),
                str(tmp_path / "o"),
                "--op",
                "scale",
                "factor=0",
                "--params",
                "normal",
            ]
        )
        == 0
    )
    normal, _ = read_image(tmp_path / "o" / "tiles_normal_gl.png")
    # scaling the frame by 0 flattens every normal to +z: (0.5, 0.5, 1) in the file
    assert np.abs(normal - [0.5, 0.5, 1.0]).max() <= 1 / 255


def test_cli_composite_over_a_path_equals_the_api(tmp_path: Path) -> None:
    rust = tmp_path / "rust"
    rust.mkdir()
    write_image(rust / "rust_basecolor.png", np.tile([[[0.6, 0.25, 0.1]]], (512, 512, 1)))
    argv = ["apply", str(SAMPLE), str(tmp_path / "cli"), "--op", "composite"]
    assert main([*argv, f"over={rust}", "opacity=0.5"]) == 0
    matshop.open(SAMPLE).apply("composite", over=rust, opacity=0.5).save(tmp_path / "api")
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")


def test_cli_clone_from_another_set_of_another_size(tmp_path: Path) -> None:
    # a 96x64 source set of a constant color: the cloned square takes its
    # color in the interior and stays seamless at the boundary
    source = tmp_path / "src"
    source.mkdir()
    write_image(source / "src_basecolor.png", np.tile([[[0.2, 0.6, 0.3]]], (64, 96, 1)))
    argv = [
        "apply",
        str(SAMPLE),
        str(tmp_path / "cli"),
        "--op",
        "clone",
        f"source={source}",
        "region=8,8;56,8;56,56;8,56",
        "offset=100,200",
        "--params",
        "base_color",
    ]
    assert main(argv) == 0
    api = matshop.open(SAMPLE).apply(
        "clone",
        source=source,
        region=[(8, 8), (56, 8), (56, 56), (8, 56)],
        offset=(100, 200),
        params="base_color",
    )
    api.save(tmp_path / "api")
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")
    before = matshop.open(SAMPLE)
    after = matshop.open(tmp_path / "cli")
    # outside the pasted square nothing changed (to one 8-bit code)
    outside = np.ones((512, 512), bool)
    outside[200:256, 100:156] = False
    diff = np.abs(after.edit["base_color"] - before.edit["base_color"])
    assert diff[outside].max() <= 1 / 255 + 1e-6
    # with a constant source and a convex region, MVC makes the interior a convex
    # combination of the target's values on the boundary (the weights are positive)
    inside = after.edit["base_color"][201:255, 101:155].reshape(-1, 3)
    ring = np.ones((56, 56), bool)
    ring[1:-1, 1:-1] = False
    boundary = before.edit["base_color"][200:256, 100:156][ring]
    assert np.all(inside >= boundary.min(axis=0) - 1 / 255)
    assert np.all(inside <= boundary.max(axis=0) + 1 / 255)
