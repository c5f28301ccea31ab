"""``keep_variance`` on ``bilateral`` and ``detail`` against closed forms.

The truth is worked out by hand from the tilts each test builds: a texel whose
averaging gives weight ``p`` to tilt ``a`` and ``1 - p`` to tilt ``b`` loses the
slope variance ``p (1 - p) |s_a - s_b|^2``; the plain ops' own results (without
the option) are the truth for every channel the option must not touch.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_variance import HAND_TRACE, TILT_A, TILT_B, _checker, _edit, _phys, _tilted, _write_set

from matshop.cli import main
from matshop.io.images import read_image
from matshop.material import Schema
from matshop.ops import get_op

SIZE = 32
# range weights ~1 across the two tilts: the filter is a plain spatial average
WIDE_RANGE = 100.0


def _run(op: str, schema: Schema, edit: np.ndarray, **values) -> np.ndarray:
    spec = get_op(op)
    params = values.pop("params", None)
    return spec.function(edit, schema=schema, params=params, **spec.bind(values))


def _material(normal: np.ndarray, r: float = 0.4) -> tuple[Schema, np.ndarray]:
    schema = Schema.from_names(["base_color", "roughness", "normal"])
    size = normal.shape[0]
    rough = np.full((size, size, 1), r, np.float32)
    color = np.random.default_rng(2).uniform(0, 1, (size, size, 3)).astype(np.float32)
    return schema, _edit(schema, base_color=color, roughness=rough, normal=normal)


@pytest.mark.parametrize("op", ["bilateral", "detail"])
def test_constant_tilt_adds_nothing_bit_for_bit(op: str) -> None:
    normal = np.broadcast_to(_tilted(0.3, -0.2), (SIZE, SIZE, 3)).astype(np.float32)
    schema, edit = _material(normal)
    rng = np.random.default_rng(3)
    edit[..., schema.edit_slices["roughness"]] = rng.uniform(-2, 0, (SIZE, SIZE, 1))
    values = {"sigma_px": 3.0, "sigma_range": 0.3}
    if op == "detail":
        values["amount"] = -0.7
    kept = _run(op, schema, edit, keep_variance=True, **values)
    # the moments ride in the same lattice pass: every channel is the plain op's, exactly
    assert np.array_equal(kept, _run(op, schema, edit, **values))


def test_two_tilt_checkerboard_smoothed_to_uniform_adds_their_variance() -> None:
    schema, edit = _material(_checker(_tilted(*TILT_A), _tilted(*TILT_B), SIZE))
    values = {"sigma_px": 8.0, "sigma_range": WIDE_RANGE, "params": ["normal", "base_color"]}
    kept = _run("bilateral", schema, edit, keep_variance=True, **values)
    plain = _run("bilateral", schema, edit, **values)
    # smoothed to uniform: each texel averages the two tilts half and half
    np.testing.assert_allclose(_phys(schema, plain, "roughness"), 0.4, atol=1e-6)
    np.testing.assert_allclose(
        _phys(schema, kept, "roughness"), (0.4**4 + HAND_TRACE) ** 0.25, rtol=2e-3
    )
    others = np.ones(edit.shape[2], bool)
    others[schema.edit_slices["roughness"]] = False
    assert np.array_equal(kept[..., others], plain[..., others])


@pytest.mark.parametrize("amount", [-1.0, -0.5])
def test_detail_smoothing_adds_the_variance_of_its_mix(amount: float) -> None:
    schema, edit = _material(_checker(_tilted(*TILT_A), _tilted(*TILT_B), SIZE))
    values = {"sigma_px": 8.0, "sigma_range": WIDE_RANGE, "amount": amount}
    kept = _run("detail", schema, edit, keep_variance=True, params="normal", **values)
    # (1 - t) own + t uniform: weight p = 1 - t/2 on the texel's own tilt
    t = -amount
    p = 1 - t / 2
    lost = p * (1 - p) * 4 * HAND_TRACE  # HAND_TRACE = |s_a - s_b|^2 / 4
    np.testing.assert_allclose(_phys(schema, kept, "roughness"), (0.4**4 + lost) ** 0.25, rtol=2e-3)


def test_detail_adding_detail_loses_nothing() -> None:
    schema, edit = _material(_checker(_tilted(*TILT_A), _tilted(*TILT_B), SIZE))
    values = {"sigma_px": 4.0, "sigma_range": 0.5, "amount": 1.5}
    kept = _run("detail", schema, edit, keep_variance=True, **values)
    assert np.array_equal(kept, _run("detail", schema, edit, **values))


def test_an_edge_in_the_guide_keeps_the_flat_side_unwidened() -> None:
    # left half: the two-tilt checkerboard; right half: one tilt and a far colour.
    # The range guide keeps the halves apart, so the right side loses nothing.
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B), SIZE)
    normal[:, SIZE // 2 :] = _tilted(*TILT_A)
    schema, edit = _material(normal)
    color = np.zeros((SIZE, SIZE, 3), np.float32)
    color[:, SIZE // 2 :] = 1.0
    edit[..., schema.edit_slices["base_color"]] = schema["base_color"].space.to_edit(color)
    values = {"sigma_px": 2.0, "sigma_range": 0.05, "params": ["normal", "base_color"]}
    kept = _phys(schema, _run("bilateral", schema, edit, keep_variance=True, **values), "roughness")
    inner = slice(SIZE // 2 + 8, SIZE - 8)  # away from the wrapped seams
    np.testing.assert_allclose(kept[:, inner], 0.4, atol=1e-5)
    assert np.all(kept[:, 4:12] > 0.4 + 1e-3)  # the checkerboard side is widened
    assert np.all(kept >= 0.4 - 1e-6)


def test_apply_cli_bilateral_keep_variance_on_files(tmp_path: Path) -> None:
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    _write_set(tmp_path / "in", normal, 0.3, SIZE)
    out = tmp_path / "out"
    argv = ["apply", str(tmp_path / "in"), str(out), "--op", "bilateral", "sigma_px=8"]
    argv += [f"sigma_range={WIDE_RANGE:g}", "keep_variance=true", "--params", "normal"]
    assert main(argv) == 0
    (rough_file,) = out.glob("*roughness*")
    np.testing.assert_allclose(
        read_image(rough_file)[0], (0.3**4 + HAND_TRACE) ** 0.25, rtol=2e-3
    )
    src, _ = read_image(tmp_path / "in" / "v_basecolor.png")
    (color_file,) = out.glob("*basecolor*")
    assert np.array_equal(read_image(color_file)[0], src)
