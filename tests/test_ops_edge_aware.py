"""The bilateral and detail ops on edit materials: what the paper says they do."""

from __future__ import annotations

import numpy as np

from matshop.material import Material, Schema
from matshop.ops.bilateral_ops import bilateral, detail

RNG = np.random.default_rng(7)
SIZE = 64


def two_materials(noise: float) -> tuple[Material, np.ndarray]:
    """Steel (left) next to rust (right): a step in color, roughness and normals, plus noise."""
    schema = Schema.from_names(["base_color", "roughness", "normal", "metallic"])
    right = np.zeros((SIZE, SIZE), bool)
    right[:, SIZE // 2 :] = True
    color = np.where(right[..., None], [0.45, 0.18, 0.07], [0.56, 0.57, 0.58])
    roughness = np.where(right, 0.8, 0.25)[..., None]
    metallic = np.where(right, 0.0, 1.0)[..., None]
    # flat on the steel, ridges along y on the rust (tilted about the y axis)
    tilt = np.where(right, 0.5 * np.sin(np.arange(SIZE) / 3.0)[None, :], 0.0)
    normal = np.stack([np.sin(tilt), np.zeros_like(tilt), np.cos(tilt)], axis=-1)
    maps = {
        "base_color": color + noise * RNG.standard_normal(color.shape),
        "roughness": roughness + noise * RNG.standard_normal(roughness.shape),
        "metallic": metallic,
    }
    maps = {k: np.clip(v, 0.01, 1).astype(np.float32) for k, v in maps.items()}
    maps["normal"] = normal.astype(np.float32)
    return Material("pair", schema, maps), right


def test_bilateral_keeps_the_step_between_two_materials_and_smooths_the_noise() -> None:
    clean, right = two_materials(noise=0.0)
    noisy, _ = two_materials(noise=0.03)
    clean_edit = clean.to_edit()
    noisy_edit = noisy.to_edit()
    schema = noisy_edit.schema
    params = ["base_color", "roughness"]
    smoothed = bilateral(
        noisy_edit.data, sigma_px=3, sigma_range=0.15, border="clamp", schema=schema, params=params
    )
    roughness = schema.edit_slices["roughness"]
    error_before = np.abs(noisy_edit.data[..., roughness] - clean_edit.data[..., roughness])
    error_after = np.abs(smoothed[..., roughness] - clean_edit.data[..., roughness])
    # noise is reduced everywhere, right at the edge too (a Gaussian blur would smear
    # the 0.55-wide roughness step over several texels and the error there would be ~0.25)
    edge = np.zeros_like(right)
    edge[:, SIZE // 2 - 2 : SIZE // 2 + 2] = True
    assert error_after.mean() < 0.5 * error_before.mean()
    assert error_after[edge].max() < 0.05
    # unselected parameters are untouched
    normal = schema.edit_slices["normal"]
    assert np.array_equal(smoothed[..., normal], noisy_edit.data[..., normal])


def test_detail_leaves_a_constant_region_unchanged_and_amplifies_the_bumps() -> None:
    material, right = two_materials(noise=0.0)
    edit = material.to_edit()
    schema = edit.schema
    enhanced = detail(
        edit.data, amount=1.5, sigma_px=4, sigma_range=0.2, border="clamp", schema=schema
    )
    # the steel half is constant: unsharp masking adds exactly nothing there
    # right up to the edge, which a bilateral of this range does not cross
    steel = np.zeros_like(right)
    steel[:, : SIZE // 2] = True
    assert np.abs(enhanced[steel] - edit.data[steel]).max() < 1e-5
    # on the rust half the frame perturbations grow (edit-space frame values are
    # perturbation angles): their spread about the mean increases
    normal = schema.edit_slices["normal"]
    inner = np.zeros_like(right)
    inner[:, SIZE // 2 + 12 :] = True
    before = edit.data[..., normal][inner].std(axis=0).max()
    after = enhanced[..., normal][inner].std(axis=0).max()
    assert before > 0.1
    assert after > 1.3 * before
